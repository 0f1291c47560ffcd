"""The fit recovers known parameters from synthetic data; FitResult statistics are right."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.model.api import Effect, JointModel, Param
from camtube.model.data import prepare
from camtube.model.core.fit import FitError, fit
from camtube.model.core.predict import model_for_pattern, pattern_values
from camtube.model.sim.synth import noise_floor_deg, synthesize
from tests.conftest import PATTERNS, PRESETS


@pytest.fixture(scope="module")
def tube2():
    return load_pattern(PATTERNS / "tube2.yaml")


@pytest.mark.parametrize("name", PRESETS)
@pytest.mark.parametrize("cycles", ["last", "all"])
def test_acceptance_recovers_e_t_at_the_noise_floor(name, cycles):
    """Base model, E_t = 28 GPa, 0.25 deg / 5 mN noise, 0.05 mm slack: the paper's pipeline."""
    p = load_pattern(PATTERNS / f"{name}.yaml")
    data = synthesize(p, n_samples=2, n_cycles=50, noise_angle_deg=0.25, noise_force_N=0.005, seed=11)
    rows = prepare(data, cycles=cycles)
    start = pattern_values(p) | {"E_t": 12.0}  # start far from the truth
    r = fit(model_for_pattern(p), rows, ("E_t",), start)
    floor = noise_floor_deg(p, 0.25, 0.005)
    assert abs(r.params["E_t"] / 28.0 - 1) < 0.03
    assert abs(r.rmse / floor - 1) < 0.10, (r.rmse, floor)
    assert r.success and r.fitted == ("E_t",) and r.n_params == 1


@pytest.mark.parametrize("e_true", [10.0, 60.0])
def test_recovers_other_moduli(tube2, e_true):
    data = synthesize(tube2, n_cycles=3, modulus_gpa=e_true, slack_mm=0.0, seed=2)
    r = fit(model_for_pattern(tube2), data, ("E_t",), pattern_values(tube2))
    assert abs(r.params["E_t"] / e_true - 1) < 0.01


def test_stderr_matches_the_spread_over_seeds(tube2):
    model = model_for_pattern(tube2)
    est, se = [], []
    for seed in range(12):
        data = synthesize(tube2, n_samples=1, n_cycles=1, noise_force_N=0.02, slack_mm=0.0, seed=seed)
        r = fit(model, data, ("E_t",), pattern_values(tube2))
        est.append(r.params["E_t"])
        se.append(r.stderr["E_t"])
    spread = float(np.std(est, ddof=1))
    assert 0.5 < spread / float(np.mean(se)) < 2.0
    assert abs(np.mean(est) - 28.0) < 4 * spread / math.sqrt(len(est)) + 1e-3


def test_statistics_are_consistent(tube2):
    data = synthesize(tube2, n_cycles=2, slack_mm=0.0, seed=7)
    model = model_for_pattern(tube2)
    r = fit(model, data, ("E_t",), pattern_values(tube2))
    n = len(data)
    res = data.angle_deg - model.predict(data, r.params)
    np.testing.assert_allclose(r.residuals, res)
    np.testing.assert_allclose(r.predict(data), r.predicted)
    np.testing.assert_allclose(r.residuals_for(data), res)
    sse = float(res @ res)
    assert r.rmse == pytest.approx(math.sqrt(sse / n))
    assert r.aic == pytest.approx(n * math.log(sse / n) + 2)
    assert r.bic == pytest.approx(n * math.log(sse / n) + math.log(n))
    per = {s: math.sqrt(np.mean(res[sl] ** 2)) for s, sl in data.sample_slices()}
    assert r.rmse_per_sample == pytest.approx(per)
    assert r.n_points == n and r.correlation.shape == (1, 1)
    # the 1-D Jacobian stderr by hand: s^2 / sum(d residual / d E_t)^2
    h = 1e-4
    d = (model.predict(data, r.params | {"E_t": r.params["E_t"] + h})
         - model.predict(data, r.params | {"E_t": r.params["E_t"] - h})) / (2 * h)
    assert r.stderr["E_t"] == pytest.approx(math.sqrt(sse / (n - 1) / float(d @ d)), rel=1e-3)


def test_degenerate_pair_shows_in_the_correlation(tube2):
    # E_t and L0 enter only as L0 / E_t: the data cannot separate them
    data = synthesize(tube2, n_cycles=2, slack_mm=0.0, seed=1)
    r = fit(model_for_pattern(tube2), data, ("E_t", "L0"), pattern_values(tube2) | {"E_t": 20.0})
    c = r.correlation_of("E_t", "L0")
    assert not np.isfinite(c) or abs(c) > 0.99
    assert r.params["L0"] / r.params["E_t"] == pytest.approx(70.0 / 28.0, rel=0.01)


def _bias_effect() -> Effect:
    return Effect(
        name="test_bias", stage="angle",
        params=(Param("bias_deg", "deg", -10.0, 10.0, 0.0, "sensor zero"),),
        apply=lambda ctx, angle, p: angle + p["bias_deg"],
        meaning="EM tracker zero offset", signature="constant residual",
    )


def test_fits_effect_parameters_by_full_name(tube2):
    data = synthesize(tube2, n_cycles=2, slack_mm=0.0, seed=3)
    data = data.with_angle(data.angle_deg + 1.7)
    model = model_for_pattern(tube2, [_bias_effect()])
    r = fit(model, data, ("E_t", "test_bias.bias_deg"), pattern_values(tube2) | {"E_t": 15.0})
    assert r.params["test_bias.bias_deg"] == pytest.approx(1.7, abs=0.05)
    assert r.params["E_t"] == pytest.approx(28.0, rel=0.01)
    assert r.units["test_bias.bias_deg"] == "deg" and r.stderr["test_bias.bias_deg"] > 0
    base = fit(model_for_pattern(tube2), data, ("E_t",), pattern_values(tube2))
    assert r.aic < base.aic and r.bic < base.bic


def test_bounds_and_at_bound(tube2):
    data = synthesize(tube2, n_cycles=1, slack_mm=0.0, seed=0)
    r = fit(model_for_pattern(tube2), data, ("E_t",), pattern_values(tube2), bounds={"E_t": (5.0, 20.0)})
    assert r.params["E_t"] == pytest.approx(20.0, abs=1e-4)
    assert r.at_bound == ("E_t",)


def test_nothing_to_fit_evaluates_the_model(tube2):
    data = synthesize(tube2, n_cycles=1, slack_mm=0.0, seed=0)
    r = fit(model_for_pattern(tube2), data, (), pattern_values(tube2))
    assert r.n_params == 0 and r.params["E_t"] == 28.0 and r.rmse < 0.4


def test_setup_errors(tube2):
    data = synthesize(tube2, n_cycles=1, seed=0)
    model = model_for_pattern(tube2)
    with pytest.raises(FitError, match="did you mean 'E_t'"):
        fit(model, data, ("E_T",))
    with pytest.raises(FitError, match="no data rows"):
        fit(model, data.take(np.zeros(len(data), bool)))
    with pytest.raises(FitError, match="empty bounds"):
        fit(model, data, bounds={"E_t": (3.0, 3.0)})


def test_generic_over_a_bare_joint_model():
    from camtube.design.geometry import joint_geometry

    g = joint_geometry(0.75, 0.45, 2.83, 0.5)
    model = JointModel(geometry=g, n_notches=10)
    p = load_pattern(PATTERNS / "tube1.yaml")
    data = synthesize(p, n_cycles=2, slack_mm=0.0, modulus_gpa=35.0, seed=9)
    r = fit(model, data)  # L0 defaults to 70 mm like tube1
    assert r.params["E_t"] == pytest.approx(35.0, rel=0.01)


def test_row_mask_fits_only_the_selected_rows(tube2):
    """A held-out fit (``rows``) of a history-free model equals a fit of those rows alone."""
    pattern = tube2
    rows = prepare(synthesize(pattern, n_samples=1, n_cycles=6, seed=3), "all", "loading", True)
    model = model_for_pattern(pattern)
    mask = rows.cycle % 2 == 1
    held = fit(model, rows, ("E_t",), pattern_values(pattern), rows=mask)
    alone = fit(model, rows.take(mask), ("E_t",), pattern_values(pattern))
    assert held.params["E_t"] == pytest.approx(alone.params["E_t"], rel=1e-6)
    assert held.n_points == alone.n_points == int(mask.sum())
    assert held.rmse == pytest.approx(alone.rmse, rel=1e-6)
    assert held.sse == pytest.approx(alone.sse, rel=1e-6)
    assert held.residuals.shape == (len(rows),)  # predictions for the held-out rows too
    other = held.residuals[~mask]
    assert math.sqrt(np.mean(other**2)) < 2 * held.rmse


def test_a_parameter_the_data_do_not_see_leaves_the_others_errors_finite(tube2):
    """A parameter that changes nothing gets an infinite standard error, the others keep theirs (the covariance of
    the directions the data see). Before, 0 x inf in the pseudo-inverse made every error infinite, so one unseen
    copy of a per-sample parameter (a nut's gap that never binds in one sample) condemned the whole fit."""
    unseen = Effect(
        name="test_unseen", stage="angle",
        params=(Param("bias_deg", "deg", -10.0, 10.0, 0.0, "sensor zero"),
                Param("nothing", "", 0.0, 1.0, 0.5, "a parameter the output does not depend on")),
        apply=lambda ctx, angle, p: angle + p["bias_deg"],
        meaning="a zero offset and a parameter that does nothing", signature="constant residual",
    )
    data = synthesize(tube2, n_cycles=2, slack_mm=0.0, seed=3)
    data = data.with_angle(data.angle_deg + 1.7)
    r = fit(model_for_pattern(tube2, [unseen]), data, ("E_t", "test_unseen.bias_deg", "test_unseen.nothing"),
            pattern_values(tube2) | {"E_t": 15.0})
    assert math.isinf(r.stderr["test_unseen.nothing"])
    assert 0.0 < r.stderr["E_t"] < 0.1 and 0.0 < r.stderr["test_unseen.bias_deg"] < 0.1, r.stderr
    ref = fit(model_for_pattern(tube2, [_bias_effect()]), data, ("E_t", "test_bias.bias_deg"),
              pattern_values(tube2) | {"E_t": 15.0})
    assert r.stderr["E_t"] == pytest.approx(ref.stderr["E_t"], rel=1e-3)


def test_the_starts_of_a_large_fit_on_the_cores_give_the_fit_of_one_after_another(tube2, monkeypatch):
    """A fit on many rows runs its starts (a grid over a slack's width) in forked workers: the result is the one of
    the starts run in turn here, to the bit (the same solver runs; the best picked in the starts' order)."""
    from camtube.model.core import fit as fit_module
    from camtube.model.core import parallel

    data = synthesize(tube2, n_samples=2, n_cycles=40, slack_mm=0.12, seed=5)
    model = model_for_pattern(tube2, ["slack"])
    names = ("E_t", "slack.deadband_mm")
    monkeypatch.setattr(fit_module, "PARALLEL_STARTS_MIN_WORK", 1)   # this fit counts as large
    calls = []
    real = parallel.map_forked

    def spy(fn, n):
        calls.append(n)
        return real(fn, n)

    monkeypatch.setattr(fit_module, "map_forked", spy)
    both = fit(model, data, names, pattern_values(tube2) | {"E_t": 12.0}, grid=3, keep=2)
    assert calls and calls[0] == both.starts_tried >= 2          # the starts went to the workers
    monkeypatch.setattr(parallel, "cores", lambda: 1)
    here = fit(model, data, names, pattern_values(tube2) | {"E_t": 12.0}, grid=3, keep=2)
    assert both.params == here.params and both.start == here.start and both.nfev == here.nfev
    np.testing.assert_array_equal(both.residuals, here.residuals)
    np.testing.assert_array_equal(both.covariance, here.covariance)
