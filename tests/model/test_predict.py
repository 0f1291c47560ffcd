"""Stroke-only prediction: stiffness, closed form vs the general solver, consistency with the fit model."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design.geometry import pattern_geometry
from camtube.design.loader import load_pattern
from camtube.model.api import Effect, Param
from camtube.model.core.predict import (
    design_summary, joint_stiffness_nmm_per_rad, model_for_pattern, pattern_values, predict_from_stroke,
    stiffness_from_data, stroke_only_angle_rad,
)
from camtube.model.sim.synth import synthesize
from tests.conftest import PATTERNS, PRESETS


@pytest.mark.parametrize("name", PRESETS)
def test_stiffness_is_e_i_over_n_h(name):
    p = load_pattern(PATTERNS / f"{name}.yaml")
    g = pattern_geometry(p).first
    n = len(p.notches)
    assert joint_stiffness_nmm_per_rad(p) == pytest.approx(2500.0 * g.second_moment_mm4 / (n * g.notch_width_mm))
    assert joint_stiffness_nmm_per_rad(p, 5.0) == pytest.approx(2 * joint_stiffness_nmm_per_rad(p))


@pytest.mark.parametrize("name", PRESETS)
def test_closed_form_satisfies_both_equations(name):
    p = load_pattern(PATTERNS / f"{name}.yaml")
    model = model_for_pattern(p)
    vals = pattern_values(p)
    k = joint_stiffness_nmm_per_rad(p)
    stroke = np.linspace(0, p.rules.max_stroke_mm, 11)
    ang, force = predict_from_stroke(model, vals, stroke, k)
    arm = model.geometry.moment_arm_mm
    # moment balance and the paper's stroke equation
    np.testing.assert_allclose(force * arm, k * np.radians(ang), rtol=1e-12, atol=1e-12)
    c = vals["L0"] / (vals["E_t"] * 1e3 * math.pi * p.tendon.radius_mm**2)
    np.testing.assert_allclose(arm * np.radians(ang) + force * c, stroke, atol=1e-12)
    # and the fit's model (a), fed the predicted force, returns the same angle
    from camtube.model.data.dataset import Dataset

    n = stroke.size
    d = Dataset(np.full(n, "a", dtype=object), np.ones(n, int), np.arange(n, dtype=float), stroke, force,
                np.zeros(n))
    np.testing.assert_allclose(model.predict(d, vals), ang, atol=1e-10)


def test_general_solver_agrees_with_closed_form():
    p = load_pattern(PATTERNS / "tube2.yaml")
    ident = Effect("test_identity_force", "force", (Param("g", "", 0.5, 2.0, 1.0),),
                   lambda ctx, f, q: f * q["g"])
    vals = pattern_values(p) | {"test_identity_force.g": 1.0}
    k = joint_stiffness_nmm_per_rad(p)
    stroke = np.linspace(0, 2.5, 26)
    a0, f0 = predict_from_stroke(model_for_pattern(p), vals, stroke, k)
    a1, f1 = predict_from_stroke(model_for_pattern(p, [ident]), vals, stroke, k)
    np.testing.assert_allclose(a1, a0, atol=1e-6)
    np.testing.assert_allclose(f1, f0, atol=1e-6)


def test_negative_stroke_is_slack():
    assert stroke_only_angle_rad(np.array([-0.2, 0.0]), 1.0, 5.0, 0.5).tolist() == [0.0, 0.0]


def test_stiffness_from_noise_free_data():
    p = load_pattern(PATTERNS / "tube3.yaml")
    k = 12.5
    d = synthesize(p, n_samples=1, n_cycles=1, noise_angle_deg=0.0, noise_force_N=0.0, slack_mm=0.0,
                   stiffness_nmm_per_rad=k, stiffness_spread=0.0)
    assert stiffness_from_data(d, model_for_pattern(p).geometry.moment_arm_mm) == pytest.approx(k, rel=1e-9)


def test_design_summary_table_reaches_max_stroke():
    p = load_pattern(PATTERNS / "tube1.yaml")
    text = design_summary(p)
    rows = [ln.split() for ln in text.splitlines() if ln.strip() and ln.strip()[0].isdigit()]
    assert float(rows[0][0]) == 0.0 and float(rows[-1][0]) == pytest.approx(p.rules.max_stroke_mm)
    k = joint_stiffness_nmm_per_rad(p)
    arm = pattern_geometry(p).first.moment_arm_mm
    c = 70.0 / (28e3 * math.pi * 0.04**2)
    assert float(rows[-1][1]) == pytest.approx(math.degrees(2.0 / (arm + k * c / arm)), abs=0.006)
    assert "N mm/rad" in text


def test_camtube_design_shows_the_prediction(capsys):
    from camtube.commands import main

    assert main(["design", str(PATTERNS / "tube2.yaml"), "-q"]) == 0
    out = capsys.readouterr().out
    assert "predicted stroke-angle" in out and "2.500" in out
