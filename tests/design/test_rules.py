"""Every design rule: feed the bad value, check the message names key, value, range and fix.

Also: when a pattern is rejected, no output file is left behind.
"""
from __future__ import annotations

import math

import pytest
import yaml

from camtube.commands import main
from camtube.design import load
from camtube.errors import PatternError
from tests.conftest import PATTERNS

TUBE1 = PATTERNS / "tube1.yaml"


def reject(overrides, path=TUBE1) -> str:
    with pytest.raises(PatternError) as exc:
        load(path, overrides)
    return str(exc.value)


def write_pattern(tmp_path, data, name="p.yaml"):
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    return p


def base_raw():
    raw = yaml.safe_load(TUBE1.read_text())
    raw["process"] = {}
    return raw


CASES = [
    # (overrides, key named, words in the message)
    (["tube.inner_radius=0.8"], "tube.inner_radius", ["smaller than the outer radius", "0.8", "< tube.outer_radius = 0.75"]),
    (["tube.length=-3"], "tube.length", ["out of range", "-3", "> 0 and <= 2000 mm", "positive"]),
    (["notch.width=0"], "notch.width", ["out of range", "> 0 mm"]),
    ([".nan"], None, None),  # placeholder replaced below
    (["notch.arc=.inf"], "notch.arc", ["must be finite"]),
    (["tendon.radius=-0.04"], "tendon.radius", ["out of range"]),
    (["notch.arc=4.8"], "notch.arc", ["shorter than the outer circumference", "4.8", "< 2 pi r_o = 4.7124"]),
    (["notch.arc=4.6"], "notch.arc", ["backbone arc", "min_backbone_arc", "reduce the arc"]),
    # a row of notches past the tube's end names the row's count and the length, and every way out
    (["notch.first_offset=9"], "notch.count", ["from x = 9 mm", "past the tube's end", "tube.length = 14",
                                               "lower notch.count to 5", "notch.first_offset"]),
    (["tube.length=5"], "notch.count", ["past the tube's end", "lower notch.count to 4",
                                        "lengthen tube.length to at least 11"]),
    (["notch.spacing=0.05"], "notch.spacing", ["too close", "web 0.05", ">= rules.min_web = 0.1", "increase notch.spacing"]),
    (["holes.0.x=1.5"], "holes[0]", ["collides with", "notch at x=1.75", "move the hole"]),
    (["holes.0.x=1.3"], "holes[0]", ["collides with (web too thin)", "web 0.05"]),
    (["notch.count=2.5"], "notch.count", ["whole number", "use 2"]),
    (["notch.count=ten"], "notch.count", ["expected a number", "plain number"]),
    (["notch.layout=uni"], "notch.layout", ["not an allowed choice", "uan, bidirectional, directions"]),
    (["notch.layout=directions"], "notch.directions_deg", ["needs a list of angles"]),
    (["process.repeats=0"], "process.repeats", ["out of range"]),
    (["process.kerf=0.3"], "process.kerf", ["half the narrowest cut"]),
    # process values that wrote a meaningless or unsafe job (fuzz report E2): each has a physical range
    (["process.frequency_khz=1e-12"], "process.frequency_khz", ["out of range", ">= 0.1 and <= 100000 kHz",
                                                                "use a value >= 0.1"]),
    (["process.frequency_khz=1e9"], "process.frequency_khz", ["out of range", "use a value <= 100000"]),
    (["process.scan_speed_mm_s=1e12"], "process.scan_speed_mm_s", ["out of range", "> 0 and <= 2000 mm/s",
                                                                   "use a value <= 2000"]),
    (["process.defocus=1e6"], "process.defocus", ["out of range", ">= 0 and <= 100 mm", "use a value <= 100"]),
    (["process.defocus=1.6"], "process.defocus", ["beyond the far side of the tube", "2 r_o = 1.5 mm",
                                                  "<= 2 r_o = 1.5 mm", "fix: set process.defocus"]),
    (["process.power_w=1e9"], "process.power_w", ["out of range", ">= 0.05 and <= 100 W", "use a value <= 100"]),
    (["process.power_w=1e-9"], "process.power_w", ["out of range", "use a value >= 0.05"]),
    (["process.wavelength_nm=1e300"], "process.wavelength_nm", ["out of range", ">= 100 and <= 20000 nm"]),
    (["process.drill_offset=1e300"], "process.drill_offset", ["out of range", ">= 0 and <= 0.1 mm"]),
    (["process.repeat_rule.0.max_depth=1e300"], "process.repeat_rule[0].max_depth", ["out of range", "<= 100 mm"]),
    (["process.kerf=1e300"], "process.kerf", ["out of range", ">= 0 and <= 1 mm"]),
    (["process.rapid_speed_mm_s=1e-300"], "process.rapid_speed_mm_s", ["out of range", ">= 0.1 and <= 10000 mm/s"]),
    (["process.focus_speed_mm_s=1e300"], "process.focus_speed_mm_s", ["out of range", ">= 0.01 and <= 1000 mm/s"]),
    (["process.max_time_h=1e-300"], "process.max_time_h", ["out of range", ">= 0.01 and <= 1000 h"]),
    # the bad-input search: design passed an empty repeat rule, and toolpath refused it naming no file or line
    (["process.repeat_rule=[]"], "process.repeat_rule", ["no row covers the beam depth 0.983 mm", "the rule is empty",
                                                         "add a repeat_rule row"]),
    # the bad-input search: taken as not given, every notch cut at notch.angle_deg without a word
    (["notch.angles_deg=[]"], "notch.angles_deg", ["is empty, for notch.count = 10", "give 10 values"]),
    (["notch.spacings=[]"], "notch.spacings", ["9 values (one per gap", "notch.spacing then applies"]),
    # the bad-input search: written as a*b?.ngc, a name that said "letters, digits, '-', '_', '.'" only
    (["name=a*b?"], "name", ["holds '*' '?'", "a file name on Windows may not hold", "none of < > : \" | ? *"]),
    (["name=run:2"], "name", ["holds ':'"]),
    # the bad-input search: written as NUL.ngc (the null device on Windows) and as '  .ngc'
    (["name=NUL"], "name", ["a device name on Windows", "CON, PRN, AUX, NUL, COM1-9, LPT1-9"]),
    (["name=com1.job"], "name", ["is 'com1', a device name on Windows"]),
    (["name=lpt9"], "name", ["a device name on Windows"]),
    (["name='  '"], "name", ["is blank", "write e.g. name: tube2"]),
    # the bad-input search: 500 % strain for a polyimide tube turned the strain warning off; 1e-300 GPa was taken
    (["rules.max_strain=5"], "rules.max_strain", ["out of range", ">= 0.0001 and <= 1", "use a value <= 1"]),
    (["tendon.modulus_gpa=1e-300"], "tendon.modulus_gpa", ["out of range", ">= 0.5 and <= 500 GPa"]),
    # the bad-input search: each dropped without a word
    (["notch.widths=[0.4, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5, 0.6]"], "notch.width",
     ["is given beside notch.widths", "notch.width would not be used", "delete one of the two"]),
    (["notch.angles_deg=[180, 0, 180, 0, 180, 0, 180, 0, 180, 0]", "notch.angle_deg=90"], "notch.angle_deg",
     ["is given beside notch.angles_deg"]),
    (["notch.directions_deg=[0, 90]"], "notch.directions_deg",
     ["notch.layout is 'uan': the directions would not be used", "set layout: directions"]),
]
CASES[3] = (["notch.spacing=.nan"], "notch.spacing", ["must be finite"])


@pytest.mark.parametrize("overrides,key,words", CASES, ids=[c[0][0] for c in CASES])
def test_rule_message(overrides, key, words):
    msg = reject(overrides)
    assert "tube1.yaml" in msg
    assert f"{key}:" in msg
    for w in words:
        assert w in msg, f"{w!r} not in {msg!r}"


def test_message_gives_line_number_of_yaml_key(tmp_path):
    raw = base_raw()
    raw["notch"]["arc"] = 9.0
    p = write_pattern(tmp_path, raw)
    msg = reject([], p)
    line = next(i for i, t in enumerate(p.read_text().splitlines(), 1) if t.strip().startswith("arc:"))
    assert f"p.yaml:{line}: notch.arc" in msg


@pytest.mark.parametrize("section,bad,hint", [
    (None, "tubes", "did you mean 'tube'?"),
    ("tube", "outer_radus", "did you mean 'outer_radius'?"),
    ("notch", "widht", "did you mean 'width'?"),
    ("process", "scan_speed", "did you mean 'scan_speed_mm_s'?"),
])
def test_unknown_keys_rejected_with_hint(tmp_path, section, bad, hint):
    raw = base_raw()
    if section is None:
        raw[bad] = {}
    else:
        raw[section][bad] = 1.0
    msg = reject([], write_pattern(tmp_path, raw))
    assert "unknown key" in msg and hint in msg


def test_unknown_key_in_hole_row_and_set(tmp_path):
    raw = base_raw()
    raw["holes"][0]["sise"] = 0.3
    msg = reject([], write_pattern(tmp_path, raw))
    assert "holes[0].sise: unknown key" in msg and "did you mean 'size'?" in msg
    assert "did you mean 'notch.count'?" in reject(["notch.cont=3"])


def test_overlapping_cuts(tmp_path):
    raw = base_raw()
    raw["cuts"] = [{"x": 2.0, "width": 0.5, "arc": 1.0, "angle_deg": 180}]
    msg = reject([], write_pattern(tmp_path, raw))
    assert "overlaps" in msg and "cuts must not overlap" in msg


def test_overlap_across_the_seam(tmp_path):
    raw = base_raw()
    raw["notch"]["angle_deg"] = 0  # notches straddle y = 0
    raw["holes"] = []
    raw["cuts"] = [{"x": 1.75, "width": 0.3, "arc": 0.4, "angle_deg": 350}]
    msg = reject([], write_pattern(tmp_path, raw))
    assert "overlaps" in msg


def test_process_values_out_of_range_in_a_pattern_file_name_its_line(tmp_path):
    """The same bounds hold for process values written in the pattern YAML (fuzz report E2)."""
    raw = base_raw()
    raw["process"] = {"defocus": 1e6}
    p = write_pattern(tmp_path, raw)
    line = next(i for i, t in enumerate(p.read_text().splitlines(), 1) if t.strip().startswith("defocus:"))
    msg = reject([], p)
    assert f"p.yaml:{line}: process.defocus: out of range" in msg and "fix: use a value <= 100" in msg


def test_process_values_out_of_range_in_a_process_file(tmp_path):
    """A process file the pattern names (process: NAME.yaml) is held to the same bounds."""
    (tmp_path / "proc.yaml").write_text("process:\n  power_w: 1e9\n  frequency_khz: 60\n")
    raw = base_raw()
    raw["process"] = "proc.yaml"
    msg = reject([], write_pattern(tmp_path, raw))
    assert "process.power_w: out of range" in msg and ">= 0.05 and <= 100 W" in msg


@pytest.mark.parametrize("top", [True, False])
def test_a_problem_in_a_process_file_is_named_in_that_file_at_its_line(tmp_path, top):
    """The bad-input search: an unknown key in the process file a pattern names was reported against the pattern,
    without a line. It is named in the process file, at its line (with or without a top-level 'process:'); a value
    given with --set is still the pattern's; a pattern named as the process file is refused as such."""
    body = "  frequency_khz: 60\n  power_wx: 2.0\n  defocus: 1e6\n"
    (tmp_path / "proc.yaml").write_text("# the lab's process\n" + ("process:\n" + body if top else body.replace("  ", "")))
    raw = base_raw()
    raw["process"] = "proc.yaml"
    p = write_pattern(tmp_path, raw)
    first = 3 if top else 2
    msg = reject([], p)
    assert f"proc.yaml:{first + 1}: process.power_wx: unknown key" in msg and "did you mean 'power_w'" in msg, msg
    (tmp_path / "proc.yaml").write_text("process:\n  frequency_khz: 60\n  defocus: 1e6\n")
    assert "proc.yaml:3: process.defocus: out of range" in reject([], p)
    msg = reject(["process.power_w=1e9"], p)
    assert "p.yaml: process.power_w: out of range" in msg and "proc.yaml:3: process.defocus" in msg, msg
    raw2 = base_raw()
    raw2["process"] = "p.yaml"
    msg = reject([], write_pattern(tmp_path, raw2, "q.yaml"))
    assert "q.yaml" in msg and "names" in msg and "a pattern file, not a process file" in msg, msg


@pytest.mark.parametrize("bad", ["process.frequency_khz=1e-12", "process.scan_speed_mm_s=1e12",
                                 "process.defocus=1e6", "process.power_w=1e9"])
def test_a_process_value_out_of_range_writes_no_toolpath(tmp_path, capsys, bad):
    """Before: exit 0 with M68 E1 Q0.000 (no pulses), F2e14, G0 Z-1000000, S100000000000 (fuzz report E2)."""
    out = tmp_path / "out"
    assert main(["toolpath", str(TUBE1), "-q", "--set", bad, "-o", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "tube1.yaml" in err[0] and bad.split("=")[0] + ":" in err[0] and "fix:" in err[0], err
    assert list(tmp_path.iterdir()) == []


def test_all_errors_reported_together():
    msg = reject(["notch.width=-1", "tendon.length=0", "process.power_w=-2"])
    assert "notch.width" in msg and "tendon.length" in msg and "process.power_w" in msg


def test_yaml_syntax_error_names_line(tmp_path):
    p = tmp_path / "bad.yaml"
    p.write_text("tube:\n  outer_radius: 0.75\n  inner_radius: [0.45\nnotch: {}\n")
    msg = reject([], p)
    assert "bad.yaml:" in msg and "not valid YAML" in msg


def test_missing_required_key(tmp_path):
    raw = base_raw()
    del raw["notch"]["arc"]
    msg = reject([], write_pattern(tmp_path, raw))
    assert "notch.arc: required key is missing" in msg


def test_warnings_only_when_the_stroke_overloads_the_joint():
    """Issue 9: the preset is fit for its stroke (no warning); a warning names the stroke, the bend and the fix."""
    assert load(TUBE1).warnings == ()
    # a stiffer limit: strain 0.036 at 2 mm is more than twice 0.015
    w = [str(x) for x in load(TUBE1, ["rules.max_strain=0.015"]).warnings]
    assert len(w) == 1 and "rules.max_strain" in w[0] and "tube1.yaml:" in w[0]
    assert "32.0 deg" in w[0] and "largest elastic bend 13.3 deg at 0.83 mm" in w[0]
    assert "fix: lower rules.max_stroke towards 0.83 mm" in w[0]
    # past closure: the notches close before the stroke is reached
    w = [str(x) for x in load(TUBE1, ["rules.max_stroke=20"]).warnings]
    assert any("a notch closes at a tendon stroke of 14.73 mm" in x for x in w)


@pytest.mark.parametrize("cmd", ["dxf"])
def test_rejected_pattern_writes_nothing(tmp_path, capsys, cmd):
    out = tmp_path / "out.dxf"
    rc = main([cmd, str(TUBE1), "--set", "notch.arc=4.8", "-o", str(out)])
    assert rc == 2
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []
    assert "notch.arc" in capsys.readouterr().err


def test_override_types_and_list_index():
    p = load(TUBE1, ["notch.count=12", "holes.0.angle_deg=170", "process.repeats=5"]).pattern
    assert len(p.notches) == 12 and p.holes[0].angle_deg == 170 and p.process.repeats == 5
    assert "past the end" in reject(["holes.3.x=1"])
    # the bad-input search: "allowed: 0..-1", and no file named
    msg = reject(["cuts.0.x=3"])
    assert "tube1.yaml: cuts.0.x: index 0, but the pattern has no cuts entries" in msg and "0..-1" not in msg, msg
    assert "tube1.yaml: holes.3.x: index 3 is past the end" in reject(["holes.3.x=1"])


def test_bidirectional_and_directions_layouts():
    p = load(PATTERNS / "tube1-bidirectional.yaml").pattern
    angles = [n.angle_deg for n in p.notches]
    assert angles[:4] == [180.0, 0.0, 180.0, 0.0]
    q = load(TUBE1, ["notch.layout=directions", "notch.directions_deg=[0, 90, 180, 270]",
                     "notch.arc=1.0", "holes.0.angle_deg=45"]).pattern
    assert [n.angle_deg for n in q.notches][:5] == [0.0, 90.0, 180.0, 270.0, 0.0]
    assert math.isclose(q.notches[1].x_mm - q.notches[0].x_mm, 1.0)


@pytest.mark.parametrize("kind", ["list", "chain", "folder", "latin-1"])
def test_a_process_file_that_is_not_one_is_named_as_a_process_file(tmp_path, kind):
    """The bad-input search: a process file holding a list was "a pattern file must be a mapping of sections; fix:
    start the file with 'tube:'"; one naming another process file was blamed on the pattern's line; a folder was "a
    process file that is not there"; a Latin-1 one asked for "a UTF-8 pattern YAML file"."""
    proc = tmp_path / "proc.yaml"
    if kind == "list":
        proc.write_text("[1, 2]\n")
    elif kind == "chain":
        proc.write_text("# the lab's\nprocess: femto-polyimide.yaml\n")
    elif kind == "folder":
        proc.mkdir()
    else:
        proc.write_bytes("# r\xe9glage du laser\npower_w: 2.0\n".encode("latin-1"))
    raw = base_raw()
    raw["process"] = "proc.yaml"
    msg = reject([], write_pattern(tmp_path, raw))
    want = {"list": ["proc.yaml:1: <top>: a process file must be a mapping of process keys", "power_w"],
            "chain": ["proc.yaml:2: process: names another process file ('femto-polyimide.yaml')",
                      "name that file from the pattern, or copy its keys here"],
            "folder": ["p.yaml", "process: names", "which is a folder"],
            "latin-1": ["proc.yaml", "a UTF-8 process YAML file"]}[kind]
    for w in want:
        assert w in msg, msg
    assert "start the file with 'tube:'" not in msg and "not there" not in msg, msg


def test_one_mistake_that_breaks_a_rule_many_times_is_one_line():
    """The bad-input search: --set notch.spacing=0.0001 printed nine lines, one per pair of notches too close."""
    msg = reject(["notch.spacing=0.0001"])
    assert len(msg.splitlines()) == 1, msg
    assert "notch.spacing: notch at x=2.25 mm" in msg and "(and 8 more like it)" in msg, msg
    # different keys stay one line each
    msg = reject(["notch.arc=9", "notch.spacing=0.0001"])
    assert any(line.count("notch.arc") for line in msg.splitlines()), msg
