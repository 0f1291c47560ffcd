"""Bend, strain and notch closure at the maximum stroke, against an independent calculation."""
from __future__ import annotations

import math

import pytest

from camtube.design.geometry import bends_at_stroke
from camtube.design.loader import load_pattern
from tests.conftest import PATTERNS


def _independent(ro, ri, s, h, n, rt, e_gpa, et_gpa, l0, stroke):
    """Textbook beam bending of an annular-sector backbone, written out from scratch."""
    phi = (2 * math.pi * ro - s) / ro
    ybar = 4 * math.sin(phi / 2) * (ro**3 - ri**3) / (3 * phi * (ro**2 - ri**2))
    area = phi / 2 * (ro**2 - ri**2)
    i_c = (ro**4 - ri**4) / 8 * (phi + math.sin(phi)) - area * ybar**2
    arm = ybar + ri - rt
    k = e_gpa * 1e3 * i_c / (n * h)  # n identical notches in series
    comp = l0 / (et_gpa * 1e3 * math.pi * rt**2)
    theta = stroke / (arm + k * comp / arm)
    lowest = ri * math.cos(phi / 2) if phi / 2 <= math.pi / 2 else ro * math.cos(phi / 2)
    c = max(ro - ybar, ybar - lowest)
    strain = c * (theta / n) / h
    return theta, strain, n * h / (ro + ybar)


@pytest.mark.parametrize("name,ro,ri,s,stroke", [("tube1", 0.75, 0.45, 2.83, 2.0), ("tube2", 0.85, 0.55, 3.20, 2.5),
                                                  ("tube3", 1.25, 0.75, 4.71, 5.0)])
def test_bend_at_max_stroke_matches_beam_theory(name, ro, ri, s, stroke):
    p = load_pattern(PATTERNS / f"{name}.yaml")
    (d,) = bends_at_stroke(p)
    theta, strain, closure = _independent(ro, ri, s, 0.5, 10, 0.04, 2.5, 28.0, 70.0, stroke)
    assert d.stroke_mm == stroke and d.notches == 10
    assert d.bend_rad == pytest.approx(theta, rel=1e-9)
    assert d.strain == pytest.approx(strain, rel=1e-9)
    assert d.closure_rad == pytest.approx(closure, rel=1e-9)
    # the largest elastic bend sits exactly on the strain limit, linearly
    assert d.strain * d.elastic_bend_rad / d.bend_rad == pytest.approx(0.03, rel=1e-9)
    assert d.strain * d.elastic_stroke_mm / d.stroke_mm == pytest.approx(0.03, rel=1e-9)
    assert not d.closes


def test_directions_are_analysed_separately():
    p = load_pattern(PATTERNS / "tube1-bidirectional.yaml")
    ds = bends_at_stroke(p)
    assert [d.angle_deg for d in ds] == [0.0, 180.0] and [d.notches for d in ds] == [8, 8]
    theta, strain, _ = _independent(0.75, 0.45, 2.83, 0.5, 8, 0.04, 2.5, 28.0, 70.0, 2.0)
    assert ds[0].bend_rad == pytest.approx(theta, rel=1e-9) and ds[1].strain == pytest.approx(strain, rel=1e-9)


def test_design_summary_agrees_with_the_notes_per_direction():
    """The model's stroke-angle table (one per direction) ends at the bend the design notes give."""
    from camtube.model.core.predict import design_summary

    p = load_pattern(PATTERNS / "tube1-bidirectional.yaml")
    text = design_summary(p)
    assert text.count("predicted stroke-angle, notches at") == 2
    last_rows = [ln.split() for ln in text.splitlines() if ln.strip().startswith("2.000")]
    assert len(last_rows) == 2
    for row, d in zip(last_rows, bends_at_stroke(p)):
        assert float(row[1]) == pytest.approx(math.degrees(d.bend_rad), abs=0.006)
