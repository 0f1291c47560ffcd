"""A scan speed the machine's axes cannot reach (camtube/machine/kinematics.py check_speeds): refused where the laser
fires in time (the pulses per mm would rise as the controller slows), allowed where it is gated by distance."""
from __future__ import annotations

import math

import pytest

from camtube.design.loader import load_pattern
from camtube.errors import PatternError
from camtube.export.dialects import dialect_from_profile
from camtube.machine import load_profile
from camtube.machine.kinematics import check_speeds
from camtube.plan import plan_job
from tests.conftest import PATTERNS
from tests.test_cli_errors import TUBE1, assert_refused, camtube, listing

SHORT = ["notch.count=2", "process.repeats=1", "process.drill_passes=1", "holes=[]"]


def job_at(speed_mm_s: float):
    return plan_job(load_pattern(PATTERNS / "tube1.yaml", SHORT + [f"process.scan_speed_mm_s={speed_mm_s}"]))


@pytest.mark.parametrize("machine,limit_mm_s", [("grbl-flat", 100.0), ("linuxcnc-surface", 50.0)])
def test_a_time_gated_machine_takes_its_axes_top_speed_and_refuses_more(machine, limit_mm_s):
    d = dialect_from_profile(load_profile(machine))
    check_speeds(job_at(limit_mm_s), d)   # an axial cut at exactly the axis's limit
    with pytest.raises(PatternError) as e:
        check_speeds(job_at(1.2 * limit_mm_s), d)
    text = str(e.value)
    assert "process.scan_speed_mm_s" in text and machine in text and f"at most {limit_mm_s:g}" in text
    assert "1.2x" in text


def test_the_rotary_axis_limit_is_read_in_degrees_per_second_on_the_outer_surface():
    """A profile gated in time on a rotary axis: the circumferential cut at v mm/s needs v / r_o x 180 / pi deg/s."""
    import dataclasses

    p = load_profile("linuxcnc-rotary")
    slow_a = tuple((k, dataclasses.replace(v, max_velocity=1000.0) if k == "A" else v) for k, v in p.limits)
    d = dialect_from_profile(dataclasses.replace(p, gating="time", limits=slow_a))
    job = job_at(25.0)
    need_deg_s = 25.0 / job.outer_radius_mm * 180.0 / math.pi   # 1910 deg/s on tube 1
    assert need_deg_s > 1000.0
    with pytest.raises(PatternError) as e:
        check_speeds(job, d)
    assert "axis A" in str(e.value) and "deg/s" in str(e.value)
    # gated by distance, the same machine keeps the pulses per mm: allowed
    check_speeds(job, dialect_from_profile(dataclasses.replace(p, limits=slow_a)))


def test_too_fast_for_the_default_flat_machine_is_one_line_and_nothing_written(tmp_path):
    r = camtube("toolpath", TUBE1, "-q", "-o", str(tmp_path / "o"), "--set", "process.scan_speed_mm_s=150")
    assert_refused(r, "process.scan_speed_mm_s", "grbl-flat", "at most 100")
    assert listing(tmp_path) == []
    ok = camtube("toolpath", TUBE1, "-q", "-o", str(tmp_path / "r"), "--set", "process.scan_speed_mm_s=150",
                 "--machine", "linuxcnc-rotary")
    assert ok.returncode == 0, ok.stderr
