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
