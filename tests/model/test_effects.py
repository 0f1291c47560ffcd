"""Built-in effects: registered, documented, and each one checked against an independent calculation."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design.geometry import joint_geometry
from camtube.design.loader import load_pattern
from camtube.model.api import STAGES, get_effect, registry
from camtube.model.data.dataset import Dataset
from camtube.model.effects import BUILTINS, _flat_wall_ybar, first_order_lag, play_operator
from camtube.model.core.predict import model_for_pattern, pattern_values
from tests.conftest import PATTERNS


def _data(stroke, time=None, force=None, samples=None):
    n = len(stroke)
    return Dataset(np.array(samples if samples is not None else ["a"] * n, dtype=object), np.ones(n, int),
                   np.arange(n, dtype=float) if time is None else np.asarray(time, float),
                   np.asarray(stroke, float), np.zeros(n) if force is None else np.asarray(force, float),
                   np.zeros(n))


@pytest.fixture(scope="module")
def tube1():
    return load_pattern(PATTERNS / "tube1.yaml")


def test_every_builtin_is_registered_and_documented():
    reg = registry()
    need = {"slack", "play", "friction", "toe", "creep", "viscoelastic", "series", "kerf", "flat_walls",
            "chords", "hardstop", "angle_bias", "force_zero"}
    assert need <= set(reg) and need <= set(BUILTINS)
    for name in BUILTINS:
        e = reg[name]
        assert e.stage in STAGES and e.meaning and e.signature
        for p in e.params:
            assert p.unit is not None and p.lo < p.hi and p.doc
    assert {get_effect(n).stage for n in BUILTINS} == set(STAGES)  # all five stages used


def test_play_operator_matches_a_plain_loop():
    rng = np.random.default_rng(1)
    # random walk with pauses, two samples
    x = np.concatenate([np.cumsum(rng.choice([-1, 0, 1], 400) * rng.uniform(0, 0.05, 400)) for _ in range(2)])
    data = _data(x, samples=["a"] * 400 + ["b"] * 400)
    for w in (0.0, 0.03, 0.2):
        y = play_operator(data, x, w)
        ref = np.empty_like(x)
        d = data.direction
        for _, sl in data.sample_slices():
            prev = x[sl][0] - (w if d[sl][0] > 0 else 0.0)
            for k in range(sl.start, sl.stop):
                prev = min(max(prev, x[k] - w), x[k])
                ref[k] = prev
        np.testing.assert_allclose(y, ref, atol=1e-12)


def test_first_order_lag_matches_the_ode_solution():
    t = np.linspace(0, 10, 2001)
    u = np.where(t > 1.0, 1.0, 0.0)
    v = first_order_lag(_data(np.zeros_like(t), time=t), u, 2.0)
    k = t > 1.0
    exact = 1.0 - np.exp(-(t[k] - t[k][0]) / 2.0)
    np.testing.assert_allclose(v[k], exact, atol=3e-3)
    # non-uniform sampling takes the loop and agrees
    tn = np.sort(np.concatenate([t, [0.0013, 3.3337]]))
    vn = first_order_lag(_data(np.zeros_like(tn), time=tn), np.where(tn > 1.0, 1.0, 0.0), 2.0)
    assert abs(np.interp(5.0, tn, vn) - np.interp(5.0, t, v)) < 3e-3


def test_stroke_effects(tube1):
    s = np.concatenate([np.linspace(0, 2, 50), np.linspace(2, 0, 50)[1:]])
    data = _data(s)
    vals = pattern_values(tube1)
    arm = model_for_pattern(tube1).geometry.moment_arm_mm
    base = model_for_pattern(tube1).predict(data, vals)
    sl = model_for_pattern(tube1, ["slack"]).predict(data, vals | {"slack.deadband_mm": 0.3})
    np.testing.assert_allclose(sl, np.degrees(np.maximum(s - 0.3, 0) / arm), atol=1e-12)
    pl = model_for_pattern(tube1, ["play"]).predict(data, vals | {"play.play_mm": 0.2})
    up, down = slice(5, 49), slice(60, 95)
    np.testing.assert_allclose(base[up] - pl[up], math.degrees(0.2 / arm), atol=1e-9)  # loading lags by w
    np.testing.assert_allclose(base[down], pl[down], atol=1e-9)  # unloading: caught up
    assert np.all(pl[49:54] == pl[49]) and pl[54] < pl[49]  # after the reversal it stays put for w
    cr = model_for_pattern(tube1, ["creep"]).predict(data, vals | {"creep.creep_mm": 0.1, "creep.tau_s": 1e-6})
    np.testing.assert_allclose(cr[1:], np.degrees(np.maximum(s[1:] - 0.1, 0) / arm), atol=1e-9)


def test_series_compliance_is_a_softer_tendon(tube1):
    rng = np.random.default_rng(0)
    data = _data(rng.uniform(0, 2, 50), force=rng.uniform(0, 3, 50))
    vals = pattern_values(tube1)
    c = vals["L0"] / (vals["E_t"] * 1e3 * tube1.tendon.area_mm2)
    ser = model_for_pattern(tube1, ["series"]).predict(data, vals | {"series.compliance_mm_per_N": 0.2})
    e_soft = vals["L0"] / ((c + 0.2) * 1e3 * tube1.tendon.area_mm2)
    np.testing.assert_allclose(ser, model_for_pattern(tube1).predict(data, vals | {"E_t": e_soft}), atol=1e-9)


def test_toe_law_is_quadratic_then_linear(tube1):
    f = np.linspace(0, 4, 81)
    data = _data(np.full_like(f, 5.0), force=f)
    vals = pattern_values(tube1)
    c = vals["L0"] / (vals["E_t"] * 1e3 * tube1.tendon.area_mm2)
    arm = model_for_pattern(tube1).geometry.moment_arm_mm
    th = np.radians(model_for_pattern(tube1, ["toe"]).predict(data, vals | {"toe.toe_mm": 0.3}))
    elong = 5.0 - th * arm
    # force from elongation: e^2/(2 e_t C) in the toe, (e - e_t/2)/C beyond
    back = np.where(elong < 0.3, elong**2 / (2 * 0.3 * c), (elong - 0.15) / c)
    np.testing.assert_allclose(back, f, atol=1e-9)


def test_flat_wall_centroid_by_numerical_integration():
    ro, ri, s = 0.75, 0.45, 2.83
    d = ro * math.cos(s / (2 * ro))
    r = np.linspace(ri, ro, 801)[:, None]
    a = np.linspace(-math.pi, math.pi, 3201)[None, :]
    y = r * np.cos(a)
    keep = y < d
    wgt = r * keep
    ybar_num = -float((y * wgt).sum() / wgt.sum())
    assert abs(_flat_wall_ybar(ro, ri, s) - ybar_num) < 2e-3
    # a flat wall removes more of the inner wall than a radial one: a different arm
    assert abs(_flat_wall_ybar(ro, ri, s) - joint_geometry(ro, ri, s, 0.5).ybar_mm) > 0.01


def test_chords_shorten_less_than_the_arc(tube1):
    model = model_for_pattern(tube1, ["chords"])
    g = model.geometry
    th_n = np.radians(np.array([1.0, 5.0, 10.0]))  # per notch
    n = model.n_notches
    dl = g.moment_arm_mm * th_n + (g.notch_width_mm / th_n - g.moment_arm_mm) * (th_n - 2 * np.sin(th_n / 2))
    data = _data(n * dl)
    got = np.radians(model.predict(data, pattern_values(tube1)))
    np.testing.assert_allclose(got, n * th_n, rtol=1e-9)


def test_offsets_and_hardstop(tube1):
    data = _data(np.linspace(0, 2, 20), force=np.linspace(0, 3, 20))
    vals = pattern_values(tube1)
    base = model_for_pattern(tube1).predict(data, vals)
    b = model_for_pattern(tube1, ["angle_bias"]).predict(data, vals | {"angle_bias.bias_deg": 1.5})
    np.testing.assert_allclose(b - base, 1.5)
    z = model_for_pattern(tube1, ["force_zero"]).predict(data, vals | {"force_zero.zero_N": 0.2})
    assert np.ptp(z - base) < 1e-9 and (z - base)[0] > 0  # a constant: same family as angle_bias
    assert get_effect("angle_bias").family == get_effect("force_zero").family
    h = model_for_pattern(tube1, ["hardstop"]).predict(data, vals | {"hardstop.stop_deg": 5.0})
    assert h.max() == pytest.approx(5.0) and np.all(h <= base + 1e-12)


def test_rest_angle_holds_the_joint_bent_once_loaded_and_not_before(tube1):
    # two samples, each: rest at zero stroke, a pull, release to zero stroke, a second pull
    up = np.linspace(0, 1.0, 11)
    one = np.r_[np.zeros(3), up, up[::-1], up]
    data = _data(np.r_[one, one], samples=["S1"] * one.size + ["S2"] * one.size)
    vals = pattern_values(tube1)
    base = model_for_pattern(tube1).predict(data, vals)
    got = model_for_pattern(tube1, ["rest_angle"]).predict(data, vals | {"rest_angle.rest_deg": 2.0})
    for sl in (slice(0, one.size), slice(one.size, 2 * one.size)):
        b, g = base[sl], got[sl]
        first = int(np.flatnonzero(b > 2.0)[0])
        # before the first load the joint is straight, as the base model says
        np.testing.assert_allclose(g[:first], b[:first])
        # afterwards it never comes below the rest angle, and above it the base model is unchanged
        np.testing.assert_allclose(g[first:], np.maximum(b[first:], 2.0))
        assert g[-len(up) - 1] == pytest.approx(2.0) and b[-len(up) - 1] == pytest.approx(0.0)
    # its place in the chain: the rest is the joint's, the sensor's offset comes on top of it
    both = model_for_pattern(tube1, ["angle_bias", "rest_angle"]).predict(
        data, vals | {"rest_angle.rest_deg": 2.0, "angle_bias.bias_deg": -0.5})
    np.testing.assert_allclose(both, got - 0.5)


def _lag_by_rows(u, dt, tau_s):
    """The lag row by row in Python: the reference of the compiled recursion."""
    ref = np.empty_like(u)
    ref[0] = prev = u[0]
    for k, step in enumerate(dt):
        a = math.exp(-max(step, 0.0) / tau_s)
        prev = a * prev + (1.0 - a) * u[k + 1]
        ref[k + 1] = prev
    return ref


@pytest.mark.parametrize("tau_s", [1e-3, 0.03, 1.0, 50.0, 1e5])
def test_first_order_lag_on_jittered_stamps_equals_the_recursion(tau_s):
    """The lag on jittered stamps (a repeated stamp, a gap of many time constants) equals the row-by-row recursion,
    per sample; the kept steps (what depends on the stamps and tau alone) give the same numbers, to the bit."""
    rng = np.random.default_rng(7)
    dt = 0.02 + rng.normal(0.0, 0.002, 4999)
    dt[100] = 0.0  # a repeated stamp
    dt[3000] = 40.0 * tau_s  # a long gap
    u = np.sin(np.cumsum(np.r_[0.0, dt])) + rng.normal(0.0, 0.1, 5000)
    t = np.cumsum(np.r_[0.0, dt])
    data = _data(np.zeros(t.size), time=t)
    steps = np.diff(t)
    first = first_order_lag(data, u, tau_s)
    np.testing.assert_allclose(first, _lag_by_rows(u, steps, tau_s), rtol=1e-12, atol=1e-13)
    np.testing.assert_array_equal(first_order_lag(data, u, tau_s), first)
    np.testing.assert_allclose(first_order_lag(data, 2.0 * u, tau_s), _lag_by_rows(2.0 * u, steps, tau_s),
                               rtol=1e-12, atol=1e-13)
    assert len(data.cache.get("history.lag_steps")) == 1
    # two samples: each starts at its own first value, nothing carries over
    two = _data(np.zeros(2 * t.size), time=np.r_[t, t], samples=np.repeat(["a", "b"], t.size))
    both = first_order_lag(two, np.r_[u, -u], tau_s)
    np.testing.assert_array_equal(both[:t.size], first)
    np.testing.assert_allclose(both[t.size:], -first, rtol=1e-12, atol=1e-13)
    bad = u.copy()
    bad[2500] = np.inf   # a non-finite input spreads from its row on, never before it
    with np.errstate(invalid="ignore"):
        got = first_order_lag(_data(np.zeros(t.size), time=t), bad, tau_s)
    np.testing.assert_array_equal(got[:2500], first[:2500])
    assert not np.isfinite(got[2500])


def test_capstan_gives_the_mean_tension_of_a_tendon_wrapping_a_guide(tube1):
    """A guide between the load cell and the joint: the joint side carries the cell's tension times
    exp(-mu_wrap) while the tendon is pulled, exp(+mu_wrap) while it is released, and keeps the last state
    through a dwell. The tendon stretches by its mean tension (half of it on either side of the guide)."""
    t = np.arange(0.0, 30.0, 0.05)
    stroke = np.interp(t, [0, 10, 15, 25, 30], [0.0, 2.0, 2.0, 0.0, 0.0])   # pull, dwell, release, rest
    tj = 1.5 * stroke                                                      # joint-side tension, N
    pulling = t <= 15.0                                                    # the last motion's direction
    mu = 0.3
    cell = tj * np.exp(np.where(pulling, mu, -mu))
    data = _data(stroke, time=t, force=cell)
    vals = pattern_values(tube1)
    model = model_for_pattern(tube1, ["capstan"])
    got = model.predict(data, vals | {"capstan.mu_wrap": mu, "capstan.slip_mm_s": 1e-5, "capstan.hold": 1.0})
    c = model.compliance_mm_per_N(vals)
    arm = model.geometry.moment_arm_mm
    want = np.degrees((stroke - c * 0.5 * (tj + cell)) / arm)
    np.testing.assert_allclose(got[1:], want[1:], atol=1e-9)
    # a guide that releases while the drive rests: the dwell and the rest see the cell's tension
    free = model.predict(data, vals | {"capstan.mu_wrap": mu, "capstan.slip_mm_s": 1e-5, "capstan.hold": 0.0})
    still = np.r_[False, np.diff(stroke) == 0]
    np.testing.assert_allclose(free[still], np.degrees((stroke - c * cell) / arm)[still], atol=1e-9)
    np.testing.assert_allclose(free[~still][1:], want[~still][1:], atol=1e-9)
    # off: the paper's model
    np.testing.assert_allclose(model.predict(data, vals | {"capstan.mu_wrap": 0.0, "capstan.slip_mm_s": 1.0,
                                                           "capstan.hold": 0.5}),
                               model_for_pattern(tube1).predict(data, vals), atol=1e-12)


def _pull_dwell_rest(pattern, seconds: float, dt: float):
    """``(t, data, values, paper model's angle)`` of 20 s cycles: pull 5 s, dwell 5 s, release 5 s, rest 5 s."""
    t = np.arange(0.0, seconds, dt)
    stroke = np.interp(t % 20.0, [0, 5, 10, 15, 20], [0.0, 2.0, 2.0, 0.0, 0.0])
    data = _data(stroke, time=t)
    vals = pattern_values(pattern)
    return t, data, vals, model_for_pattern(pattern).predict(data, vals)


def test_relaxation_follows_a_joint_with_a_relaxing_backbone(tube1):
    """A backbone of a spring k and a Maxwell arm (k1, tau), stepped in time by hand: while the tendon is taut the
    joint follows it; once the tendon goes slack the joint stands at k1 / (k + k1) of the arm's relaxed angle and
    creeps back. The effect's two-pass lag stays within 2 % of that free angle's scale."""
    dt = 0.01
    t, data, vals, kin = _pull_dwell_rest(tube1, 60.0, dt)
    model = model_for_pattern(tube1, ["relaxation"])
    for c, tau_s, tol in ((0.1, 3.0, 0.005), (0.3, 2.0, 0.02)):
        got = model.predict(data, vals | {"relaxation.fraction": c, "relaxation.tau_s": tau_s})
        relaxed, ref = 0.0, np.empty(t.size)
        for k in range(t.size):
            ref[k] = max(kin[k], c * relaxed)
            a = math.exp(-dt / tau_s)
            relaxed = a * relaxed + (1.0 - a) * ref[k]
        assert np.abs(got - ref).max() < tol * c * kin.max()
        rest = (t % 20.0) > 15.5
        assert np.all(got[rest] > 0.5 * c * kin.max() * np.exp(-5.0 / tau_s))   # it rests bent, not straight
    # on top of a rest angle earlier in the chain: the slack joint stands above it
    both = model_for_pattern(tube1, ["rest_angle", "relaxation"])
    v = vals | {"rest_angle.rest_deg": 2.0, "relaxation.fraction": 0.1, "relaxation.tau_s": 3.0}
    got = both.predict(data, v)
    only = model_for_pattern(tube1, ["rest_angle"]).predict(data, v)
    late = t > 20.0
    assert np.all(got[late] >= only[late] - 1e-12) and np.all(got[late & ((t % 20.0) > 15.5)] > 2.0 + 1e-3)
    # off: the paper's model
    np.testing.assert_allclose(model.predict(data, vals | {"relaxation.fraction": 0.0, "relaxation.tau_s": 1.0}),
                               kin, atol=1e-12)


def test_relaxation2_follows_a_backbone_with_a_fast_and_a_slow_arm(tube1):
    """A backbone of a spring and two Maxwell arms (a fast and a slow one), stepped in time by hand: unloaded, the
    joint stands at the arms' shares of their relaxed angles and creeps back, quickly and then over cycles. The
    effect's two-pass lags stay within 2 % of that free angle's scale; one arm alone is `relaxation` to the bit."""
    dt = 0.01
    t, data, vals, kin = _pull_dwell_rest(tube1, 80.0, dt)
    model = model_for_pattern(tube1, ["relaxation2"])
    for c1, tau1, c2, ratio in ((0.1, 1.5, 0.1, 20.0), (0.2, 2.0, 0.15, 10.0)):
        got = model.predict(data, vals | {"relaxation2.fraction": c1, "relaxation2.tau_s": tau1,
                                          "relaxation2.slow_fraction": c2, "relaxation2.slow_ratio": ratio})
        r1 = r2 = 0.0
        ref = np.empty(t.size)
        for k in range(t.size):
            ref[k] = max(kin[k], c1 * r1 + c2 * r2)
            a1, a2 = math.exp(-dt / tau1), math.exp(-dt / (tau1 * ratio))
            r1 = a1 * r1 + (1.0 - a1) * ref[k]
            r2 = a2 * r2 + (1.0 - a2) * ref[k]
        assert np.abs(got - ref).max() < 0.02 * (c1 + c2) * kin.max()
        # the slow arm holds the rest up long after the fast one has let go: more than one arm can
        late_rest = (t % 20.0) > 19.0
        one = model_for_pattern(tube1, ["relaxation"]).predict(data, vals | {"relaxation.fraction": c1,
                                                                             "relaxation.tau_s": tau1})
        assert np.all(got[late_rest & (t > 20.0)] > one[late_rest & (t > 20.0)] + 0.2 * c2 * kin.max() * 0.5)
    # the slow arm off: relaxation, to the bit
    v = {"relaxation2.fraction": 0.3, "relaxation2.tau_s": 2.0, "relaxation2.slow_fraction": 0.0,
         "relaxation2.slow_ratio": 10.0}
    np.testing.assert_array_equal(model.predict(data, vals | v),
                                  model_for_pattern(tube1, ["relaxation"]).predict(
                                      data, vals | {"relaxation.fraction": 0.3, "relaxation.tau_s": 2.0}))
    # both off: the paper's model
    np.testing.assert_allclose(model.predict(data, vals | v | {"relaxation2.fraction": 0.0}), kin, atol=1e-12)


def test_a_thinned_record_keeps_the_speed_of_the_full_one():
    """Steps between kept rows average over the dropped ones; the thinned copy carries the full record's speed."""
    from camtube.model.diagnose.search import thin

    t = np.arange(0.0, 40.0, 0.01)
    stroke = np.clip(np.sin(t), 0.0, None)          # pulls, releases, rests at zero
    data = _data(stroke, time=t, samples=["a"] * 2000 + ["b"] * 2000)
    full = data.stroke_speed_mm_s
    moving = np.r_[True, np.diff(stroke) != 0]
    np.testing.assert_allclose(full[1:2000][moving[1:2000]], (np.diff(stroke[:2000]) / 0.01)[moving[1:2000]])
    rest = np.flatnonzero(~moving[:2000])
    assert rest.size > 100 and np.all(full[rest] == 0.0)
    small = thin(data, 400)
    assert len(small) < len(data)
    idx = np.searchsorted(t[:2000], small.time_s[small.sample == "a"])
    np.testing.assert_array_equal(small.stroke_speed_mm_s[small.sample == "a"], full[idx])


def test_every_builtin_says_where_it_sits_on_the_bench():
    """The answer names the side of the bench (drive, tendon, joint, instruments) of each recommended effect."""
    from camtube.model.report.diagnosis import SIDES

    assert set(BUILTINS) <= set(SIDES)




class NoCacheFolder:
    """A numba cache locator that finds no folder (a read-only install without a writable home)."""

    @classmethod
    def from_function(cls, py_func, source_path):
        return None


def test_the_compiled_laws_work_where_numba_can_write_no_cache():
    """Where numba finds no folder to cache its machine code in, the laws compile in each process instead (numba
    raises "no locator available" for a cached function there)."""
    import os
    import subprocess
    import sys

    code = ("import numpy as np\n"
            "from camtube.model.effects import kernels\n"
            "print(kernels.lag_rows(np.array([1.0, 3.0]), np.array([0.5]), np.array([0.5])).tolist())\n")
    from tests.conftest import ROOT

    env = {**os.environ, "NUMBA_CACHE_LOCATOR_CLASSES": "tests.model.test_effects.NoCacheFolder",
           "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=str(ROOT))
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "[1.0, 2.0]"


def _relaxed_numpy(data, theta, arms):
    """The relaxing backbone's law as NumPy passes: :func:`camtube.model.effects.builtin._relaxed` with its compiled
    path switched off."""
    from unittest import mock

    from camtube.model.effects import builtin

    with mock.patch.object(builtin, "relaxed_compiled", lambda *a: None):
        return builtin._relaxed(_ctx(data), theta, arms)


def _ctx(data):
    """The context a kinematics-stage law reads its rows from."""
    return type("Ctx", (), {"data": data})()


@pytest.mark.parametrize("arms", [((0.3, 2.0),), ((0.25, 0.7), (0.2, 40.0)), ((0.6, 1e-2),)])
def test_the_compiled_relaxation_gives_the_numpy_laws_numbers_to_the_bit(arms):
    """The compiled relaxing backbone (kernels.relaxed_rows) against its NumPy law, on jittered stamps of two samples:
    a joint bent and unloaded (a rest floor), one whose angle starts below zero (no floor), one arm and two."""
    from camtube.model.effects.builtin import _relaxed
    from camtube.model.effects.history import relaxed_compiled

    rng = np.random.default_rng(3)
    n = 3000
    t = np.concatenate([np.cumsum(rng.uniform(0.015, 0.025, n)), np.cumsum(rng.uniform(0.008, 0.012, n))])
    phase = 2 * np.pi * np.arange(n) / 400
    theta = np.concatenate([np.maximum(np.sin(phase), 0.0) * 0.5 + 0.002 * rng.normal(size=n) + 0.01,
                            np.sin(phase) * 0.4 - 0.05])
    data = _data(np.zeros(2 * n), time=t, samples=["S1"] * n + ["S2"] * n)
    fast = relaxed_compiled(data, theta, arms)
    assert fast is not None
    slow = _relaxed_numpy(data, theta, arms)
    assert np.array_equal(fast.view(np.int64), slow.view(np.int64))
    assert np.array_equal(_relaxed(_ctx(data), theta, arms), slow)
    # the law does something here: the unloaded first sample stands above its angle (a slow arm; a 10 ms arm follows)
    if max(tau for _, tau in arms) >= 1.0:
        assert (slow[:n] > theta[:n] + 1e-3).sum() > 100


def test_the_compiled_relaxation_leaves_uniform_stamps_and_non_finite_angles_to_numpy():
    from camtube.model.effects.history import relaxed_compiled

    theta = np.abs(np.sin(np.arange(200) / 20.0))
    assert relaxed_compiled(_data(np.zeros(200)), theta, ((0.3, 2.0),)) is None   # uniform: scipy's lfilter
    jittered = _data(np.zeros(200), time=np.cumsum(np.random.default_rng(1).uniform(0.9, 1.1, 200)))
    assert relaxed_compiled(jittered, theta, ((0.3, 2.0),)) is not None
    bad = theta.copy()
    bad[5] = np.nan
    assert relaxed_compiled(jittered, bad, ((0.3, 2.0),)) is None
