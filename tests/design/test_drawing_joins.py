"""Drawing styles CAD users draw: slits in pieces, degree-1 splines, a cut past the outline."""
from __future__ import annotations

import math

import ezdxf
import numpy as np
import pytest

from camtube.design.contour import cut_contour
from camtube.design.drawing import load_drawing
from camtube.design.source import DrawingOptions
from camtube.errors import PatternError

RO, LENGTH = 0.75, 10.0
HEIGHT = 2 * math.pi * RO


def drawing(tmp_path, add, name="d.dxf"):
    doc = ezdxf.new("R2013", setup=False)
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (LENGTH, 0), (LENGTH, HEIGHT), (0, HEIGHT)], close=True,
                       dxfattribs={"layer": "OUTLINE"})
    add(msp)
    path = tmp_path / name
    doc.saveas(path)
    return path


def slit_points(pattern):
    return [np.asarray(cut_contour(c, RO).points) for c in pattern.slits]


def test_a_straight_slit_broken_at_a_point_is_one_slit(tmp_path):
    path = drawing(tmp_path, lambda m: (m.add_line((4, 1), (4, 2), dxfattribs={"layer": "SLIT"}),
                                        m.add_line((4, 3), (4, 2), dxfattribs={"layer": "SLIT"})))
    p = load_drawing(path, [], DrawingOptions()).pattern
    assert len(p.slits) == 1 and not p.notches
    pts = slit_points(p)[0]
    ends = sorted([tuple(pts[0]), tuple(pts[-1])], key=lambda q: q[1])
    np.testing.assert_allclose(ends, [(4, 1), (4, 3)], atol=1e-6)


def test_a_zig_zag_of_lines_is_one_slit_through_every_vertex_in_order(tmp_path):
    verts = [(6.0, 1.0), (6.2, 1.5), (6.4, 1.0), (6.6, 1.5), (6.8, 1.0)]

    def add(m):
        for k, (a, b) in enumerate(zip(verts, verts[1:])):
            m.add_line(*((b, a) if k % 2 else (a, b)), dxfattribs={"layer": "SLIT"})  # drawn both ways

    p = load_drawing(drawing(tmp_path, add), [], DrawingOptions()).pattern
    assert len(p.slits) == 1
    pts = slit_points(p)[0]
    if pts[0][0] > pts[-1][0]:
        pts = pts[::-1]
    np.testing.assert_allclose(pts, verts, atol=1e-6)


def test_slits_that_only_touch_each_other_sideways_are_still_refused(tmp_path):
    """Joining is end to end: two slits crossing in an X are two overlapping slits, as before."""
    path = drawing(tmp_path, lambda m: (m.add_line((4, 1), (5, 2), dxfattribs={"layer": "SLIT"}),
                                        m.add_line((4, 2), (5, 1), dxfattribs={"layer": "SLIT"})))
    with pytest.raises(PatternError, match="overlaps"):
        load_drawing(path, [], DrawingOptions())


@pytest.mark.parametrize("closed_by", ["flag", "repeated point"])
def test_a_closed_degree_1_spline_is_its_control_polygon(tmp_path, closed_by):
    corners = [(2, 1, 0), (2.5, 1, 0), (2.5, 3, 0), (2, 3, 0)]

    def add(m):
        sp = m.add_spline(dxfattribs={"layer": "NOTCH"})
        sp.dxf.degree = 1
        if closed_by == "flag":
            sp.control_points = corners
            sp.knots = [0, 0, 1, 2, 3, 3]
            sp.closed = True
        else:
            sp.control_points = corners + [corners[0]]
            sp.knots = [0, 0, 1, 2, 3, 4, 4]

    p = load_drawing(drawing(tmp_path, add), [], DrawingOptions()).pattern
    assert len(p.notches) == 1
    c = p.notches[0]
    assert (c.x_mm, c.width_mm, c.arc_mm) == pytest.approx((2.25, 0.5, 2.0))


def test_a_cut_past_a_correct_outline_is_named(tmp_path):
    path = drawing(tmp_path, lambda m: (
        m.add_lwpolyline([(2, 1), (2.5, 1), (2.5, 3), (2, 3)], close=True, dxfattribs={"layer": "NOTCH"}),
        m.add_lwpolyline([(12, 1), (12.5, 1), (12.5, 3), (12, 3)], close=True, dxfattribs={"layer": "NOTCH"})))
    with pytest.raises(PatternError) as err:
        load_drawing(path, [], DrawingOptions())
    msg = str(err.value)
    assert "no tube outline found" not in msg
    assert "on layer OUTLINE" in msg and "lies outside it" in msg and "on layer NOTCH" in msg and "fix:" in msg


def _spline_on_domain(cps, knots, degree, n=400):
    """Points of the B-spline on its domain t_p .. t_n (the textbook's: de Boor)."""
    from ezdxf.math import BSpline

    bs = BSpline(cps, order=degree + 1, knots=knots)
    return np.array([tuple(v)[:2] for v in bs.points(np.linspace(knots[degree], knots[len(cps)], n))])


def test_a_spline_with_unclamped_knots_is_cut_where_it_is_drawn(tmp_path):
    """The bad-input search: a cubic slit with a uniform knot vector (0..9), as some CAD programs write one, drawn
    within y = 1.17..1.33 mm, was cut up to y = 14.7 mm (ezdxf's path runs it over every knot, where it is not
    defined): the beam outside the drawn cut, exit 0."""
    cps = [(2.0, 1.0, 0), (2.5, 1.5, 0), (3.0, 1.0, 0), (3.5, 1.5, 0), (4.0, 1.0, 0), (4.5, 1.5, 0)]
    knots = list(range(10))

    def add(m):
        sp = m.add_spline(dxfattribs={"layer": "SLITS"})
        sp.dxf.degree = 3
        sp.control_points = cps
        sp.knots = knots

    p = load_drawing(drawing(tmp_path, add), [], DrawingOptions()).pattern
    assert len(p.slits) == 1
    got = slit_points(p)[0]
    want = _spline_on_domain(cps, knots, 3)
    # every cut point on the drawn curve, and the cut from its start to its end
    from shapely.geometry import LineString, Point

    curve = LineString(want)
    assert max(curve.distance(Point(q)) for q in got) < 1e-3   # (the chord tolerance is 1 um)
    assert got[:, 1].min() > 1.16 and got[:, 1].max() < 1.34
    ends = sorted([tuple(got[0]), tuple(got[-1])])
    assert ends[0] == pytest.approx(tuple(want[0]), abs=1e-6) and ends[1] == pytest.approx(tuple(want[-1]), abs=1e-6)


def test_a_closed_periodic_spline_is_a_closed_cut(tmp_path):
    """The bad-input search: a closed spline as AutoCAD writes a periodic one (flag closed, uniform knots, the first
    three control points repeated at the end) was refused as 'an open path on a notch layer: its ends ... 1.82 mm
    apart; fix: close the outline in CAD'."""
    import math as _m

    ring = [(3.0 + 0.3 * _m.cos(a), 2.0 + 0.9 * _m.sin(a), 0.0) for a in np.linspace(0, 2 * _m.pi, 8, endpoint=False)]
    cps = ring + ring[:3]
    knots = list(range(len(cps) + 4))

    def add(m):
        sp = m.add_spline(dxfattribs={"layer": "NOTCH"})
        sp.dxf.degree = 3
        sp.control_points = cps
        sp.knots = knots
        sp.closed = True

    p = load_drawing(drawing(tmp_path, add), [], DrawingOptions()).pattern
    assert len(p.notches) == 1
    want = _spline_on_domain(cps, knots, 3)
    from shapely.geometry import Polygon

    area = Polygon(want).area
    got = cut_contour(p.notches[0], RO)
    assert got.closed and Polygon(np.asarray(got.points)).area == pytest.approx(area, rel=1e-3)


@pytest.mark.parametrize("what", ["polyline", "insert"])
def test_an_invisible_entity_is_set_aside_not_cut(tmp_path, what):
    """The bad-input search: an LWPOLYLINE with the DXF 'invisible' flag (group 60 = 1), which CAD programs do not
    show, was cut as any other notch."""
    def add(m):
        m.add_lwpolyline([(2, 1), (2.5, 1), (2.5, 3), (2, 3)], close=True, dxfattribs={"layer": "NOTCH"})
        if what == "polyline":
            m.add_lwpolyline([(5, 1), (5.5, 1), (5.5, 3), (5, 3)], close=True,
                             dxfattribs={"layer": "NOTCH", "invisible": 1})
        else:
            blk = m.doc.blocks.new("N")
            blk.add_lwpolyline([(0, 0), (0.5, 0), (0.5, 2), (0, 2)], close=True, dxfattribs={"layer": "NOTCH"})
            m.add_blockref("N", (5, 1), dxfattribs={"layer": "NOTCH", "invisible": 1})

    loaded = load_drawing(drawing(tmp_path, add), [], DrawingOptions())
    assert len(loaded.pattern.notches) == 1 and loaded.pattern.notches[0].x_mm == pytest.approx(2.25)
    assert "set aside: 1 (invisible entity)" in loaded.summary, loaded.summary


@pytest.mark.parametrize("cut", ["slit", "notch"])
def test_the_one_cut_drawn_past_the_outline_is_named_not_the_outline_missed(tmp_path, cut):
    """The bad-input search: with the only cut drawn past the tube's end, a drawn outline was 'no tube outline found;
    fix: draw the unrolled tube outline'."""
    def add(m):
        m.doc.layers.add("CONSTRUCTION")
        if cut == "slit":
            m.add_line((9.5, 1.0), (11.0, 1.0), dxfattribs={"layer": "SLITS"})
        else:
            m.add_lwpolyline([(9.8, 1), (10.3, 1), (10.3, 3), (9.8, 3)], close=True, dxfattribs={"layer": "NOTCH"})

    path = drawing(tmp_path, add)
    with pytest.raises(PatternError) as err:
        load_drawing(path, [], DrawingOptions())
    msg = str(err.value)
    assert "on layer OUTLINE: would be the tube outline" in msg and "lies outside it" in msg, msg
    assert "no tube outline found" not in msg


def test_a_slit_that_crosses_itself_is_refused(tmp_path):
    """The bad-input search: one polyline on a slit layer crossing itself was cut (the beam over the crossing twice),
    where two crossing slits are refused as overlapping."""
    path = drawing(tmp_path, lambda m: m.add_lwpolyline([(2, 1), (4, 3), (4, 1), (2, 3)], dxfattribs={"layer": "SLITS"}))
    with pytest.raises(PatternError, match=r"LWPOLYLINE #\w+ on layer SLITS: the slit crosses or runs back over itself"):
        load_drawing(path, [], DrawingOptions())
    # three points that run back over themselves (x 3.5..4 cut twice): accepted before, as only paths of four or more
    # points were checked
    back = drawing(tmp_path, lambda m: m.add_lwpolyline([(3, 3), (4, 3), (3.5, 3)], dxfattribs={"layer": "SLITS"}),
                   "back.dxf")
    with pytest.raises(PatternError, match=r"LWPOLYLINE #\w+ on layer SLITS: the slit crosses or runs back over itself"):
        load_drawing(back, [], DrawingOptions())
    # a zigzag that does not cross itself is a slit
    ok = drawing(tmp_path, lambda m: m.add_lwpolyline([(2, 1), (3, 3), (4, 1), (5, 3)], dxfattribs={"layer": "SLITS"}),
                 "ok.dxf")
    assert len(load_drawing(ok, [], DrawingOptions()).pattern.slits) == 1


@pytest.mark.parametrize("gap", [-0.1, 0.05])
def test_drawn_cuts_too_close_get_a_drawing_s_fix_not_a_yaml_key(tmp_path, gap):
    """The bad-input search: two drawn notches that overlap (or leave a web under rules.min_web) were told to
    "increase notch.spacing", a key a drawing does not have (--set notch.* is refused for drawings)."""
    def add(m):
        m.add_lwpolyline([(2, 1), (2.5, 1), (2.5, 3), (2, 3)], close=True, dxfattribs={"layer": "NOTCH"})
        x = 2.5 + gap
        m.add_lwpolyline([(x, 1), (x + 0.5, 1), (x + 0.5, 3), (x, 3)], close=True, dxfattribs={"layer": "NOTCH"})

    with pytest.raises(PatternError) as err:
        load_drawing(drawing(tmp_path, add), [], DrawingOptions())
    msg = str(err.value)
    assert "fix: move the two cuts apart in the drawing" in msg and "notch.spacing" not in msg, msg
