"""Open paths (slits): passes follow the path end to end, alternate direction, no offset; the safety
region is the path itself; G-code read back by rs274 stays on the path."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from camtube.design.contour import Contour, rectangle
from camtube.design.pattern import Process
from camtube.errors import SafetyError
from camtube.export.dialects import LINUXCNC
from camtube.export.gcode import gcode
from camtube.plan import estimate, job_moves, plan_job
from camtube.plan.moves import CUT
from camtube.plan.safety import check_job, check_moves
from camtube.tol import TOL
from tests.export.test_gcode_rs274 import canonical, replay

RO = 1.0
SLIT = Contour(((2.0, 1.0), (3.0, 1.5), (3.5, 1.5), (4.0, 2.2)), "cut", closed=False)  # a bent slit


def seg_distance(p, a, b) -> float:
    """Distance from point p to segment ab (independent of shapely)."""
    p, a, b = map(np.asarray, (p, a, b))
    t = np.clip(np.dot(p - a, b - a) / np.dot(b - a, b - a), 0.0, 1.0)
    return float(np.linalg.norm(p - (a + t * (b - a))))


def on_slit(p) -> float:
    pts = SLIT.points
    return min(seg_distance(p, a, b) for a, b in zip(pts, pts[1:]))


@pytest.fixture(scope="module", params=["interleaved", "sequential", "chained"])
def job(request):
    return plan_job([SLIT, rectangle(5.0, 0.5, 5.4, 1.4, "cut")], Process(), ordering=request.param,
                    outer_radius_mm=RO, length_mm=8.0)


def test_slit_passes_follow_the_path_alternately_without_offset(job):
    slit = [p for p in job.passes if not p.contour.closed]
    pr = job.process
    assert len(slit) == job.repeats * 2 * pr.drill_passes
    for p in slit:
        assert p.offset_mm == 0.0
        assert p.contour.points in (SLIT.points, SLIT.points[::-1])
        assert p.length_mm == pytest.approx(SLIT.length_mm)
    if job.ordering in ("sequential", "chained"):
        # consecutive passes of the slit alternate direction: each starts where the last ended
        by_drill = {p.drill_index: p.contour.points for p in slit if p.repeat == 0 and p.focus_level == 0}
        assert by_drill[0] == by_drill[2] == by_drill[1][::-1] == by_drill[3][::-1]
        for a, b in zip(slit, slit[1:]):
            assert b.contour.points[0] == a.contour.points[-1]
    # every slit pass starts at the end nearer to where the beam was (chained: a slit's group returns to its
    # start, so the starts are chosen for where the rounds before leave the beam, not for the origin: the
    # job's very first pass is the exception)
    prev = (0.0, 0.0)
    for k, p in enumerate(job.passes):
        pts = p.contour.points
        if not p.contour.closed and not (k == 0 and job.ordering == "chained"):
            assert math.dist(prev, pts[0]) <= math.dist(prev, pts[-1]) + 1e-12
        prev = pts[0] if p.contour.closed else pts[-1]


def test_slit_moves_have_no_closing_move_and_are_safe(job):
    check_job(job)
    mv = job_moves(job)
    rows = mv.pass_rows()
    for p, ps in enumerate(job.passes):
        n_cut = int((mv.kind[rows[p]:rows[p + 1]] == CUT).sum())
        assert n_cut == (len(ps.contour.points) - (0 if ps.contour.closed else 1))
    e = estimate(job)
    assert e.cut_length_mm == pytest.approx(sum(p.length_mm for p in job.passes))
    assert e.cut_length_mm == pytest.approx(job.cut_length_mm)


def test_slit_region_is_the_path_within_tol_safety(job):
    mv = job_moves(job)
    cut_of = job.packed.pass_cut[mv.pass_index]
    slit_cut = next(i for i, c in enumerate(job.design) if not c.closed)
    rows = np.flatnonzero(mv.laser & (cut_of == slit_cut))
    i = int(rows[1])  # ends on the slit's middle vertices
    # perpendicular to the slit's second segment (horizontal): move the target in y
    for dy, ok in ((TOL.safety / 2, True), (3 * TOL.safety, False), (0.01, False)):
        y = mv.y.copy()
        y[i] += dy
        moved = replace(mv, y=y)
        if ok:
            check_moves(job, moved)
        else:
            with pytest.raises(SafetyError, match="leaves the cut region"):
                check_moves(job, moved)
    # a slit pass does not reach the rectangle's region, and vice versa
    assert on_slit((5.2, 1.0)) > 1.0


def test_rs274_feeds_lie_on_the_slit_or_in_the_rectangle(job, tmp_path):
    path = tmp_path / "slit.ngc"
    path.write_text(gcode(job, LINUXCNC))
    segs, gates = replay(canonical(path), LINUXCNC, RO)
    # one gate-on per pass; chained: per group of drill passes of a closed cut (a slit's are not linked)
    assert gates == len(job.passes) - int(job.packed.pass_link.sum())
    on_len = 0.0
    for name, a, b, on, surf, secs in segs:
        if name != "STRAIGHT_FEED" or abs(a[2] - b[2]) > 1e-9:
            continue
        assert on
        for x, y, _ in (a, b):
            in_rect = 5.0 - 2e-4 <= x <= 5.4 + 2e-4 and 0.5 - 2e-4 <= y <= 1.4 + 2e-4
            assert in_rect or on_slit((x, y)) < 2e-4, (x, y)
        on_len += surf
    assert on_len == pytest.approx(estimate(job).cut_length_mm + job.link_length_mm, rel=1e-4)


def test_too_short_slit_is_a_pattern_error():
    from camtube.errors import PatternError

    with pytest.raises(PatternError, match="too few points"):
        plan_job([Contour(((1.0, 1.0),), "cut", closed=False)], Process(), outer_radius_mm=RO, length_mm=3.0)
    assert math.isfinite(SLIT.length_mm)
