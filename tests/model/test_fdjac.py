"""The grouped forward-difference Jacobian (camtube.model.core.fdjac) equals scipy's 2-point Jacobian to the bit,
on a real model with per-sample parameters and history effects, so a fit with it gives the very same result."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.optimize import least_squares
from scipy.optimize._numdiff import approx_derivative

from camtube.design.loader import load_pattern
from camtube.model.core.fdjac import GroupedJacobian, forward_steps, sample_groups
from camtube.model.core.fit import _residual_and_jacobian, fit
from camtube.model.core.predict import model_for_pattern, pattern_values
from camtube.model.core.registry import builtin_registry
from camtube.model.sim.bench import Clock, Protocol, SampleBench, Tendon, Tracker, simulate_bench
from tests.conftest import PATTERNS

EFFECTS = ["viscoelastic", "creep", "toe_shape", "slack"]
PER_SAMPLE = ["viscoelastic", "creep.creep_mm", "toe_shape", "slack"]


@pytest.fixture(scope="module")
def problem():
    """Three samples of tube 2 (a creeping tendon with a toe), the model with history effects fitted per
    sample (shared E_t and creep time constant), a residual on every other row, and a point inside the
    bounds ``x``."""
    p = load_pattern(PATTERNS / "tube2.yaml")
    trk = Tracker(noise_deg=0.15, n_spikes=0, n_dropouts=0)
    tendon = Tendon(creep_A_mm_per_s=4e-4, creep_n=2.0, creep_sat_mm=0.1, crimp_mm=0.2, crimp_shape=2.0)
    prot = Protocol(n_cycles=4, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=1.0)
    rec = simulate_bench(p, tuple(SampleBench(tendon=tendon, tracker=trk) for _ in range(3)), prot,
                         Clock(rate_hz=25.0), seed=3)
    data = rec.data
    model = model_for_pattern(p).with_effects(EFFECTS, builtin_registry())
    names = ["E_t"] + [n for e in model.effects for n in e.full_names()]
    params = model.make_params(data, names, pattern_values(p), per_sample=PER_SAMPLE)
    names = params.varying
    values = dict(params.values)
    sel = np.arange(len(data)) % 2 == 0
    measured = np.asarray(data.angle_deg, float)
    lo = np.array([params[n].lo for n in names])
    hi = np.array([params[n].hi for n in names])
    # near the initial values (each copy its own value): every effect acts, none takes the whole stroke
    rng = np.random.default_rng(0)
    x = np.array([values[n] for n in names]) * rng.uniform(0.8, 1.2, len(names))
    x = np.clip(x, lo + 1e-3 * (hi - lo), hi - 1e-3 * (hi - lo))

    def residual(xv):
        work = dict(values)
        work.update(zip(names, map(float, xv)))
        return (measured - model.predict(data, work))[sel]

    return SimpleNamespace(model=model, data=data, names=names, values=values, sel=sel, residual=residual,
                           lo=lo, hi=hi, x=x, params=params)


def _unpack(pb):
    return pb.model, pb.data, pb.names, pb.values, pb.sel, pb.residual, pb.lo, pb.hi, pb.x


def _scipy_jac(residual, x, lo, hi):
    return approx_derivative(residual, x, method="2-point", f0=residual(x), bounds=(lo, hi))


def test_groups_are_the_per_sample_copies_of_one_parameter():
    assert sample_groups(["E_t", "a.b@S1", "c.d", "a.b@S2", "a.e@S1"]) == [[0], [1, 3], [2], [4]]


def test_steps_follow_scipys_rule_at_and_near_the_bounds():
    lo = np.array([0.0, 0.0, -1.0, 1.0, -np.inf])
    hi = np.array([1.0, 1e-9, 1.0, 2.0, np.inf])
    for x in (np.array([1.0, 5e-10, -1.0, 2.0 - 1e-12, -3.0]), np.array([0.5, 0.0, 1.0, 1.0, 0.0])):
        h = forward_steps(x, lo, hi)
        f = lambda v: np.array([np.sum(v * np.arange(1, 6)), np.prod(v + 3.0)])  # noqa: E731
        ref = approx_derivative(f, x, method="2-point", bounds=(lo, hi))
        mine = GroupedJacobian(f, lo, hi, [[i] for i in range(5)], {})(x)
        assert np.all((x + h >= lo) & (x + h <= hi))
        assert np.array_equal(mine, ref)


def test_grouped_jacobian_is_scipys_bit_for_bit_with_history_effects(problem):
    model, data, names, values, sel, residual, lo, hi, x = _unpack(problem)
    fun, jac = _residual_and_jacobian(model, data, names, values, sel, residual, lo, hi)
    assert isinstance(jac, GroupedJacobian)
    assert any("viscoelastic" in n and "@" in n for n in names) and any("creep" in n and "@" in n for n in names)
    # near the upper bound too: the step is turned back there
    x_hi = np.where(np.arange(x.size) % 3 == 0, hi - 1e-12 * (hi - lo), x)
    for point in (x, x_hi):
        fun(point)
        ref = _scipy_jac(residual, point, lo, hi)
        if point is x:
            assert (ref != 0).any(axis=0).all()  # every parameter moves the residual here
        got = jac(point)
        assert got.shape == ref.shape and got.flags.f_contiguous == ref.flags.f_contiguous
        assert np.array_equal(got, ref)
        assert np.array_equal(np.signbit(got), np.signbit(ref))
    groups = sample_groups(names)
    assert jac.evaluations == 2 * len(groups) < 2 * len(names)


def test_jacobian_without_a_remembered_residual_evaluates_it(problem):
    model, data, names, values, sel, residual, lo, hi, x = _unpack(problem)
    _, jac = _residual_and_jacobian(model, data, names, values, sel, residual, lo, hi)
    assert np.array_equal(jac(x), _scipy_jac(residual, x, lo, hi))


def test_a_copy_moves_only_its_own_samples_rows(problem):
    """The claim the grouping rests on, checked directly on the history effects' per-sample copies."""
    model, data, names, values, sel, residual, lo, hi, x = _unpack(problem)
    f0 = residual(x)
    samples = np.asarray(data.sample)[sel]
    seen = set()
    for i, nm in enumerate(names):
        if "@" not in nm:
            continue
        x1 = x.copy()
        x1[i] += 0.05 * (hi[i] - lo[i])
        moved = residual(x1) != f0
        assert set(samples[moved]) <= {nm.partition("@")[2]}, nm
        if moved.any():
            seen.add(nm.split(".")[0])
    assert {"viscoelastic", "creep", "toe_shape"} <= seen


def test_least_squares_takes_the_same_path(problem):
    model, data, names, values, sel, residual, lo, hi, x = _unpack(problem)
    fun, jac = _residual_and_jacobian(model, data, names, values, sel, residual, lo, hi)
    opts = dict(bounds=(lo, hi), x_scale=np.abs(x), method="trf", max_nfev=15, xtol=1e-8, ftol=1e-8, gtol=1e-8)
    ref = least_squares(residual, x, **opts)
    got = least_squares(fun, x, jac=jac, **opts)
    assert np.array_equal(got.x, ref.x) and got.cost == ref.cost and got.nfev == ref.nfev
    assert np.array_equal(got.jac, ref.jac)


def test_fit_is_unchanged_by_the_grouping(problem, monkeypatch):
    model, data, names, values, sel, residual, lo, hi, x = _unpack(problem)
    params = problem.params.with_values(dict(zip(names, map(float, x))))
    new = fit(model, data, params=params, rows=sel, max_nfev=12, tol=1e-8)
    import camtube.model.core.fit as fit_module

    monkeypatch.setattr(fit_module, "_residual_and_jacobian", lambda *a: (a[5], "2-point"))
    old = fit(model, data, params=params, rows=sel, max_nfev=12, tol=1e-8)
    assert new.params == old.params and new.nfev == old.nfev
    assert np.array_equal(new.residuals, old.residuals) and np.array_equal(new.covariance, old.covariance,
                                                                             equal_nan=True)

