"""Issue 20's machine cases: one line naming the file or key and the fix, exit 2, quickly, nothing written."""
from __future__ import annotations

import os
import time

import pytest

from camtube.commands import main
from camtube.machine import load_profile
from camtube.motion import linuxcnc as lc
from tests.conftest import PATTERNS


@pytest.fixture()
def linuxcnc_here(monkeypatch):
    """The checks run before LinuxCNC starts: pretend it is installed (nothing may start it)."""
    monkeypatch.setattr(lc, "unavailable_reason", lambda: None)

    def never(*a, **k):
        raise AssertionError("LinuxCNC was started for a file it cannot run")
    monkeypatch.setattr(lc, "run_program", never)


def one_line(capsys) -> str:
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    return err[0]


def test_a_binary_program(tmp_path, capsys, linuxcnc_here):
    p = tmp_path / "job.ngc"
    p.write_bytes(os.urandom(4096).replace(b"\n", b"x"))
    t0 = time.monotonic()
    assert main(["motion", str(p)]) == 2
    assert time.monotonic() - t0 < 5
    line = one_line(capsys)
    assert "job.ngc" in line and "not a G-code program" in line and "camtube toolpath" in line


def test_a_flat_bed_program(tmp_path, capsys, linuxcnc_here):
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "--set", "notch.count=2", "-o", str(tmp_path), "-q"]) == 0
    capsys.readouterr()
    assert main(["motion", str(tmp_path / "tube1.nc")]) == 2
    line = one_line(capsys)
    assert "tube1.nc" in line and "axis Y" in line and "GRBL" in line


def test_a_program_for_another_machine_names_it(tmp_path, capsys, linuxcnc_here):
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "--set", "notch.count=2", "--machine", "linuxcnc-path",
                 "-o", str(tmp_path), "-q"]) == 0
    capsys.readouterr()
    assert main(["motion", str(tmp_path / "tube1.ngc")]) == 2
    assert "give --machine linuxcnc-path" in one_line(capsys)


def test_a_yaml_file(capsys, linuxcnc_here):
    assert main(["motion", str(PATTERNS / "tube1.yaml")]) == 2
    line = one_line(capsys)
    assert "tube1.yaml" in line and "YAML" in line and "camtube toolpath" in line


def test_a_feed_that_rounds_to_zero_is_refused(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "--set", "process.scan_speed_mm_s=0.000001",
                 "-o", str(out), "-q"]) == 2
    line = one_line(capsys)
    assert "process.scan_speed_mm_s" in line and "F0.000" in line and "at least" in line
    assert not out.exists() or not any(out.iterdir())


def test_check_program_accepts_what_camtube_wrote(tmp_path):
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "--set", "notch.count=2", "-o", str(tmp_path), "-q"]) == 0
    text = lc.check_program(tmp_path / "tube1.ngc", load_profile())
    assert text.startswith("(camtube")


@pytest.mark.parametrize("edit", ["G1 X=abc", "G1 X A10.0 F60"])
def test_a_word_without_a_number_is_named_at_its_line_before_linuxcnc_starts(tmp_path, capsys, linuxcnc_here, edit):
    """The bad-input search: the controller, after a real-time start, said only "bad number format (conversion
    failed) parsing ''", naming no line and no fix. Programs camtube writes (their header comments hold ';' and
    words in parentheses) pass."""
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "--set", "notch.count=2", "-o", str(tmp_path), "-q"]) == 0
    capsys.readouterr()
    ngc = tmp_path / "tube1.ngc"
    lines = ngc.read_text().splitlines()
    k = next(i for i, ln in enumerate(lines) if ln.startswith("G1 "))
    assert lc.check_program(ngc, load_profile("linuxcnc-rotary"))   # as written: passes
    lines[k] = edit
    ngc.write_text("\n".join(lines) + "\n")
    assert main(["motion", str(ngc)]) == 2
    line = one_line(capsys)
    assert f"tube1.ngc:{k + 1}: the word X has no number ({edit!r})" in line and "fix: correct that line" in line
