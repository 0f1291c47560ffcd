"""The shaped toe law (`toe_shape`): checked against independent calculations, and a diagnosis on toe
regions whose form the library does not have (logistic and piecewise-cubic stiffening)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.model.core.registry import builtin_registry
from camtube.model.core.predict import joint_stiffness_nmm_per_rad, model_for_pattern, pattern_values
from camtube.model.data.dataset import Dataset
from camtube.model.diagnose import diagnose
from camtube.model.effects.builtin import local_force_N, weibull_toe_force
from camtube.model.sim import truth
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def tube2():
    return load_pattern(PATTERNS / "tube2.yaml")


def _const_force_data(forces, stroke_mm=5.0, rows=5):
    """One sample per force value, each ``rows`` rows of constant force (the force average keeps it)."""
    n = len(forces) * rows
    smp = np.repeat([f"s{i}" for i in range(len(forces))], rows).astype(object)
    t = np.tile(np.arange(rows, dtype=float), len(forces))
    f = np.repeat(np.asarray(forces, float), rows)
    return Dataset(smp, np.ones(n, int), t, np.full(n, stroke_mm), f, np.zeros(n))


@pytest.mark.parametrize("shape", [0.6, 1.0, 2.0, 4.5])
def test_law_matches_quadrature_and_root_finding(tube2, shape):
    """Force from elongation by numerical quadrature of the Weibull recruitment, inverted by brentq."""
    from scipy.integrate import quad
    from scipy.optimize import brentq
    from scipy.special import gamma

    offset = 0.25
    forces = [0.002, 0.05, 0.3, 1.0, 2.5, 6.0]
    data = _const_force_data(forces)
    m = model_for_pattern(tube2, ["toe_shape"])
    vals = m.initial_values(data, pattern_values(tube2)) | {"toe_shape.offset_mm": offset,
                                                            "toe_shape.shape": shape}
    c = m.compliance_mm_per_N(vals)
    arm = m.geometry.moment_arm_mm
    elong = 5.0 - np.radians(m.predict(data, vals)) * arm  # model elongation (mm) per row
    lam = offset / gamma(1.0 + 1.0 / shape)

    def tension(e):  # N: stiffness fraction 1 - exp(-(u/lam)^k) integrated from 0 to e, over C
        return quad(lambda u: -math.expm1(-(u / lam) ** shape), 0.0, e, epsabs=1e-13, epsrel=1e-11)[0] / c

    want = [brentq(lambda e: tension(e) - f, 0.0, c * f + 20 * offset + 1.0, xtol=1e-12) for f in forces]
    np.testing.assert_allclose(elong[::5], want, rtol=2e-4, atol=2e-6)
    # the linear part is shifted by the offset: at high force elongation = C F + offset
    assert elong[-1] - c * forces[-1] == pytest.approx(offset, rel=0.02 if shape < 1 else 1e-3)
    # the normalised force function itself, against quadrature
    x = np.array([1e-3, 0.1, 1.0, 3.0])
    ref = [quad(lambda u: -math.expm1(-u**shape), 0.0, xi, epsabs=1e-14)[0] for xi in x]
    np.testing.assert_allclose(weibull_toe_force(x, shape), ref, rtol=1e-6, atol=1e-15)


def test_shape_one_is_the_truth_simulators_exponential_toe(tube2):
    """Weibull modulus 1 is the exponential toe T(e) = (e - e_t (1 - exp(-e/e_t))) / C of the truth simulator."""
    from scipy.optimize import brentq

    forces = [0.01, 0.2, 0.8, 3.0]
    data = _const_force_data(forces)
    m = model_for_pattern(tube2, ["toe_shape"])
    vals = m.initial_values(data, pattern_values(tube2)) | {"toe_shape.offset_mm": 0.3, "toe_shape.shape": 1.0}
    c = m.compliance_mm_per_N(vals)
    elong = 5.0 - np.radians(m.predict(data, vals)) * m.geometry.moment_arm_mm
    want = [brentq(lambda e: truth._tension(e, c, 0.3, exponential=True) - f, 1e-12, 10.0, xtol=1e-13)
            for f in forces]
    np.testing.assert_allclose(elong[::5], want, rtol=1e-4, atol=1e-6)



@pytest.mark.parametrize("shape,share", [(0.7, 0.3), (1.5, 0.6), (3.0, 0.9)])
def test_soft_toe_law_matches_quadrature(tube2, shape, share):
    """toe_soft: stiffness fraction share + (1 - share)(1 - exp(-(u/lam)^k)), integrated by quadrature and inverted
    by brentq; it starts at the share's stiffness (finite) and its linear part is shifted by the offset."""
    from scipy.integrate import quad
    from scipy.optimize import brentq
    from scipy.special import gamma

    offset = 0.2
    forces = [0.002, 0.05, 0.3, 1.0, 2.5, 8.0]
    data = _const_force_data(forces)
    m = model_for_pattern(tube2, ["toe_soft"])
    vals = m.initial_values(data, pattern_values(tube2)) | {"toe_soft.offset_mm": offset, "toe_soft.shape": shape,
                                                            "toe_soft.share": share}
    c = m.compliance_mm_per_N(vals)
    elong = 5.0 - np.radians(m.predict(data, vals)) * m.geometry.moment_arm_mm
    lam = offset / ((1.0 - share) * gamma(1.0 + 1.0 / shape))

    def tension(e):
        crimped = quad(lambda u: -math.expm1(-(u / lam) ** shape), 0.0, e, epsabs=1e-13, epsrel=1e-11)[0]
        return (share * e + (1.0 - share) * crimped) / c

    want = [brentq(lambda e: tension(e) - f, 0.0, c * f / share + 1.0, xtol=1e-12) for f in forces]
    np.testing.assert_allclose(elong[::5], want, rtol=5e-4, atol=2e-6)
    # finite stiffness at zero force: never softer than the straight share alone, softer than the whole tendon
    assert c * forces[0] < elong[0] <= c * forces[0] / share * (1.0 + 5e-4)
    assert elong[-1] - c * forces[-1] == pytest.approx(offset, rel=0.02)

def test_force_average_keeps_a_ramp_and_lowers_the_noise():
    rng = np.random.default_rng(3)
    n = 400
    t = np.arange(n) * 0.1
    ramp = 0.01 * np.arange(n)
    cyc = 1 + np.arange(n) // 100  # four 10 s cycles: a window of 0.5 s = 5 rows
    data = Dataset(np.array(["a"] * n, dtype=object), cyc, t, ramp.copy(), ramp + rng.normal(0, 0.005, n),
                   np.zeros(n))
    clean = Dataset(data.sample, cyc, t, ramp.copy(), ramp, np.zeros(n))
    m = model_for_pattern(load_pattern(PATTERNS / "tube2.yaml"))
    ctx = m.context(clean, {})
    ctx.force_N = np.asarray(clean.force_N, float)
    np.testing.assert_allclose(local_force_N(ctx)[5:-5], ramp[5:-5], atol=1e-12)  # a linear trend is kept
    ctx = m.context(data, {})
    ctx.force_N = np.asarray(data.force_N, float)
    err_avg = np.std(local_force_N(ctx)[5:-5] - ramp[5:-5])
    err_raw = np.std(data.force_N[5:-5] - ramp[5:-5])
    assert err_avg < 0.55 * err_raw  # 5 rows: noise / sqrt(5)


# ----------------------------------------------------------------------------- an independent generator

def _logistic_tension(e, c, e0, w):
    """N: stiffness fraction rising as a logistic in e (from 0 at e = 0 to 1), integrated; compliance c."""
    s0 = 1.0 / (1.0 + math.exp(e0 / w))
    softplus = lambda z: np.logaddexp(0.0, z)  # noqa: E731
    integral = w * (softplus((e - e0) / w) - softplus(-e0 / w)) - e * s0
    return integral / (1.0 - s0) / c


def _cubic_tension(e, c, et):
    """N: stiffness fraction 3u^2 - 2u^3 (u = e / et, a piecewise-cubic stiffening), then 1."""
    u = np.minimum(e / et, 1.0)
    inside = et * (u**3 - 0.5 * u**4)
    return (inside + np.maximum(e - et, 0.0)) / c


def _generate(pattern, law, seed, n_cycles=10, rate_hz=10.0, peak_N=3.0, sa=0.25, sf=0.005):
    """Independent toy measurement: a tension path, a linear joint, a toe law; stroke = arm theta + e(T)."""
    m = model_for_pattern(pattern)
    vals = pattern_values(pattern)
    c = m.compliance_mm_per_N(vals | {"E_t": vals.get("E_t", 28.0)})
    arm = m.geometry.moment_arm_mm
    k = joint_stiffness_nmm_per_rad(pattern)
    rng = np.random.default_rng(seed)
    per = int(10 * rate_hz)  # 10 s per cycle: 1 s at zero, 4.5 s up, 4.5 s down
    phase = np.arange(per) / per
    tri = np.clip(np.where(phase < 0.55, (phase - 0.1) / 0.45, (1.0 - phase) / 0.45), 0.0, 1.0)
    e_grid = np.linspace(0.0, 5.0, 200001)
    t_grid = law(e_grid, c)
    cols = {k_: [] for k_ in ("s", "cyc", "t", "x", "f", "a")}
    for smp in ("1", "2"):
        tension = np.tile(tri, n_cycles) * peak_N
        e = np.interp(tension, t_grid, e_grid)
        theta = arm * tension / (k * (1.0 + 0.05 * (smp == "2")))
        n = tension.size
        cols["s"].append(np.full(n, smp, dtype=object))
        cols["cyc"].append(1 + np.arange(n) // per)
        cols["t"].append(np.arange(n) / rate_hz)
        cols["x"].append(arm * theta + e)
        cols["f"].append(tension + rng.normal(0, sf, n))
        cols["a"].append(np.degrees(theta) + rng.normal(0, sa, n))
    cat = {k_: np.concatenate(v) for k_, v in cols.items()}
    data = Dataset(cat["s"], cat["cyc"], cat["t"], cat["x"], cat["f"], cat["a"])
    return data, math.hypot(sa, math.degrees(c / arm) * sf)


def _exp_compliance_tension(e, c, d, f0):
    """N: a tendon whose elongation is c T + d (1 - exp(-T / f0)): extra compliance d / f0 at zero force, fading
    (finite stiffness at zero force), inverted on a grid of tensions."""
    t = np.concatenate([[0.0], np.geomspace(1e-7, 50.0, 20001)])
    return np.interp(e, c * t + d * -np.expm1(-t / f0), t)


def _fung_tension(e, c, b):
    """N: Fung's exponential law T = (exp(b e) - 1) / (b C0), its stiffness exp(b e) / C0 finite at zero force and
    capped at 1 / C (then linear), C0 = 3 C."""
    c0 = 3.0 * c
    e_cap = math.log(c0 / c) / b
    t_cap = (math.exp(b * e_cap) - 1.0) / (b * c0)
    return np.where(e < e_cap, np.expm1(b * np.minimum(e, e_cap)) / (b * c0), t_cap + (e - e_cap) / c)


@pytest.mark.parametrize("form", ["exponential compliance", "fung"])
def test_diagnosis_on_toes_stiff_at_zero_force(tube2, form):
    """Toes that start at a finite stiffness (no toe_shape: its stiffness starts at zero): a toe of the family is
    recommended, alone, and reaches the floor."""
    law = {"exponential compliance": lambda e, c: _exp_compliance_tension(e, c, 0.08, 0.7),
           "fung": lambda e, c: _fung_tension(e, c, 12.0)}[form]
    data, floor = _generate(tube2, law, seed=23)
    d = diagnose(model_for_pattern(tube2), data, ("E_t",), pattern_values(tube2))
    toes = {e.name for e in builtin_registry().effects if e.family == "toe"}
    assert len(d.recommended) == 1 and d.recommended[0] in toes, (d.recommended, d.stop_reason)
    assert d.final.rmse_deg <= 1.15 * floor, (d.final.rmse_deg, floor)

@pytest.mark.parametrize("form", ["logistic", "cubic"])
def test_diagnosis_on_a_toe_form_the_library_does_not_have(tube2, form):
    law = {"logistic": lambda e, c: _logistic_tension(e, c, 0.15, 0.05),
           "cubic": lambda e, c: _cubic_tension(e, c, 0.35)}[form]
    data, floor = _generate(tube2, law, seed=11)
    d = diagnose(model_for_pattern(tube2), data, ("E_t",), pattern_values(tube2))
    first = d.candidates[0]
    toes = {e.name for e in builtin_registry().effects if e.family == "toe"}   # toe, toe_shape, toe_soft
    assert toes & ({first.effect} | set(first.equivalent)), [c.effect for c in d.candidates[:4]]
    # one effect was hidden: one is recommended (no spurious offset on top), and it reaches the floor
    assert len(d.recommended) == 1 and d.recommended[0] in toes, (d.recommended, d.stop_reason)
    assert d.final.rmse_deg < 0.5 * d.waterfall[0].rmse_deg
    assert d.final.rmse_deg <= 1.15 * floor, (d.final.rmse_deg, floor)
    for name, se in d.final.stderr.items():
        assert math.isfinite(se) and se > 0, name


def test_near_zero_force_the_law_is_averaged_over_the_tensions_posterior(tube2):
    """Rows with a force near zero: the model's toe elongation is the mean of the law over a normal of the
    force noise's size truncated at zero (checked by trapezoidal integration of the noise-free law)."""
    from scipy.stats import norm

    from camtube.model.effects.builtin import local_force_sd_N

    rng = np.random.default_rng(5)
    n = 3000
    f = rng.normal(0.0, 0.005, n) + np.repeat([0.0, 0.01, 0.05], n // 3)
    # one cycle per row: the force window is one row (no average), only the posterior mean acts
    data = Dataset(np.array(["a"] * n, dtype=object), np.arange(1, n + 1), np.arange(n) * 0.1, np.full(n, 5.0), f,
                   np.zeros(n))
    sd = local_force_sd_N(data)
    assert sd[0] == pytest.approx(0.005, rel=0.1)  # the white noise of the force, from its differences
    m = model_for_pattern(tube2, ["toe_shape"])
    vals = m.initial_values(data, pattern_values(tube2)) | {"toe_shape.offset_mm": 0.3, "toe_shape.shape": 1.0}
    c = m.compliance_mm_per_N(vals)
    arm = m.geometry.moment_arm_mm
    extra = 5.0 - np.radians(m.predict(data, vals)) * arm - c * f  # toe elongation (mm) per row
    # the noise-free law on a fine force grid (no noise: one sample per force, constant rows)
    grid = np.concatenate([[0.0], np.geomspace(1e-7, 0.2, 1500)])
    law_data = _const_force_data(grid, rows=5)
    law = (5.0 - np.radians(m.predict(law_data, vals)) * arm)[::5] - c * grid
    checked = 0
    for i in range(0, n, 97):
        mu, s = f[i], sd[i]
        if mu >= 4 * s:
            assert extra[i] == pytest.approx(np.interp(mu, grid, law), rel=1e-3)  # the law at the force itself
            continue
        checked += 1
        w = norm.pdf(grid, mu, s)
        want = np.trapezoid(law * w, grid) / np.trapezoid(w, grid)
        assert extra[i] == pytest.approx(want, rel=0.03), (i, mu)
    assert checked > 10


def test_the_compiled_rows_give_the_numpy_expressions_numbers_to_the_bit():
    # speed: toe_rows replaced about ten NumPy passes over the rows; the numbers must be those passes', bit for bit
    # (a fit's path depends on them), at every row: low forces, zero forces, the largest force, a table's last cell
    from camtube.model.effects.builtin import TOE_GRID, _toe_table
    from camtube.model.effects.kernels import toe_rows

    rng = np.random.default_rng(11)
    q = np.arange(TOE_GRID + 1) / TOE_GRID
    for trial in range(40):
        n = int(rng.integers(1, 20_000))
        f = np.maximum(rng.normal(0.3, 1.0, n), 0.0) * rng.uniform(0.01, 5.0)
        f[rng.integers(0, n, size=max(n // 10, 1))] = 0.0
        c, shape, lam = rng.uniform(1e-3, 0.3), rng.uniform(0.5, 10.0), rng.uniform(1e-3, 3.0)
        tau = c * f / lam
        t_max = float(tau.max(initial=0.0))
        if t_max <= 0.0:
            continue
        assert c * float(f.max()) / lam == t_max   # what the law computes instead of tau.max()
        xg, tg = _toe_table(shape, t_max + 2.0)
        xj = np.interp(t_max * q**2, tg, xg)
        pos = np.sqrt(tau * (1.0 / t_max)) * TOE_GRID
        i = np.minimum(pos.astype(np.intp), TOE_GRID - 1)
        lo = xj.take(i)
        want = lam * (lo + (pos - i) * (xj.take(i + 1) - lo) - tau)
        got = toe_rows(f, c, lam, t_max, xj)
        assert np.array_equal(got.view(np.int64), want.view(np.int64)), trial


def test_toe_law_on_a_load_cell_read_in_coarse_steps(tube2):
    """A load cell logged in 0.1 N steps, its noise 2 mN and its zero 0.06 N low: most rows repeat the last reading,
    and the rests read -0.1 N. The toe law's posterior near zero force takes the steps' own error as the noise left
    (it read none: a division by zero, a warning on the user's terminal)."""
    import warnings

    from camtube.model.sim.synth import synthesize

    data = synthesize(tube2, n_samples=1, n_cycles=5, noise_force_N=0.002, seed=4)
    read = data.with_force(np.round((data.force_N - 0.06) / 0.1) * 0.1)
    m = model_for_pattern(tube2, ["toe_shape"])
    vals = m.initial_values(read, pattern_values(tube2)) | {"toe_shape.offset_mm": 0.2, "toe_shape.shape": 1.5}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        out = m.predict(read, vals)
    assert np.all(np.isfinite(out))
