"""``camtube synthesize`` and ``camtube design --stroke`` as a user runs them: output, exit status,
one-line errors naming file, line and key, nothing written on failure; the written pattern builds
into a job that verifies; the independent re-simulation from the job's cut geometry agrees."""
from __future__ import annotations

import json
import re

import pytest

from camtube.design.loader import load_pattern
from camtube.joint import simulate
from camtube.synthesis.check import as_cut_notches, resimulate
from tests.conftest import ROOT
from tests.test_cli_errors import assert_refused, camtube, listing

GOALS = ROOT / "examples" / "goals"


def test_synthesize_prints_target_predicted_limit_and_tolerance(tmp_path):
    out = tmp_path / "p.yaml"
    r = camtube("synthesize", str(GOALS / "04-tube1-tip-first.yaml"), "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert "target deg  predicted deg" in r.stdout and "active limit: limits." in r.stdout
    assert "deg/10um depth" in r.stdout and "deg/10um kerf" in r.stdout
    row = next(line for line in r.stdout.splitlines() if line.strip().startswith("180"))
    nums = [float(x) for x in re.findall(r"[-+]?\d+\.\d+", row)]
    target, predicted, depth, kerf = nums[1], nums[2], nums[-2], nums[-1]
    assert target == 60.0 and abs(predicted - target) <= 0.5
    assert depth > 0 and kerf > 0  # a deeper or wider notch is softer: more bend
    # the kerf tolerance against the independent model: widen every as-cut notch by 10 um
    p = load_pattern(out)
    cut = as_cut_notches(p)
    base = resimulate(p, {180.0: 1.5}, notches=cut)[0].bend_deg
    wider = [type(n)(n.x_mm, n.angle_deg, n.width_mm + 0.01, n.arc_mm + 0.01) for n in cut]
    assert resimulate(p, {180.0: 1.5}, notches=tuple(wider))[0].bend_deg - base == pytest.approx(kerf, rel=0.15)


@pytest.mark.parametrize("goal,stroke", [("01-tube1-uniform-60", {180.0: 1.5}),
                                         ("07-tube1-two-directions", {180.0: 1.5, 0.0: 1.2}),
                                         ("10-tube3-curve-bell", {270.0: 3.0}),
                                         ("13-tube1-3d-hook", {180.0: 1.2, 90.0: 1.2})])
def test_written_pattern_builds_verifies_and_resimulates(goal, stroke, tmp_path):
    out = tmp_path / "p.yaml"
    assert camtube("synthesize", str(GOALS / f"{goal}.yaml"), "-o", str(out)).returncode == 0
    b = camtube("build", str(out), "-o", str(tmp_path / "job"), "-q", "--no-step", "--no-pictures")
    assert b.returncode == 0 and "verification: PASS" in b.stdout, b.stdout + b.stderr
    assert any(p.suffix == ".ngc" for p in (tmp_path / "job").iterdir())
    # the written check reads each direction at its own stroke (07's 0 deg direction was checked at 1.5 mm, not 1.2)
    check = next(line for line in out.read_text().splitlines() if line.startswith("# Check:"))
    first, *rest = stroke.items()
    assert f"--stroke {first[1]:g} " in check
    for angle, mm in rest:
        assert mm == first[1] or f"--stroke {mm:g} for the {angle:g} deg direction" in check, check
    p = load_pattern(out)
    targets = {"01": {180.0: 60.0}, "07": {180.0: 45.0, 0.0: 30.0}, "10": {270.0: 43.125},
               "13": {180.0: 45.0, 90.0: 45.0}}[goal[:2]]
    for r in resimulate(p, stroke):
        assert abs(r.bend_deg - targets[r.angle_deg]) <= 0.05 * targets[r.angle_deg]
        assert r.max_strain <= p.rules.max_strain


def test_infeasible_goal_one_line_exit_2_nothing_written(tmp_path):
    r = camtube("synthesize", str(GOALS / "12-infeasible-short-stroke.yaml"), "-o", str(tmp_path / "p.yaml"))
    assert_refused(r, "12-infeasible-short-stroke.yaml", "infeasible", "nearest feasible target", "stroke")
    assert listing(tmp_path) == []


GOOD = """tube: {outer_radius: 0.75, inner_radius: 0.45}
goal:
  bends:
    - {angle_deg: 180, bend_deg: 40, stroke_mm: 1.2}
limits: {max_strain: 0.04}
"""


@pytest.mark.parametrize("edit,words", [
    (("limits: {max_strain: 0.04}", "limits: {max_strian: 0.04}"), ["limits.max_strian", "did you mean 'max_strain'", ":5:"]),
    (("bend_deg: 40", "bend_deg: -40"), ["goal.bends[0].bend_deg", "> 0", "-40"]),
    (("stroke_mm: 1.2", "stroke_mm: 1.2mm"), ["goal.bends[0].stroke_mm", "expected a number"]),
    (("inner_radius: 0.45", "inner_radius: 0.95"), ["tube.inner_radius", "smaller than the outer radius"]),
    # (the solver searched on and named limits.max_force_N: "the stroke stretches the tendon beyond any force")
    (("tube: {", "tendon: {radius: 0.5}\ntube: {"), ["tendon.radius", "thicker than the tube's lumen", ":1:",
                                                       "< tube.inner_radius = 0.45 mm"]),
    (("goal:", "goal:\n  distribution: tipfirst"), ["goal.distribution", "did you mean 'tip_first'"]),
    # (the bad-input search: "a notch must bend 0.00 deg, more than 0.75 of its closure angle")
    (("goal:", "goal:\n  distribution: [1, 1e-9, 1, 1]"), ["goal.distribution", "share 2 (from the tip) is 1e-09",
                                                          "bend next to nothing", "fix: leave that notch out"]),
    (("goal:", "goal:\n  curve: [2, 4]\n  curve_length: 10"), ["goal.bends[0].bend_deg", "30.00"]),
    (("limits:", "limit:"), ["did you mean 'limits'"]),
    (("tube:", "name: runs/tube4\ntube:"), ["name", "must be a plain file name", ":1:", "runs/tube4"]),
])
def test_goal_mistakes_one_line_each(tmp_path, edit, words):
    g = tmp_path / "g.yaml"
    g.write_text(GOOD.replace(*edit))
    r = camtube("synthesize", str(g), "-o", str(tmp_path / "p.yaml"))
    assert_refused(r, str(g), *words)
    assert listing(tmp_path) == ["g.yaml"]


def test_output_must_be_a_yaml_file(tmp_path):
    g = tmp_path / "g.yaml"
    g.write_text(GOOD)
    assert_refused(camtube("synthesize", str(g), "-o", str(tmp_path / "p.dxf")), "p.dxf", "PATTERN.yaml")


def test_calibration_changes_the_design_and_is_met_under_it(tmp_path):
    fit = tmp_path / "fit.json"
    fit.write_text(json.dumps({"schema": "camtube.fit/1", "params": {
        "E_t": {"value": 14.0, "unit": "GPa"}, "slack.deadband_mm": {"value": 0.1, "unit": "mm"}}}))
    plain, cal = tmp_path / "plain.yaml", tmp_path / "cal.yaml"
    goal = str(GOALS / "01-tube1-uniform-60.yaml")
    assert camtube("synthesize", goal, "-o", str(plain)).returncode == 0
    r = camtube("synthesize", goal, "-o", str(cal), "--calibration", str(fit))
    assert r.returncode == 0 and str(fit) in r.stdout
    from camtube.joint import Mechanics

    mech = Mechanics.from_fit_json(fit)
    p_cal, p_plain = load_pattern(cal), load_pattern(plain)
    k = 0.02  # the expected overcut both designs are drawn net of
    from dataclasses import replace

    got = simulate(p_cal, 1.5, replace(mech, kerf_mm=k)).direction(180.0).bend_deg
    assert abs(got - 60.0) <= 0.5
    assert abs(simulate(p_plain, 1.5, replace(mech, kerf_mm=k)).direction(180.0).bend_deg - 60.0) > 2.0


def test_design_stroke_prints_the_forward_model(tmp_path):
    r = camtube("design", "tube1", "--stroke", "1.5")
    assert r.returncode == 0, r.stderr
    assert "cut 20 um wider than drawn" in r.stdout  # the preset's process has no kerf compensation
    from camtube.joint import Mechanics

    st = simulate(load_pattern("tube1"), 1.5, Mechanics(kerf_mm=0.02)).direction(180.0)
    assert f"bend {st.bend_deg:.2f} deg" in r.stdout and f"force {st.force_N:.3f} N" in r.stdout
    r = camtube("design", "tube1", "--stroke", "1.5", "--overcut", "0")
    st = simulate(load_pattern("tube1"), 1.5).direction(180.0)
    assert f"bend {st.bend_deg:.2f} deg" in r.stdout and f"force {st.force_N:.3f} N" in r.stdout
    assert r.stdout.count("\n       ") >= 10  # a row per notch
    assert_refused(camtube("design", "tube1", "--stroke", "-1"), "--stroke", ">= 0")


def test_missing_process_file_is_named(tmp_path):
    g = tmp_path / "g.yaml"
    g.write_text(GOOD + "process: nowhere.yaml\n")
    assert_refused(camtube("synthesize", str(g), "-o", str(tmp_path / "p.yaml")), "process", "nowhere.yaml")
    assert listing(tmp_path) == ["g.yaml"]


@pytest.mark.parametrize("hinge,other", [("fe_row", "beam"), ("beam", "fe_row"), ("fe_fit", "beam")])
def test_synthesize_prints_the_bend_under_the_other_stiffness_model(tmp_path, hinge, other):
    """The stiffness line: the written pattern re-simulated with the other hinge, as the forward model gives it.
    Softer notches (fe_row, fe_fit) need less force for the same kinematic travel, so the tendon stretches less
    and the joint bends more at the same stroke; stiffer ones (beam) bend less."""
    from dataclasses import replace

    from camtube.joint import Mechanics

    g = tmp_path / "g.yaml"
    g.write_text(GOOD.replace("tube: {outer_radius: 0.75, inner_radius: 0.45}",
                              f"tube: {{outer_radius: 0.75, inner_radius: 0.45, hinge: {hinge}}}"))
    out = tmp_path / "p.yaml"
    r = camtube("synthesize", str(g), "-o", str(out))
    assert r.returncode == 0, r.stderr
    line = next(x for x in r.stdout.splitlines() if x.startswith("stiffness:"))
    assert f"designed with the {hinge} hinge; with the {other} hinge" in line
    m = re.search(r"notches ([\d.]+)(?: to ([\d.]+))? x as stiff", line)
    lo, hi = float(m.group(1)), float(m.group(2) or m.group(1))
    assert (hi < 1.0) if other != "beam" else (lo > 1.0)
    bend, delta = map(float, re.search(r"would be ([\d.]+) deg \(([-+][\d.]+)\) towards 180 deg", line).groups())
    want = simulate(load_pattern(out), {180.0: 1.2}, Mechanics(kerf_mm=0.02, hinge=other)).direction(180.0).bend_deg
    assert bend == pytest.approx(want, abs=0.006)
    assert delta == pytest.approx(bend - 40.0, abs=0.02)  # the design meets 40 deg under its own hinge
    assert (delta > 2.0) if other != "beam" else (delta < -2.0)


CURVE3D = """tube: {outer_radius: 0.75, inner_radius: 0.45}
goal:
  centerline:
    - {length_mm: 6, bend_deg: 45, towards_deg: 180, stroke_mm: 1.2}
    - {length_mm: 6, bend_deg: 45, towards_deg: 90, stroke_mm: 1.2}
limits: {max_strain: 0.04, max_force_N: 3, max_length: 16}
"""


@pytest.mark.parametrize("edit,words", [
    (("towards_deg: 90", "towards_deg: 180"), ["goal.centerline[1].towards_deg", "own tendon", "turn one"]),
    (("towards_deg: 90", "towards_deg: -180"), ["goal.centerline[1].towards_deg", "already goal.centerline[0]"]),
    (("length_mm: 6, bend_deg: 45, towards_deg: 90", "bend_deg: 45, towards_deg: 90"),
     ["goal.centerline[1].length_mm", "required"]),
    (("length_mm: 6, bend_deg: 45, towards_deg: 90", "length_mm: -6, bend_deg: 45, towards_deg: 90"),
     ["goal.centerline[1].length_mm", "> 0"]),
    (("towards_deg: 90, stroke_mm: 1.2}", "towards_deg: 90, stroke_mm: 1.2, twist: 3}"),
     ["goal.centerline[1].twist", "unknown"]),
    (("goal:", "goal:\n  bends:\n    - {angle_deg: 180, bend_deg: 40, stroke_mm: 1.2}"),
     ["goal.bends", "remove goal.bends"]),
    (("goal:", "goal:\n  distribution: tip_first"), ["goal.distribution", "constant curvature"]),
    (("goal:", "goal:\n  curve: [2, 4]\n  curve_length: 10"), ["goal.curve", "remove goal.curve"]),
    (("centerline:", "centreline:"), ["goal.centreline", "did you mean 'centerline'"]),
    (("length_mm: 6, bend_deg: 45, towards_deg: 90", "length_mm: 2, bend_deg: 45, towards_deg: 90"),
     ["goal.centerline[1]", "infeasible", "nearest feasible target"]),
])
def test_3d_centerline_mistakes_one_line_each(tmp_path, edit, words):
    g = tmp_path / "g.yaml"
    assert edit[0] in CURVE3D
    g.write_text(CURVE3D.replace(*edit, 1))
    r = camtube("synthesize", str(g), "-o", str(tmp_path / "p.yaml"))
    assert_refused(r, str(g), *words)
    assert listing(tmp_path) == ["g.yaml"]


def test_a_goal_named_like_a_date_writes_a_pattern_whose_name_stays_text(tmp_path):
    """The written pattern held ``name: 2024-01-01`` unquoted, which YAML reads back as a date (a traceback in the
    job file then; refused since): the name is written quoted, and the pattern builds."""
    goal = tmp_path / "g.yaml"
    text = (GOALS / "01-tube1-uniform-60.yaml").read_text()
    goal.write_text("name: '2024-01-01'\n" + "\n".join(ln for ln in text.splitlines() if not ln.startswith("name:")))
    out = tmp_path / "p.yaml"
    r = camtube("synthesize", str(goal), "-o", str(out))
    assert r.returncode == 0, r.stderr
    assert load_pattern(out).name == "2024-01-01"
    r = camtube("toolpath", str(out), "-o", str(tmp_path / "job"))
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "job" / "2024-01-01.job.json").is_file()


def test_a_backbone_arc_that_leaves_no_notch_is_refused_with_one_line(tmp_path):
    """limits.min_backbone_arc 4.7 mm on a tube of 4.712 mm circumference leaves no notch arc: the solver's bounds
    crossed (a scipy traceback). Refused as infeasible, naming the limit."""
    goal = tmp_path / "g.yaml"
    goal.write_text((GOALS / "01-tube1-uniform-60.yaml").read_text().replace("min_backbone_arc: 0.3",
                                                                            "min_backbone_arc: 4.7"))
    out = tmp_path / "p.yaml"
    assert_refused(camtube("synthesize", str(goal), "-o", str(out)), "limits.min_backbone_arc", "reach the lumen")
    assert not out.exists()


# bugs 17-19 (fuzzing): a bad goal file was several lines for one mistake (a section that is not a mapping, a
# missing tube section, an empty file, a list of zero shares), 'out of memory' naming nothing (a tiny
# max_notch_bend_deg), or a message about the unwritten output pattern's keys (a web of 1e-12 mm written as a
# spacing of 0, a first_offset or base_length of 1e300 mm); a huge length printed 300 digits
@pytest.mark.parametrize("text,words", [
    ("", [":1:", "the goal file is empty", "fix: write at least 'tube:' and 'goal:'"]),
    ("# only a comment\n", ["the goal file is empty"]),
    (GOOD.replace("tube: {outer_radius: 0.75, inner_radius: 0.45}\n", ""),
     ["tube: required section is missing", "outer_radius, inner_radius", "fix: add e.g. 'tube: {"]),
    (GOOD.replace("{outer_radius: 0.75, inner_radius: 0.45}", "[0.75, 0.45]"),
     [":1:", "tube: expected a mapping", "fix: indent the keys under 'tube:'"]),
    (GOOD.replace("limits: {max_strain: 0.04}", "limits: 3"), ["limits: expected a mapping"]),
    (GOOD.replace("goal:", "goal:\n  distribution: [0, 0, 0]"),
     ["goal.distribution[0]", "(and 2 more entries of goal.distribution)", "fix: use a positive value"]),
    (GOOD.replace("goal:", "goal:\n  max_notch_bend_deg: 1e-9"),
     ["goal.max_notch_bend_deg", "more than the 200 a direction may have", ">= 0.2 deg", "fix: raise it to 0.2"]),
    (GOOD.replace("goal:", "goal:\n  web: 1e-12").replace("max_strain: 0.04", "max_strain: 0.04, min_web: 0"),
     [":3:", "goal.web", ">= 0.001 mm"]),
    (GOOD.replace("goal:", "goal:\n  first_offset: 1e300"),
     ["goal.first_offset = 1e+300 mm", "longer than a pattern's tube.length may be (2000 mm)",
      "fix: shorten goal.first_offset or goal.base_length"]),
    (GOOD.replace("goal:", "goal:\n  base_length: 1e300"), ["goal.base_length = 1e+300 mm", "fix: shorten"]),
    # (was designed, then found infeasible: "limits.max_length ... e+299 mm long"; now refused as read)
    (GOOD.replace("inner_radius: 0.45}", "inner_radius: 0.45, modulus_gpa: 1e300}"),
     ["tube.modulus_gpa: out of range", "<= 1000 GPa"]),
    # the bad-input search: 500 % strain was taken (a design at twice polyimide's elastic limit, no warning)
    (GOOD.replace("limits: {max_strain: 0.04}", "limits: {max_strain: 5}"),
     ["limits.max_strain: out of range", "<= 1", "fix: use a value <= 1"]),
    (GOOD.replace("goal:", "tendon: {modulus_gpa: 1e-300}\ngoal:"), ["tendon.modulus_gpa: out of range", ">= 0.5"]),
    # the bad-input search: dropped without a word (20 deg per notch written for a maximum of 2)
    (GOOD.replace("goal:", "goal:\n  tip_ratio: 10"), ["goal.tip_ratio: is given, but goal.distribution is uniform",
                                                      "set distribution: tip_first"]),
    # the bad-input search: "a notch must bend 6.00 deg, more than 0.75 of its closure angle; fix: give more stroke"
    (GOOD.replace("stroke_mm: 1.2", "stroke_mm: 100"), ["goal.bends[0].stroke_mm: is as long as the tendon or longer",
                                                      "tendon.length = 70 mm", "< 70 mm"]),
    (GOOD.replace("goal:", "goal:\n  notches: 2\n  max_notch_bend_deg: 4"),
     ["goal.notches: gives 20 deg per notch", "more than goal.max_notch_bend_deg = 4 deg", ">= 10 notches, or auto"]),
])
def test_bad_goal_files_are_one_line_naming_the_key_with_a_fix(tmp_path, capsys, text, words):
    from camtube.commands import main

    g = tmp_path / "g.yaml"
    g.write_text(text)
    code = main(["synthesize", str(g), "-o", str(tmp_path / "p.yaml")])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert "Traceback" not in err and len(err.splitlines()) == 1 and "fix:" in err and str(g) in err, err
    assert not re.search(r"\d{20}", err), err
    for w in words:
        assert w in err, err
    assert listing(tmp_path) == ["g.yaml"]


def test_a_designed_pattern_the_rules_refuse_names_the_goal_not_the_unwritten_output(tmp_path, capsys, monkeypatch):
    """The last guard: camtube's rules refusing the designed pattern were one line per issue, each naming the output
    file, which is not written."""
    import camtube.synthesis.report as report
    from camtube.commands import main

    real = report.pattern_yaml
    monkeypatch.setattr(report, "pattern_yaml", lambda d: re.sub(r"spacings: \[[^\]]*\]",
                                                                   "spacings: [" + ", ".join(["0"] * 20) + "]", real(d)))
    g = tmp_path / "g.yaml"
    g.write_text(GOOD)
    assert main(["synthesize", str(g), "-o", str(tmp_path / "p.yaml")]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "p.yaml" not in err and str(g) in err, err
    assert "notch.spacings" in err and "more)" in err and "fix: relax the goal's" in err, err
    assert listing(tmp_path) == ["g.yaml"]


def test_an_infeasible_goal_with_no_nearest_target_is_not_told_to_go_to_it(tmp_path, capsys):
    """The bad-input search: "nearest feasible target: none found ...; fix: lower bend_deg to the nearest target"."""
    from camtube.commands import main

    goal = tmp_path / "g.yaml"
    goal.write_text(GOOD.replace("stroke_mm: 1.2", "stroke_mm: 0.000001"))
    assert main(["synthesize", str(goal), "-o", str(tmp_path / "p.yaml")]) == 2
    err = capsys.readouterr().err
    assert "nearest feasible target: none found" in err and "to the nearest target" not in err, err
    assert "or change the stock (the tube)" in err and len(err.strip().splitlines()) == 1, err


def test_two_directions_whose_anchor_holes_collide_are_told_to_move_apart(tmp_path, capsys):
    """The bad-input search: directions 0 and 10 deg: "holes[1] ... collides with hole ...; fix: relax the goal's
    lengths or limits behind holes[1]", which no length or limit fixes."""
    from camtube.commands import main

    goal = tmp_path / "g.yaml"
    goal.write_text("tube: {outer_radius: 0.75, inner_radius: 0.45}\ngoal: {bends: [{angle_deg: 0, bend_deg: 30, "
                    "stroke_mm: 1.5}, {angle_deg: 10, bend_deg: 30, stroke_mm: 1.5}]}\n")
    assert main(["synthesize", str(goal), "-o", str(tmp_path / "p.yaml")]) == 2
    err = capsys.readouterr().err
    assert "collides with hole" in err and "set the bending directions (goal.bends[].angle_deg) further apart" in err, err
    assert not (tmp_path / "p.yaml").exists()
