"""Every example goal: solved in seconds, the written pattern accepted by camtube's own loader and
rules, the forward model on that pattern meeting the target (0.5 deg) and the distribution (2 %),
and the limits kept. The target shares are recomputed here from the goal's words, not taken from
the solver."""
from __future__ import annotations

import json
import re
import time

import numpy as np
import pytest

from camtube.design.loader import load_text
from camtube.joint import simulate
from camtube.synthesis.goal import load_goal
from camtube.synthesis.report import check_design, pattern_yaml
from camtube.synthesis.solve import InfeasibleGoal, synthesize
from tests.conftest import ROOT

GOALS = sorted((ROOT / "examples" / "goals").glob("*.yaml"))


def expected_shares(goal, n: int) -> np.ndarray:
    """Target shares from the tip, from the goal file's own definition."""
    if goal.curve_deg_per_mm:
        k = np.asarray(goal.curve_deg_per_mm)
        u = np.linspace(0.0, 1.0, len(k))
        w = np.interp((np.arange(n) + 0.5) / n, u, k)
    elif isinstance(goal.distribution, tuple):
        w = np.asarray(goal.distribution)
    elif goal.distribution == "uniform":
        w = np.ones(n)
    else:
        ends = (goal.tip_ratio, 1.0) if goal.distribution == "tip_first" else (1.0, goal.tip_ratio)
        w = np.linspace(*ends, n)
    return w / w.sum()


def test_there_are_fourteen_goals_of_every_kind():
    kinds = [load_goal(g) for g in GOALS]
    assert len(GOALS) == 14
    assert sum(bool(g.centerline) for g in kinds) == 2
    assert any(g.distribution == "tip_first" for g in kinds)
    assert any(len(g.bends) == 2 for g in kinds)
    assert any(g.curve_deg_per_mm for g in kinds)
    assert any("infeasible" in g.name for g in kinds)


@pytest.mark.parametrize("path", [g for g in GOALS if "infeasible" not in g.name], ids=lambda p: p.stem)
def test_goal_is_met(path, tmp_path):
    goal = load_goal(path)
    t0 = time.perf_counter()
    design = synthesize(goal)
    assert time.perf_counter() - t0 < 10.0
    loaded = load_text(pattern_yaml(design), tmp_path / "p.yaml")  # the rules raise on any error
    p = loaded.pattern
    assert not [w for w in loaded.warnings if "closes" in w.message]
    lim = goal.limits
    joint = max(n.x_end_mm for n in p.notches) - min(n.x_start_mm for n in p.notches)
    assert joint <= lim.max_length_mm + 1e-9
    assert min(n.width_mm for n in p.notches) >= lim.min_feature_mm - 1e-12
    assert p.tube.circumference_mm - max(n.arc_mm for n in p.notches) >= lim.min_backbone_arc_mm - 1e-12
    for b in goal.bends:
        st = simulate(p, {b.angle_deg: b.stroke_mm}, design.mechanics)
        d = st.direction(b.angle_deg)
        assert abs(d.bend_deg - b.bend_deg) <= 0.5
        want = expected_shares(goal, len(d.shares))[::-1]  # the state lists base to tip
        assert np.max(np.abs(d.shares - want) / want) <= 0.02
        assert float(d.strain.max()) <= lim.max_strain
        assert d.force_N <= lim.max_force_N
        assert not d.closed.any()
    # the printed check says the same
    for c, b in zip(check_design(design, p), goal.bends):
        assert abs(c.predicted_deg - b.bend_deg) <= 0.5 and c.share_error <= 0.02


def test_planar_curve_is_followed(tmp_path):
    """The bent centre line's curvature (angle per pitch) follows the goal's profile notch by notch."""
    goal = load_goal(ROOT / "examples" / "goals" / "09-tube2-curve-tip-tight.yaml")
    design = synthesize(goal)
    p = load_text(pattern_yaml(design), tmp_path / "p.yaml").pattern
    b = goal.bends[0]
    st = simulate(p, {b.angle_deg: b.stroke_mm}, design.mechanics)
    xs = np.array([n.x_mm for n in p.notches])
    pitch = np.diff(xs)
    np.testing.assert_allclose(pitch, pitch[0], atol=2e-4)  # uniform pitch
    kappa = np.degrees(st.notch_angles_rad) / pitch[0]  # deg/mm, pattern order = from the tip
    u = (xs - xs[0] + pitch[0] / 2) / (len(xs) * pitch[0])
    want = np.interp(u, np.linspace(0, 1, len(goal.curve_deg_per_mm)), goal.curve_deg_per_mm)
    want *= b.bend_deg / (want.sum() * pitch[0])  # the profile's shape at the goal's total bend
    np.testing.assert_allclose(kappa, want, rtol=0.02)


def test_infeasible_goal_names_the_limit_and_a_nearest_target_that_is_feasible():
    goal = load_goal(ROOT / "examples" / "goals" / "12-infeasible-short-stroke.yaml")
    t0 = time.perf_counter()
    with pytest.raises(InfeasibleGoal) as ei:
        synthesize(goal)
    assert time.perf_counter() - t0 < 10.0
    msg = str(ei.value)
    assert "\n" not in msg and "stroke" in ei.value.limit and "nearest feasible target" in msg
    bend, stroke = map(float, re.match(r"([\d.]+) deg at ([\d.]+) mm", ei.value.nearest).groups())
    b = goal.bends[0]
    near = goal.with_bends([type(b)(b.angle_deg, bend, stroke)])
    d = synthesize(near)  # feasible
    assert d.directions[0].count >= 2
    with pytest.raises(InfeasibleGoal):  # and 3 % more is not: it is the nearest
        synthesize(goal.with_bends([type(b)(b.angle_deg, bend * 1.03, stroke)]))


def test_force_limit_asks_for_less_stroke():
    goal = load_goal(ROOT / "examples" / "goals" / "01-tube1-uniform-60.yaml")
    from dataclasses import replace

    tight = replace(goal, limits=replace(goal.limits, max_force_N=0.5))
    with pytest.raises(InfeasibleGoal) as ei:
        synthesize(tight)
    assert ei.value.limit == "limits.max_force_N"
    bend, stroke = map(float, re.match(r"([\d.]+) deg at ([\d.]+) mm", ei.value.nearest).groups())
    assert bend == pytest.approx(60.0) and stroke < 1.5
    d = synthesize(tight.with_bends([type(goal.bends[0])(180.0, 60.0, stroke)]))
    assert d.directions[0].force_N <= 0.5


def test_a_bend_too_small_for_its_stroke_asks_for_less_stroke_and_that_target_is_feasible():
    """The bad-input search: 0.1 deg at 1.5 mm was told "a notch must bend 0.05 deg, more than 0.75 of its closure
    angle" and "give more stroke". The stroke is what is too much: no notch bears the force that would stretch the
    tendon by the rest of it."""
    goal = load_goal(ROOT / "examples" / "goals" / "01-tube1-uniform-60.yaml")
    b = goal.bends[0]
    small = goal.with_bends([type(b)(b.angle_deg, 0.1, 1.5)])
    with pytest.raises(InfeasibleGoal) as ei:
        synthesize(small)
    msg = str(ei.value)
    assert ei.value.limit == "goal.bends[].stroke_mm", msg
    assert "is more than a 0.1 deg bend takes up" in msg and "give more stroke" not in msg, msg
    assert "fix: lower stroke_mm to the nearest target, or ask for more bend" in msg, msg
    bend, stroke = map(float, re.match(r"([\d.]+) deg at ([\d.]+) mm", ei.value.nearest).groups())
    assert bend == pytest.approx(0.1) and stroke < 1.5
    d = synthesize(small.with_bends([type(b)(b.angle_deg, 0.1, stroke)]))   # the nearest target is feasible
    assert d.directions[0].count >= 1


def test_a_calibration_slack_that_takes_the_stroke_is_named_in_the_infeasible_line(tmp_path):
    """The bad-input search: a calibration with 1.4 mm of slack made 60 deg at 1.5 mm infeasible, and the line said
    only that the bend needs 2.4 mm of travel, never the slack."""
    from camtube.joint.forward import Mechanics

    goal = load_goal(ROOT / "examples" / "goals" / "01-tube1-uniform-60.yaml")
    cal = tmp_path / "fit.json"
    cal.write_text(json.dumps({"schema": "camtube.fit/1", "params": {
        "E_t": {"value": 28.0, "stderr": 0.01, "unit": "GPa", "fitted": True},
        "slack.deadband_mm": {"value": 1.4, "stderr": 0.01, "unit": "mm", "fitted": True}}}))
    with pytest.raises(InfeasibleGoal) as ei:
        synthesize(goal, Mechanics.from_fit_json(cal))
    assert "(1.400 mm of it the calibration's slack" in str(ei.value), str(ei.value)


def test_fe_fit_hinge_design_meets_the_goal_under_that_model(tmp_path):
    from dataclasses import replace

    goal = replace(load_goal(ROOT / "examples" / "goals" / "04-tube1-tip-first.yaml"), hinge="fe_fit")
    design = synthesize(goal)
    assert design.mechanics.hinge == "fe_fit"
    p = load_text(pattern_yaml(design), tmp_path / "p.yaml").pattern
    d = simulate(p, {180.0: 1.5}, design.mechanics).direction(180.0)
    assert abs(d.bend_deg - 60.0) <= 0.5
    want = expected_shares(goal, len(d.shares))[::-1]
    assert np.max(np.abs(d.shares - want) / want) <= 0.02
    assert float(d.strain.max()) <= goal.limits.max_strain
    # the same pattern under the beam model is stiffer: it bends less
    assert simulate(p, {180.0: 1.5}, replace(design.mechanics, hinge="beam")).direction(180.0).bend_deg < 57.0


def test_a_hopeless_goal_is_refused_within_the_time_limit():
    from camtube.synthesis.goal import build_goal

    raw = {"tube": {"outer_radius": 1.54, "inner_radius": 0.55}, "tendon": {"friction": 1.5},
           "goal": {"bends": [{"bend_deg": 168, "stroke_mm": 9.3}], "distribution": "tip_first",
                    "max_notch_bend_deg": 2.1},
           "limits": {"max_strain": 0.048, "max_force_N": 12.7, "max_length": 34, "min_feature": 0.03}}
    t0 = time.perf_counter()
    with pytest.raises(InfeasibleGoal) as ei:
        synthesize(build_goal(raw, "g.yaml", {}))
    assert time.perf_counter() - t0 < 10.0
    assert "\n" not in str(ei.value) and ei.value.limit == "limits.max_length"


def _tip_direction(arcs) -> np.ndarray:
    """The goal's tip direction by composing the pieces' rotations with scipy (independent of the solver's code):
    each piece turns the tube's own frame about ``z x towards`` in that frame."""
    from scipy.spatial.transform import Rotation

    r = Rotation.identity()
    for a in arcs:
        t = np.radians(a.towards_deg)
        axis = np.cross([0.0, 0.0, 1.0], [np.cos(t), np.sin(t), 0.0])  # in the piece's own (body) frame
        r = r * Rotation.from_rotvec(axis * np.radians(a.bend_deg))
    return r.apply([0.0, 0.0, 1.0])


@pytest.mark.parametrize("name", ["13-tube1-3d-hook", "14-tube2-3d-three-planes"])
def test_3d_centerline_is_followed(name, tmp_path):
    """The forward model's centre line with every tendon at its stroke stays within 50 um of the goal's and its tip
    points within 0.5 deg of the goal's tip direction (1 deg for the independent re-simulation); the shape is out
    of any one plane."""
    from camtube.synthesis.centerline import follow, target_points

    goal = load_goal(ROOT / "examples" / "goals" / f"{name}.yaml")
    design = synthesize(goal)
    p = load_text(pattern_yaml(design), tmp_path / "p.yaml").pattern
    # one direction per piece, each with its notches at a uniform pitch, pieces one after the other from the base
    for arc in goal.centerline:
        xs = sorted(n.x_mm for n in p.notches if abs(n.angle_deg - arc.towards_deg) < 1e-6)
        assert len(xs) >= 4
        np.testing.assert_allclose(np.diff(xs), np.diff(xs)[0], atol=2e-4)
    f = follow(goal, p, design.mechanics)
    assert f.max_deviation_mm <= 0.05 and f.tip_error_mm <= 0.05
    st = simulate(p, {b.angle_deg: b.stroke_mm for b in goal.bends}, design.mechanics)
    want = _tip_direction(goal.centerline)
    assert np.degrees(np.arccos(np.clip(st.tip_direction @ want, -1, 1))) <= 0.5
    # the independent re-simulation from the job's cut geometry, its notch angles composed apart: within 1 deg
    from camtube.synthesis.check import resimulate, tip_direction

    res = resimulate(p, {b.angle_deg: b.stroke_mm for b in goal.bends})
    assert np.degrees(np.arccos(np.clip(tip_direction(p, res) @ want, -1, 1))) <= 1.0
    # the target itself: its length is the pieces' plus the plain tube, and it is not planar
    tgt = target_points(goal, p)
    assert np.linalg.norm(np.diff(tgt, axis=0), axis=1).sum() > sum(a.length_mm for a in goal.centerline)
    centred = tgt - tgt.mean(axis=0)
    assert np.linalg.svd(centred, compute_uv=False)[2] > 0.1  # third singular value: out of plane
