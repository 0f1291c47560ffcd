from __future__ import annotations

import math

import pytest

from camtube.design.contour import merge_seam_pieces, rectangle, split_at_seam

C = 2 * math.pi * 0.75


@pytest.mark.parametrize("y0,y1,n", [(1.0, 2.0, 1), (-0.5, 0.5, 2), (C - 0.5, C + 0.5, 2), (C + 1, C + 2, 1),
                                     (0.0, 1.0, 1), (C - 1.0, C, 1)])
def test_split_at_seam_pieces_cover_the_cut(y0, y1, n):
    pieces = split_at_seam(rectangle(0, y0, 1, y1, "notch", 3), C)
    assert len(pieces) == n
    assert sum(p.area_mm2 for p in pieces) == pytest.approx(y1 - y0)
    for p in pieces:
        b = p.bounds
        assert -1e-12 <= b[1] and b[3] <= C + 1e-12
        assert p.area_mm2 > 0 and p.cut_index == 3 and p.kind == "notch"
    merged = merge_seam_pieces(pieces, C)
    assert len(merged) == 1
    assert merged[0].bounds[3] - merged[0].bounds[1] == pytest.approx(y1 - y0)


def test_merge_does_not_join_different_x():
    a = rectangle(0, C - 0.5, 1, C, "notch")
    b = rectangle(0.5, 0, 1.5, 0.5, "notch")
    assert len(merge_seam_pieces([a, b], C)) == 2


def test_contour_length_and_area():
    r = rectangle(0, 0, 2, 3)
    assert r.length_mm == pytest.approx(10) and r.area_mm2 == pytest.approx(6)


# ---------------------------------------------------------------- any polygon, and open paths (drawn cuts)
from hypothesis import given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@settings(max_examples=40, deadline=None, derandomize=True, database=None)
@given(cx=st.floats(1.0, 5.0), cy=st.floats(-1.0, C + 1.0), rx=st.floats(0.1, 0.5), ry=st.floats(0.2, 1.5),
       n=st.integers(3, 12), turn=st.floats(0, 180))
def test_any_polygon_split_at_the_seam_and_joined_back_keeps_its_area(cx, cy, rx, ry, n, turn):
    """Checked with shapely: the pieces lie on the sheet, cover the polygon, and rejoin into it."""
    from shapely.geometry import Polygon

    from camtube.design.contour import Contour, merge_seam_polygons

    a = [math.radians(turn) + 2 * math.pi * k / n for k in range(n)]
    pts = tuple((cx + rx * math.cos(t), cy + ry * math.sin(t)) for t in a)
    con = Contour(pts, "notch", 5)
    pieces = split_at_seam(con, C)
    area = Polygon(pts).area
    assert sum(abs(p.area_mm2) for p in pieces) == pytest.approx(area, rel=1e-9)
    for p in pieces:
        b = p.bounds
        assert -1e-9 <= b[1] and b[3] <= C + 1e-9 and p.kind == "notch" and p.cut_index == 5
    merged = merge_seam_polygons(pieces, C, 1e-6)
    assert len(merged) == 1
    back, used = merged[0]
    assert sorted(used) == list(range(len(pieces)))
    assert abs(back.area_mm2) == pytest.approx(area, rel=1e-9)
    shift = round((Polygon(back.points).centroid.y - Polygon(pts).centroid.y) / C) * C
    assert Polygon(back.points).symmetric_difference(
        Polygon([(x, y + shift) for x, y in pts])).area < 1e-9


def test_open_path_split_and_joined():
    from camtube.design.contour import Contour, merge_seam_polygons

    path = Contour(((2.0, C - 0.4), (2.0, C + 0.3)), "slit", 0, False)
    pieces = split_at_seam(path, C)
    assert len(pieces) == 2 and not any(p.closed for p in pieces)
    assert sum(p.length_mm for p in pieces) == pytest.approx(0.7)
    (back, used), = merge_seam_polygons(pieces, C, 1e-6)
    assert not back.closed and back.length_mm == pytest.approx(0.7) and len(used) == 2
