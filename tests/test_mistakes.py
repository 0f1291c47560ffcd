"""The mistakes a new user made (issue 20): each gets one line naming the file, line or key and the
fix, exit 2 (130 / 0 for Ctrl-C as said), and nothing left behind."""
from __future__ import annotations

import json
import math
import os
import signal
import time

import pytest

from camtube.commands import main
from tests.conftest import PATTERNS, ROOT
from tests.test_cli_errors import TUBE1, assert_refused, camtube, listing


def pattern_text(**notch) -> str:
    n = {"count": 3, "width": 0.5, "spacing": 0.5, "arc": 2.83, "first_offset": 1.0, **notch}
    return ("name: p\ntube: {outer_radius: 0.75, inner_radius: 0.45, length: 14}\n"
            "notch: {" + ", ".join(f"{k}: {v}" for k, v in n.items()) + "}\n"
            "process: femto-polyimide.yaml\n")


def test_random_bytes_as_a_pattern(tmp_path):
    bad = tmp_path / "p.yaml"
    bad.write_bytes(bytes(range(256)) * 4)
    assert_refused(camtube("design", str(bad)), str(bad), "not a text file")
    assert_refused(camtube("toolpath", str(bad), "-o", str(tmp_path / "o")), "not a text file")
    assert listing(tmp_path) == ["p.yaml"]


def test_a_key_given_twice_is_refused_with_both_lines(tmp_path):
    p = tmp_path / "p.yaml"
    p.write_text(pattern_text() + "name: q\n")
    r = camtube("design", str(p))
    assert_refused(r, f"{p}:5", "'name' is given twice", "first at line 1")


def test_a_nested_key_given_twice_too(tmp_path):
    p = tmp_path / "p.yaml"
    p.write_text(pattern_text().replace("count: 3,", "count: 3, count: 4,"))
    assert_refused(camtube("design", str(p)), "'count' is given twice")


@pytest.mark.parametrize("form", ["5e-1", "5E-1", "0.5", "5.0e-1", "+5e-1", ".5e0", "5_0e-2"])
def test_every_yaml_number_form_is_a_number(tmp_path, form):
    p = tmp_path / "p.yaml"
    p.write_text(pattern_text(width=form))
    r = camtube("design", str(p))
    assert r.returncode == 0, r.stderr
    r = camtube("design", TUBE1, "--set", f"notch.width={form}")
    assert r.returncode == 0, r.stderr


def test_a_missing_process_file_names_the_key_and_where_it_looked(tmp_path):
    p = tmp_path / "p.yaml"
    p.write_text(pattern_text().replace("femto-polyimide.yaml", "nothere.yaml"))
    assert_refused(camtube("design", str(p)), f"{p}:4", "process:", "nothere.yaml", str(tmp_path),
                   "femto-polyimide")


def test_a_shipped_process_is_found_for_a_pattern_anywhere(tmp_path):
    p = tmp_path / "p.yaml"
    p.write_text(pattern_text())
    r = camtube("design", str(p), cwd=tmp_path)
    assert r.returncode == 0, r.stderr


def test_presets_by_name_from_any_folder(tmp_path):
    r = camtube("design", "tube2", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert "0.850" in r.stdout
    assert_refused(camtube("design", "tube9", cwd=tmp_path), "tube9", "no such file or preset", "tube1")


def test_no_message_prints_a_placeholder_for_the_file():
    r = camtube("design", TUBE1, "--set", "notch.count")
    assert r.returncode == 2 and "<pattern>" not in r.stderr
    r = camtube("design", TUBE1, "--set", "nosuch.key=1")
    assert r.returncode == 2 and "<pattern>" not in r.stderr


def test_an_unwritable_output_is_refused_before_any_work(tmp_path, monkeypatch, capsys):
    import camtube.pipeline

    def never(*a, **k):
        raise AssertionError("the job was built before the output was checked")

    monkeypatch.setattr(camtube.pipeline, "run", never)
    assert main(["toolpath", TUBE1, "-o", "/proc/camtube-x/out", "-q"]) == 2
    err = capsys.readouterr().err
    assert "/proc/camtube-x/out" in err and "fix:" in err and len(err.strip().splitlines()) == 1


def test_too_many_notches_blame_the_count_and_the_length():
    r = camtube("design", TUBE1, "--set", "notch.count=15")
    assert_refused(r, "notch.count", "15 notches", "tube.length = 14", "lower notch.count to 13",
                   "lengthen tube.length to at least 16")
    assert "notch.first_offset:" not in r.stderr


def test_fix_holds_a_parameter_the_default_fit_would_vary(tmp_path):
    data = tmp_path / "d.csv"
    assert camtube("model", "synth", "--pattern", str(PATTERNS / "tube2.yaml"), "-o", str(data)).returncode == 0
    out = tmp_path / "fit.json"
    r = camtube("model", "fit", str(data), "--pattern", str(PATTERNS / "tube2.yaml"), "--fix", "E_t=20",
                "--json", str(out))
    assert r.returncode == 0, r.stderr
    fit = json.loads(out.read_text())
    e_t = fit["params"]["E_t"] if "params" in fit else fit["parameters"]["E_t"]
    value = e_t["value"] if isinstance(e_t, dict) else e_t
    assert value == pytest.approx(20.0)
    r = camtube("model", "fit", str(data), "--pattern", str(PATTERNS / "tube2.yaml"), "--fix", "E_t=-20")
    assert_refused(r, "--fix E_t=-20", "0.5..500 GPa")
    r = camtube("model", "fit", str(data), "--pattern", str(PATTERNS / "tube2.yaml"), "--fix", "E_t=20",
                "--fit", "E_t")
    assert_refused(r, "--fit and --fix both name E_t")


def test_ctrl_c_while_the_set_is_published_publishes_it_whole_and_says_so(tmp_path, monkeypatch, capsys):
    """A real SIGINT arrives in the middle of the swap: it is held until the set is in place, then
    the command exits 0 saying the set is complete (not 130 'nothing published')."""
    import camtube.io as io

    swap = io._swap_in

    def interrupted_swap(stage, out, files):
        os.kill(os.getpid(), signal.SIGINT)  # Ctrl-C now, while the swap runs
        return swap(stage, out, files)

    monkeypatch.setattr(io, "_swap_in", interrupted_swap)
    out = tmp_path / "o"
    assert main(["toolpath", TUBE1, "-o", str(out), "-q"]) == 0
    err = capsys.readouterr().err
    assert "interrupted after the outputs were published" in err and str(out) in err
    assert sorted(p.name for p in out.iterdir()) == [".tube1.camtube-set", "tube1.job.json", "tube1.nc", "tube1.ngc",
                                                     "tube1.toolpath.dxf"]   # (the set's list: camtube.io)


def test_ctrl_c_before_the_swap_publishes_nothing(tmp_path, monkeypatch, capsys):
    import camtube.io as io

    def interrupted(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(io, "_swap_in", interrupted)
    assert main(["toolpath", TUBE1, "-o", str(tmp_path / "o"), "-q"]) == 130
    assert "no output of this command was published" in capsys.readouterr().err
    assert listing(tmp_path) == []


def test_ctrl_c_during_an_extension_import_exits_130_without_a_traceback(tmp_path, monkeypatch, capsys):
    """An extension module stopped by Ctrl-C while it initialises fails as an ImportError whose context
    is the KeyboardInterrupt (the CAD kernel did this): that is an interrupt, not a crash."""
    import camtube.pipeline

    def importing(*a, **k):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt:
            raise ImportError("initialization failed")  # noqa: B904 (as the extension does)

    monkeypatch.setattr(camtube.pipeline, "run", importing)
    assert main(["build", TUBE1, "-o", str(tmp_path / "o"), "-q"]) == 130
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert listing(tmp_path) == []


def test_a_real_import_error_is_not_taken_for_an_interrupt(monkeypatch, tmp_path):
    import camtube.pipeline

    def broken(*a, **k):
        raise ImportError("no module named nothing")

    monkeypatch.setattr(camtube.pipeline, "run", broken)
    with pytest.raises(ImportError):
        main(["build", TUBE1, "-o", str(tmp_path / "o"), "-q"])


@pytest.mark.parametrize("content,words", [(b"\x00\x01binary\xff" * 50, ("bad.py:", "fix: give a Python source file")),
                                           (b"def x(:\n", ("bad.py:1:", "fix: correct the Python at that line"))])
def test_an_effect_file_that_is_not_python(tmp_path, content, words):
    data = tmp_path / "d.csv"
    assert camtube("model", "synth", "--pattern", str(PATTERNS / "tube2.yaml"), "-o", str(data)).returncode == 0
    bad = tmp_path / "bad.py"
    bad.write_bytes(content)
    r = camtube("model", "fit", str(data), "--pattern", str(PATTERNS / "tube2.yaml"), "--effect-file", str(bad))
    assert_refused(r, *words)
    assert ":None" not in r.stderr


def test_a_binary_measurement_file(tmp_path):
    bad = tmp_path / "d.csv"
    bad.write_bytes(bytes(range(128, 256)) * 8)
    assert_refused(camtube("model", "fit", str(bad), "--pattern", TUBE1), str(bad), "not a UTF-8 text file")


@pytest.mark.parametrize("section,value,words", [
    ("tube", "3", "tube: expected a mapping"), ("notch", "[1,2]", "notch: expected a mapping"),
    ("process", "[1,2]", "process: expected a mapping"),
    # a text names a process file, as the pattern's own 'process:' may
    ("process", "fast", "process: names a process file that is not there")])
def test_a_section_that_is_not_a_mapping_is_one_line_not_one_per_missing_key(section, value, words):
    assert_refused(camtube("design", TUBE1, "--set", f"{section}={value}"), words)


def test_a_tendon_thicker_than_the_lumen():
    assert_refused(camtube("design", TUBE1, "--set", "tendon.radius=0.5"), "tendon.radius", "inner_radius = 0.45")


@pytest.mark.parametrize("argv,words", [
    (["build", TUBE1], ("required: -o/--output", "camtube build --help")),
    (["toolpath", TUBE1, "-o", "x", "--ordering", "fastest"], ("invalid choice: 'fastest'",)),
    (["model", "fit", "x.csv"], ("--pattern", "camtube model fit --help")),
    (["nosuch"], ("invalid choice: 'nosuch'",)),
])
def test_command_line_mistakes_are_one_line_too(tmp_path, argv, words):
    assert_refused(camtube(*argv, cwd=tmp_path), *words)
    assert listing(tmp_path) == []


@pytest.mark.parametrize("cmd", [["toolpath", TUBE1, "-o", ""], ["dxf", TUBE1, "-o", ""], ["build", TUBE1, "-o", " "]])
def test_an_empty_output_path_is_refused_not_taken_for_the_working_directory(tmp_path, cmd):
    r = camtube(*cmd, cwd=tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "fix:" in r.stderr
    assert listing(tmp_path) == []


@pytest.mark.parametrize("where", ["pattern", "set", "goal"])
def test_yaml_nested_too_deeply_is_a_yaml_error_not_a_recursion_traceback(tmp_path, where):
    deep = "[" * 3000 + "]" * 3000
    if where == "set":
        r = camtube("design", TUBE1, "--set", f"notch.width={deep}")
        assert r.returncode == 2 and "Traceback" not in r.stderr and "RecursionError" not in r.stderr, r.stderr
        return
    f = tmp_path / "f.yaml"
    f.write_text(f"a: {deep}\n")
    r = camtube("design", str(f)) if where == "pattern" else camtube("synthesize", str(f), "-o", str(tmp_path / "o.yaml"))
    assert_refused(r, str(f), "nested too deeply", "fix: remove the runaway brackets")
    assert listing(tmp_path) == ["f.yaml"]


@pytest.mark.parametrize("argv,words", [
    (["design", TUBE1, "-q", "--stroke", "1", "--calibration", "{f}"], ("the calibration is not JSON",)),
    (["synthesize", str(ROOT / "examples" / "goals" / "01-tube1-uniform-60.yaml"), "-o", "{o}/p.yaml",
      "--calibration", "{f}"], ("the calibration is not JSON",)),
    (["model", "effect", "new", "okname", "--from", "{f}", "-o", "{o}/y.py"], ("not a diagnosis JSON",)),
], ids=["design", "synthesize", "effect-new"])
def test_json_nested_too_deeply_is_not_json_not_a_recursion_traceback(tmp_path, argv, words):
    """A calibration or diagnosis of 100000 '[' then ']' (valid JSON, too deep for Python's parser) was a
    RecursionError traceback, exit 1; the YAML readers already refused the same nesting in one line."""
    f = tmp_path / "deep.json"
    f.write_text("[" * 100_000 + "]" * 100_000)
    r = camtube(*[a.replace("{f}", str(f)).replace("{o}", str(tmp_path / "o")) for a in argv])
    assert_refused(r, str(f), *words, "nested too deeply", "fix: ")
    assert listing(tmp_path) == ["deep.json"]


def billion_laughs(levels: int = 9) -> str:
    """Anchors each aliased ten times in the next: a few lines that expand to 10**levels values."""
    lines = ["l0: &l0 [x, x, x, x, x, x, x, x, x, x]"]
    lines += [f"l{i}: &l{i} [{', '.join([f'*l{i - 1}'] * 10)}]" for i in range(1, levels)]
    return "\n".join(lines) + "\n"


@pytest.mark.parametrize("where", ["pattern", "goal"])
@pytest.mark.parametrize("kind,words", [
    ("bomb", ("aliases repeat more than 100000 values", "*l3 here", "fix: write the values out")),
    ("self", ("the alias *a stands inside the value of its own anchor", "fix: point the alias")),
])
def test_a_yaml_alias_bomb_is_refused_at_once_not_expanded(tmp_path, where, kind, words):
    """A "billion laughs" pattern (nested anchors, each aliased ten times) hung the loader, which walked every
    expanded value to map the keys' lines; an alias inside its own anchor was a RecursionError traceback."""
    f = tmp_path / "f.yaml"
    f.write_text(pattern_text() + (billion_laughs() if kind == "bomb" else "a: &a [1, *a]\n"))
    t0 = time.monotonic()
    r = (camtube("design", str(f), timeout=60) if where == "pattern"
         else camtube("synthesize", str(f), "-o", str(tmp_path / "o.yaml"), timeout=60))
    assert_refused(r, f"{f}:{9 if kind == 'bomb' else 5}: yaml: refused YAML", *words)
    assert time.monotonic() - t0 < 30
    assert listing(tmp_path) == ["f.yaml"]


def test_anchors_and_aliases_used_sensibly_still_work(tmp_path):
    f = tmp_path / "p.yaml"
    f.write_text(pattern_text().replace("width: 0.5, spacing: 0.5", "width: &w 0.5, spacing: *w")
                 + "holes:\n  - &h {x: 0.75, size: 0.3, angle_deg: 180}\n  - {<<: *h, x: 13}\n")
    r = camtube("design", str(f))
    assert r.returncode == 0, r.stderr
    assert "3 / 2" in r.stdout


@pytest.mark.parametrize("value,words", [("1e400", ("notch.count", "must be finite")),
                                         (".nan", ("notch.count", "must be finite")),
                                         ("1" + "0" * 400, ("notch.count", "out of range", "401 digits"))])
def test_an_infinite_nan_or_huge_count_is_refused_not_a_crash(value, words):
    assert_refused(camtube("design", TUBE1, "--set", f"notch.count={value}"), *words)


@pytest.mark.parametrize("value", ["-0.5", ".nan", "[1,2]"])
def test_a_refused_notch_width_is_not_also_called_missing(value):
    r = camtube("design", TUBE1, "--set", f"notch.width={value}")
    assert_refused(r, "notch.width")
    assert "required key is missing" not in r.stderr


@pytest.mark.parametrize("name", ["../../etc/x", "runs/tube4", "a\\\\b", "..", "[a, b]"])
def test_a_pattern_name_that_is_not_a_plain_file_name(tmp_path, name):
    """``name:`` names the output files: a folder in it was a ValueError traceback from the writer."""
    p = tmp_path / "p.yaml"
    p.write_text(f"name: {name}\n" + pattern_text().split("\n", 1)[1])
    r = camtube("toolpath", str(p), "-o", str(tmp_path / "o"), "-q")
    assert_refused(r, f"{p}:1", "name:", "fix:")
    assert listing(tmp_path) == ["p.yaml"]


@pytest.mark.parametrize("override", ["holes.1={x: 3, size: 0.3}", "process.repeat_rule.3={max_depth: 3, repeats: 9}"])
def test_a_set_of_a_whole_list_entry_past_the_end_names_the_index(override):
    """``--set holes.1=...`` (adding a second hole) was an IndexError traceback."""
    assert_refused(camtube("design", TUBE1, "--set", override), "past the end of the list", "fix:")


@pytest.mark.parametrize("entry", ["0.75", "[1, 2]"])
def test_a_set_into_a_list_entry_that_is_not_a_mapping_names_the_entry(tmp_path, entry):
    """``holes: [0.75]`` with ``--set holes.0.x=1`` was a TypeError traceback."""
    p = tmp_path / "p.yaml"
    p.write_text(pattern_text() + f"holes:\n  - {entry}\n")
    assert_refused(camtube("design", str(p), "--set", "holes.0.x=1"), f"{p}:6", "holes[0]: expected a mapping")


@pytest.mark.parametrize("index", ["\u00b2", "9" * 5000], ids=["superscript-two", "5000-digits"])
def test_a_set_index_that_is_not_a_small_ascii_number(index):
    """``'²'.isdigit()`` is true and ``int('9' * 5000)`` is refused by Python: both were tracebacks."""
    r = camtube("design", TUBE1, "--set", f"holes.{index}.x=1")
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert "fix:" in r.stderr and len(r.stderr.strip().splitlines()) == 1


def test_a_whole_number_of_thousands_of_digits(tmp_path):
    """More digits than Python converts from text (4300) was a ValueError traceback from the YAML reader."""
    big = "9" * 5000
    p = tmp_path / "p.yaml"
    p.write_text(pattern_text(count=big))
    assert_refused(camtube("design", str(p)), f"{p}:3", "a whole number of 5000 digits", "fix:")
    r = camtube("toolpath", TUBE1, "--set", f"notch.count={big}", "-o", str(tmp_path / "o"))
    assert_refused(r, "notch.count", "out of range", "5000 digits")
    assert listing(tmp_path) == ["p.yaml"]


@pytest.mark.parametrize("argv", [
    ["toolpath", TUBE1, "-o", "{tmp}/o", "--machine", ""],
    ["design", TUBE1, "--stroke", "1", "--calibration", ""],
    ["model", "fit", "{data}", "--pattern", "tube2", "--json", ""],
    ["model", "fit", "{data}", "--pattern", "tube2", "--plot", ""],
    ["model", "diagnose", "{data}", "--pattern", "tube2", "--report", " "],
    ["model", "effect", "new", "drive", "--follows", "stroke", "-o", ""],
], ids=["machine", "calibration", "fit-json", "fit-plot", "diagnose-report", "effect-output"])
def test_an_empty_option_value_is_refused_not_taken_for_no_option(tmp_path, argv):
    """``--machine "$MACHINE"`` with the variable unset: the option was dropped (the default machine, exit 0),
    ``--json ''`` a ValueError traceback, ``--report ''`` no report and exit 0."""
    data = tmp_path / "d.csv"
    data.write_text("sample,cycle,time_s,stroke_mm,force_N,angle_deg\n1,1,0,0,0,0\n")
    r = camtube(*[a.replace("{tmp}", str(tmp_path)).replace("{data}", str(data)) for a in argv], cwd=tmp_path)
    assert_refused(r, "the path is empty")
    assert listing(tmp_path) == ["d.csv"]


@pytest.mark.parametrize("path,words", [(".", ("is a directory", "--json out.json")),
                                        ("/", ("is a directory", "--json /out.json")),
                                        ("..", ("is a directory",))])
def test_a_json_output_that_is_a_folder_with_no_file_name(tmp_path, path, words):
    """``--json .`` was a ValueError traceback from pathlib (a path with an empty name has no suffix to set)."""
    data = tmp_path / "d.csv"
    data.write_text("sample,cycle,time_s,stroke_mm,force_N,angle_deg\n1,1,0,0,0,0\n")
    r = camtube("model", "fit", str(data), "--pattern", "tube2", "--json", path, cwd=tmp_path)
    assert_refused(r, f"--json {path}", *words)
    assert listing(tmp_path) == ["d.csv"]


@pytest.mark.parametrize("argv,name", [(["design", ""], "PATTERN"), (["model", "fit", "", "--pattern", "tube2"], "DATA.csv"),
                                       (["model", "synth", "--pattern", "", "-o", "d.csv"], "--pattern"),
                                       (["synthesize", "", "-o", "p.yaml"], "GOAL.yaml")])
def test_an_empty_input_path_is_named_not_called_the_working_directory(tmp_path, argv, name):
    """``camtube design ''`` said '.: is a directory' (the empty path read as the working directory)."""
    r = camtube(*argv, cwd=tmp_path)
    assert_refused(r, f"argument {name}: the path is empty")
    assert ".: is a directory" not in r.stderr and listing(tmp_path) == []


BENCH = ROOT / "examples" / "bench"


def ingest_argv(tmp_path, *extra) -> list[str]:
    return ["model", "ingest", "--tracker", str(BENCH / "aurora-export.csv"), "--daq", str(BENCH / "daq.csv"),
            "--motor", str(BENCH / "motor.csv"), "-o", str(tmp_path / "data.csv"), *extra]


def test_a_tracker_rest_that_runs_into_the_first_pull_is_refused(tmp_path):
    """The bad-input search: tracker.rest_s = 10 s over a rest of 4 s read zero bend (and the force's zero) over the
    first pull: angles -11 to 21 deg, E_t 24 GPa, exit 0."""
    r = camtube(*ingest_argv(tmp_path, "--bench", str(BENCH / "bench.yaml"), "--map", "tracker.rest_s=10"))
    assert_refused(r, "aurora-export.csv", "the joint bends by", "within tracker.rest_s = 10 s",
                   "fix: give the rest before the first pull (--map tracker.rest_s=")
    assert listing(tmp_path) == []
    assert camtube(*ingest_argv(tmp_path, "--bench", str(BENCH / "bench.yaml"))).returncode == 0


@pytest.mark.parametrize("extra,words", [("notes: 1\n", ("notes: unknown section",)),
                                         ("angle: 3\n", ("angle: expected a mapping of keys, got 3",))])
def test_a_bench_map_section_that_is_not_a_mapping(tmp_path, extra, words):
    """An extra top-level key of the bench map (``notes: 1``) was a TypeError traceback."""
    bench = tmp_path / "bench.yaml"
    bench.write_text((BENCH / "bench.yaml").read_text() + extra)
    r = camtube(*ingest_argv(tmp_path, "--bench", str(bench)))
    assert_refused(r, str(bench), *words)
    assert listing(tmp_path) == ["bench.yaml"]


@pytest.mark.parametrize("role,content,words", [("daq", "", ("the file is empty", "fix: give the daq log")),
                                                ("motor", "t_us,enc_counts\n", ("no data lines after the header",)),
                                                ("tracker", None, ("no frames after the header",))])
def test_an_empty_bench_log_says_the_fix(tmp_path, role, content, words):
    """An empty DAQ or motor log, or a header-only tracker export, was refused without a fix."""
    if content is None:
        content = (BENCH / "aurora-export.csv").read_text().splitlines()[0] + "\n"
    log = tmp_path / f"{role}.csv"
    log.write_text(content)
    argv = ingest_argv(tmp_path, "--bench", str(BENCH / "bench.yaml"))
    argv[argv.index(f"--{role}") + 1] = str(log)
    assert_refused(camtube(*argv), str(log), *words)
    assert listing(tmp_path) == [f"{role}.csv"]


def test_an_output_that_is_an_input_file_is_refused_and_the_input_kept(tmp_path):
    """``synthesize goal.yaml -o goal.yaml``, ``dxf d.dxf -o d.dxf`` and ``model ingest --daq daq.csv -o daq.csv``
    replaced the input with the output (the goal, the drawing, the raw log lost), exit 0."""
    goal, drawing, daq = tmp_path / "g.yaml", tmp_path / "d.dxf", tmp_path / "daq.csv"
    goal.write_text((ROOT / "examples" / "goals" / "01-tube1-uniform-60.yaml").read_text())
    drawing.write_bytes((ROOT / "examples" / "dxf" / "four_lines.dxf").read_bytes())
    daq.write_text((BENCH / "daq.csv").read_text())
    before = {p: p.read_bytes() for p in (goal, drawing, daq)}
    assert_refused(camtube("synthesize", str(goal), "-o", str(goal)), f"is the input GOAL.yaml {goal}")
    assert_refused(camtube("dxf", str(drawing), "-o", str(drawing)), f"is the input PATTERN {drawing}")
    argv = ingest_argv(tmp_path, "--bench", str(BENCH / "bench.yaml"))
    argv[argv.index("--daq") + 1] = argv[argv.index("-o") + 1] = str(daq)
    assert_refused(camtube(*argv), f"is the input --daq {daq}")
    assert {p: p.read_bytes() for p in (goal, drawing, daq)} == before
    assert listing(tmp_path) == ["d.dxf", "daq.csv", "g.yaml"]


def test_an_ingest_report_folder_named_like_the_csv_is_refused_before_the_csv_is_written(tmp_path):
    """``-o o.csv --report o.csv`` wrote o.csv, then failed on the report: half the outputs left behind."""
    out = str(tmp_path / "data.csv")
    r = camtube(*ingest_argv(tmp_path, "--bench", str(BENCH / "bench.yaml"), "--report", out))
    assert_refused(r, f"--report {out}: is also the -o file")
    assert listing(tmp_path) == []


@pytest.mark.parametrize("sample,words", [("#1", ("--sample '#1' starts with '#'",)), ("", ("--sample '' is empty",)),
                                          ("a\nb", ("holds a line break",))])
def test_an_ingest_sample_name_that_would_break_the_csv(tmp_path, sample, words):
    """``--sample '#1'`` wrote a CSV whose every row reads as a comment (model fit: 'no data rows'), exit 0;
    ``--sample ''`` was taken for no name."""
    r = camtube(*ingest_argv(tmp_path, "--bench", str(BENCH / "bench.yaml"), "--sample", sample))
    assert_refused(r, *words)
    assert listing(tmp_path) == []


def test_a_measurement_file_whose_rows_all_start_with_a_hash_says_why(tmp_path):
    data = tmp_path / "d.csv"
    data.write_text("sample,cycle,time_s,stroke_mm,force_N,angle_deg\n#1,1,0,0,0,0\n#1,1,1,1,1,1\n")
    r = camtube("model", "fit", str(data), "--pattern", "tube2")
    # the first such row is named: a data row whose sample starts with '#' (the whole sample would be skipped)
    assert_refused(r, f"{data}:2", "the line starts with '#', so it is a comment, yet it holds a data row",
                   "rename the sample")


def test_nul_bytes_in_a_measurement_file_are_refused_not_read_as_a_sample_name(tmp_path):
    """NULs in the sample cell (a logger's unfinished write) made a new sample '1\\x00\\x00...' and the fit ran, exit 0."""
    data = tmp_path / "d.csv"
    assert camtube("model", "synth", "--pattern", "tube2", "-o", str(data), "--cycles", "3").returncode == 0
    lines = data.read_bytes().split(b"\n")
    lines[12] = lines[12][:1] + b"\x00" * 8 + lines[12][1:]
    data.write_bytes(b"\n".join(lines))
    assert_refused(camtube("model", "fit", str(data), "--pattern", "tube2"), f"{data}:13", "NUL bytes")


@pytest.mark.parametrize("cmd", [["model", "synth", "-o", "{tmp}/d.csv"], ["model", "fit", "{data}"],
                                 ["model", "diagnose", "{data}"]], ids=["synth", "fit", "diagnose"])
def test_a_model_command_on_a_pattern_without_notches(tmp_path, cmd):
    """``--set notch.count=0`` (or a pattern of holes only) was a ValueError traceback from the joint geometry."""
    data = tmp_path / "data.csv"
    data.write_text("sample,cycle,time_s,stroke_mm,force_N,angle_deg\n1,1,0,0,0,0\n1,1,1,1,1,1\n")
    argv = [a.replace("{tmp}", str(tmp_path)).replace("{data}", str(data)) for a in cmd]
    r = camtube(*argv, "--pattern", "tube2", "--set", "notch.count=0")
    assert_refused(r, "tube2: notch.count: the pattern has no notches")
    assert listing(tmp_path) == ["data.csv"]


@pytest.mark.parametrize("cmd,outputs", [
    (["model", "fit", "{data}", "--json", "{tmp}/fit.json", "--plot", "/proc/camtube-x/fit.png"], "--plot"),
    (["model", "diagnose", "{data}", "--max-rows", "300", "--json", "{tmp}/d.json", "--report", "/proc/camtube-x/rep"],
     "--report"),
    (["model", "diagnose", "{data}", "--max-rows", "300", "--json", "{tmp}/d.json", "--report", "{tmp}/d.json"],
     "--report"),
], ids=["fit-plot-unwritable", "diagnose-report-unwritable", "diagnose-report-is-the-json"])
def test_model_outputs_are_written_both_or_neither(tmp_path, cmd, outputs):
    """The --json was written, then the --plot or --report failed (after the whole fit or diagnosis): one output of
    two left behind. Now where both go is checked before the work."""
    data = tmp_path / "data.csv"
    assert camtube("model", "synth", "--pattern", "tube2", "-o", str(data), "--cycles", "4").returncode == 0
    argv = [a.replace("{tmp}", str(tmp_path)).replace("{data}", str(data)) for a in cmd]
    r = camtube(*argv, "--pattern", "tube2", "-q")
    assert r.returncode == 2 and "Traceback" not in r.stderr and "fix:" in r.stderr, r.stderr
    assert listing(tmp_path) == ["data.csv"]


def test_an_unwritable_json_output_names_the_option_and_the_file(tmp_path):
    r = camtube("model", "fit", str(tmp_path / "d.csv"), "--pattern", "tube2", "--json", "/proc/camtube-x/f.json")
    assert_refused(r, "--json /proc/camtube-x/f.json: cannot write")


@pytest.mark.parametrize("cmd", ["fit", "diagnose"])
def test_a_json_output_that_is_the_measurement_file(tmp_path, cmd):
    """Measurements saved as d.json and ``--json d.json``: the fit's summary replaced the data, exit 0."""
    data = tmp_path / "d.json"
    assert camtube("model", "synth", "--pattern", "tube2", "-o", str(tmp_path / "d.csv"), "--cycles", "3").returncode == 0
    (tmp_path / "d.csv").rename(data)
    before = data.read_bytes()
    r = camtube("model", cmd, str(data), "--pattern", "tube2", "-q", "--json", str(data))
    assert_refused(r, f"--json {data}: is the input DATA.csv")
    assert data.read_bytes() == before


@pytest.mark.parametrize("spec", ["9" * 5000, "last" + "9" * 5000], ids=["5000-digits", "last-5000-digits"])
def test_a_cycle_selection_of_thousands_of_digits(tmp_path, spec):
    """``--cycles 999...9`` (5000 digits) was a ValueError traceback from int()."""
    data = tmp_path / "d.csv"
    data.write_text("sample,cycle,time_s,stroke_mm,force_N,angle_deg\n1,1,0,0,0,0\n1,1,1,1,1,1\n")
    r = camtube("model", "fit", str(data), "--pattern", "tube2", "--cycles", spec)
    assert_refused(r, "cycle selection", "cannot read")


@pytest.mark.parametrize("cmd", ["fit", "diagnose"])
def test_an_angle_lag_of_clocks_not_aligned_is_refused(tmp_path, cmd):
    """An angle lag of 10^9 ms (--set-aside --lag-ms 1e9) left no row past the slack: fit said 'try --no-deadband'
    with no fix, diagnose 'no data rows to fit'. A lag beyond 2 s is clocks not aligned: refused as such."""
    data = tmp_path / "d.csv"
    assert camtube("model", "synth", "--pattern", "tube2", "-o", str(data), "--cycles", "3").returncode == 0
    extra = ["--set-aside"] if cmd == "fit" else []
    r = camtube("model", cmd, str(data), "--pattern", "tube2", "-q", *extra, "--lag-ms", "1e9")
    assert_refused(r, "--lag-ms 1e+09", "clocks that were not aligned", "fix: give the tracker's delay")


@pytest.mark.parametrize("opt,value", [("--rate", "1e-6"), ("--speed", "1e9")])
def test_a_synthetic_sampling_too_coarse_says_the_fix(tmp_path, opt, value):
    r = camtube("model", "synth", "--pattern", "tube2", "-o", str(tmp_path / "d.csv"), opt, value)
    assert_refused(r, "rows per cycle", "fix: raise --rate or lower --speed")
    assert listing(tmp_path) == []


def test_a_drawing_named_with_a_folder_by_set_is_refused_before_planning(tmp_path):
    """A DXF with ``--set name=runs/a`` planned the whole job, then failed in the writer with a ValueError
    traceback; the YAML path refused the same name at once."""
    drawing = ROOT / "examples" / "dxf" / "outline_layer0.dxf"
    r = camtube("toolpath", str(drawing), "--set", "name=runs/a", "-q", "-o", str(tmp_path / "o"))
    assert_refused(r, f"{drawing}", "name:", "must be a plain file name")
    assert listing(tmp_path) == []


def test_a_block_that_places_itself_is_refused_not_a_recursion_traceback(tmp_path):
    """A block whose definition holds an INSERT of itself (a script's or a broken file's) was a RecursionError."""
    import math

    import ezdxf

    doc = ezdxf.new("R2013", setup=False)
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    c = 2 * math.pi
    msp.add_lwpolyline([(0, 0), (10, 0), (10, c), (0, c)], close=True)
    msp.add_lwpolyline([(2, 2), (2.5, 2), (2.5, 4), (2, 4)], close=True, dxfattribs={"layer": "NOTCHES"})
    blk = doc.blocks.new("SELF")
    blk.add_line((0, 0), (0.1, 0.1))
    blk.add_blockref("SELF", (0, 0))
    msp.add_blockref("SELF", (6, 2))
    drawing = tmp_path / "d.dxf"
    doc.saveas(drawing)
    r = camtube("toolpath", str(drawing), "-q", "-o", str(tmp_path / "o"))
    assert_refused(r, str(drawing), "places block 'SELF' inside itself", "fix:")
    assert listing(tmp_path) == ["d.dxf"]


def _drawing_with_a_block(path, layer_table: bool = True, scale: str | None = None):
    """A tube outline, a notch block placed on layer NOTCH (by an INSERT scaled 1.25 x 1.75, whose X or Y scale
    ``scale`` replaces in the file: ezdxf does not write a zero scale) and a hole on layer CUTS (not in the layer
    table unless ``layer_table``)."""
    import math

    import ezdxf

    doc = ezdxf.new("R2013", setup=False)
    doc.header["$INSUNITS"] = 4
    if layer_table:
        doc.layers.add("CUTS")
    msp = doc.modelspace()
    c = 2 * math.pi
    msp.add_lwpolyline([(0, 0), (10, 0), (10, c), (0, c)], close=True, dxfattribs={"layer": "OUTLINE"})
    msp.add_lwpolyline([(1, 3), (1.3, 3), (1.3, 3.3), (1, 3.3)], close=True, dxfattribs={"layer": "CUTS"})
    blk = doc.blocks.new("N")
    blk.add_lwpolyline([(0, 0), (0.4, 0), (0.4, 1.2), (0, 1.2)], close=True)
    ins = msp.add_blockref("N", (4, 2.5), dxfattribs={"layer": "NOTCH", "xscale": 1.25, "yscale": 1.75})
    doc.saveas(path)
    if scale is not None:
        axis, value = scale.split("=")
        text = path.read_text()
        old = " 41\n1.25\n 42\n1.75\n"
        assert text.count(old) == 1
        path.write_text(text.replace(old, old.replace("1.25" if axis == "x" else "1.75", value)))
    return ins.dxf.handle


@pytest.mark.parametrize("scale,words", [("x=0.0", ("by 0 along X (xscale)", "flattens it")),
                                         ("y=0", ("by 0 along Y (yscale)", "flattens it")),
                                         ("x=1e-300", ("by 1e-300 along X", "too small to cut"))])
def test_an_insert_of_zero_scale_is_refused_naming_it(tmp_path, scale, words):
    """An INSERT with xscale or yscale 0 (or 1e-300) was a ZeroDivisionError traceback from ezdxf's placing of it."""
    drawing = tmp_path / "d.dxf"
    handle = _drawing_with_a_block(drawing, scale=scale)
    r = camtube("toolpath", str(drawing), "-q", "-o", str(tmp_path / "o"))
    assert_refused(r, f"{drawing}: INSERT #{handle} on layer NOTCH: scales block 'N'", *words,
                   "fix: set the INSERT's X and Y scale")
    assert listing(tmp_path) == ["d.dxf"]


def test_a_layer_that_entities_are_on_but_the_layer_table_lacks_can_be_given_a_role(tmp_path):
    """A drawing (from a script or an old program) with entities on layer CUTS but no CUTS in its layer table:
    ``--layer CUTS=hole`` was refused 'the drawing has no such layer; allowed: 0' (the layers listed were the
    table's only, not CUTS). A layer in neither is refused listing the drawing's layers."""
    drawing = tmp_path / "d.dxf"
    _drawing_with_a_block(drawing, layer_table=False)
    r = camtube("design", str(drawing), "-q", "--layer", "cuts=hole")
    assert r.returncode == 0, r.stderr
    assert "1 / 1" in r.stdout   # the notch of the block and the hole on CUTS
    r = camtube("design", str(drawing), "-q", "--layer", "CUT=hole")
    assert_refused(r, f"{drawing}: --layer CUT=hole: the drawing has no such layer", "CUTS, ", "NOTCH, OUTLINE",
                   "fix: did you mean 'CUTS'?")
    r = camtube("design", str(drawing), "-q", "--layer", "ZZZ=ignore")
    assert_refused(r, "--layer ZZZ=ignore", "fix: name one of the drawing's layers")


def test_a_drawing_finds_a_shipped_process_and_names_a_missing_one(tmp_path):
    """With a DXF, ``--set process=femto-polyimide.yaml`` (the shipped process a YAML pattern finds anywhere) and
    ``--set process=nothere.yaml`` were both 'file: cannot read pattern: No such file or directory'."""
    drawing = tmp_path / "d.dxf"
    drawing.write_bytes((ROOT / "examples" / "dxf" / "outline_layer0.dxf").read_bytes())
    r = camtube("design", str(drawing), "--set", "process=femto-polyimide.yaml", "-q", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    r = camtube("design", str(drawing), "--set", "process=nothere.yaml", cwd=tmp_path)
    assert_refused(r, f"{drawing}: process: names a process file that is not there", "femto-polyimide")


@pytest.mark.parametrize("params,words", [('{"E_t": -5}', ("parameter E_t = -5 GPa", "physical range")),
                                          ('{"E_t": 20, "slack.deadband_mm": -0.1}', ("slack.deadband_mm = -0.1",)),
                                          ('{"E_t": 20, "kerf.kerf_mm": 5}', ("kerf.kerf_mm = 5 mm",)),
                                          # the bad-input search: taken, a tendon that does not stretch
                                          ('{"E_t": 1e300}', ("parameter E_t = 1e+300 GPa", "at most 1000 GPa")),
                                          ('{"E_t": 20, "L0": 1e9}', ("L0 = 1e+09 mm", "at most 10000 mm")),
                                          ('{"E_t": 20}, "schema": "other/9"', ("schema 'other/9' is not a fit's",
                                                                                "camtube.fit/1")),
                                          # the bad-input search: taken, 1e295 mm of tendon travel asked for
                                          ('{"E_t": 1e-300}', ("parameter E_t = 1e-300 GPa", "at least 0.5 GPa")),
                                          ('{"E_t": 20, "arm_scale": 0.01}', ("arm_scale = 0.01", "at least 0.3")),
                                          # the bad-input search: one of the two kept without a word
                                          ('{"E_t": 28, "E_t": 50}', ("the key 'E_t' is given twice in one object",))])
def test_a_calibration_with_an_unphysical_value_names_it(tmp_path, params, words):
    """A calibration with E_t = -5 was used as given: 'the joint cannot take up the stroke (no finite force found)',
    no fix; a kerf of 5 mm was blamed on --overcut, which was not given."""
    cal = tmp_path / "c.json"
    cal.write_text('{"params": %s}' % params)
    r = camtube("design", TUBE1, "-q", "--stroke", "1", "--calibration", str(cal))
    assert_refused(r, str(cal), *words)


@pytest.mark.parametrize("doc,words", [
    ('{"params": {"E_t": NaN, "L0": 70}}', ("params.E_t: not a finite number (got NaN)",)),
    ('{"params": {"E_t": {"value": "28"}}}', ("params.E_t.value: not a finite number (got \"28\")",)),
    ('{"final": {"params": {"E_t": {"value": 28}, "slack.deadband_mm@2": {"value": null}}}}',
     ("final.params.slack.deadband_mm@2.value: not a finite number (got null)",)),
    ('{"params": {"arm_scale": Infinity}}', ("params.arm_scale", "(got Infinity)")),
], ids=["nan", "text", "null-per-sample", "infinity"])
def test_a_calibration_value_that_is_not_a_number_names_the_key(tmp_path, doc, words):
    """A NaN, text or null parameter value in a calibration was skipped silently: the joint was computed with the
    pattern's value instead, exit 0."""
    cal = tmp_path / "c.json"
    cal.write_text(doc)
    for argv in (["design", TUBE1, "-q", "--stroke", "1"],
                 ["synthesize", str(ROOT / "examples" / "goals" / "01-tube1-uniform-60.yaml"), "-o",
                  str(tmp_path / "p.yaml")]):
        assert_refused(camtube(*argv, "--calibration", str(cal)), f"{cal}: ", *words, "fix: write the fitted value")
    assert listing(tmp_path) == ["c.json"]


def test_a_goal_with_an_empty_list_of_shares(tmp_path):
    """``goal.distribution: []`` was a ValueError traceback from numpy ('zero-size array to reduction')."""
    goal = tmp_path / "g.yaml"
    goal.write_text((ROOT / "examples" / "goals" / "01-tube1-uniform-60.yaml").read_text()
                    .replace("distribution: uniform", "distribution: []"))
    r = camtube("synthesize", str(goal), "-o", str(tmp_path / "p.yaml"))
    assert_refused(r, f"{goal}:7", "goal.distribution: an empty list of shares")
    assert listing(tmp_path) == ["g.yaml"]


@pytest.mark.parametrize("section", ["5", '{"leading": "stroke", "range": 5}', '{"leading": "stroke", "periodic": [5]}'])
def test_a_diagnosis_json_whose_unexplained_section_was_edited(tmp_path, section):
    """``model effect new NAME --from d.json`` with ``"unexplained": 5`` was a TypeError traceback."""
    diag = tmp_path / "d.json"
    diag.write_text('{"unexplained": %s}' % section)
    r = camtube("model", "effect", "new", "mine", "--from", str(diag), cwd=tmp_path)
    assert_refused(r, f"{diag}: the 'unexplained' section", "fix: write it again")
    assert listing(tmp_path) == ["d.json"]


def test_a_starter_effect_file_not_named_py_is_refused(tmp_path):
    """``effect new mine --follows stroke -o mine.txt`` wrote a file --effect-file then could not import."""
    r = camtube("model", "effect", "new", "mine", "--follows", "stroke", "-o", "mine.txt", cwd=tmp_path)
    assert_refused(r, "-o mine.txt", "must end in .py", "fix: e.g. -o mine.py")
    assert listing(tmp_path) == []


@pytest.mark.parametrize("params,words", [
    ("Param('a', 'mm', 0, 1, 0.5, 'x'), Param('a', 'mm', 0, 2, 0.5, 'y')", ("two parameters are named 'a'",)),
    ("Param('a', 'mm', float('nan'), 1, 0.5, 'x'),", ("has a NaN bound",)),
], ids=["duplicate-name", "nan-bound"])
def test_an_effect_file_with_clashing_or_nan_parameters(tmp_path, params, words):
    """Two Params of one name (one value fitted for both) and a NaN bound were accepted, the fit ran, exit 0."""
    data = tmp_path / "d.csv"
    assert camtube("model", "synth", "--pattern", "tube2", "-o", str(data), "--cycles", "3").returncode == 0
    eff = tmp_path / "mine.py"
    eff.write_text("from camtube.model.api import Effect, Param\n"
                   f"E = Effect(name='mine', stage='stroke', params=({params}), apply=lambda c, s, p: s)\n")
    r = camtube("model", "fit", str(data), "--pattern", "tube2", "-q", "--effect-file", str(eff), "--effects", "mine")
    assert_refused(r, f"{eff}:2", *words)


@pytest.mark.parametrize("argv", [
    ["design", "{dev}"], ["build", "{dev}", "-o", "{tmp}/o"], ["design", "{tmp}/drawing.dxf"],
    ["build", TUBE1, "--machine", "{dev}", "-o", "{tmp}/o"], ["synthesize", "{dev}", "-o", "{tmp}/p.yaml"],
    ["model", "diagnose", "{dev}", "--pattern", "tube1"], ["model", "fit", "{tmp}/data.csv", "--pattern", "tube1"],
    ["model", "ingest", "--tracker", "{dev}", "--daq", "{dev}", "--motor", "{dev}", "-o", "{tmp}/m.csv"],
])
def test_a_device_given_as_an_input_is_refused_not_read_forever(tmp_path, argv):
    # /dev/zero never ends: a reader that reads it to the end runs until memory runs out (found by the bad-input sweep)
    for name in ("drawing.dxf", "data.csv"):
        (tmp_path / name).symlink_to("/dev/zero")
    args = [a.format(dev="/dev/zero", tmp=tmp_path) for a in argv]
    assert_refused(camtube(*args, timeout=60), "a device, not a file")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["data.csv", "drawing.dxf"]


def test_a_pipe_is_still_read_as_a_file(tmp_path):
    # what the device check must not refuse: a measurement file given through a pipe (<(gunzip -c data.csv.gz))
    from camtube.inputfile import read_input_text

    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    pid = os.fork()
    if pid == 0:   # the writer
        with open(fifo, "w") as fh:
            fh.write("sample,cycle,time_s,stroke_mm,force_N,angle_deg\r\n")
        os._exit(0)
    try:
        assert read_input_text(fifo) == "sample,cycle,time_s,stroke_mm,force_N,angle_deg\n"
    finally:
        os.waitpid(pid, 0)


@pytest.mark.parametrize("name, words", [
    ('"x\\nM3 S1000\\nG0 X500"', ["name:", "line break", "x\\nM3 S1000", "one line"]),
    ("2024-01-01", ["name:", "expected a text, got a date", "quote it: name: '2024-01-01'"]),
    ("123", ["name:", "expected a text, got a int", "quote it: name: '123'"]),
])
def test_a_name_that_is_not_one_line_of_text_is_refused(tmp_path, name, words):
    """A pattern's name is written into the G-code's header comment: a line break in it would make the text after it
    G-code lines (M3 S1000: the beam on) (the bug the fuzzing of issue 19's session found); YAML reads an unquoted
    date or number as such, which crashed the job file and the preview."""
    p = tmp_path / "p.yaml"
    p.write_text(pattern_text().replace("name: p\n", f"name: {name}\n"))
    for cmd in ("design", "toolpath", "preview"):
        out = tmp_path / ("o.svg" if cmd == "preview" else "o")
        assert_refused(camtube(cmd, str(p), "-o", str(out)) if cmd != "design" else camtube(cmd, str(p)),
                       f"{p}:1", *words)
        assert not out.exists()


def test_a_profile_description_that_is_not_one_line_is_refused(tmp_path):
    prof = tmp_path / "m.yaml"
    src = (ROOT / "machines" / "linuxcnc-rotary.yaml").read_text()
    assert "description:" in src
    prof.write_text("\n".join('  description: "x\\nM3 S1000"' if ln.strip().startswith("description:") else ln
                              for ln in src.splitlines()) + "\n")
    assert_refused(camtube("toolpath", TUBE1, "--machine", str(prof), "-o", str(tmp_path / "o")),
                   "description", "line break", "one line")
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("value", ["nan", "inf"])
def test_a_drawn_coordinate_that_is_not_a_number_is_refused_naming_the_entity(tmp_path, value):
    """A LINE on a cut layer ending at nan was read as a slit, and the job file then failed with a traceback; one at
    inf was set aside as of zero length. Both are a damaged drawing: refused, naming the entity."""
    import ezdxf

    doc = ezdxf.new(units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0.0, 0.0), (10.0, 0.0), (10.0, 4.712389), (0.0, 4.712389)], close=True,
                       dxfattribs={"layer": "OUTLINE"})   # the unrolled tube, r_o 0.75 mm
    msp.add_lwpolyline([(1.0, 0.5), (1.5, 0.5), (1.5, 3.3), (1.0, 3.3)], close=True, dxfattribs={"layer": "NOTCH"})
    msp.add_line((3.0, 1.0), (float(value), 2.0), dxfattribs={"layer": "SLIT"})
    path = tmp_path / "d.dxf"
    doc.saveas(path)
    for cmd in ("design", "toolpath"):
        args = [cmd, str(path)] + (["-o", str(tmp_path / "o")] if cmd == "toolpath" else [])
        assert_refused(camtube(*args), "d.dxf", "LINE", "on layer SLIT", "not a finite number")
    assert listing(tmp_path) == ["d.dxf"]


@pytest.mark.parametrize("layer", ["HOLES", "CONSTRUCTION"])
def test_a_circle_far_larger_than_any_tube_is_refused_or_set_aside_without_flattening_it(tmp_path, layer):
    """A CIRCLE of radius 1e12 mm was flattened to 25 nm chords: the kernel killed camtube (exit 137, no message),
    also on the ignored layer CONSTRUCTION. Run here with 2 GB of address space, so the old code fails at once."""
    import resource
    import subprocess
    import sys

    import ezdxf

    doc = ezdxf.new(units=4)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0.0, 0.0), (10.0, 0.0), (10.0, 6.283185307179586), (0.0, 6.283185307179586)], close=True,
                       dxfattribs={"layer": "CONSTRUCTION"})
    msp.add_lwpolyline([(2.0, 2.0), (2.5, 2.0), (2.5, 4.5), (2.0, 4.5)], close=True, dxfattribs={"layer": "NOTCHES"})
    msp.add_circle((5.0, 3.0), 1e12, dxfattribs={"layer": layer})
    path = tmp_path / "d.dxf"
    doc.saveas(path)

    def limit():
        resource.setrlimit(resource.RLIMIT_AS, (2 << 30, 2 << 30))

    r = subprocess.run([sys.executable, "-m", "camtube", "design", str(path)], capture_output=True, text=True,
                       timeout=120, env=dict(os.environ, PYTHONPATH=str(ROOT)), preexec_fn=limit)
    if layer == "HOLES":
        assert_refused(r, f"{path}: CIRCLE #", "on layer HOLES: is 2e+12 mm across, far larger than any tube",
                       "fix: redraw it at the tube's size")
    else:
        assert r.returncode == 0, r.stderr
        assert "set aside: 1 (ignored layer)" in r.stderr
    assert listing(tmp_path) == ["d.dxf"]


def test_a_tube_far_larger_than_any_stage_holds_is_refused_not_overflowed(tmp_path):
    """A radius of 1e103 mm overflowed the geometry (a traceback); the tube's sizes have an upper bound now."""
    assert_refused(camtube("design", TUBE1, "--set", "tube.outer_radius=1e103"), "tube.outer_radius",
                   "<= 50 mm", "fix: use a value <= 50")
    assert_refused(camtube("preview", TUBE1, "--set", "tube.length=1e9", "-o", str(tmp_path / "p.svg")),
                   "tube.length", "fix: use a value <= 2000")
    assert listing(tmp_path) == []


def test_output_folder_given_as_a_link_gets_the_files_and_stays_a_link(tmp_path, capsys):
    """Bug 14: ``toolpath -o current`` (current -> jobs/v2) replaced the link with a new folder and left the
    link behind as ``.current.*.staging``; jobs/v2 kept its old files."""
    (tmp_path / "jobs" / "v2").mkdir(parents=True)
    (tmp_path / "jobs" / "v2" / "tube1.ngc").write_text("old")
    (tmp_path / "current").symlink_to(tmp_path / "jobs" / "v2")
    assert main(["toolpath", TUBE1, "-o", str(tmp_path / "current"), "-q"]) == 0
    assert f"wrote {tmp_path / 'current' / 'tube1.ngc'}" in capsys.readouterr().out
    assert (tmp_path / "current").is_symlink()
    assert listing(tmp_path) == ["current", "jobs", "jobs/v2", "jobs/v2/.tube1.camtube-set", "jobs/v2/tube1.job.json",
                                 "jobs/v2/tube1.nc", "jobs/v2/tube1.ngc", "jobs/v2/tube1.toolpath.dxf"]
    assert (tmp_path / "jobs" / "v2" / "tube1.ngc").read_text() != "old"


@pytest.mark.parametrize("override,key", [("process.repeats=1000", "process.repeats"),
                                          ("process.repeat_rule.0={max_depth: 3, repeats: 500}",
                                           "process.repeat_rule[0].repeats")])
def test_repeats_beyond_any_tube_are_refused_at_once_with_the_bound(tmp_path, override, key):
    """Bug 12 (fuzzing): 1000 repeats were accepted and planned (a curved drawing on linuxcnc-surface: minutes and
    gigabytes); the paper cuts with 4, 6 and 8. Refused before any work, naming the key and the bound."""
    r = camtube("toolpath", "tube1", "--machine", "linuxcnc-surface", "--set", override, "-o", str(tmp_path / "o"),
                "-q")
    assert_refused(r, key, "<= 100", "fix: use a value <= 100")
    assert listing(tmp_path) == []


def test_the_largest_repeats_is_accepted():
    from camtube.design.loader import load
    from camtube.design.schema import MAX_REPEATS

    assert load(PATTERNS / "tube1.yaml", [f"process.repeats={MAX_REPEATS}"]).pattern.process.repeats == MAX_REPEATS


@pytest.mark.parametrize("argv,words", [
    # the bad-input search: each was taken, the option ignored without a word (the last --layer won)
    (["design", TUBE1, "--overcut", "0.1"], ("--overcut 0.1 is used by the forward model", "add --stroke MM")),
    (["design", str(ROOT / "examples" / "dxf" / "slits.dxf"), "--layer", "KERF=slit", "--layer", "kerf=notch"],
     ("layer 'kerf' is given a role twice (slit and notch)", "one --layer NAME=ROLE")),
])
def test_an_option_that_would_be_ignored_or_overridden_is_refused(tmp_path, argv, words):
    assert_refused(camtube(*argv, cwd=tmp_path), *words)
    assert listing(tmp_path) == []


def test_set_process_names_a_process_file_as_the_pattern_may(tmp_path):
    """The bad-input search: --set process=femto-polyimide.yaml was refused as 'expected a mapping', though a
    pattern's 'process:' may name a file; a file that is not there is named as such."""
    (tmp_path / "slow.yaml").write_text((ROOT / "patterns" / "femto-polyimide.yaml").read_text().replace(
        "scan_speed_mm_s: 25", "scan_speed_mm_s: 12.5"))
    pattern = tmp_path / "t.yaml"
    pattern.write_text((ROOT / "patterns" / "tube1.yaml").read_text())
    r = camtube("toolpath", str(pattern), "-q", "-o", str(tmp_path / "o"), "--set", "process=slow.yaml")
    assert r.returncode == 0, r.stderr
    assert "12.5 mm/s" in (tmp_path / "o" / "tube1.ngc").read_text()[:2000]
    assert_refused(camtube("design", str(pattern), "--set", "process=nothere.yaml"),
                   "process: names a process file that is not there", "'nothere.yaml'")


@pytest.mark.parametrize("option,value", [("--lag-ms", "-1e9"), ("--modulus-range", "-1,5")])
def test_a_negative_value_after_an_option_gets_its_fix(tmp_path, option, value):
    """The bad-input search: argparse reads -1e9 as an option and said only 'expected one argument'."""
    r = camtube("model", "diagnose", "x.csv", "--pattern", "tube1", option, value, cwd=tmp_path)
    assert_refused(r, f"{option} {value}: a value that starts with '-' is read as an option",
                   f"fix: write {option}={value}")


@pytest.mark.parametrize("how", ["same name", "earlier set"])
def test_a_job_that_would_replace_its_own_input_drawing_is_refused(tmp_path, how):
    """The bad-input search: ``build t.design.dxf --set name=t -o DIR`` (the design DXF camtube wrote, edited in CAD)
    replaced the drawing it was reading with its own design DXF, exit 0; ``toolpath`` removed it as a file of the set
    the earlier ``build`` of job t had written there."""
    drawing = tmp_path / "t.design.dxf"
    if how == "same name":
        assert camtube("dxf", TUBE1, "-q", "--set", "name=t", "-o", str(drawing)).returncode == 0
        argv = ("build", str(drawing), "--set", "name=t", "-o", str(tmp_path), "-q", "--no-step", "--no-pictures")
    else:
        r = camtube("build", TUBE1, "-q", "--set", "name=t", "-o", str(tmp_path), "--no-step", "--no-pictures")
        assert r.returncode == 0, r.stderr
        argv = ("toolpath", str(drawing), "--set", "name=t", "-o", str(tmp_path), "-q")
    before = drawing.read_bytes()
    files = listing(tmp_path)
    assert_refused(camtube(*argv), f"would replace its own input {drawing}", "fix: write to another folder")
    assert drawing.read_bytes() == before and listing(tmp_path) == files


@pytest.mark.parametrize("how", ["yaml", "drawing"])
def test_a_cut_the_passes_cannot_offset_is_named_by_its_file_and_origin(tmp_path, how):
    """The bad-input search: "cut[0] (hole at x ...): the contour vanishes" named neither the file nor the entity (or
    the YAML key) the cut came from."""
    if how == "yaml":
        r = camtube("toolpath", TUBE1, "--set", "notch.width=0.01", "-o", str(tmp_path / "o"), "-q")
        assert_refused(r, "tube1.yaml: notch (notch at x", "the contour vanishes")
    else:
        import ezdxf

        doc = ezdxf.new("R2013", setup=False)
        doc.header["$INSUNITS"] = 4
        msp = doc.modelspace()
        msp.add_lwpolyline([(0, 0), (10, 0), (10, 2 * math.pi), (0, 2 * math.pi)], close=True,
                           dxfattribs={"layer": "CONSTRUCTION"})
        msp.add_lwpolyline([(3, 1), (3.5, 1), (3.5, 3), (3, 3)], close=True, dxfattribs={"layer": "NOTCHES"})
        msp.add_circle((5, 3), 0.004, dxfattribs={"layer": "HOLES"})
        path = tmp_path / "d.dxf"
        doc.saveas(path)
        r = camtube("toolpath", str(path), "-o", str(tmp_path / "o"), "-q")
        assert_refused(r, f"{path}: CIRCLE #", "on layer HOLES (hole at x", "the contour vanishes")
    assert not (tmp_path / "o").exists()


def test_a_set_without_a_value_names_the_option_not_the_preset(tmp_path):
    """The bad-input search: --set notch.count= (an empty shell variable) was told "required key is missing; fix: add
    'count:'" in the shipped preset file."""
    r = camtube("design", "tube1", "--set", "notch.count=")
    assert_refused(r, "--set notch.count=: no value after the equals sign", "fix: write the value")
    assert "presets" not in r.stderr


def test_a_set_given_twice_with_different_values_is_refused(tmp_path):
    """The bad-input search: --set notch.count=10 --set notch.count=3 cut 3 notches without a word (ingest refuses a
    --map given twice); the same value twice is harmless."""
    r = camtube("toolpath", "tube1", "-q", "-o", str(tmp_path / "o"), "--set", "notch.count=10", "--set", "notch.count=3")
    assert_refused(r, "--set notch.count: given twice, with different values", "keep one of 'notch.count=10' and "
                   "'notch.count=3'")
    assert "presets" not in r.stderr and not (tmp_path / "o").exists()
    assert camtube("design", "tube1", "--set", "notch.count=10", "--set", "notch.count=10").returncode == 0


def test_a_mapping_set_on_a_section_merges_into_it(tmp_path):
    """The bad-input search: --set 'notch={count: 3}' replaced the section: four "required key is missing" lines at
    the preset's lines that hold those keys. It sets the keys it gives, as --set notch.count=3 does."""
    a = camtube("design", "tube1", "--set", "notch={count: 3}")
    b = camtube("design", "tube1", "--set", "notch.count=3")
    assert a.returncode == b.returncode == 0, a.stderr
    assert a.stdout == b.stdout and "3 / 1" in a.stdout


def test_a_name_too_long_for_a_file_name_is_named_by_its_key(tmp_path):
    """The bad-input search: a name of 300 characters failed as "cannot write: File name too long" on the output
    folder."""
    r = camtube("toolpath", "tube1", "--set", "name=" + "x" * 300, "-o", str(tmp_path / "out"))
    assert_refused(r, "name: is 300 characters long", "fix: shorten the name")
    assert not (tmp_path / "out").exists()


def test_a_max_lag_shorter_than_the_clocks_offset_is_named_in_the_fix(tmp_path):
    """The bad-input search: --max-lag 0.1 with the example logs 0.6 s apart was told only to check that the logs
    belong to the same run."""
    r = camtube(*ingest_argv(tmp_path, "--bench", str(BENCH / "bench.yaml"), "--max-lag", "0.1"))
    assert_refused(r, "both show motion", "give a larger --max-lag", "--max-lag 0.1 s")


def test_a_tracker_quaternion_that_is_not_of_length_one_is_named(tmp_path):
    """The bad-input search: quaternions of length 2 (every frame state OK) were told "no frame in which the coil is
    tracked; fix: check the tool names", though the names were right."""
    lines = (BENCH / "aurora-export.csv").read_text().splitlines()
    out = [lines[0]] + [",".join(c if not 6 <= i <= 9 else f"{2 * float(c):.7f}" for i, c in enumerate(ln.split(",")))
                        for ln in lines[1:]]
    trk = tmp_path / "trk.csv"
    trk.write_text("\n".join(out) + "\n")
    argv = ingest_argv(tmp_path, "--bench", str(BENCH / "bench.yaml"))
    argv[argv.index("--tracker") + 1] = str(trk)
    r = camtube(*argv)
    assert_refused(r, f"{trk}:2:", "quaternion", "has length 2, not 1", "not a rotation")


def test_a_motor_counter_that_wraps_is_refused_naming_the_line(tmp_path):
    """The bad-input search: a 16-bit encoder register (counts mod 65536) wrote 12 cycles to 1 mm for 3 cycles to
    2.5 mm with exit 0."""
    lines = (BENCH / "motor.csv").read_text().splitlines()
    out = [lines[0]] + [",".join([c[0], str(int(float(c[1])) % 65536)] + c[2:]) for c in
                        (ln.split(",") for ln in lines[1:])]
    mot = tmp_path / "mot.csv"
    mot.write_text("\n".join(out) + "\n")
    argv = ingest_argv(tmp_path, "--bench", str(BENCH / "bench.yaml"))
    argv[argv.index("--motor") + 1] = str(mot)
    r = camtube(*argv)
    assert_refused(r, f"{mot}:", "about 2^16: a 16-bit position counter that wrapped", "fix: unwrap the counts")
