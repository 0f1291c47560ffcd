"""Over-travel corner strategy: the cut edges are untouched, the leads are beam-off, collinear, long enough."""
from __future__ import annotations

import math
import re

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.export.dialects import dialect_from_profile
from camtube.export.gcode import gcode
from camtube.machine import load_profile
from camtube.machine.corners import LEAD_MARGIN, StrategyMoves
from camtube.plan import job_moves, plan_job
from camtube.plan.moves import CUT, LEAD, Moves
from camtube.plan.safety import check_moves
from tests.conftest import PATTERNS
from tests.export.test_gcode_rs274 import canonical


@pytest.fixture(scope="module")
def surface():
    return load_profile("linuxcnc-surface")


@pytest.fixture(scope="module")
def job():
    # the hole at x = 0.6..0.9 mm is closer to the tip than a lead: its leads are clipped at x = 0
    return plan_job(load_pattern(PATTERNS / "tube1.yaml", ["notch.count=2", "process.repeats=1"]))


def test_edges_unchanged_leads_beam_off_and_long_enough(job, surface):
    mv = Moves.concat(StrategyMoves(job, surface))
    check_moves(job, mv)  # the safety check proves the gate closed on every lead, and x on the tube
    orig = job_moves(job)
    cut, ocut = mv.kind == CUT, orig.kind == CUT
    assert np.array_equal(mv.x[cut], orig.x[ocut]) and np.array_equal(mv.y[cut], orig.y[ocut])
    assert mv.laser[cut].all() and not mv.laser[~cut].any()
    x0, y0, _ = mv.starts()
    v = job.process.scan_speed_mm_s
    need = v * v / (2 * 500.0)  # both surface axes: 500 mm/s^2
    clipped = 0
    for i in np.flatnonzero(cut):
        u = np.array([mv.x[i] - x0[i], mv.y[i] - y0[i]])
        u /= np.linalg.norm(u)
        for j in (i - 1, i + 1):  # lead-in ends at the edge's start, lead-out starts at its end
            assert mv.kind[j] == LEAD and mv.speed[j] == v
            w = np.array([mv.x[j] - x0[j], mv.y[j] - y0[j]])
            length = np.linalg.norm(w)
            assert np.dot(w / length, u) == pytest.approx(1.0, abs=1e-12)  # collinear, same direction
            if length < LEAD_MARGIN * need:
                clipped += 1
                assert min(mv.x[j], x0[j]) == pytest.approx(0.0, abs=1e-12)  # only where the tube ends
    assert clipped == 2 * 8  # the hole's two axial edges, 8 passes


def test_written_program_gates_only_the_cut_edges(job, surface, tmp_path):
    """rs274 (independent reader): gate-open feeds are exactly the cut edges; leads are feeds with the gate closed."""
    dialect = dialect_from_profile(surface)
    path = tmp_path / "t.ngc"
    path.write_text(gcode(job, dialect))
    gate, pos, on_len, off_feeds = False, np.zeros(3), 0.0, 0
    for name, args in canonical(path):
        if name == "SET_MOTION_OUTPUT_BIT":
            gate = True
        elif name == "CLEAR_MOTION_OUTPUT_BIT":
            gate = False
        elif name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            new = np.array([float(t) for t in args.split(",")[:3]])
            if gate:
                assert name == "STRAIGHT_FEED"
                on_len += math.hypot(*(new - pos)[:2])
            elif name == "STRAIGHT_FEED":
                off_feeds += 1
            pos = new
    assert on_len == pytest.approx(job.cut_length_mm, abs=1e-3)
    n_edges = int((job_moves(job).kind == CUT).sum())
    assert off_feeds == 2 * n_edges
    assert re.search(r"^G64 P0\.001$", path.read_text(), re.M)
