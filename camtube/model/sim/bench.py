"""Bench simulator: the whole test bench, one physical component at a time, stepped in time.

Written for issue 19 as a second, independent source of truth for the diagnosis. It shares no code and
no functional forms with the effect library (:mod:`camtube.model.effects`) or with the truth simulator
(:mod:`camtube.model.sim.truth`); it uses only the pattern's geometry (:mod:`camtube.design.geometry`).

The chain, per time step ``dt`` (the logger's own row times, 25-100 Hz):

* **motor + lead screw** (:class:`Drive`): the motor follows the commanded profile (raised-cosine ramps,
  a dwell at the top, a rest at zero; the first cycle dwells longer). The nut drives a carriage through a
  lug with a gap ``backlash_mm``. The tendon pulls the carriage back onto the nut's pushing flank while the
  tension exceeds the rail's friction; below it, on unloading, the carriage stays where it is while the
  nut retreats (up to the gap), so the joint rests slightly bent and the next pull first takes the gap up:
  lost motion at the bottom of the stroke that the first pull (from a carriage on the flank) does not have.
* **load cell** on the carriage (:class:`LoadCell`): tension at the carriage, plus a zero that can wander
  (a slow thermal ramp plus a random walk), plus white noise.
* **guide** (:class:`Guide`): the tendon wraps a pin; capstan friction ``exp(mu wrap)`` between the load
  cell's side and the joint's side, its sign following the tendon's sliding, regularised over 0.05 mm/s by
  default (``tanh``; ``Guide.slip_mm_s``): it fades as the carriage stops and is gone while it rests.
* **braided tendon** (:class:`Tendon`): a bundle of fibres of equal stiffness with crimp lengths drawn
  from a gamma distribution (the toe: fibres become taut one by one); an optional loose length (slack);
  a power-law, strain-hardening creep ``de/dt = A (T/T1)^n / (1 + e/e_sat)^2`` that never recovers.
* **joint** (:class:`Backbone`): ten notch flexures in series, each a polymer backbone: an elastic spring,
  two Maxwell arms (relaxation) and a permanent set that grows while the moment exceeds a yield moment.
* **EM tracker** (:class:`Tracker`): the sum of the notch angles, delayed by ``lag_ms``, white noise,
  a few interference spikes of several degrees, and short dropouts (``nan``).
* **logger clock** (:class:`Clock`): nominal rate, Gaussian jitter on the stamps, a few repeated stamps.

The tendon tension at each step comes from the tendon's length balance (carriage travel = bend x arm +
elongation of the bundle + slack + creep), solved with :func:`scipy.optimize.brentq`; the joint's state is
updated semi-implicitly (the Maxwell arms exactly for a linear change over the step).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import brentq
from scipy.signal import lfilter

from camtube.design.geometry import pattern_geometry
from camtube.design.pattern import Pattern
from camtube.model.data.dataset import Dataset

#: Polyimide's Young's modulus (GPa) for the backbone stiffness.
BACKBONE_MODULUS_GPA = 2.5


@dataclass(frozen=True)
class Drive:
    """Motor, lead screw and carriage.

    Attributes
    ----------
    backlash_mm : float
        Gap of the nut's lug (lost motion after an unloading to low tension).
    rail_friction_N : float
        Carriage rail friction: below this tension the carriage sticks while the nut retreats.
    settle : bool
        How a held carriage moves once the tension exceeds the rail's friction (at a rest, the backbone's
        recovery raises it). True: it slides toward the nut's flank only until the tension is back at the
        friction (quasi-static: each step moves it by the excess tension times the tendon-and-joint compliance
        there). False, the law of every batch drawn before it: it lands on the flank in one step, where the
        tendon goes nearly slack; at one step per logged row that is hidden in the step's own error, but with a
        fine step (:attr:`Clock.sim_step_ms`) it releases the joint at most rests, a stick-slip no rail shows.
    """

    backlash_mm: float = 0.0
    rail_friction_N: float = 0.05
    settle: bool = False


@dataclass(frozen=True)
class LoadCell:
    """Load cell on the carriage: ``zero(t) = offset_N + drift_N_per_h t / 3600 + random walk``; noise ``noise_N``;
    ``range_N``: the largest reading its amplifier gives (the reading is clipped there: a cell too small for the
    tension); ``inf``: none reached. ``offset_N``: its reading at zero tension from the start (a cell not zeroed
    before the test)."""

    noise_N: float = 0.005
    drift_N_per_h: float = 0.0
    walk_N_per_sqrt_h: float = 0.0
    range_N: float = math.inf
    offset_N: float = 0.0


@dataclass(frozen=True)
class Guide:
    """A pin the tendon wraps: friction coefficient ``mu`` over ``wrap_rad``; its sign follows the tendon's
    sliding, regularised over ``slip_mm_s`` (``tanh``; a value far below the drive's speeds: Coulomb's step)."""

    mu: float = 0.0
    wrap_rad: float = math.pi / 2
    slip_mm_s: float = 0.05


@dataclass(frozen=True)
class Tendon:
    """Braided tendon (UHMWPE): fibre crimp (toe), loose length (slack), creep.

    Attributes
    ----------
    crimp_mm : float
        Mean crimp length of the fibres (gamma-distributed with shape ``crimp_shape``); 0 = linear tendon.
    crimp_shape : float
    slack_mm : float
        Loose length taken up before any fibre carries load.
    creep_A_mm_per_s : float
        Creep rate at tension ``creep_T1_N``; 0 = none.
    creep_n : float
        Power of the tension in the creep rate.
    creep_sat_mm : float
        Strain-hardening length: the rate falls as ``(1 + e/e_sat)^-2``.
    modulus_scale : float
        True modulus over the pattern's.
    """

    crimp_mm: float = 0.0
    crimp_shape: float = 3.0
    slack_mm: float = 0.0
    creep_A_mm_per_s: float = 0.0
    creep_T1_N: float = 1.0
    creep_n: float = 2.0
    creep_sat_mm: float = 0.05
    modulus_scale: float = 1.0


@dataclass(frozen=True)
class Backbone:
    """Polymer backbone of the notches: spring, two relaxation arms, permanent set.

    Attributes
    ----------
    relax : tuple of (fraction, tau_s)
        Maxwell arms: extra stiffness (fraction of the elastic one) relaxing with ``tau_s``.
    yield_fraction : float
        Yield moment as a fraction of the peak moment of the record's first pull (estimated: ``yield_nmm``
        when given); 0 = no set.
    set_rate_per_s : float
        Rate of the set (rad/s per unit relative over-moment).
    stiffness_scale : float
    """

    relax: tuple = ()
    yield_nmm: float = 0.0
    set_rate_per_s: float = 0.0
    stiffness_scale: float = 1.0


@dataclass(frozen=True)
class Tracker:
    """EM tracker: lag, noise, spikes, dropouts, and a zero that drifts (``drift_deg_per_h``: the reading's offset
    grows with the time since the record began, as a tracker's field and sensor warm up).

    ``dropout``: what the tracker writes while it has lost the sensor: ``"nan"`` (a missing value), ``"zero"``
    (0.0), ``"hold"`` (its last reading again). ``n_bursts``: interference lasting ``burst_rows`` rows, each
    row of a burst displaced by the same ``spike_deg``-sized amount. ``filter_ms``: the time constant of a
    first-order filter the tracker's noise passes (correlated from row to row; its standard deviation stays
    ``noise_deg``); 0: white."""

    noise_deg: float = 0.15
    lag_ms: float = 0.0
    drift_deg_per_h: float = 0.0
    n_spikes: int = 8
    spike_deg: tuple = (3.0, 9.0)
    n_dropouts: int = 4
    dropout_rows: tuple = (2, 15)
    dropout: str = "nan"
    n_bursts: int = 0
    burst_rows: tuple = (2, 6)
    filter_ms: float = 0.0


@dataclass(frozen=True)
class Clock:
    """Logger clock: nominal rate, stamp jitter, repeated stamps; and the simulation's own step.

    ``sim_step_ms``: the longest step the bench's mechanics are integrated over (the logged rows are read from
    that finer run). 0: one step per logged row, as every batch drawn before it had. There a carriage that lands
    on the nut's flank (``Drive.settle`` off) sticks at the first row after its tension fell to the rail's
    friction, up to a row's travel past the crossing (0.03 mm at 25 Hz on a 3 s ramp of 2 mm): a random lost
    motion per cycle that comes from the step. A settling carriage slides back to the crossing, and one step per
    row agrees with a 1 ms step to a micrometre (a check; the batches need no finer step)."""

    rate_hz: float = 50.0
    jitter_ms: float = 1.0
    n_repeats: int = 3
    sim_step_ms: float = 0.0


@dataclass(frozen=True)
class SampleBench:
    """The physical parts of one sample's bench (one cut tube on the rig)."""

    drive: Drive = field(default_factory=Drive)
    load_cell: LoadCell = field(default_factory=LoadCell)
    guide: Guide = field(default_factory=Guide)
    tendon: Tendon = field(default_factory=Tendon)
    backbone: Backbone = field(default_factory=Backbone)
    tracker: Tracker = field(default_factory=Tracker)


@dataclass(frozen=True)
class Protocol:
    """The commanded motion: ``n_cycles`` of ramp up, dwell, ramp down, rest (seconds, mm)."""

    n_cycles: int = 50
    peak_mm: float | None = None
    ramp_s: float = 3.0
    dwell_s: float = 2.0
    rest_s: float = 2.0
    first_dwell_s: float = 6.0


@dataclass(frozen=True, eq=False)
class BenchRecord:
    """A simulated bench file.

    Attributes
    ----------
    data : Dataset
        What the logger wrote (``nan`` in the angle where the tracker dropped out).
    angle_true_deg, tension_cell_true_N : (n,) float
        The joint's true bend and the true tension at the load cell (at the true times).
    carriage_true_mm : (n,) float
        Where the carriage truly stood (the drive's lost motion: the motor's stroke is ``data.stroke_mm``).
    spike_rows, dropout_rows, repeat_rows : (k,) int
        Rows of ``data`` carrying a spike, a missing angle (or the zero or held value the tracker wrote in its
        place, :attr:`Tracker.dropout`), a repeated time stamp.
    burst_rows : (k,) int
        Rows of ``data`` in a burst of interference.
    noise_deg : float
        The tracker's white-noise standard deviation (the angle's sensor noise; RMS over the samples).
    floor_deg : float
        RMSE a perfect model leaves: the tracker noise and the force noise through the tendon's compliance
        (RMS over the samples, which have the same number of rows).
    params : dict
    """

    data: Dataset
    angle_true_deg: np.ndarray
    tension_cell_true_N: np.ndarray
    spike_rows: np.ndarray
    dropout_rows: np.ndarray
    repeat_rows: np.ndarray
    noise_deg: float
    floor_deg: float
    params: dict = field(default_factory=dict)
    carriage_true_mm: np.ndarray | None = None
    burst_rows: np.ndarray = field(default_factory=lambda: np.zeros(0, int))


def motor_profile(p: Protocol, peak_mm: float, t_s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Commanded motor stroke (mm) and cycle number at times ``t_s`` (s)."""
    lengths = [2 * p.ramp_s + (p.first_dwell_s if k == 0 else p.dwell_s) + p.rest_s for k in range(p.n_cycles)]
    starts = np.concatenate(([0.0], np.cumsum(lengths)))
    k = np.clip(np.searchsorted(starts, t_s, side="right") - 1, 0, p.n_cycles - 1)
    tau = t_s - starts[k]
    dwell = np.where(k == 0, p.first_dwell_s, p.dwell_s)
    up = np.clip(tau / p.ramp_s, 0.0, 1.0)
    down = np.clip((tau - p.ramp_s - dwell) / p.ramp_s, 0.0, 1.0)
    x = peak_mm * 0.5 * ((1.0 - np.cos(np.pi * up)) - (1.0 - np.cos(np.pi * down)))
    return x, k + 1


def record_length_s(p: Protocol) -> float:
    return p.n_cycles * (2 * p.ramp_s + p.dwell_s + p.rest_s) + (p.first_dwell_s - p.dwell_s)


class _Bundle:
    """Fibre bundle: tension (N) against elongation (mm), tabulated and inverted."""

    def __init__(self, compliance_mm_per_N: float, crimp_mm: float, shape: float, rng: np.random.Generator):
        m = 400
        crimp = rng.gamma(shape, crimp_mm / shape, m) if crimp_mm > 0 else np.zeros(m)
        crimp = np.sort(crimp)
        top = float(crimp[-1]) + 50.0 * compliance_mm_per_N * 10.0 + 1.0
        e = np.concatenate((np.linspace(0.0, max(float(crimp[-1]), 1e-6) * 1.05, 3000), [top]))
        # each fibre carries (e - crimp)+ / (m C)
        t = np.maximum(e[:, None] - crimp[None, :], 0.0).sum(axis=1) / (m * compliance_mm_per_N)
        self.e = e
        self.t = t

    def elongation(self, tension_N: float) -> float:
        return float(np.interp(tension_N, self.t, self.e))


def _stamps(clock: Clock, duration_s: float, rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """True sample times, the logged stamps and the rows whose stamp repeats the previous one."""
    n = int(duration_s * clock.rate_hz)
    t_true = np.arange(n) / clock.rate_hz + rng.normal(0.0, clock.jitter_ms * 1e-3, n)
    t_true = np.maximum.accumulate(np.clip(t_true, 0.0, None))
    logged = np.round(np.arange(n) / clock.rate_hz + rng.normal(0.0, clock.jitter_ms * 1e-3, n), 4)
    logged = np.maximum(logged, 0.0)
    rep = np.sort(rng.choice(np.arange(10, n), clock.n_repeats, replace=False)) if clock.n_repeats else np.zeros(0, int)
    logged[rep] = logged[rep - 1]
    return t_true, logged, rep


def _fine_grid(t: np.ndarray, step_s: float) -> tuple[np.ndarray, np.ndarray]:
    """Times holding every one of ``t`` (sorted, (n,)) with at most ``step_s`` between neighbours, and the
    index of each of ``t`` in them."""
    gaps = np.diff(t)
    parts = np.maximum(np.ceil(gaps / step_s - 1e-9).astype(np.int64), 1)
    at = np.concatenate(([0], np.cumsum(parts)))
    fine = np.empty(int(at[-1]) + 1)
    fine[at] = t
    for k in np.flatnonzero(parts > 1):
        fine[at[k] + 1:at[k + 1]] = t[k] + gaps[k] * np.arange(1, parts[k]) / parts[k]
    return fine, at


def _run_sample(pattern: Pattern, b: SampleBench, t: np.ndarray, motor: np.ndarray,
                rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """True bend (rad) of the joint, tension at the load cell (N) and the carriage's position (mm) at times ``t``
    (n,)."""
    geo = pattern_geometry(pattern)
    arm = geo.first.moment_arm_mm
    e_pa = BACKBONE_MODULUS_GPA * 1e3 * b.backbone.stiffness_scale
    k_notch = np.array([e_pa * g.second_moment_mm4 / g.notch_width_mm for g in geo.notches])
    k_notch = k_notch * (1.0 + 0.03 * rng.standard_normal(k_notch.size))
    area = math.pi * pattern.tendon.radius_mm ** 2
    comp = pattern.tendon.length_mm / (pattern.tendon.modulus_gpa * 1e3 * b.tendon.modulus_scale * area)
    bundle = _Bundle(comp, b.tendon.crimp_mm, b.tendon.crimp_shape, rng)
    relax = np.array(b.backbone.relax, float).reshape(-1, 2)
    frac, tau = relax[:, 0], relax[:, 1]
    n = t.size
    theta_n = np.zeros(k_notch.size)          # notch bends (rad)
    q = np.zeros((frac.size, k_notch.size))   # Maxwell arm moments (N mm)
    set_n = np.zeros(k_notch.size)            # permanent set per notch (rad)
    e_creep = 0.0
    tension = 0.0
    cell = 0.0
    v_prev = 0.0
    slide = 0.0
    carriage_prev = 0.0
    compliance_prev = 0.0
    out_theta = np.zeros(n)
    out_cell = np.zeros(n)
    out_carriage = np.zeros(n)
    ewrap = math.exp(b.guide.mu * b.guide.wrap_rad)
    td = b.tendon
    for i in range(n):
        dt = float(t[i] - t[i - 1]) if i else 0.0
        m_i = float(motor[i])
        # drive: the tension pulls the carriage onto the nut's pushing flank (carriage = nut); below the rail's
        # friction the carriage sticks and the gap of the lug (0 .. backlash) opens or closes
        if cell > b.drive.rail_friction_N and not (b.drive.settle and carriage_prev > m_i and dt > 0):
            carriage = m_i
        elif cell > b.drive.rail_friction_N:
            # pulled off the rail's hold: it slides toward the flank by what brings the tension back to the
            # friction (the last step's compliance, mm of carriage per N at the cell), never past the flank
            carriage = max(m_i, min(carriage_prev, m_i + b.drive.backlash_mm)
                           - (cell - b.drive.rail_friction_N) * compliance_prev)
        else:
            carriage = min(max(carriage_prev, m_i), m_i + b.drive.backlash_mm)
        v = (carriage - carriage_prev) / dt if dt > 0 else v_prev
        # creep of the tendon (explicit, from the last tension)
        if td.creep_A_mm_per_s > 0.0 and tension > 0.0:
            e_creep += dt * td.creep_A_mm_per_s * (tension / td.creep_T1_N) ** td.creep_n / (1.0 + e_creep / td.creep_sat_mm) ** 2
        # joint: each notch theta = alpha * T + beta (Maxwell arms exact for a linear change over dt)
        if frac.size and dt > 0:
            a = np.exp(-dt / tau)
            g = (1.0 - a) * tau / dt
        else:
            a = np.ones(frac.size)
            g = np.ones(frac.size)
        k_tot = k_notch * (1.0 + (frac * g).sum())
        q_carry = (q * a[:, None]).sum(axis=0) - (frac * g)[:, None].sum(axis=0) * k_notch * theta_n
        alpha = arm / k_tot
        beta = (k_notch * set_n - q_carry) / k_tot
        a_sum, b_sum = float(alpha.sum()), float(beta.sum())
        # sliding at the guide: friction in the direction of motion, regularised over slip_mm_s. It used to hold
        # the last moving step's value at rest, which made each dwell's state the speed of one discrete step (a
        # random 0-0.3 of the full friction per dwell); the law's own value at rest is zero: the guide releases
        slide = math.tanh(v / b.guide.slip_mm_s)
        ratio = ewrap ** slide          # cell tension / joint tension

        def gap(tj: float) -> float:
            mean_t = 0.5 * tj * (1.0 + ratio)
            return arm * (a_sum * tj + b_sum) + bundle.elongation(mean_t) + td.slack_mm + e_creep - carriage

        if gap(0.0) >= 0.0:
            tj = 0.0
        else:
            hi = 1.0
            while gap(hi) < 0.0:
                hi *= 2.0
            tj = brentq(gap, 0.0, hi, xtol=1e-9)
        new_theta = alpha * tj + beta
        q = q * a[:, None] + (frac * g)[:, None] * k_notch[None, :] * (new_theta - theta_n)[None, :]
        theta_n = new_theta
        if b.backbone.yield_nmm > 0.0 and dt > 0:
            moment = arm * tj
            over = max(moment / b.backbone.yield_nmm - 1.0, 0.0)
            set_n = set_n + dt * b.backbone.set_rate_per_s * over * (theta_n - set_n) / max(float(theta_n.sum()), 1e-9)
        if b.drive.settle:   # d(carriage)/d(cell tension) at this state, for the next step's slide
            dt_n = max(1e-4, 1e-3 * tj)
            compliance_prev = (gap(tj + dt_n) - gap(tj)) / (dt_n * ratio) if tj > 0.0 else 0.0
        tension = tj
        cell = tj * ratio
        carriage_prev = carriage
        v_prev = v
        out_theta[i] = float(theta_n.sum())
        out_cell[i] = cell
        out_carriage[i] = carriage
    return out_theta, out_cell, out_carriage


def simulate_bench(pattern: Pattern, samples: tuple[SampleBench, SampleBench] | SampleBench,
                   protocol: Protocol = Protocol(), clock: Clock = Clock(), seed: int = 0) -> BenchRecord:
    """Simulate one bench file: two samples (or as many as given), each with its own bench parts.

    Parameters
    ----------
    pattern : Pattern
        The cut tube (geometry, tendon).
    samples : SampleBench or tuple of SampleBench
        The bench parts of each sample (one value: both samples alike).
    protocol : Protocol
        Commanded motion (peak stroke defaults to ``rules.max_stroke``).
    clock : Clock
        The logger's clock (rate 25-100 Hz).
    seed : int

    Returns
    -------
    BenchRecord
    """
    rng = np.random.default_rng(seed)
    per = (samples, samples) if isinstance(samples, SampleBench) else tuple(samples)
    peak = pattern.rules.max_stroke_mm if protocol.peak_mm is None else protocol.peak_mm
    duration = record_length_s(protocol)
    geo = pattern_geometry(pattern)
    arm = geo.first.moment_arm_mm
    parts: dict[str, list] = {k: [] for k in ("sample", "cycle", "time", "stroke", "force", "angle", "true", "cell",
                                                "carriage")}
    spikes, drops, reps, bursts = [], [], [], []
    offset = 0
    floors = []
    for s, b in enumerate(per):
        t_true, logged, rep = _stamps(clock, duration, rng)
        motor, cycle = motor_profile(protocol, peak, t_true)
        if clock.sim_step_ms > 0.0:   # the mechanics on a finer grid holding every logged time, read at those
            t_fine, at = _fine_grid(t_true, clock.sim_step_ms * 1e-3)
            theta, cell, carriage = (x[at] for x in _run_sample(pattern, b, t_fine,
                                                                motor_profile(protocol, peak, t_fine)[0], rng))
        else:
            theta, cell, carriage = _run_sample(pattern, b, t_true, motor, rng)
        n = t_true.size
        tr, lc = b.tracker, b.load_cell
        # the tracker reports the bend it saw lag_ms ago
        seen = np.interp(t_true - tr.lag_ms * 1e-3, t_true, theta)
        noise = rng.normal(0.0, tr.noise_deg, n)
        if tr.filter_ms > 0.0:   # a first-order filter at the logger's rate, its output's spread kept
            rho = math.exp(-1e3 / (clock.rate_hz * tr.filter_ms))
            gain = math.sqrt(1.0 - rho * rho)
            noise = lfilter([gain], [1.0, -rho], noise, zi=[(1.0 - gain) * noise[0]])[0]   # stationary from row 0
        angle = np.degrees(seen) + noise + tr.drift_deg_per_h * t_true / 3600.0
        k_sp = np.sort(rng.choice(np.arange(5, n - 5), tr.n_spikes, replace=False)) if tr.n_spikes else np.zeros(0, int)
        angle[k_sp] += rng.choice([-1.0, 1.0], k_sp.size) * rng.uniform(*tr.spike_deg, k_sp.size)
        k_dr = []
        for _ in range(tr.n_dropouts):
            a0 = int(rng.integers(20, n - 40))
            k_dr.extend(range(a0, a0 + int(rng.integers(tr.dropout_rows[0], tr.dropout_rows[1] + 1))))
        k_dr = np.unique(np.array(k_dr, int))
        k_bu = []
        for _ in range(tr.n_bursts):   # (no draws without bursts: the records drawn before are unchanged)
            a0 = int(rng.integers(20, n - 40))
            rows = np.arange(a0, min(a0 + int(rng.integers(tr.burst_rows[0], tr.burst_rows[1] + 1)), n))
            angle[rows] += float(rng.choice([-1.0, 1.0])) * float(rng.uniform(*tr.spike_deg))
            k_bu.extend(rows.tolist())
        k_bu = np.unique(np.array(k_bu, int))
        if tr.dropout == "nan":
            angle[k_dr] = np.nan
        elif tr.dropout == "zero":
            angle[k_dr] = 0.0
        elif tr.dropout == "hold":
            for a0, a1 in _runs(k_dr):
                angle[a0:a1] = angle[a0 - 1]
        else:
            raise ValueError(f"Tracker.dropout {tr.dropout!r}: one of 'nan', 'zero', 'hold'")
        zero = lc.drift_N_per_h * t_true / 3600.0
        if lc.offset_N:
            zero = zero + lc.offset_N
        if lc.walk_N_per_sqrt_h > 0:
            zero = zero + np.cumsum(rng.normal(0.0, lc.walk_N_per_sqrt_h * math.sqrt(1.0 / clock.rate_hz / 3600.0), n))
        force = np.minimum(cell + zero + rng.normal(0.0, lc.noise_N, n), lc.range_N)
        comp = pattern.tendon.length_mm / (pattern.tendon.modulus_gpa * 1e3 * b.tendon.modulus_scale
                                            * math.pi * pattern.tendon.radius_mm ** 2)
        floors.append(math.hypot(tr.noise_deg, math.degrees(comp / arm) * lc.noise_N))
        parts["sample"].append(np.full(n, f"S{s + 1}", dtype=object))
        parts["cycle"].append(cycle.astype(np.int64))
        parts["time"].append(logged)
        parts["stroke"].append(np.round(motor, 6))
        parts["force"].append(force)
        parts["angle"].append(angle)
        parts["true"].append(np.degrees(theta))
        parts["cell"].append(cell)
        parts["carriage"].append(carriage)
        spikes.append(k_sp + offset)
        bursts.append(k_bu + offset)
        drops.append(k_dr + offset)
        reps.append(rep + offset)
        offset += n
    cat = {k: np.concatenate(v) for k, v in parts.items()}
    data = Dataset(cat["sample"], cat["cycle"], cat["time"], cat["stroke"], cat["force"], cat["angle"])
    params = {"arm_mm": arm, "samples": [repr(b) for b in per], "protocol": repr(protocol), "clock": repr(clock)}
    return BenchRecord(data, cat["true"], cat["cell"], np.concatenate(spikes), np.concatenate(drops),
                       np.concatenate(reps), float(math.sqrt(np.mean([b.tracker.noise_deg ** 2 for b in per]))),
                       float(math.sqrt(np.mean(np.square(floors)))), params, cat["carriage"], np.concatenate(bursts))


def _runs(rows: np.ndarray) -> list[tuple[int, int]]:
    """``[(first, stop)]`` of the runs of consecutive values in sorted ``rows``."""
    if not rows.size:
        return []
    cut = np.flatnonzero(np.diff(rows) > 1) + 1
    return [(int(r[0]), int(r[-1]) + 1) for r in np.split(rows, cut)]


def with_tracker(b: SampleBench, **kw) -> SampleBench:
    """``b`` with tracker fields replaced."""
    return replace(b, tracker=replace(b.tracker, **kw))
