"""Safety check: unsafe jobs and unsafe move lists are refused with the pass and place, and nothing is written."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from camtube.design.contour import Contour
from camtube.design.loader import load_pattern
from camtube.errors import SafetyError
from camtube.export.dialects import GRBL, LINUXCNC
from camtube.export.gcode import gcode
from camtube.export.jobfile import job_json
from camtube.export.toolpath_dxf import toolpath_dxf
from camtube.plan import job_moves, plan_job
from camtube.plan.moves import FOCUS, RAPID
from camtube.export.outputs import write_toolpaths
from camtube.plan.safety import check_job, check_moves
from camtube.tol import TOL
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def job():
    return plan_job(load_pattern(PATTERNS / "tube1.yaml"))


def with_pass(job, k, **changes):
    passes = list(job.passes)
    passes[k] = replace(passes[k], **changes)
    return replace(job, passes=tuple(passes))


def shifted(contour, dx, dy):
    return Contour(tuple((x + dx, y + dy) for x, y in contour.points), contour.kind, contour.cut_index)


def test_presets_are_safe(job):
    check_job(job)


def test_pass_outside_its_cut_region_is_refused_and_nothing_written(job, tmp_path):
    bad = with_pass(job, 17, contour=shifted(job.passes[17].contour, 0.01, 0.0))
    for writer in (lambda j: gcode(j, LINUXCNC), lambda j: gcode(j, GRBL), job_json, toolpath_dxf):
        with pytest.raises(SafetyError, match=r"pass 17 \(cut \d+ (notch|hole), repeat 0.*leaves the cut region"):
            writer(bad)
    out = tmp_path / "out"
    with pytest.raises(SafetyError):
        write_toolpaths(bad, out)
    assert not out.exists() or not any(out.iterdir())


def test_tolerance_is_tol_safety(job):
    k = 5
    c = job.passes[k].contour
    x0 = job.design[job.passes[k].cut_index].bounds[0]
    assert min(x for x, _ in c.points) == pytest.approx(x0)  # drill 0 lies on the design line
    check_job(with_pass(job, k, contour=shifted(c, -TOL.safety / 2, 0.0)))
    with pytest.raises(SafetyError):
        check_job(with_pass(job, k, contour=shifted(c, -3 * TOL.safety, 0.0)))


def test_pass_in_the_wrong_cut_region_is_refused(job):
    other = next(p for p in job.passes if p.cut_index != job.passes[3].cut_index)
    with pytest.raises(SafetyError, match="pass 3 "):
        check_job(with_pass(job, 3, contour=other.contour))


def test_beyond_the_tube_is_refused(job):
    short = replace(job, length_mm=5.0)
    with pytest.raises(SafetyError, match="leaves the tube"):
        gcode(short)


def _moves_with(mv, **arrays):
    return replace(mv, **arrays)


def test_laser_on_during_rapid_or_focus_is_refused(job):
    mv = job_moves(job)
    laser = mv.laser.copy()
    laser[np.flatnonzero(mv.kind == RAPID)[7]] = True
    with pytest.raises(SafetyError, match="laser is on during a rapid"):
        check_moves(job, _moves_with(mv, laser=laser))
    laser = mv.laser.copy()
    laser[np.flatnonzero(mv.kind == FOCUS)[1]] = True
    with pytest.raises(SafetyError, match="laser is on during a focus"):
        check_moves(job, _moves_with(mv, laser=laser))


def test_focus_change_while_cutting_is_refused(job):
    mv = job_moves(job)
    z = mv.z.copy()
    i = np.flatnonzero(mv.laser)[10]
    z[i] += 0.05
    with pytest.raises(SafetyError, match="focus changes while the laser is on"):
        check_moves(job, _moves_with(mv, z=z))


def test_wind_up_is_refused(job):
    mv = job_moves(job)
    y = mv.y.copy()
    i = np.flatnonzero(mv.kind == RAPID)[3]
    y[i] += 10 * 2 * np.pi * job.outer_radius_mm
    with pytest.raises(SafetyError, match="winds up"):
        check_moves(job, _moves_with(mv, y=y))


def test_report_names_few_moves_and_counts_the_rest(job):
    bad = replace(job, length_mm=1.0)
    with pytest.raises(SafetyError) as exc:
        check_job(bad)
    msg = str(exc.value)
    assert "unsafe move(s); nothing was written" in msg and "more" in msg
    assert msg.count("\npass ") == 5
