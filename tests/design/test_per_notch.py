"""Per-notch lists in the pattern schema: positions from the lists, old files unchanged, mistakes named."""
from __future__ import annotations

import pytest

from camtube.design.loader import build, load_pattern
from camtube.errors import PatternError

BASE = {"tube": {"outer_radius": 0.75, "inner_radius": 0.45, "length": 10.0}}


def test_lists_place_each_notch():
    raw = dict(BASE, notch={"count": 3, "first_offset": 1.0, "widths": [0.4, 0.5, 0.6], "arcs": [2.5, 2.6, 2.7],
                            "spacings": [0.3, 0.2], "angles_deg": [180, 0, 180]})
    p = build(raw).pattern
    n = p.notches
    assert [c.x_start_mm for c in n] == pytest.approx([1.0, 1.7, 2.4])
    assert [c.x_end_mm for c in n] == pytest.approx([1.4, 2.2, 3.0])
    assert [c.arc_mm for c in n] == [2.5, 2.6, 2.7] and [c.angle_deg for c in n] == [180.0, 0.0, 180.0]


def test_scalar_files_are_unchanged():
    p = load_pattern("tube1")
    assert [round(c.x_mm, 9) for c in p.notches] == [1.75 + i for i in range(10)]


@pytest.mark.parametrize("notch,key,words", [
    ({"count": 3, "widths": [0.4, 0.5], "arc": 2.5, "spacing": 0.3}, "notch.widths", "3 values"),
    ({"count": 3, "width": 0.4, "arc": 2.5, "spacings": [0.3, 0.3, 0.3]}, "notch.spacings", "2 values"),
    ({"count": 3, "width": 0.4, "spacing": 0.3}, "notch.arc", "'arcs: [...]'"),
    ({"count": 2, "width": 0.4, "spacing": 0.3, "arcs": [2.5, 4.5]}, "notch.arc", "backbone arc"),
])
def test_list_mistakes_are_named(notch, key, words):
    with pytest.raises(PatternError) as ei:
        build(dict(BASE, notch=dict({"first_offset": 1.0}, **notch)), "p.yaml")
    assert any(i.key == key and words in str(i) for i in ei.value.issues), str(ei.value)
