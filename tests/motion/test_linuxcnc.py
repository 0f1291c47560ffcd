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
from camtube.machine.motion_time import estimate_program
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


def test_the_ini_gives_limits_with_every_digit_and_no_exponent(tmp_path):
    """LinuxCNC is given the profile's own limits: ``{:g}`` wrote a velocity of 33.3333333 mm/s as 33.3333 (above
    or below the profile by the digits dropped) and the travel of the rotary axis as 1e+06."""
    import dataclasses

    profile = load_profile("linuxcnc-rotary")
    odd = {"max_velocity": 33.3333333, "max_acceleration": 1234.56789}
    limits = tuple((k, dataclasses.replace(v, **odd)) for k, v in profile.limits)
    ini = lc.config_texts(dataclasses.replace(profile, limits=limits), tmp_path, "driver.py")["camtube.ini"]
    lines = [ln for ln in ini.splitlines() if " = " in ln]
    values = {ln.split(" = ")[0]: ln.split(" = ")[1] for ln in lines}
    assert values["MAX_VELOCITY"] == "33.3333333" and values["MAX_ACCELERATION"] == "1234.56789"
    assert values["MAX_LINEAR_VELOCITY"] == "33.3333333"
    limits_written = [ln.split(" = ")[1] for ln in lines if ln.startswith(("MIN_LIMIT", "MAX_LIMIT"))]
    assert limits_written and all("e" not in v.lower() for v in limits_written)
    assert "-1000000" in limits_written


def test_the_controllers_error_names_the_line_and_the_fix():
    """The bad-input search: 'the controller reported: bad number format ...' gave no line of the program and no fix."""
    text = lc.controller_error("t.ngc", ["Bad number format (conversion failed) parsing '1.2.3'", "near line 14"])
    assert text.startswith("t.ngc: the controller reported: Bad number format") and "fix: correct the program at line 14" in text
    assert "\n" not in text
    assert "fix: run it again" in lc.controller_error("t.ngc", [])
    # the driver's own watch timed out: not the program's fault
    late = lc.controller_error("t.ngc", ["RuntimeError: timed out waiting for the program to start"])
    assert "fix: run it again on a quieter machine" in late and "correct the program" not in late
