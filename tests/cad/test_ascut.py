"""Kerf simulation: exact areas for a known case, slugs, overcut/undercut, broken jobs named."""
from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from camtube.cad.ascut import DEFAULT_SIM_KERF_MM, simulate
from camtube.design.contour import Contour
from camtube.plan import job_moves
from tests.cad.conftest import job_of


def _rebuilt(job, passes):
    """A copy of ``job`` with other passes (and its packed cache dropped)."""
    j = dataclasses.replace(job, passes=tuple(passes))
    j.__dict__.pop("packed", None)
    return j


def test_uncompensated_job_removes_design_plus_half_kerf(preset_name):
    """kerf_mm = 0: the first pass runs on the design line, so each rectangle loses exactly its
    outward offset by kerf/2 with round corners: A + P k/2 + pi (k/2)^2 (Steiner formula)."""
    job = job_of(preset_name)
    a = simulate(job)
    k = DEFAULT_SIM_KERF_MM
    assert a.kerf_mm == k and not a.kerf_from_process
    for c, r in zip(job.design, a.cuts):
        assert r.status == "slug freed"
        want = abs(c.area_mm2) + c.length_mm * k / 2 + math.pi * (k / 2) ** 2
        assert r.removed_area_mm2 == pytest.approx(want, rel=2e-4)
        assert r.undercut_mm2 == 0.0
    assert max(x.depth_mm for x in a.overcut) == pytest.approx(k / 2, rel=1e-6)
    assert a.min_web.as_cut_mm == pytest.approx(a.min_web.design_mm - k, abs=1e-9)


def test_compensated_job_has_no_overcut():
    job = job_of("tube1", "process.kerf=0.02")
    a = simulate(job)
    assert a.kerf_from_process and a.kerf_mm == pytest.approx(0.02)
    assert all(r.status == "slug freed" for r in a.cuts)
    assert a.overcut_mm2 < 1e-9
    # a round beam leaves (1 - pi/4)(k/2)^2 in each sharp outer corner
    corner = (1 - math.pi / 4) * 0.01 ** 2
    assert a.undercut_mm2 == pytest.approx(4 * len(job.design) * corner, rel=0.05)
    assert max(r.depth_mm for r in a.undercut) <= a.allow_undercut_mm


def test_moved_pass_is_overcut_named():
    job = job_of("tube1")
    passes = list(job.passes)
    i = next(k for k, q in enumerate(passes) if q.cut_index == 5 and q.drill_index == 0)
    q = passes[i]
    moved = Contour(tuple((x, y + 0.2) for x, y in q.contour.points), q.contour.kind, q.contour.cut_index)
    passes[i] = dataclasses.replace(q, contour=moved)
    a = simulate(_rebuilt(job, passes))
    bad = [r for r in a.overcut if r.depth_mm > a.allow_overcut_mm]
    assert len(bad) == 1 and bad[0].cut_index == 5
    assert bad[0].depth_mm == pytest.approx(0.2 + a.kerf_mm / 2, abs=1e-3)
    x0, y0, x1, y1 = job.design[5].bounds
    assert bad[0].deepest[1] == pytest.approx(y1 + 0.2 + a.kerf_mm / 2, abs=1e-3)
    assert x0 - 0.02 <= bad[0].deepest[0] <= x1 + 0.02
    others = [r for r in a.overcut if r.cut_index != 5]
    assert all(r.depth_mm <= a.allow_overcut_mm for r in others)


def test_gap_in_contour_leaves_slug_named():
    """Every pass of cut 3 skips its low-y side: the kerf ring is open, the slug stays."""
    job = job_of("tube1")
    mv = job_moves(job)
    x0, y0, _ = mv.starts()
    cut = np.asarray(job.packed.pass_cut)[mv.pass_index]
    ymid = 0.5 * (job.design[3].bounds[1] + job.design[3].bounds[3])
    gap = mv.laser & (cut == 3) & (y0 == mv.y) & (mv.y < ymid)
    assert gap.sum() > 0
    a = simulate(job, dataclasses.replace(mv, laser=mv.laser & ~gap))
    assert a.cuts[3].status == "not freed" and a.cuts[3].slug_area_mm2 == 0.0
    assert [r.status for i, r in enumerate(a.cuts) if i != 3] == ["slug freed"] * (len(a.cuts) - 1)
    big = a.undercut[0]
    assert big.cut_index == 3 and big.area_mm2 > 0.8 * abs(job.design[3].area_mm2)
    dx0, dy0, dx1, dy1 = job.design[3].bounds
    assert dx0 <= big.centroid[0] <= dx1 and dy0 <= big.centroid[1] <= dy1


def test_slug_freed_across_the_seam():
    """A hole straddling rotary angle 0 is one closed ring in the unwrapped frame: its slug is freed."""
    job = job_of("tube1", "holes.0.angle_deg=0")
    a = simulate(job)
    hole = next(r for r in a.cuts if r.kind == "hole")
    assert hole.status == "slug freed"
    assert a.undercut_mm2 == 0.0
