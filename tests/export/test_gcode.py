"""G-code emitter: determinism, the rotary wrap, inverse-time feeds, bounded A, dialects as data."""
from __future__ import annotations

import dataclasses
import math
import re

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.export.dialects import DIALECTS, GRBL, LINUXCNC, Dialect, get_dialect
from camtube.export.gcode import gcode
from camtube.plan import plan_job
from tests.conftest import PATTERNS

G1 = re.compile(r"^G1 X(\S+) ([AY])(\S+) F(\S+)$")


@pytest.fixture(scope="module")
def bidir():
    return plan_job(load_pattern(PATTERNS / "tube1-bidirectional.yaml"))


@pytest.mark.parametrize("dialect", list(DIALECTS.values()), ids=lambda d: d.name)
def test_same_input_same_bytes(dialect):
    p = load_pattern(PATTERNS / "tube2.yaml")
    a = gcode(plan_job(p), dialect)
    b = gcode(plan_job(load_pattern(PATTERNS / "tube2.yaml")), dialect)
    assert a.encode() == b.encode()


@pytest.mark.parametrize("dialect", list(DIALECTS.values()), ids=lambda d: d.name)
def test_memoised_blocks_equal_row_by_row_formatting(bidir, dialect):
    assert gcode(bidir, dialect, memo=True) == gcode(bidir, dialect, memo=False)


def test_wrap_is_degrees_of_y_over_r(bidir):
    ro = bidir.outer_radius_mm
    text = gcode(bidir, LINUXCNC)
    lines = [m for m in map(G1.match, text.splitlines()) if m]
    assert len(lines) == sum(len(p.contour.points) for p in bidir.passes)
    ys = {y for p in bidir.passes for _, y in p.contour.points}
    a_deg = {float(m.group(3)) for m in lines}
    assert a_deg == {round(math.degrees(y / ro), 6) for y in ys}
    assert min(a_deg) > -180 and max(a_deg) < 540  # bounded: no wind-up
    assert min(a_deg) < 0  # the seam-crossing notches are cut continuously through A = 0


def test_inverse_time_feed_gives_the_scan_speed_on_the_surface(bidir):
    ro = bidir.outer_radius_mm
    text = gcode(bidir, LINUXCNC)
    x = a = None
    speeds = []
    for line in text.splitlines():
        m = G1.match(line)
        if line.startswith("G0 X"):
            _, xs, as_ = line.split()
            x, a = float(xs[1:]), float(as_[1:])
        if m:
            nx, na, f = float(m.group(1)), float(m.group(3)), float(m.group(4))
            dist = math.hypot(nx - x, math.radians(na - a) * ro)
            speeds.append(dist * f / 60.0)  # F = 1 / minutes
            x, a = nx, na
    assert np.allclose(speeds, 25.0, rtol=1e-5)
    assert "G93" in text.split("(pass 0")[0]


def test_grbl_is_flat_and_feeds_mm_per_min():
    job = plan_job(load_pattern(PATTERNS / "tube1.yaml"))
    text = gcode(job, GRBL)
    assert " A" not in text and "M4 S200" in text and "G93" not in text
    feeds = {m.group(4) for m in map(G1.match, text.splitlines()) if m}
    assert feeds == {"1500.000"}


def test_gate_wraps_every_pass_and_rapids_are_laser_off():
    job = plan_job(load_pattern(PATTERNS / "tube1.yaml"))
    state = False
    for line in gcode(job, LINUXCNC).splitlines():
        if line == "M62 P0":
            assert not state
            state = True
        elif line in ("M63 P0", "M65 P0"):
            state = False
        elif line.startswith("G0"):
            assert not state
        elif line.startswith("G1"):
            assert state
    assert not state


def test_dialect_is_frozen_data():
    with pytest.raises(dataclasses.FrozenInstanceError):
        LINUXCNC.laser_on = "M3"  # type: ignore[misc]
    assert get_dialect("grbl") is GRBL
    with pytest.raises(KeyError, match="known: linuxcnc, grbl"):
        get_dialect("fanuc")
    # a new dialect is data: the same emitter serves it
    m3 = dataclasses.replace(LINUXCNC, name="linuxcnc-m3", laser_on="M3 S{power_w:.1f}", laser_off="M5",
                             settings=())
    text = gcode(plan_job(load_pattern(PATTERNS / "tube1.yaml")), m3)
    lines = text.splitlines()
    assert lines.count("M3 S2.0") == 352 and "M62 P0" not in lines
    assert isinstance(m3, Dialect)


@pytest.mark.parametrize("dialect", list(DIALECTS.values()), ids=lambda d: d.name)
def test_no_text_a_user_gives_becomes_a_gcode_line(dialect):
    """A name or description with line breaks (here set past the loader's check, as a DXF file's name reaches it)
    stays inside its one header comment: the job's lines are those of the plain name, the name's text in one line."""
    p = load_pattern(PATTERNS / "tube1.yaml")
    plain = gcode(plan_job(p), dialect).splitlines()
    evil = gcode(plan_job(dataclasses.replace(p, name="x\nM3 S1000\r\nG0 X500\u2028M5")), dialect).splitlines()
    assert len(evil) == len(plain)
    assert all(b.startswith(("(", ";")) for a, b in zip(plain, evil) if a != b)   # only comments differ
    assert not any(ln.strip() in ("M3 S1000", "G0 X500") for ln in evil)
    assert "x M3 S1000  G0 X500 M5" in evil[0]
    assert dialect.comment_line("a\nb\tc\x00d") in ("(a b c d)", "; a b c d")


EXPONENT = re.compile(r"\d[eE][-+]?\d")


def test_every_number_in_the_gcode_is_fixed_point(tmp_path):
    """rs274ngc reads no exponent: ``G64 P{:g}`` wrote P5e-05 for a 50 nm tolerance, and the header's
    ``{:g}`` process values 5e-05 mm (fuzz report E3); every number is now written in fixed-point notation."""
    from camtube.export.dialects import dialect_from_profile
    from camtube.machine import load_profile
    from tests.conftest import ROOT

    text = (ROOT / "machines" / "linuxcnc-path.yaml").read_text().replace("blending: 0.001 ", "blending: 0.00005 ")
    (tmp_path / "m.yaml").write_text(text)
    d = dialect_from_profile(load_profile(tmp_path / "m.yaml"))
    job = plan_job(load_pattern(PATTERNS / "tube2.yaml", ["process.drill_offset=0.00005", "process.defocus=0.00007",
                                                          "notch.count=2"]))
    out = gcode(job, d)
    assert "G64 P0.00005\n" in out and "0.00005 mm apart, defocus 0.00007 mm" in out and "at 0.00007 mm" in out
    assert not EXPONENT.search(out), EXPONENT.search(out)
