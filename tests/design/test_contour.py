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
