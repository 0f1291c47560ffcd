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
