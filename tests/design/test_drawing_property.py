"""Property: a random valid pattern, drawn in a random CAD style, imports to the same cuts.

Styles (as labs draw): closed LWPOLYLINEs, old-style POLYLINEs, loose LINEs or
scaled block INSERTs; mm or inch; the outline anywhere in the drawing; cuts
crossing the seam split into pieces on the sheet or drawn whole past its edge.
The truth is the pattern built from YAML data (independent of the reader).
Hypothesis runs derandomized: no test depends on the example database or luck.
"""
from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from camtube.design.contour import cut_contours, split_at_seam
from camtube.design.drawing import load_drawing
from camtube.design.loader import build
from camtube.design.source import DrawingOptions
from camtube.errors import PatternError
from examples.dxf.make_examples import Sheet, draw_outline, draw_polygon


@st.composite
def valid_patterns(draw):
    ro = draw(st.floats(0.5, 1.5))
    circ = 2 * math.pi * ro
    n = draw(st.integers(1, 6))
    h = draw(st.floats(0.2, 0.6))
    c = draw(st.floats(0.25, 0.8))
    s = draw(st.floats(0.2 * circ, circ - 0.4))
    first = draw(st.floats(0.3, 1.0))
    length = first + n * h + (n - 1) * c + 1.0
    notch = {"layout": draw(st.sampled_from(["uan", "bidirectional"])), "count": n, "width": h, "spacing": c,
             "arc": s, "first_offset": first, "angle_deg": draw(st.floats(0, 359.9))}
    raw = {"tube": {"outer_radius": ro, "inner_radius": 0.6 * ro, "length": length}, "notch": notch}
    if draw(st.booleans()):
        raw["holes"] = [{"x": length - 0.5, "size": 0.3, "angle_deg": draw(st.floats(0, 359.9))}]
    return raw


styles = st.fixed_dictionaries({
    "units": st.sampled_from(["mm", "inch"]),
    "origin": st.tuples(st.floats(-50, 50), st.floats(-50, 50)),
    "entity": st.sampled_from(["lwpolyline", "polyline", "lines", "block"]),
    "seam": st.sampled_from(["split", "whole"]),
    "outline_layer": st.sampled_from(["0", "CONSTRUCTION"]),
})


def draw_pattern(pattern, style, path):
    sheet = Sheet(units=style["units"], origin=style["origin"])
    draw_outline(sheet, layer=style["outline_layer"], length=pattern.tube.length_mm,
                 circ=pattern.tube.circumference_mm)
    if style["entity"] == "block":
        unit = sheet.doc.blocks.new("CUT")  # a unit square, placed by scaled INSERTs
        unit.add_lwpolyline([(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)], close=True)
    circ = pattern.tube.circumference_mm
    for con in cut_contours(pattern):
        pieces = split_at_seam(con, circ) if style["seam"] == "split" else (con,)
        layer = "NOTCHES" if con.kind == "notch" else "HOLES"
        for piece in pieces:
            x0, y0, x1, y1 = piece.bounds
            if style["entity"] == "block":
                sheet.msp.add_blockref("CUT", sheet.at(0.5 * (x0 + x1), 0.5 * (y0 + y1)), dxfattribs={
                    "layer": layer, "xscale": sheet.length(x1 - x0), "yscale": sheet.length(y1 - y0)})
            else:
                draw_polygon(sheet, piece.points, layer, style["entity"])
    sheet.doc.saveas(path)


@settings(max_examples=60, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(raw=valid_patterns(), style=styles)
def test_random_patterns_in_random_styles_import_to_the_same_cuts(tmp_path, raw, style):
    try:
        pattern = build(raw).pattern
    except PatternError:
        assume(False)  # only valid patterns are drawn
    path = tmp_path / "drawn.dxf"
    draw_pattern(pattern, style, path)
    back = load_drawing(path, [], DrawingOptions()).pattern
    t, b = pattern.tube, back.tube
    assert b.outer_radius_mm == pytest.approx(t.outer_radius_mm, abs=1e-9)
    assert b.length_mm == pytest.approx(t.length_mm, abs=1e-9)
    assert len(back.cuts) == len(pattern.cuts)

    def key(c):
        return (c.kind, round(c.x_mm, 6), round(math.radians(c.angle_deg) * t.outer_radius_mm % t.circumference_mm, 5))

    for a, c in zip(sorted(pattern.cuts, key=key), sorted(back.cuts, key=key)):
        assert a.kind == c.kind and not c.is_drawn  # rectangles stay rectangles
        assert (c.x_mm, c.width_mm, c.arc_mm) == pytest.approx((a.x_mm, a.width_mm, a.arc_mm), abs=1e-9)
        d = (a.angle_deg - c.angle_deg) % 360.0
        assert min(d, 360.0 - d) * math.pi / 180 * t.outer_radius_mm < 1e-9


# ---------------------------------------------------------------- round-ended slots: arcs and lines chained
def draw_slot(sheet, xc, yc, width, arc, style, layer="NOTCHES"):
    """A slot ``width`` mm along x, ``arc`` mm around, round ends of radius width/2 at its y ends."""
    r = width / 2.0
    y0, y1 = yc - arc / 2 + r, yc + arc / 2 - r  # centres of the round ends
    if style == "bulges":
        pts = [(xc - r, y0, 0.0), (xc - r, y1, -1.0), (xc + r, y1, 0.0), (xc + r, y0, -1.0)]
        d = [(*sheet.at(x, y), 0.0, 0.0, b) for x, y, b in pts]
        sheet.msp.add_lwpolyline(d, format="xyseb", close=True, dxfattribs={"layer": layer})
    elif style == "arcs_and_lines":  # how a CAD user draws a slot: two LINEs and two ARCs
        k = sheet.length(1.0)
        sheet.msp.add_line(sheet.at(xc - r, y0), sheet.at(xc - r, y1), dxfattribs={"layer": layer})
        sheet.msp.add_line(sheet.at(xc + r, y1), sheet.at(xc + r, y0), dxfattribs={"layer": layer})
        sheet.msp.add_arc(sheet.at(xc, y1), r * k, 0.0, 180.0, dxfattribs={"layer": layer})
        sheet.msp.add_arc(sheet.at(xc, y0), r * k, 180.0, 360.0, dxfattribs={"layer": layer})
    else:
        raise ValueError(style)


@settings(max_examples=25, deadline=None, derandomize=True, database=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(n=st.integers(1, 4), width=st.floats(0.2, 0.6), arc=st.floats(1.0, 3.0), angle=st.floats(90, 270),
       style=st.sampled_from(["bulges", "arcs_and_lines"]), units=st.sampled_from(["mm", "inch"]),
       origin=st.tuples(st.floats(-20, 20), st.floats(-20, 20)))
def test_round_ended_slots_import_with_their_exact_area(tmp_path, n, width, arc, angle, style, units, origin):
    ro = 1.0
    circ = 2 * math.pi * ro
    assume(arc > width + 0.05)
    sheet = Sheet(units=units, origin=origin)
    length = 1.0 + n * (width + 0.5)
    draw_outline(sheet, length=length, circ=circ)
    yc = math.radians(angle) * ro  # whole on the sheet: arc / 2 <= 1.5 < yc, circ - yc
    xs = [1.0 + k * (width + 0.5) for k in range(n)]
    for x in xs:
        draw_slot(sheet, x, yc, width, arc, style)
    path = tmp_path / "slots.dxf"
    sheet.doc.saveas(path)
    back = load_drawing(path, [], DrawingOptions()).pattern
    from shapely.geometry import Polygon

    r = width / 2
    exact = width * (arc - 2 * r) + math.pi * r * r
    assert len(back.notches) == n
    if style == "arcs_and_lines":
        assert f"{4 * n} loose entities joined into {n} loop" in load_drawing(path, [], DrawingOptions()).summary
    for x, c in zip(xs, back.notches):
        g = Polygon(c.outline)
        assert g.area == pytest.approx(exact, rel=5e-4)  # chords lie inside the arcs by <= TOL.chord
        assert g.area <= exact + 1e-12
        assert (g.centroid.x, g.centroid.y) == pytest.approx((x, yc), abs=1e-6)
        assert (c.width_mm, c.arc_mm) == pytest.approx((width, arc), abs=1e-6)
        assert c.angle_deg == pytest.approx(angle, abs=1e-6)
