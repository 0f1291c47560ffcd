"""The analysis of a recording against independent, hand-made recordings of known figures."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.machine import load_profile
from camtube.motion.analysis import JobGeometry, analyse
from camtube.motion.linuxcnc import Recording
from camtube.plan import plan_job
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def job():
    return plan_job(load_pattern(PATTERNS / "tube1.yaml", ["notch.count=1", "process.repeats=1",
                                                           "process.drill_passes=1", "holes=[]"]))


def trace(job, speed_mm_s, period_s, shift_mm=(0.0, 0.0), pause_s=0.0):
    """Sampled beam path: every pass at ``speed`` with the gate open, a closed-gate pause between passes.

    As LinuxCNC records it: the machine rests at a pass's start with the gate closed; the gate is set
    at each sample the stage moves to with the beam on (the first step's sample on), closed again at
    the sample of the next move's first step (here the jump to the next pass's start)."""
    ro = job.outer_radius_mm
    xs, ys, zs, gs = [], [], [], []
    for p in job.passes:
        pts = np.asarray(p.contour.points + p.contour.points[:1], float) + shift_mm
        xs.append(pts[:1, 0]), ys.append(pts[:1, 1]), zs.append([-p.focus_offset_mm]), gs.append(np.zeros(1, bool))
        for a, b in zip(pts[:-1], pts[1:]):
            n = max(1, int(round(math.dist(a, b) / (speed_mm_s * period_s))))
            t = np.arange(1, n + 1) / n
            seg = a + (b - a) * t[:, None]
            xs.append(seg[:, 0]), ys.append(seg[:, 1]), zs.append(np.full(n, -p.focus_offset_mm))
            gs.append(np.ones(n, bool))
        k = max(1, int(pause_s / period_s))
        xs.append(np.full(k, pts[-1, 0])), ys.append(np.full(k, pts[-1, 1]))
        zs.append(np.full(k, -p.focus_offset_mm)), gs.append(np.zeros(k, bool))
    x, y, z, g = (np.concatenate(v) for v in (xs, ys, zs, gs))
    return Recording(np.arange(len(x)), x, np.degrees(y / ro), z, g, period_s, 0.0)


def test_a_perfect_trace(job):
    prof = load_profile("linuxcnc-rotary")
    rec = trace(job, 25.0, 1e-4)
    r = analyse(rec, JobGeometry.from_job(job, estimate_s=1.0), prof)
    assert r.length_error == pytest.approx(0.0, abs=1e-4)
    assert r.speed_share == pytest.approx(1.0, abs=1e-3) and r.median_speed_mm_s == pytest.approx(25.0, rel=2e-3)
    assert r.max_outside_mm < 1e-6 and r.max_corner_miss_mm < 1e-6


def test_a_shifted_slow_trace_is_measured(job):
    prof = load_profile("linuxcnc-rotary")
    rec = trace(job, 20.0, 1e-4, shift_mm=(0.003, 0.0))  # 3 um along x, 20 % slow
    r = analyse(rec, JobGeometry.from_job(job), prof)
    assert r.max_outside_mm == pytest.approx(0.003, abs=1e-6)
    assert r.max_corner_miss_mm == pytest.approx(0.003, abs=1e-6)
    assert r.speed_share == pytest.approx(0.0, abs=1e-9)


def test_idle_pauses_are_not_run_time(job):
    rec = trace(job, 25.0, 1e-4, pause_s=0.05)
    moving = (len(rec) - 1) * 1e-4
    idle = 0.05 * (len(job.passes) - 1)  # the last pause comes after the last motion
    assert rec.run_time_s == pytest.approx(moving - idle - 0.05, abs=5e-4)


def test_the_dose_counts_each_cycles_pulses_over_the_step_to_its_position(job):
    """The rate of sample k is in force while the stage moves from sample k - 1 to k (with the gate of k): a
    rate that follows each step exactly scores 100 %; the same rates paired one step late do not."""
    prof = load_profile("linuxcnc-rotary")
    base = trace(job, 10.0, 1e-4)
    # uneven steps (1, 2, 3, 2 base steps per cycle): the speed changes every cycle, as at a chord's turn
    idx = np.cumsum(np.resize([1, 2, 3, 2], len(base)))
    idx = np.concatenate(([0], idx[idx < len(base)]))
    cut = Recording(np.arange(len(idx)), base.axial[idx], base.circ[idx], base.focus[idx], base.gate[idx], 1e-4, 0.0)
    geom = JobGeometry.from_job(job)
    ppmm = 1000.0 * geom.frequency_khz / geom.scan_speed_mm_s
    y = np.radians(cut.circ) * job.outer_radius_mm
    step = np.concatenate(([0.0], np.hypot(np.diff(cut.axial), np.diff(y))))  # the step to each sample's position
    rate = ppmm * step / 1e-4 * cut.gate / 1000.0  # kHz
    own = Recording(cut.cycle, cut.axial, cut.circ, cut.focus, cut.gate, 1e-4, 0.0, rate)
    assert analyse(own, geom, prof).dose_share == pytest.approx(1.0, abs=1e-9)
    late = Recording(cut.cycle, cut.axial, cut.circ, cut.focus, cut.gate, 1e-4, 0.0,
                     np.concatenate(([0.0], rate[:-1])))
    assert analyse(late, geom, prof).dose_share < 0.5


def chained_trace(job, speed_mm_s, period_s, link_shift_mm=0.0):
    """Sampled beam path of a chained job: each group one beam-on stretch (its passes and the links between
    them, the gate open throughout), the gate closed at rest between groups. ``link_shift_mm`` moves the
    samples inside every link sideways (at right angles to it, along the passes) by that much: a beam that
    strays from the commanded link."""
    from camtube.plan.moves import LINK, job_moves

    mv = job_moves(job)
    x0, y0, _ = mv.starts()
    xs, ys, zs, gs = [[0.0]], [[0.0]], [[0.0]], [[False]]
    for i in range(len(mv)):
        a, b = np.array([x0[i], y0[i]]), np.array([mv.x[i], mv.y[i]])
        n = max(1, int(round(math.dist(a, b) / (speed_mm_s * period_s))))
        seg = a + (b - a) * (np.arange(1, n + 1) / n)[:, None]
        if mv.kind[i] == LINK:
            u = (b - a) / math.dist(a, b)
            seg[:-1] += link_shift_mm * np.array([-u[1], u[0]])
        xs.append(seg[:, 0]), ys.append(seg[:, 1]), zs.append(np.full(n, -mv.z[i]))
        gs.append(np.full(n, bool(mv.laser[i])))
    x, y, z, g = (np.concatenate(v) for v in (xs, ys, zs, gs))
    return Recording(np.arange(len(x)), x, y, z, g, period_s, 0.0)


def test_a_chained_job_is_scored_per_group_with_its_links_stated():
    """A chained job's gate opens once per group: each stretch is scored against its group's path (its passes
    joined by the links); the links' length is stated beside the cut length (issue 21)."""
    from camtube.design.source import DrawingOptions, load_source
    from tests.conftest import ROOT

    loaded = load_source(ROOT / "examples" / "curved" / "slotted.dxf", ["process.repeats=1"],
                         DrawingOptions(outer_radius_mm=0.8))
    job = plan_job(loaded.pattern, ordering="chained")
    geom = JobGeometry.from_job(job, estimate_s=1.0)
    assert geom.link_length_mm == pytest.approx(job.link_length_mm) and geom.link_length_mm > 0
    prof = load_profile("linuxcnc-path")
    r = analyse(chained_trace(job, 25.0, 5e-5), geom, prof)  # 1.25 um steps: 4 per link
    groups = int(np.count_nonzero(~job.packed.pass_link))
    assert groups < len(job.passes)
    # own group: every sample on its group's path, every vertex reached (a pass-by-pass pairing has no answer)
    assert r.max_path_dev_mm < 1e-9 and r.max_vertex_miss_mm < 1e-9
    # the beam-on path is the cut length plus the links, exactly
    assert r.link_length_mm == pytest.approx(job.link_length_mm)
    assert r.path_length_error == pytest.approx(0.0, abs=1e-9)
    assert r.length_error == pytest.approx(job.link_length_mm / job.cut_length_mm, rel=1e-6)
    assert r.max_outside_mm < 1e-9 and r.dose_share == pytest.approx(1.0)
    # a beam that strays 2 um off its links is seen
    off = analyse(chained_trace(job, 25.0, 5e-5, link_shift_mm=0.002), geom, prof)
    assert off.max_path_dev_mm == pytest.approx(0.002, rel=0.05)


def test_a_job_file_nested_too_deeply_is_not_a_job_file(tmp_path):
    """100000 '[' then ']' (valid JSON, too deep for Python's parser) was a RecursionError traceback."""
    from camtube.errors import DataError

    p = tmp_path / "t.job.json"
    p.write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(DataError, match="not a camtube job file .nested too deeply"):
        JobGeometry.from_job_file(p)
