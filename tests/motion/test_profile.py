"""Machine profiles: the shipped files load, the dialects come from them, mistakes are named."""
from __future__ import annotations

import pytest

from camtube.errors import PatternError
from camtube.export.dialects import GRBL, LINUXCNC, dialect_from_profile
from camtube.machine import load_profile, profile_names


def test_shipped_profiles_load_and_build_the_dialects():
    assert {"linuxcnc-rotary", "grbl-flat"} <= set(profile_names())
    p = load_profile()
    assert p.name == "linuxcnc-rotary" and p.axes == ("X", "A", "Z")
    assert p.axis("X").max_velocity == 50 and p.axis("A").max_acceleration == 36000
    assert LINUXCNC.profile == p and dialect_from_profile(p) == LINUXCNC
    assert LINUXCNC.laser_on == f"M62 P{p.gate_output}" and "M68 E0 Q{power_w:.3f}" in LINUXCNC.settings
    g = load_profile("grbl-flat")
    assert GRBL.spindle_per_watt == g.s_per_watt == 100 and GRBL.laser_on.startswith("M4 S")
    rec = p.record()
    assert rec["axes"]["A"] == {"max_velocity": 3600.0, "max_acceleration": 36000.0, "unit": "deg"}


def _write(tmp_path, body: str):
    f = tmp_path / "m.yaml"
    f.write_text(body)
    return f


BASE = """machine:
  dialect: linuxcnc
  axes: [X, A, Z]
  limits:
    X: {max_velocity: 50, max_acceleration: 500}
    A: {max_velocity: 3600, max_acceleration: 36000}
    Z: {max_velocity: 50, max_acceleration: 500}
  laser: {gate_output: 2, power_output: 3}
"""


def test_a_profile_file_of_ones_own(tmp_path):
    p = load_profile(_write(tmp_path, BASE))
    d = dialect_from_profile(p)
    assert d.laser_on == "M62 P2" and d.settings == ("M68 E3 Q{power_w:.3f}",)
    assert "G61" in d.preamble  # exact stop is the default blending


def test_unknown_key_gets_a_hint_with_file_and_line(tmp_path):
    f = _write(tmp_path, BASE + "  blendng: exact_stop\n")
    with pytest.raises(PatternError) as e:
        load_profile(f)
    msg = str(e.value)
    assert "machine.blendng" in msg and "did you mean 'blending'" in msg and f"{f}:9" in msg


def test_bad_values_are_all_reported(tmp_path):
    body = BASE.replace("max_velocity: 50, max_acceleration: 500}\n    A", "max_velocity: -1, max_acceleration: 500}\n    A")
    body += "  blending: fast\n  comment: hash\n"
    with pytest.raises(PatternError) as e:
        load_profile(_write(tmp_path, body))
    keys = [i.key for i in e.value.issues]
    assert keys == ["machine.limits.X.max_velocity", "machine.blending", "machine.comment"]


def test_unknown_name_suggests_a_shipped_one():
    with pytest.raises(PatternError, match="did you mean 'linuxcnc-rotary'"):
        load_profile("linuxcnc-rotry")
