"""Everyday mistakes: one clear line naming the path or value and the fix, exit 2, no traceback, nothing left.

Each case runs the real command in a subprocess (as a user would), so the exit status, stderr
and the files on disk are exactly what a user sees.
"""
from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import PATTERNS, ROOT

TUBE1 = str(PATTERNS / "tube1.yaml")


def camtube(*argv: str, cwd: Path | None = None, timeout: float = 120) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    return subprocess.run([sys.executable, "-m", "camtube", *argv], capture_output=True, text=True,
                          timeout=timeout, cwd=cwd, env=env)


def assert_refused(r: subprocess.CompletedProcess, *words: str) -> None:
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert "Traceback" not in r.stderr, r.stderr
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert len(lines) == 1, r.stderr
    assert "fix:" in lines[0], r.stderr
    for w in words:
        assert w in lines[0], (w, r.stderr)


def listing(d: Path) -> list[str]:
    return sorted(str(p.relative_to(d)) for p in d.rglob("*"))


@pytest.fixture
def readonly_dir(tmp_path):
    """A directory nobody may write into: a read-only tmpfs as root, permissions otherwise."""
    d = tmp_path / "ro"
    d.mkdir()
    if os.geteuid() == 0:
        r = subprocess.run(["mount", "-t", "tmpfs", "-o", "ro,size=1m", "tmpfs", str(d)], capture_output=True)
        if r.returncode != 0:
            pytest.skip("running as root without permission to mount a read-only file system")
        yield d, "Read-only file system"
        subprocess.run(["umount", str(d)], check=False)
    else:
        d.chmod(0o500)
        yield d, "Permission denied"
        d.chmod(0o700)


@pytest.mark.parametrize("cmd", [["toolpath", TUBE1, "-o", "{ro}/out"], ["dxf", TUBE1, "-o", "{ro}/t.dxf"],
                                 ["preview", TUBE1, "-o", "{ro}/t.svg"]])
def test_read_only_output(readonly_dir, cmd):
    d, reason = readonly_dir
    r = camtube(*[a.replace("{ro}", str(d)) for a in cmd], "-q")
    assert_refused(r, str(d), reason)
    assert listing(d) == []


def test_output_file_named_like_a_directory(tmp_path):
    (tmp_path / "x.dxf").mkdir()
    assert_refused(camtube("dxf", TUBE1, "-o", str(tmp_path / "x.dxf"), "-q"), "x.dxf", "is a directory")
    assert listing(tmp_path) == ["x.dxf"]


def test_toolpath_output_directory_that_is_a_file(tmp_path):
    f = tmp_path / "out"
    f.write_text("mine")
    assert_refused(camtube("toolpath", TUBE1, "-o", str(f), "-q"), str(f), "is a file")
    assert f.read_text() == "mine" and listing(tmp_path) == ["out"]


def test_pattern_path_that_is_a_directory_or_missing(tmp_path):
    assert_refused(camtube("design", str(tmp_path)), str(tmp_path), "is a directory")
    assert_refused(camtube("toolpath", str(tmp_path / "nope.yaml"), "-o", str(tmp_path / "o")), "no such file")
    assert listing(tmp_path) == []


def test_preview_refuses_a_suffix_it_does_not_write(tmp_path):
    assert_refused(camtube("preview", TUBE1, "-o", str(tmp_path / "x.png"), "-q"), "x.png", "SVG")
    assert listing(tmp_path) == []


def test_no_notches_is_described_not_crashed(tmp_path):
    r = camtube("design", TUBE1, "--set", "notch.count=0")
    assert r.returncode == 0 and "Traceback" not in r.stderr
    assert "no notches" in r.stdout and "notches / holes        0 / 1" in r.stdout


def test_broken_pipe_is_quiet():
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.run(f"{sys.executable} -m camtube design {TUBE1} | head -1", shell=True, capture_output=True,
                       text=True, env=env, timeout=60)
    assert p.stdout.startswith("pattern") and p.stdout.count("\n") == 1
    assert "Traceback" not in p.stderr and "BrokenPipe" not in p.stderr, p.stderr


def test_ctrl_c_exits_130_and_publishes_nothing(tmp_path):
    """SIGINT in the middle of a long build: exit 130, one line, no traceback, no output directory."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    out = tmp_path / "big"
    p = subprocess.Popen([sys.executable, "-m", "camtube", "build", TUBE1, "--set", "notch.count=300",
                          "--set", "tube.length=310", "-o", str(out), "-q"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=env)
    time.sleep(4.0)
    assert p.poll() is None, "the build ended before it could be interrupted"
    p.send_signal(signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert listing(tmp_path) == []


def test_sigterm_while_the_set_is_written_exits_143_and_leaves_no_staging(tmp_path):
    """Bug 27: SIGTERM (kill, a scheduler) while the G-code was being written into ``.big.*.staging`` ended
    the process at once and left the staging folder behind. Now it cleans up as Ctrl-C does."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    p = subprocess.Popen([sys.executable, "-m", "camtube", "toolpath", TUBE1, "--set", "notch.count=300",
                          "--set", "tube.length=310", "-o", str(tmp_path / "big"), "-q"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE, text=True, env=env)
    deadline = time.monotonic() + 60
    while not any(n.endswith(".staging") for n in os.listdir(tmp_path)):
        assert p.poll() is None and time.monotonic() < deadline, "the set was never staged while the command ran"
        time.sleep(0.02)
    p.send_signal(signal.SIGTERM)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 143, (p.returncode, err)
    assert "Traceback" not in err and err.strip().splitlines() == [
        "camtube: terminated (SIGTERM); no output of this command was published"]
    assert listing(tmp_path) == []


def test_sigterm_during_the_swap_is_held_until_the_set_is_whole(tmp_path):
    """Bug 27: SIGTERM in the middle of the swap waits for it, like Ctrl-C: the set is published whole, exit 0."""
    script = (
        "import os, signal, sys\n"
        "import camtube.io as io\n"
        "from camtube.commands import main\n"
        "swap = io._swap_in\n"
        "def terminated_swap(stage, out, files):\n"
        "    os.kill(os.getpid(), signal.SIGTERM)\n"
        "    return swap(stage, out, files)\n"
        "io._swap_in = terminated_swap\n"
        "sys.exit(main(sys.argv[1:]))\n")
    (tmp_path / "o").mkdir()
    (tmp_path / "o" / "notes.txt").write_text("mine")
    r = subprocess.run([sys.executable, "-c", script, "toolpath", TUBE1, "-o", str(tmp_path / "o"), "-q"],
                       capture_output=True, text=True, timeout=120, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert r.returncode == 0, (r.returncode, r.stderr)
    assert "interrupted after the outputs were published" in r.stderr and "Traceback" not in r.stderr
    assert listing(tmp_path) == ["o", "o/.tube1.camtube-set", "o/notes.txt", "o/tube1.job.json", "o/tube1.nc",
                                 "o/tube1.ngc", "o/tube1.toolpath.dxf"]


def test_failed_verification_is_not_success(tmp_path):
    """A beam 5x wider than the kerf the job compensates for cuts outside the design: FAIL -> exit 1."""
    bad = ("--kerf", "0.1", "--set", "process.kerf=0.02")
    r = camtube("cad", TUBE1, "-q", "-o", str(tmp_path / "c"), "--no-step", "--no-pictures", *bad)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "verification: FAIL" in r.stdout and "do not cut it" in r.stderr
    assert (tmp_path / "c" / "tube1.verify.txt").exists()  # the report that says why is written
    r = camtube("cad", TUBE1, "-q", "-o", str(tmp_path / "d"), "--no-step", "--no-pictures", *bad, "--allow-fail")
    assert r.returncode == 0


@pytest.mark.parametrize("opt,value", [("--kerf", "-1"), ("--segments", "2"), ("--outer-radius", "-1"),
                                       ("--layer", "NOTCHES")])
def test_bad_option_values(tmp_path, opt, value):
    assert_refused(camtube("cad", TUBE1, "-q", "-o", str(tmp_path / "c"), opt, value), opt)
    assert listing(tmp_path) == []


def test_calibration_without_stroke_says_the_fix():
    """Before: '...forward model: fix: add --stroke MM' (a colon, not '; fix:')."""
    r = camtube("design", TUBE1, "--calibration", "cal.json", "-q")
    assert_refused(r, "--calibration", "; fix: add --stroke MM")


def test_a_folder_named_like_an_output_file_is_kept_and_refused(tmp_path):
    """A folder ``out/tube1.ngc/`` was replaced by the new G-code, the files in it deleted, exit 0."""
    (tmp_path / "out" / "tube1.ngc").mkdir(parents=True)
    (tmp_path / "out" / "tube1.ngc" / "mine.txt").write_text("mine")
    r = camtube("toolpath", TUBE1, "-o", str(tmp_path / "out"), "-q")
    assert_refused(r, str(tmp_path / "out" / "tube1.ngc"), "a folder of that name")
    assert listing(tmp_path) == ["out", "out/tube1.ngc", "out/tube1.ngc/mine.txt"]


@pytest.mark.parametrize("opt,value,fix", [("--outer-radius", "0.8", "use --set tube.outer_radius=0.8"),
                                           ("--length", "20", "use --set tube.length=20"),
                                           ("--units", "inch", "remove --units"),
                                           ("--layer", "CUTS=notch", "remove --layer")])
def test_a_drawing_option_with_a_yaml_pattern_is_refused_not_ignored(tmp_path, opt, value, fix):
    """``--outer-radius 0.8`` with a YAML pattern was silently ignored (r_o stayed 0.75, exit 0)."""
    r = camtube("toolpath", TUBE1, "-q", "-o", str(tmp_path / "o"), opt, value)
    assert_refused(r, opt, "reads a DXF drawing", "fix: " + fix)
    assert listing(tmp_path) == []


def test_a_job_beyond_the_machine_profiles_rotary_travel_is_refused(tmp_path):
    """``rotary_range_deg: [0, 10]`` was read and never checked: the G-code turned A to 288 deg, exit 0."""
    prof = tmp_path / "stage.yaml"
    prof.write_text((ROOT / "machines" / "linuxcnc-rotary.yaml").read_text()
                    .replace("rotary_range_deg: [-360, 720]", "rotary_range_deg: [0, 10]"))
    r = camtube("toolpath", TUBE1, "-q", "--machine", str(prof), "-o", str(tmp_path / "o"))
    assert_refused(r, str(prof), "outside the stage's travel rotary_range_deg = [0, 10] deg")
    assert listing(tmp_path) == ["stage.yaml"]


def test_too_few_decimals_in_a_machine_profile_are_named(tmp_path):
    """``decimals: 4`` on the GRBL profile: '264 unsafe move(s)' and five lines of moves, no fix."""
    prof = tmp_path / "bed.yaml"
    prof.write_text((ROOT / "machines" / "grbl-flat.yaml").read_text().replace("decimals: 6", "decimals: 4"))
    r = camtube("toolpath", TUBE1, "-q", "--machine", str(prof), "-o", str(tmp_path / "o"))
    assert_refused(r, str(prof), "decimals = 4", "fix: set decimals: 6")
    assert listing(tmp_path) == ["bed.yaml"]


def test_two_laser_signals_on_one_analog_output_are_refused(tmp_path):
    """``frequency_output: 0`` beside ``power_output: 0``: both written as M68 E0, each overwriting the other, exit 0."""
    prof = tmp_path / "stage.yaml"
    prof.write_text((ROOT / "machines" / "linuxcnc-rotary.yaml").read_text()
                    .replace("frequency_output: 1 ", "frequency_output: 0 "))
    r = camtube("toolpath", TUBE1, "-q", "--machine", str(prof), "-o", str(tmp_path / "o"))
    assert_refused(r, f"{prof}:", "laser.frequency_output: is the same analog output as laser.power_output")
    assert listing(tmp_path) == ["stage.yaml"]


@pytest.mark.parametrize("argv", [[], ["model"], ["model", "effect"]])
def test_a_command_without_its_subcommand_is_a_usage_mistake(argv):
    """``camtube``, ``camtube model`` and ``camtube model effect`` alone printed the help and exited 1 (the code of a
    result that failed a check); a command left out is a usage mistake: the help, one line with the fix, exit 2."""
    r = camtube(*argv)
    assert r.returncode == 2, r.stdout + r.stderr
    assert r.stdout.startswith("usage:")
    assert len(r.stderr.strip().splitlines()) == 1 and "fix: give one of the" in r.stderr


def _fit_tiny_forces(tmp_path, *flags: str) -> subprocess.CompletedProcess:
    """``model fit`` on a synthetic record whose forces are 1e-200 N (refused: the force cannot identify E_t)."""
    import csv

    data = tmp_path / "d.csv"
    assert camtube("model", "synth", "--pattern", "tube2", "-o", str(data), "--cycles", "2", "-q").returncode == 0
    with open(data, newline="") as fh:
        rows = list(csv.DictReader(fh))
    for row in rows:
        row["force_N"] = repr(float(row["force_N"]) * 1e-200)
    tiny = tmp_path / "tiny.csv"
    with open(tiny, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return camtube("model", "fit", str(tiny), "--pattern", "tube2", *flags)


def test_quiet_keeps_library_warnings_off_stderr(tmp_path):
    """With ``-q``, numpy's RuntimeWarning ('invalid value encountered in divide', two lines each: the warning and
    the source line) reached stderr around the one error line; and ezdxf's log record 'Found non-unique entity
    handle' was printed for a drawing that imports fine."""
    r = _fit_tiny_forces(tmp_path, "-q")
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert r.returncode == 2 and len(lines) == 1 and "fix:" in lines[0], r.stderr
    assert "Warning" not in r.stderr

    drawing = tmp_path / "dup.dxf"   # two entities of one handle (a hand-edited or merged file)
    text = (ROOT / "examples" / "dxf" / "outline_layer0.dxf").read_text().splitlines(keepends=True)
    handles = [i + 1 for i in range(len(text) - 1) if text[i].strip() == "5" and text[i - 1].strip() == "LWPOLYLINE"]
    assert len(handles) >= 2
    text[handles[1]] = text[handles[0]]
    drawing.write_text("".join(text))
    r = camtube("design", str(drawing), "-q")
    assert r.returncode == 0 and r.stderr == "", r.stderr


def test_forces_too_small_to_weigh_give_their_line_and_no_warning_without_quiet(tmp_path):
    """Forces of 1e-200 N: the deadband search weighed the force by one over its noise squared, which underflows to
    0, and numpy's 'invalid value encountered in divide' reached stderr beside the one error line (without ``-q``)."""
    r = _fit_tiny_forces(tmp_path)
    lines = [x for x in r.stderr.splitlines() if x.strip()]
    assert r.returncode == 2 and len(lines) == 1 and "fix:" in lines[0], r.stderr
    assert "Warning" not in r.stderr
