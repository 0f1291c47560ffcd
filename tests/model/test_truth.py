"""The truth simulator obeys its physics: base case equals the closed form, each hidden effect shows its signature."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design.geometry import pattern_geometry
from camtube.design.loader import load_pattern
from camtube.model.core.predict import joint_stiffness_nmm_per_rad, stroke_only_angle_rad
from camtube.model.sim.truth import Hidden, simulate
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def tube2():
    return load_pattern(PATTERNS / "tube2.yaml")


def _c(p):
    return p.tendon.length_mm / (p.tendon.modulus_gpa * 1e3 * p.tendon.area_mm2)


def test_no_hidden_effect_is_the_closed_form(tube2):
    k = joint_stiffness_nmm_per_rad(tube2)
    s = simulate(tube2, Hidden(joint_friction_nmm=0.0), n_samples=1, n_cycles=2, stiffness_nmm_per_rad=k, stiffness_spread=0.0)
    arm = pattern_geometry(tube2).first.moment_arm_mm
    ref = np.degrees(stroke_only_angle_rad(s.data.stroke_mm, arm, k, _c(tube2)))
    np.testing.assert_allclose(s.angle_true_deg, ref, atol=1e-6)
    # the length balance holds with the true tension
    th = np.radians(s.angle_true_deg)
    np.testing.assert_allclose(s.data.stroke_mm, arm * th + _c(tube2) * s.tension_true_N, atol=1e-8)


def test_slack_and_play_signatures(tube2):
    arm = pattern_geometry(tube2).first.moment_arm_mm
    sl = simulate(tube2, Hidden(slack_mm=0.2, joint_friction_nmm=0.0), n_samples=1, n_cycles=2, noise_angle_deg=0, noise_force_N=0)
    x = sl.data.stroke_mm
    assert np.all(sl.angle_true_deg[x <= 0.2] == 0.0) and np.all(sl.angle_true_deg[x > 0.25] > 0)
    np.testing.assert_allclose(x[x > 0.2] - 0.2, arm * np.radians(sl.angle_true_deg[x > 0.2])
                               + _c(tube2) * sl.tension_true_N[x > 0.2], atol=1e-8)
    pl = simulate(tube2, Hidden(play_mm=0.1, joint_friction_nmm=0.0), n_samples=1, n_cycles=2, noise_angle_deg=0, noise_force_N=0)
    d = pl.data.direction
    pull = x - arm * np.radians(pl.angle_true_deg) - _c(tube2) * pl.tension_true_N  # lost stroke
    moving = (pl.angle_true_deg > 1.0)
    np.testing.assert_allclose(pull[moving & (d > 0)], 0.1, atol=1e-8)
    assert np.all(pull[moving & (d < 0)] < 0.1 - 1e-6)


def test_friction_trap_is_hysteretic_in_force_but_keeps_the_length_balance(tube2):
    s = simulate(tube2, Hidden(joint_friction_nmm=0.2), n_samples=1, n_cycles=2, noise_angle_deg=0, noise_force_N=0)
    arm = pattern_geometry(tube2).first.moment_arm_mm
    th = np.radians(s.angle_true_deg)
    x = s.data.stroke_mm
    d = s.data.direction
    mid = np.abs(x - 1.25) < 0.05
    assert s.tension_true_N[mid & (d > 0)].mean() - s.tension_true_N[mid & (d < 0)].mean() > 0.05
    taut = s.tension_true_N > 0
    np.testing.assert_allclose(x[taut], arm * th[taut] + _c(tube2) * s.tension_true_N[taut], atol=1e-8)


def test_viscoelastic_and_creep(tube2):
    v = simulate(tube2, Hidden(visco_ratio=0.5, visco_tau_s=2.0, joint_friction_nmm=0.0), n_samples=1, n_cycles=3,
                 noise_angle_deg=0, noise_force_N=0)
    arm = pattern_geometry(tube2).first.moment_arm_mm
    lost = v.data.stroke_mm - arm * np.radians(v.angle_true_deg) - _c(tube2) * v.tension_true_N
    d = v.data.direction
    x = v.data.stroke_mm
    mid = np.abs(x - 1.25) < 0.05
    assert lost[mid & (d < 0)].mean() > lost[mid & (d > 0)].mean() > 0  # delayed elongation lags the force
    assert np.all(lost <= 0.5 * _c(tube2) * v.tension_true_N.max() + 1e-9)
    c = simulate(tube2, Hidden(creep_mm_per_N=0.05, creep_tau_s=20.0, joint_friction_nmm=0.0), n_samples=1, n_cycles=6,
                 noise_angle_deg=0, noise_force_N=0)
    peak = [c.angle_true_deg[c.data.cycle == k].max() for k in range(1, 7)]
    assert all(b < a for a, b in zip(peak, peak[1:]))  # later cycles bend less
    assert peak[-2] - peak[-1] < peak[0] - peak[1]  # and settle


def test_noise_and_determinism(tube2):
    a = simulate(tube2, Hidden(), seed=4)
    b = simulate(tube2, Hidden(), seed=4)
    np.testing.assert_array_equal(a.data.angle_deg, b.data.angle_deg)
    r = a.data.angle_deg - a.angle_true_deg
    assert abs(np.std(r) / 0.25 - 1) < 0.1
    assert a.sensor_floor_deg == pytest.approx(math.hypot(0.25, math.degrees(
        _c(tube2) / pattern_geometry(tube2).first.moment_arm_mm) * 0.005))


def test_harder_forms_exponential_toe_cycle_creep_per_sample_effects_and_friction_on_by_default(tube2):
    assert Hidden().joint_friction_nmm > 0  # the distractor is on unless turned off
    quiet = dict(n_samples=1, noise_angle_deg=0, noise_force_N=0, stiffness_spread=0.0)
    base = simulate(tube2, Hidden(joint_friction_nmm=0.0), n_cycles=2, **quiet)
    quad = simulate(tube2, Hidden(toe_mm=0.3, joint_friction_nmm=0.0), n_cycles=2, **quiet)
    expo = simulate(tube2, Hidden(toe_mm=0.3, toe_form="exponential", joint_friction_nmm=0.0), n_cycles=2, **quiet)
    top = int(np.argmax(base.angle_true_deg))
    # both toes stretch the tendon more: less angle; the exponential law has its own shape (not the quadratic one)
    assert expo.angle_true_deg[top] < base.angle_true_deg[top]
    assert np.max(np.abs(expo.angle_true_deg - quad.angle_true_deg)) > 0.2
    # creep counted in cycles: each cycle's peak angle falls by the stated law (no time dependence within a cycle)
    cc = simulate(tube2, Hidden(cycle_creep_mm=0.1, cycle_creep_n=2.0, joint_friction_nmm=0.0), n_cycles=4, **quiet)
    b4 = simulate(tube2, Hidden(joint_friction_nmm=0.0), n_cycles=4, **quiet)
    cyc = np.asarray(cc.data.cycle)
    loss = [b4.angle_true_deg[cyc == k].max() - cc.angle_true_deg[cyc == k].max() for k in (1, 2, 3, 4)]
    assert loss[0] == pytest.approx(0.0, abs=1e-6)
    ratio = [(1 - np.exp(-(k - 1) / 2.0)) for k in (2, 3, 4)]
    assert np.allclose(np.array(loss[1:]) / loss[3], np.array(ratio) / ratio[2], rtol=0.02)
    # samples with different effects
    two = simulate(tube2, [Hidden(play_mm=0.1, joint_friction_nmm=0.0), Hidden(joint_friction_nmm=0.0)],
                   n_samples=2, n_cycles=2, noise_angle_deg=0, noise_force_N=0, stiffness_spread=0.0)
    s1 = two.data.sample == "1"
    assert np.max(np.abs(two.angle_true_deg[~s1] - base.angle_true_deg)) < 1e-9
    assert np.max(np.abs(two.angle_true_deg[s1] - base.angle_true_deg)) > 0.5


def test_sine_stroke_and_dwell(tube2):
    # a raised cosine over the triangle's ramp time, then the pause at zero stroke; the friction holds the
    # joint bent during the pause once it has been loaded (the unloaded tendon goes slack)
    smax, speed, rate, dwell = 2.5, 0.5, 10.0, 2.0
    sim = simulate(tube2, Hidden(), n_samples=1, n_cycles=3, stroke_shape="sine", dwell_s=dwell, rate_hz=rate,
                   speed_mm_s=speed, noise_angle_deg=0.0, noise_force_N=0.0)
    t, x = np.asarray(sim.data.time_s), np.asarray(sim.data.stroke_mm)
    period = 2 * smax / speed + dwell
    ph = (t % period) / (2 * smax / speed)
    moving = ph < 1.0
    np.testing.assert_allclose(x[moving], 0.5 * smax * (1 - np.cos(2 * np.pi * ph[moving])), atol=1e-12)
    assert np.all(x[~moving] == 0.0) and x.max() == pytest.approx(smax)
    paused = ~moving & (np.asarray(sim.data.cycle) > 1)
    k = sim.params["K_nmm_per_rad"][0]
    assert np.allclose(sim.angle_true_deg[paused], math.degrees(0.05 / k), rtol=0.05)
    with pytest.raises(ValueError, match="stroke_shape"):
        simulate(tube2, Hidden(), n_cycles=1, stroke_shape="square")
