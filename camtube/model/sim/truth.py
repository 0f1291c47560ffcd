"""Truth simulator: a time-stepping forward simulation of the joint with hidden effects.

Used to test the diagnosis against physics it does not share code with: this
module never calls :mod:`camtube.model.effects`. Each time step follows the
physical chain

    motor stroke x --play (lost motion in the drive)--> drive u --slack--> tendon pull p = u - slack
    p = arm theta + e_elastic(T) + e_delayed + e_creep          (tendon length balance)
    arm T = K theta + M_f sgn(dtheta/dt)   (stick while |arm T - K theta| <= M_f)   (joint moment balance)

with

* a tendon whose force-elongation law has a toe region: ``T(e) = e^2 / (2 e_t C)``
  for ``e < e_t``, ``(e - e_t / 2) / C`` beyond (``C = L0 / (E_t pi r_t^2)``);
* a Kelvin element in series (viscoelastic tendon, standard linear solid):
  ``tau_v de_d/dt = ratio C T - e_d``, integrated exactly for a constant ``T``
  over the step, implicit in ``T``;
* ratcheting creep of the tendon: ``tau_c de_c/dt = max(C_c T - e_c, 0)``
  (it grows under load and never recovers, so the first cycles differ and
  later ones settle);
* Coulomb friction in the joint (``M_f``, N mm). It makes the *measured*
  force hysteretic, but the length balance with the measured force still
  holds: the base model absorbs it, and a diagnosis must not flag it (a trap
  for false alarms);
* sensor noise (Gaussian, angle and force), an angle bias and a load-cell zero offset.

The tendon tension at the joint is found each step by bisection on the
elastic elongation. Deterministic for a given ``seed``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from camtube.design.geometry import pattern_geometry
from camtube.design.pattern import Pattern
from camtube.model.data.dataset import Dataset
from camtube.model.sim.synth import triangle_stroke


#: Toe-region laws of the truth simulator (see :attr:`Hidden.toe_form`).
TOE_FORMS = ("quadratic", "exponential", "power", "tanh", "fung")


@dataclass(frozen=True)
class Hidden:
    """The physics the base model leaves out (all zero: the base model plus the friction trap).

    Attributes
    ----------
    slack_mm : float
        Motor stroke taken up before the tendon is taut.
    play_mm : float
        Lost motion in the drive (full width).
    toe_mm : float
        Toe-region elongation ``e_t`` of the tendon.
    visco_ratio, visco_tau_s : float
        Delayed compliance over instantaneous compliance, and its retardation time.
    creep_mm_per_N, creep_tau_s : float
        Ratcheting creep compliance ``C_c`` and time constant.
    joint_friction_nmm : float
        Coulomb friction moment ``M_f`` of the joint (absorbed by the model: a trap); on by
        default (0.05 N mm), as in a real joint; 0 turns it off.
    angle_bias_deg, force_zero_N : float
        Sensor offsets.
    toe_form : str
        ``quadratic`` (the library's ``toe`` law); ``exponential``:
        ``T(e) = (e - e_t (1 - exp(-e / e_t))) / C`` (soft at zero force, the same linear asymptote
        shifted by ``e_t``; ``toe_shape`` with modulus 1); ``power``: stiffness rising as
        ``(e / e_t)^2`` up to ``e_t`` (a convex, power-law toe: ``T = e^3 / (3 e_t^2 C)``, then
        ``(e - 2 e_t / 3) / C``); ``tanh``: stiffness ``tanh(e / e_t)``
        (``T = e_t log cosh(e / e_t) / C``, asymptote shifted by ``e_t ln 2``); ``fung``: Fung's
        exponential toe, stiffness ``exp(3 (e / e_t - 1))`` up to ``e_t`` (5 % of the linear stiffness at
        zero force, a sharp knee), then linear. The last three are forms the library does not have.
    cycle_creep_mm, cycle_creep_n : float
        Creep counted in cycles: the tendon has lengthened by
        ``cycle_creep_mm (1 - exp(-(k - 1) / cycle_creep_n))`` during cycle ``k`` (a step at each
        cycle start, not a function of time).
    """

    slack_mm: float = 0.0
    play_mm: float = 0.0
    toe_mm: float = 0.0
    visco_ratio: float = 0.0
    visco_tau_s: float = 1.0
    creep_mm_per_N: float = 0.0
    creep_tau_s: float = 60.0
    joint_friction_nmm: float = 0.05
    angle_bias_deg: float = 0.0
    force_zero_N: float = 0.0
    toe_form: str = "quadratic"
    cycle_creep_mm: float = 0.0
    cycle_creep_n: float = 5.0

    def __post_init__(self):
        if self.toe_form not in TOE_FORMS:
            raise ValueError(f"toe_form must be one of {', '.join(TOE_FORMS)}, not {self.toe_form!r}")


@dataclass(frozen=True, eq=False)
class Simulation:
    """Outcome of :func:`simulate`.

    Attributes
    ----------
    data : Dataset
        The noisy measurement (what a lab would record).
    angle_true_deg, tension_true_N : (n,) float
        Noise-free joint angle and tendon tension.
    sensor_floor_deg : float
        RMSE a perfect model leaves: ``sqrt(sa^2 + (deg(C / arm) sF)^2)``.
    params : dict
        Values used: ``E_t``, ``L0``, ``arm``, ``K`` per sample, the hidden effects.
    """

    data: Dataset
    angle_true_deg: np.ndarray
    tension_true_N: np.ndarray
    sensor_floor_deg: float
    params: dict = field(default_factory=dict)


def _tension(e: float, c: float, et: float, exponential: bool = False, form: str | None = None) -> float:
    """Tendon tension (N) at elastic elongation ``e`` (mm): toe region (``form``, see :data:`TOE_FORMS`;
    ``exponential=True`` is ``form="exponential"``) then linear."""
    if e <= 0.0:
        return 0.0
    form = form or ("exponential" if exponential else "quadratic")
    if form == "exponential" and et > 0.0:
        return (e + et * math.expm1(-e / et)) / c
    if form == "power" and et > 0.0:
        return (e**3 / (3.0 * et * et) if e < et else e - 2.0 * et / 3.0) / c
    if form == "fung" and et > 0.0:
        if e < et:
            return et / 3.0 * (math.exp(3.0 * (e / et - 1.0)) - math.exp(-3.0)) / c
        return (et / 3.0 * -math.expm1(-3.0) + e - et) / c
    if form == "tanh" and et > 0.0:
        x = e / et
        return et * (x + math.log1p(math.exp(-2.0 * x)) - math.log(2.0)) / c
    if et > 0.0 and e < et:
        return e * e / (2.0 * et * c)
    return (e - 0.5 * et) / c


def _run(x: np.ndarray, t: np.ndarray, arm: float, k: float, c: float, h: Hidden,
         cycle: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """One sample's angle (rad) and tension (N) for the motor stroke ``x`` (n,) at times ``t`` (n,)."""
    n = x.size
    form = h.toe_form
    if cycle is not None and h.cycle_creep_mm != 0.0:
        cyc_loss = h.cycle_creep_mm * -np.expm1(-(np.asarray(cycle, float) - 1.0) / h.cycle_creep_n)
    else:
        cyc_loss = np.zeros(n)
    theta_out = np.zeros(n)
    t_out = np.zeros(n)
    w, mf, et = h.play_mm, h.joint_friction_nmm, h.toe_mm
    u = float(x[0]) - w
    theta = 0.0
    e_d = 0.0
    e_c = 0.0
    tension = 0.0
    t_prev = float(t[0])
    for i in range(n):
        xi = float(x[i])
        dt = max(float(t[i]) - t_prev, 0.0)
        t_prev = float(t[i])
        # creep: explicit, from the previous tension (slow)
        if h.creep_mm_per_N > 0.0:
            e_c += dt / h.creep_tau_s * max(h.creep_mm_per_N * tension - e_c, 0.0)
        # play in the drive
        if xi - u > w:
            u = xi - w
        elif xi < u:
            u = xi
        p = u - h.slack_mm - float(cyc_loss[i])
        a_v = math.exp(-dt / h.visco_tau_s) if h.visco_ratio > 0.0 else 1.0
        rc = h.visco_ratio * c

        def delayed(tn: float) -> float:
            return a_v * e_d + (1.0 - a_v) * rc * tn

        def solve(theta_of) -> float:
            """Elastic elongation e with p - e - e_d(T(e)) - e_c - arm theta(T(e)) = 0 (decreasing in e)."""
            lo, hi = 0.0, max(p - e_c, 0.0) + 1e-12
            if p - e_c - delayed(0.0) - arm * theta_of(0.0) <= 0.0:
                return 0.0
            for _ in range(48):
                mid = 0.5 * (lo + hi)
                tn = _tension(mid, c, et, form=form)
                if p - mid - delayed(tn) - e_c - arm * theta_of(tn) > 0.0:
                    lo = mid
                else:
                    hi = mid
            return 0.5 * (lo + hi)

        if mf > 0.0:
            # stick: the joint keeps its angle while the tension stays inside the friction band
            e_s = solve(lambda tn: theta)
            t_s = _tension(e_s, c, et, form=form)
            stuck = abs(arm * t_s - k * theta) <= mf
            if stuck:
                e_el = e_s
            else:
                sgn = 1.0 if arm * t_s > k * theta else -1.0
                e_el = solve(lambda tn: max((arm * tn - sgn * mf) / k, 0.0))
        else:
            e_el = solve(lambda tn: arm * tn / k)
        tension = _tension(e_el, c, et, form=form)
        if mf > 0.0:
            if e_el <= 0.0:
                # slack tendon: the joint springs back until friction holds it
                theta = min(theta, mf / k)
            elif not stuck:
                theta = max((arm * tension - sgn * mf) / k, 0.0)
        else:
            theta = arm * tension / k
        e_d = delayed(tension)
        theta_out[i] = theta
        t_out[i] = tension
    return theta_out, t_out


def simulate(
    pattern: Pattern,
    hidden: Hidden | Sequence[Hidden] = Hidden(),
    *,
    n_samples: int = 2,
    n_cycles: int = 10,
    noise_angle_deg: float = 0.25,
    noise_force_N: float = 0.005,
    seed: int = 0,
    modulus_gpa: float | None = None,
    max_stroke_mm: float | None = None,
    speed_mm_s: float = 0.5,
    rate_hz: float = 10.0,
    dwell_s: float = 0.0,
    stiffness_nmm_per_rad: float | None = None,
    stiffness_spread: float = 0.1,
    stroke_shape: str = "triangle",
) -> Simulation:
    """Simulate a measurement of ``pattern`` with the ``hidden`` physics.

    Parameters
    ----------
    pattern : Pattern
        Geometry (first notch's arm), tendon (E_t, L0, r_t), ``rules.max_stroke``.
    hidden : Hidden or sequence of Hidden
        One for every sample, or one per sample (samples that carry different effects).
    n_samples, n_cycles : int
    noise_angle_deg, noise_force_N : float
        Standard deviations of the sensor noise.
    seed : int
    modulus_gpa : float, optional
        True E_t (default: the pattern's).
    max_stroke_mm : float, optional
        Peak stroke (default ``rules.max_stroke``).
    speed_mm_s, rate_hz, dwell_s : float
        Stroke speed, sampling rate, pause at zero stroke per cycle.
    stiffness_nmm_per_rad : float, optional
        Joint bending stiffness K (default: E_pi I / (n h) with E_pi = 2.5 GPa).
    stiffness_spread : float
        Relative spread of K between samples.
    stroke_shape : str
        ``triangle`` (ramps at ``speed_mm_s``) or ``sine`` (a raised cosine 0 -> max -> 0 over the same
        time: slow near the turning points, fastest mid-stroke, as a crank or a smoothed motion profile).

    Returns
    -------
    Simulation
    """
    from camtube.model.core.predict import joint_stiffness_nmm_per_rad, pattern_compliance_mm_per_N

    rng = np.random.default_rng(seed)
    g = pattern_geometry(pattern).first
    arm = g.moment_arm_mm
    e_t = pattern.tendon.modulus_gpa if modulus_gpa is None else float(modulus_gpa)
    c = pattern_compliance_mm_per_N(pattern, e_t)
    k0 = joint_stiffness_nmm_per_rad(pattern) if stiffness_nmm_per_rad is None else stiffness_nmm_per_rad
    smax = pattern.rules.max_stroke_mm if max_stroke_mm is None else max_stroke_mm
    time, stroke, cycle = triangle_stroke(smax, speed_mm_s, rate_hz, n_cycles, dwell_s)
    if stroke_shape == "sine":
        ramp_s = smax / speed_mm_s
        phase = np.minimum((time % (2.0 * ramp_s + dwell_s)) / (2.0 * ramp_s), 1.0)
        stroke = 0.5 * smax * (1.0 - np.cos(2.0 * np.pi * phase))
    elif stroke_shape != "triangle":
        raise ValueError(f"stroke_shape must be 'triangle' or 'sine', not {stroke_shape!r}")
    m = stroke.size
    parts: dict[str, list] = {k: [] for k in ("sample", "angle", "force", "true", "tension")}
    ks = []
    per = [hidden] * n_samples if isinstance(hidden, Hidden) else list(hidden)
    if len(per) != n_samples:
        raise ValueError(f"{len(per)} Hidden values for {n_samples} samples")
    for i in range(n_samples):
        k = k0 * (1.0 + stiffness_spread * rng.uniform(-1.0, 1.0))
        ks.append(k)
        hidden_i = per[i]
        theta, tension = _run(stroke, time, arm, k, c, hidden_i, cycle)
        ang = np.degrees(theta)
        parts["sample"].append(np.full(m, str(i + 1), dtype=object))
        parts["true"].append(ang)
        parts["tension"].append(tension)
        parts["angle"].append(ang + hidden_i.angle_bias_deg + rng.normal(0.0, noise_angle_deg, m))
        parts["force"].append(tension + hidden_i.force_zero_N + rng.normal(0.0, noise_force_N, m))
    cat = {k: np.concatenate(v) for k, v in parts.items()}
    data = Dataset(cat["sample"], np.tile(cycle, n_samples).astype(int), np.tile(time, n_samples),
                   np.tile(stroke, n_samples), cat["force"], cat["angle"])
    floor = math.hypot(noise_angle_deg, math.degrees(c / arm) * noise_force_N)
    params = {"E_t": e_t, "L0": pattern.tendon.length_mm, "arm_mm": arm, "K_nmm_per_rad": ks,
              **({f: getattr(hidden, f) for f in hidden.__dataclass_fields__} if isinstance(hidden, Hidden)
                 else {"per_sample": [dict(vars(h)) for h in per]})}
    return Simulation(data, cat["true"], cat["tension"], floor, params)
