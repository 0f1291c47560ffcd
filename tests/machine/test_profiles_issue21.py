"""The issue 21 profile keys and profiles: ``ordering``, and the air-bearing demonstration profile."""
from __future__ import annotations

import pytest

from camtube.errors import PatternError
from camtube.machine import load_profile, profile_names

BASE = """machine:
  dialect: linuxcnc
  axes: [X, Y, Z]
  rotary: false
  limits:
    X: {max_velocity: 50, max_acceleration: 500}
    Y: {max_velocity: 50, max_acceleration: 500}
    Z: {max_velocity: 50, max_acceleration: 500}
  laser: {gate_output: 0}
"""


def test_the_airbearing_profile_is_linuxcnc_path_on_faster_linear_axes():
    assert "linuxcnc-path-airbearing" in profile_names()
    fast, path = load_profile("linuxcnc-path-airbearing"), load_profile("linuxcnc-path")
    # a demonstration, said so where the user sees it (camtube machines, the G-code header)
    assert fast.description.startswith("DEMONSTRATION, not a datasheet")
    assert len(f"(camtube 0.0.0 job filleted, dialect linuxcnc: {fast.description})") < 256
    for letter in ("X", "Y"):
        assert fast.axis(letter).max_acceleration == 10000 and fast.axis(letter).max_velocity == 250
    assert fast.axis("Z") == path.axis("Z")
    # everything but the X and Y limits and the description is linuxcnc-path's
    # a faster servo: at 1 kHz LinuxCNC strayed 3.3 um from a 0.2 mm arc's chords at 25 mm/s and 1 g
    assert fast.servo_period_s == 0.00025
    same = ("dialect", "rotary", "axes", "blending", "corner_strategy", "gate_output",
            "power_output", "frequency_output", "gating", "dose_output", "radius_output", "ordering", "decimals",
            "feed_decimals", "comment", "warn_time_factor")
    assert {k: getattr(fast, k) for k in same} == {k: getattr(path, k) for k in same}
    # the existing profiles keep their limits
    assert path.axis("X").max_acceleration == path.axis("Y").max_acceleration == 500
    assert load_profile("linuxcnc-rotary").axis("A").max_acceleration == 36000


@pytest.mark.parametrize("value, ok", [("chained", True), ("sequential", True), ("interleaved", True),
                                       ("chain", False), (3, False)])
def test_the_ordering_key_is_checked(tmp_path, value, ok):
    f = tmp_path / "m.yaml"
    f.write_text(BASE + f"  ordering: {value}\n")
    if ok:
        assert load_profile(f).ordering == value
        return
    with pytest.raises(PatternError) as e:
        load_profile(f)
    msg = str(e.value)
    assert "machine.ordering" in msg and "m.yaml" in msg and "interleaved | sequential | chained" in msg
    if value == "chain":
        assert "did you mean 'chained'" in msg


def test_a_profile_without_the_key_plans_interleaved(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text(BASE)
    assert load_profile(f).ordering == "interleaved"
