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
