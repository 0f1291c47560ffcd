"""Mistakes in a machine profile of one's own (camtube/machine/profile.py): one line naming the file, line
and key, exit 2, nothing written."""
from __future__ import annotations

import pytest

from tests.conftest import ROOT
from tests.test_cli_errors import TUBE1, assert_refused, camtube, listing

GRBL = (ROOT / "machines" / "grbl-flat.yaml").read_text()


@pytest.mark.parametrize("old,new,words", [
    ("suffix: .nc", "suffix: ../x", ("machine.suffix", "no folder", "'../x'")),
    ("suffix: .nc", "suffix: .job.json", ("machine.suffix", "another file camtube writes", "'.job.json'")),
    ("suffix: .nc", "suffix: .toolpath.dxf", ("machine.suffix", "another file camtube writes")),
    ("decimals: 6", "decimals: 1" + "0" * 400, ("machine.decimals", "401 digits")),
])
def test_a_profile_mistake_is_one_line_and_nothing_is_written(tmp_path, old, new, words):
    """Before: '../x' and a huge number were tracebacks; '.job.json' silently lost the G-code to the job file."""
    m = tmp_path / "m.yaml"
    assert old in GRBL
    m.write_text(GRBL.replace(old, new))
    r = camtube("toolpath", TUBE1, "-q", "-o", str(tmp_path / "o"), "--machine", str(m))
    assert_refused(r, f"{m}:", *words)
    assert listing(tmp_path) == ["m.yaml"]


ROTARY = (ROOT / "machines" / "linuxcnc-rotary.yaml").read_text()
BASES = {"rotary": ROTARY, "grbl": GRBL}


@pytest.mark.parametrize("base,old,new,words", [
    # fuzz report E3: each was accepted with exit 0 and wrote doubtful G-code or a meaningless estimate
    ("rotary", "blending: exact_stop", "blending: 1e-9", ("machine.blending", "got 1e-09", ">= 0.000001 and <= 0.01 mm")),
    ("rotary", "blending: exact_stop", "blending: 1e9", ("machine.blending", "a path tolerance", "<= 0.01 mm")),
    ("rotary", "blending: exact_stop", "blending: 0", ("machine.blending", "got 0")),
    # (the bad-input search: the G61 line left out, LinuxCNC's G64 rounding every corner with the beam on, exit 0)
    ("rotary", "blending: exact_stop", "blending: controller", ("machine.blending", "controller on LinuxCNC",
                                                                "would round them", "exact_stop (G61)")),
    ("rotary", "decimals: 6 ", "decimals: 50 ", ("machine.decimals", "got 50", ">= 0 and <= 9")),
    ("rotary", "feed_decimals: 3", "feed_decimals: 30", ("machine.feed_decimals", "got 30", "<= 9")),
    ("rotary", "X: {max_velocity: 50, max_acceleration: 500}", "X: {max_velocity: 50, max_acceleration: 1e-300}",
     ("machine.limits.X.max_acceleration", ">= 0.1 and <= 10000000 mm/s^2")),
    ("rotary", "A: {max_velocity: 3600,", "A: {max_velocity: 1e300,",
     ("machine.limits.A.max_velocity", ">= 0.01 and <= 100000 deg/s")),
    ("rotary", "servo_period_s: 0.001 ", "servo_period_s: 1e-300 ", ("machine.servo_period_s", "<= 0.01 s")),
    ("rotary", "power_output: 0 ", "power_output: 1000000 ", ("machine.laser.power_output", "<= 63")),
    ("rotary", "warn_time_factor: 3.0", "warn_time_factor: 1e300", ("machine.warn_time_factor", ">= 1 and <= 1000")),
    ("rotary", "rotary_range_deg: [-360, 720]", "rotary_range_deg: [-1e300, 720]",
     ("machine.rotary_range_deg", "-36000..36000", "continuous axis")),
    ("grbl", "s_per_watt: 100 ", "s_per_watt: 1e300 ", ("machine.laser.s_per_watt", ">= 1 and <= 100000 S per W")),
])
def test_a_profile_number_out_of_its_range_is_one_line_naming_file_line_and_key(tmp_path, base, old, new, words):
    """Before: exit 0 with G64 P1e-09 / P1e+09, 50-digit coordinates, a 150-digit time estimate (fuzz report E3)."""
    m = tmp_path / "m.yaml"
    assert old in BASES[base]
    text = BASES[base].replace(old, new)
    m.write_text(text)
    line = next(i for i, t in enumerate(text.splitlines(), 1) if new.strip() in t)
    r = camtube("toolpath", TUBE1, "-q", "-o", str(tmp_path / "o"), "--machine", str(m))
    assert_refused(r, f"{m}:{line}: ", *words)
    assert listing(tmp_path) == ["m.yaml"]


def test_a_spindle_value_that_rounds_to_zero_is_refused(tmp_path):
    """S = 0.3 W x 1 S/W is written S0: the GRBL beam never comes on, yet the job was written with exit 0."""
    m = tmp_path / "m.yaml"
    m.write_text(GRBL.replace("s_per_watt: 100 ", "s_per_watt: 1 "))
    r = camtube("toolpath", TUBE1, "-q", "-o", str(tmp_path / "o"), "--machine", str(m),
                "--set", "process.power_w=0.3")
    assert_refused(r, "process.power_w", "'M4 S0'", "machine.laser.s_per_watt")
    assert listing(tmp_path) == ["m.yaml"]


@pytest.mark.parametrize("drop,words", [
    # the bad-input search: a key left out read "must be a finite number ...", never that it was missing
    ("    A: {max_velocity: 3600, max_acceleration: 36000}", ("machine.limits.A.max_acceleration: is missing",
                                                         "add max_acceleration:")),
    # and "allowed: 0..3", while outputs 0..63 are taken
    ("gate_output: 0", ("machine.laser.gate_output: is missing", "a digital output 0..63")),
])
def test_a_key_left_out_of_a_profile_is_said_to_be_missing(tmp_path, drop, words):
    text = (ROOT / "machines" / "linuxcnc-rotary.yaml").read_text()
    assert drop in text
    if drop.startswith("    A:"):
        text = text.replace(drop, "    A: {max_velocity: 3600}")
    else:
        text = text.replace("gate_output: 0, ", "").replace("gate_output: 0}", "}").replace("gate_output: 0", "")
    m = tmp_path / "m.yaml"
    m.write_text(text)
    assert_refused(camtube("toolpath", TUBE1, "-q", "-o", str(tmp_path / "o"), "--machine", str(m)), *words)
    assert listing(tmp_path) == ["m.yaml"]


def test_feeds_the_profile_cannot_carry_name_the_decimals_that_would(tmp_path):
    """The bad-input search: a profile with feed_decimals 0 and a long slit was told to raise the scan speed to 583
    mm/s (23x the process's); the profile's decimals are the fix."""
    m = tmp_path / "m.yaml"
    assert "feed_decimals: " in ROTARY
    import re

    m.write_text(re.sub(r"feed_decimals: \d+", "feed_decimals: 0", ROTARY))
    r = camtube("toolpath", TUBE1, "-q", "--set", "process.scan_speed_mm_s=0.5", "-o", str(tmp_path / "o"),
                "--machine", str(m))
    assert_refused(r, "process.scan_speed_mm_s: too slow for machine", "fix: set the machine profile's feed_decimals to")
    want = int(re.search(r"feed_decimals to (\d+) or more", r.stderr).group(1))
    m.write_text(re.sub(r"feed_decimals: \d+", f"feed_decimals: {want}", ROTARY))
    ok = camtube("toolpath", TUBE1, "-q", "--set", "process.scan_speed_mm_s=0.5", "-o", str(tmp_path / "o"),
                 "--machine", str(m))
    assert ok.returncode == 0, ok.stderr


@pytest.mark.parametrize("axes,rotary,words", [
    ("[X, Z, A]", "true", ("machine.axes", "the focus axis A turns", "must move in mm")),
    ("[A, X, Z]", "true", ("machine.axes", "the axial axis A turns")),
    ("[X, Y, Z]", "true", ("machine.axes", "rotary: true, but the circumferential axis Y is a linear axis")),
    ("[X, A, Z]", "false", ("machine.axes", "rotary: false", "but A is a rotary axis")),
    ("[x, X, Z]", "true", ("machine.axes", "three different axis letters")),
])
def test_axis_letters_must_fit_their_roles(tmp_path, axes, rotary, words):
    """The bad-input search: axes [X, Z, A] drove the focus axis to 168 mm (exit 0); [A, X, Z] the linear stage to
    191 mm; rotary: false sent mm to A; [x, X, Z] was told "limits.A ... allowed X, X, Z"."""
    import re

    text = re.sub(r"axes: \[[^\]]*\]", f"axes: {axes}", ROTARY)
    text = re.sub(r"rotary: (true|false)", f"rotary: {rotary}", text)
    # limits for every letter named (so the roles, not a missing limit, are what is refused)
    if "A" not in axes:
        text = text.replace("    A: {max_velocity: 3600, max_acceleration: 36000}", "    Y: {max_velocity: 50, "
                            "max_acceleration: 500}")
    m = tmp_path / "m.yaml"
    m.write_text(text)
    assert_refused(camtube("toolpath", TUBE1, "-q", "-o", str(tmp_path / "o"), "--machine", str(m)), *words)
    assert listing(tmp_path) == ["m.yaml"]
