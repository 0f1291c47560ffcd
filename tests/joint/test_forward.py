"""The notch-by-notch forward model against independent truth: the closed-form series model of
``design.geometry`` (uniform, no friction), the capstan law, notch closure, the stroke balance,
and a calibration JSON written by ``camtube model fit``."""
from __future__ import annotations

import json
import math
from dataclasses import replace

import numpy as np
import pytest

from camtube.design.geometry import bends_at_stroke, joint_geometry, pattern_geometry, tendon_compliance_mm_per_N
from camtube.design.loader import load_pattern
from camtube.joint import Mechanics, simulate
from tests.conftest import PRESETS

#: The paper's hinge (E I / h), which the closed-form series model of design.geometry is.
BEAM = Mechanics(hinge="beam")


@pytest.mark.parametrize("name", PRESETS)
@pytest.mark.parametrize("stroke", [0.3, 1.0, 2.0])
def test_uniform_frictionless_matches_the_closed_form_series_model(name, stroke):
    p = load_pattern(name)
    d = bends_at_stroke(p, stroke)[0]
    st = simulate(p, stroke, BEAM).direction(180.0)
    assert st.bend_deg == pytest.approx(math.degrees(d.bend_rad), rel=1e-9)
    assert float(st.strain.max()) == pytest.approx(d.strain, rel=1e-9)
    np.testing.assert_allclose(st.shares, 1.0 / len(st.shares), rtol=1e-9)


def test_capstan_friction_lowers_the_tension_notch_by_notch():
    p = replace(load_pattern("tube1"), tendon=replace(load_pattern("tube1").tendon, friction=0.3))
    st = simulate(p, 1.5, BEAM).direction(180.0)
    th = st.notch_angles_rad  # base to tip
    # uniform notches: the angle is proportional to the tension, which falls by exp(-mu theta) per notch
    np.testing.assert_allclose(th[1:] / th[:-1], np.exp(-0.3 * th[:-1]), rtol=1e-9)
    g = joint_geometry(0.75, 0.45, 2.83, 0.5)
    c = tendon_compliance_mm_per_N(70.0, 28.0, 0.04)
    # the stroke balance: kinematic shortening plus the tendon's stretch
    assert g.moment_arm_mm * th.sum() + st.force_N * c == pytest.approx(1.5, rel=1e-9)
    # the base notch sees the full force
    k = 2.5e3 * g.second_moment_mm4 / 0.5
    assert th[0] == pytest.approx(st.force_N * g.moment_arm_mm / k, rel=1e-9)
    assert simulate(p, 1.5, Mechanics(friction=0.0, hinge="beam")).direction(180.0).bend_deg > st.bend_deg


def test_fe_row_hinge_counts_the_webs_to_the_neighbours():
    """The default hinge: each backbone bends over h plus a root length r_o A (tanh(w_1 / B r_o) + tanh(w_2 / B r_o))
    / 2, w the webs (as cut) to the neighbouring notches; an end notch has plain tube on one side (tanh = 1), so it
    is softer than the notches inside the row, which are equal; all are softer than the beam E I / h."""
    from camtube.joint.forward import HINGE_ROW, direction_notches

    assert Mechanics().hinge == "fe_row"
    p = load_pattern("tube1")  # uniform: h 0.5, s 2.83, web 0.5 mm
    kerf = 0.02
    ns = direction_notches(p, Mechanics(kerf_mm=kerf))[0]
    g = joint_geometry(0.75, 0.45, 2.83 + kerf, 0.5 + kerf)
    (a0, a1, a2), b = HINGE_ROW["a"], HINGE_ROW["b"]
    root = 0.75 * (a0 + a1 * g.phi_rad + a2 * 0.45 / 0.75)
    web = 0.5 - kerf  # the cut widens each notch by the kerf: the web between two is that much shorter
    inside = 0.52 + root * math.tanh(web / (b * 0.75))
    end = 0.52 + root * (math.tanh(web / (b * 0.75)) + 1.0) / 2.0
    np.testing.assert_allclose(ns.bending_length_mm[1:-1], inside, rtol=1e-12)
    np.testing.assert_allclose(ns.bending_length_mm[[0, -1]], end, rtol=1e-12)
    ei = 2.5e3 * g.second_moment_mm4
    np.testing.assert_allclose(ns.stiffness_nmm_per_rad, ei / ns.bending_length_mm, rtol=1e-12)
    assert ns.stiffness_nmm_per_rad[0] < ns.stiffness_nmm_per_rad[1] < ei / 0.52
    # a lone notch (plain tube on both sides) has the whole root; a web of nothing leaves none
    from camtube.joint.forward import hinge_extra_mm

    assert hinge_extra_mm(0.75, g.phi_rad, "fe_row", inner_radius_mm=0.45) == pytest.approx(root, rel=1e-12)
    assert hinge_extra_mm(0.75, g.phi_rad, "fe_row", inner_radius_mm=0.45, webs_mm=(0.0, 0.0)) == 0.0
    # the stroke balance holds with the softer notches, and they bend more at the same stroke
    st = simulate(p, 1.5, Mechanics(kerf_mm=kerf)).direction(180.0)
    assert st.bend_deg > simulate(p, 1.5, replace(Mechanics(kerf_mm=kerf), hinge="beam")).direction(180.0).bend_deg


def test_closed_notches_stop_bending_and_the_tendon_takes_the_rest():
    p = load_pattern("tube3")
    geo = pattern_geometry(p)
    st = simulate(p, 150.0).direction(180.0)
    assert st.closed.all()
    assert math.radians(st.bend_deg) == pytest.approx(geo.total_closure_angle_rad, rel=1e-9)
    c = tendon_compliance_mm_per_N(70.0, 28.0, 0.04)
    arm = geo.first.moment_arm_mm
    assert st.force_N == pytest.approx((150.0 - arm * geo.total_closure_angle_rad) / c, rel=1e-9)


def test_tip_pose_points_towards_the_notches_and_keeps_the_straight_lengths():
    p = load_pattern("tube1-bidirectional")
    for ang in (0.0, 180.0):
        st = simulate(p, {ang: 1.0})
        d = st.direction(ang)
        assert st.tip_angle_deg == pytest.approx(d.bend_deg, abs=1e-9)  # planar: angles add
        assert st.tip_plane_deg == pytest.approx(ang, abs=1e-6)
        lateral = st.tip_position_mm[0] * math.cos(math.radians(ang))
        assert lateral > 0.5
    straight = simulate(p, 0.0)
    np.testing.assert_allclose(straight.tip_position_mm, [0, 0, p.tube.length_mm], atol=1e-12)
    # the base segment before the first notch stays straight and keeps its length
    bent = simulate(p, {180.0: 2.0})
    first_edge = p.tube.length_mm - max(n.x_end_mm for n in p.notches)
    assert np.linalg.norm(bent.centerline_mm[1] - bent.centerline_mm[0]) == pytest.approx(first_edge)


def test_calibration_from_a_real_fit_json(tmp_path):
    from camtube.model.core.fit import fit
    from camtube.model.data import prepare
    from camtube.model.core.predict import model_for_pattern, pattern_values
    from camtube.model.report.fit import fit_json
    from camtube.model.sim.synth import synthesize

    p = load_pattern("tube2")
    soft = replace(p, tendon=replace(p.tendon, modulus_gpa=14.0))
    data = prepare(synthesize(soft, n_samples=1, n_cycles=3, seed=3), cycles="last", branch="loading")
    r = fit(model_for_pattern(p), data, fit_params=("E_t",), fixed=pattern_values(p))
    path = tmp_path / "fit.json"
    path.write_text(fit_json(r))
    mech = replace(Mechanics.from_fit_json(path), hinge="beam")  # the closed form below is the beam's
    assert mech.tendon_modulus_gpa == pytest.approx(14.0, rel=0.05)
    # closed form with the fitted E_t: stroke = arm theta + F C, F arm = K theta
    g = joint_geometry(0.85, 0.55, 3.20, 0.5)
    k = 2.5e3 * g.second_moment_mm4 / 0.5 / 10
    c = tendon_compliance_mm_per_N(70.0, mech.tendon_modulus_gpa, 0.04)
    theta = 2.0 / (g.moment_arm_mm + k * c / g.moment_arm_mm)
    assert simulate(p, 2.0, mech).direction(180.0).bend_deg == pytest.approx(math.degrees(theta), rel=1e-6)


def test_calibration_slack_and_bad_files(tmp_path):
    from camtube.errors import CamtubeError

    path = tmp_path / "d.json"
    path.write_text(json.dumps({"schema": "camtube.diagnose/1", "final": {"params": {
        "E_t": {"value": 28.0}, "slack.deadband_mm@1": {"value": 0.2}, "slack.deadband_mm@2": {"value": 0.4},
        "creep.tau_s": {"value": 9.0}}}}))
    mech = Mechanics.from_fit_json(path)
    assert mech.slack_mm == pytest.approx(0.3) and mech.ignored == ("creep.tau_s",)
    p = load_pattern("tube1")
    assert simulate(p, 1.3, mech).direction(180.0).bend_deg == pytest.approx(
        simulate(p, 1.0).direction(180.0).bend_deg, rel=1e-9)
    bad = tmp_path / "bad.json"
    bad.write_text("{not json")
    with pytest.raises(CamtubeError, match="not JSON"):
        Mechanics.from_fit_json(bad)
    bad.write_text("{}")
    with pytest.raises(CamtubeError, match="no fitted parameters"):
        Mechanics.from_fit_json(bad)


def test_a_calibration_that_did_not_converge_or_determine_e_t_is_refused(tmp_path):
    """The bad-input search: a fit JSON with success false, or E_t 28 +- 9e5 GPa (fitted beside L0), was designed
    with, without a word. An effect's value within its error of zero (a slack of 0.00003 +- 0.0006 mm) is taken."""
    from camtube.errors import CamtubeError

    def fit_json(success=True, se=0.007, slack=(0.1, 0.01)):
        return json.dumps({"schema": "camtube.fit/1", "success": success, "message": "m", "params": {
            "E_t": {"value": 28.0, "stderr": se, "unit": "GPa", "fitted": True},
            "slack.deadband_mm": {"value": slack[0], "stderr": slack[1], "unit": "mm", "fitted": True}}})

    path = tmp_path / "f.json"
    path.write_text(fit_json(success=False))
    with pytest.raises(CamtubeError, match="success: false: this fit did not converge"):
        Mechanics.from_fit_json(path)
    path.write_text(fit_json(se=9e5))
    with pytest.raises(CamtubeError, match=r"params.E_t: 28 \+- 900000: its standard error exceeds the value"):
        Mechanics.from_fit_json(path)
    path.write_text(fit_json(slack=(3e-5, 6e-4)))
    assert Mechanics.from_fit_json(path).slack_mm == pytest.approx(3e-5)


def test_centerline_png_draws_the_3d_shape():
    """The 3-D picture is a PNG that reads back, of the size asked for."""
    import io

    import matplotlib.pyplot as plt

    from camtube.design.loader import load_pattern
    from camtube.joint.plot import centerline_png

    p = load_pattern("tube1-bidirectional")
    png = centerline_png(p, [{180.0: 0.8, 0.0: 0.4}, {180.0: 1.5, 0.0: 0.8}])
    img = plt.imread(io.BytesIO(png), format="png")
    assert img.shape[:2] == (912, 960)
    assert (img[..., :3] < 0.9).any()  # something drawn


def test_the_copies_of_a_fit_s_bounds_agree_with_the_model_s():
    """The layers below the model (the pattern and goal schemas, the calibration reader) cannot import it, so they
    hold the fit's bounds as copies: a tendon modulus, L0 and arm scale a fit could not give are refused by each."""
    from camtube.design.schema import SCHEMA
    from camtube.joint.forward import CALIBRATION_MIN
    from camtube.model.core.model import BASE_PARAMS
    from camtube.synthesis.goal import GOAL_SCHEMA

    bounds = {p.name: (p.lo, p.hi) for p in BASE_PARAMS}
    assert {k: v[0] for k, v in CALIBRATION_MIN.items()} == {k: bounds[k][0] for k in CALIBRATION_MIN}
    for f in (SCHEMA["tendon"]["modulus_gpa"], GOAL_SCHEMA["tendon"]["modulus_gpa"]):
        assert (f.lo, f.hi) == bounds["E_t"]


def test_a_calibration_takes_only_what_its_fit_measured_and_within_the_fit_ranges(tmp_path):
    """The bad-input search: a fit's held L0 (70 mm, the pattern's, ``fitted: false``) overrode a design's 200 mm
    tendon; a friction.mu of 1.5 (a fit keeps it within -0.9..0.9) was designed with: a bend of 0 deg at 3 N."""
    from camtube.errors import CamtubeError

    path = tmp_path / "f.json"
    path.write_text(json.dumps({"schema": "camtube.fit/1", "params": {
        "E_t": {"value": 27.9, "stderr": 0.01, "unit": "GPa", "fitted": True},
        "L0": {"value": 70.0, "stderr": None, "unit": "mm", "fitted": False}}}))
    mech = Mechanics.from_fit_json(path)
    assert mech.tendon_modulus_gpa == pytest.approx(27.9)
    assert mech.tendon_length_mm == Mechanics().tendon_length_mm   # the pattern's, not the fit's held 70
    p = load_pattern("tube1")
    long = replace(p, tendon=replace(p.tendon, length_mm=200.0))
    assert simulate(long, 1.0, mech).direction(180.0).bend_deg < simulate(p, 1.0, mech).direction(180.0).bend_deg
    for name, value in (("friction.mu", 1.5), ("kerf.kerf_mm", 20.0), ("toe.toe_mm", 30.0)):
        path.write_text(json.dumps({"schema": "camtube.fit/1", "params": {
            "E_t": {"value": 27.9, "stderr": 0.01, "fitted": True}, name: {"value": value, "fitted": True}}}))
        with pytest.raises(CamtubeError, match=rf"{name} = {value:g}( mm)?: outside the range a fit takes it in"):
            Mechanics.from_fit_json(path)


def test_the_calibration_ranges_are_the_effects_bounds():
    """joint.forward keeps the ranges a fit takes the calibrated effect parameters in (it does not import the model's
    registry, a higher floor): they must be the built-in effects' Param bounds and units."""
    from camtube.joint.forward import CALIBRATION_RANGE
    from camtube.model.core.registry import builtin_registry

    reg = builtin_registry()
    for name, (lo, hi, unit) in CALIBRATION_RANGE.items():
        eff, pname = name.split(".")
        spec = next(q for q in reg.get_effect(eff).params if q.name == pname)
        assert (spec.lo, spec.hi, spec.unit) == (lo, hi, unit), name
