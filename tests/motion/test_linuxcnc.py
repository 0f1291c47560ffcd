"""A short job run on LinuxCNC's real motion controller (real time, ~10 s), measured against the job.

Independent truth: LinuxCNC's trajectory planner and motion controller (``linuxcnc-uspace``),
recorded every servo cycle. Skips where LinuxCNC is not installed, fails under CI (``.ci/run``
installs it). The shipped presets run in ``scripts/run_motion.py`` (minutes each).
"""
from __future__ import annotations

import json
import os

import pytest

from camtube.commands import main
from camtube.design.loader import load_pattern
from camtube.errors import CamtubeError
from camtube.export.dialects import dialect_from_profile
from camtube.machine import load_profile
from camtube.motion import linuxcnc as lc
from camtube.motion.analysis import JobGeometry, analyse
from camtube.plan import plan_job
from camtube.export.motion_time import estimate_program
from camtube.export.outputs import toolpath_streams
from camtube.io import write_set
from tests.conftest import PATTERNS

SHORT = ["notch.count=2", "process.repeats=1", "process.drill_passes=1", "holes=[]"]  # 4 passes, 2 notches


def require_linuxcnc() -> None:
    why = lc.unavailable_reason()
    if why:
        if os.environ.get("CI"):
            pytest.fail(f"{why}; .ci/run installs linuxcnc-uspace")
        pytest.skip(why)


def write_short_job(tmp_path, machine: str):
    profile = load_profile(machine)
    dialect = dialect_from_profile(profile)
    job = plan_job(load_pattern(PATTERNS / "tube1.yaml", SHORT))
    streams = toolpath_streams(job, (dialect,))
    write_set(tmp_path, {k: v for k, v in streams.items() if k.endswith((".ngc", ".job.json"))})
    return profile, job, tmp_path / f"{job.name}.ngc", tmp_path / f"{job.name}.job.json"


def test_default_profile_exact_stop_on_the_controller(tmp_path):
    require_linuxcnc()
    profile, job, ngc, jf = write_short_job(tmp_path, "linuxcnc-rotary")
    est = estimate_program(ngc.read_text(), profile).total_s
    rec = lc.run_program(ngc, profile)
    r = analyse(rec, JobGeometry.from_job_file(jf), profile, estimate_s=est)
    assert abs(r.estimate_error) < 0.03
    assert r.max_outside_mm <= 0.001 and r.max_corner_miss_mm <= 0.002
    assert abs(r.length_error) < 0.01
    # exact stop: the gate switches at rest, but every edge accelerates with the beam on
    assert r.speed_share < 0.9
    assert r.run_time_s > r.lower_bound_s


def test_uniform_dose_profile_through_the_cli(tmp_path, capsys):
    require_linuxcnc()
    profile, job, ngc, jf = write_short_job(tmp_path, "linuxcnc-surface")
    assert main(["motion", str(ngc), "--machine", "linuxcnc-surface", "--json"]) == 0
    r = json.loads(capsys.readouterr().out)
    assert r["machine"] == "linuxcnc-surface" and r["cut_length_mm"] == pytest.approx(job.cut_length_mm, abs=1e-5)
    assert abs(r["estimate_error"]) < 0.03
    assert r["speed_share"] >= 0.99
    assert abs(r["length_error"]) < 0.01
    assert r["max_outside_mm"] <= 0.001 and r["max_corner_miss_mm"] <= 0.002


def test_missing_linuxcnc_is_one_line_and_exit_2(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(lc, "unavailable_reason", lambda: "LinuxCNC is not installed (linuxcnc not found)")
    assert main(["motion", str(tmp_path / "x.ngc")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "LinuxCNC is not installed" in err[0]


def test_machines_lists_the_profiles(capsys):
    assert main(["machines"]) == 0
    out = capsys.readouterr().out
    assert "linuxcnc-rotary (default)" in out and "linuxcnc-surface" in out and "grbl-flat" in out


def test_a_grbl_profile_cannot_run_on_linuxcnc(tmp_path):
    with pytest.raises(CamtubeError, match="linuxcnc profile"):
        lc.config_texts(load_profile("grbl-flat"), tmp_path, "driver.py")
