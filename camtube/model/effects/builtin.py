"""Built-in effects: the physics the paper's base model leaves out.

Each effect is a named term on one stage of the model chain (see
:mod:`camtube.model.core.model`); :data:`BUILTIN_EFFECTS` lists them for
:func:`camtube.model.core.registry.builtin_registry`:

=============  ==========  =====================================================
name           stage       physics (parameters)
=============  ==========  =====================================================
slack          stroke      tendon slack: a deadband at low stroke (deadband_mm)
play           stroke      lost motion in the drive, direction dependent (play_mm)
play_held      stroke      the same with the carriage held by its rail: it stands a gap above the motor after an
                           unloading (play_mm)
carriage_hold  stroke      lost motion in the drive: the rail's friction holds the carriage while the tension
                           is low, until it lets go (ratio: the friction over the tension held at rest)
carriage_gap   stroke      the same within a nut's gap that binds: the far flank pushes the held carriage down
                           with the motor (ratio, gap_mm)
creep          stroke      tendon creep / drift over time (creep_mm, tau_s)
creep_load     stroke      tendon creep under load: Findley's power law in the load-time integral
                           (creep_mm, exponent)
friction       elongation  tendon-sheath friction: mean tension differs from the
                           load cell by a fraction, sign of motion (mu)
toe            elongation  toe region of the tendon (quadratic, then linear) (toe_mm)
toe_shape      elongation  toe region of fitted shape: Weibull fibre recruitment, at a short force
                           average (offset_mm, shape)
toe_soft       elongation  toe region that starts at a share of the stiffness: straight fibres carry load from
                           zero force, the crimped ones straighten as toe_shape's (offset_mm, shape, share)
viscoelastic   elongation  standard linear solid: delayed elongation (ratio, tau_s)
series         elongation  extra series compliance: sheath/tube compression (compliance_mm_per_N)
kerf           kinematics  notch arc widened by the kerf: phi, hence the arm, change (kerf_mm)
flat_walls     kinematics  flat (planar) instead of radial notch walls: other arm (none)
chords         kinematics  tendon as straight chords across the notches (none)
hardstop       kinematics  notches close: the joint stops bending (stop_deg)
rest_angle     kinematics  joint friction: once loaded, the unloaded joint rests bent (rest_deg)
relaxation     kinematics  viscoelastic backbone: the slack joint stands at a share of the angle it held and
                           returns with a relaxation time (fraction, tau_s)
angle_bias     angle       tracker offset (bias_deg)
force_zero     force       load-cell zero offset (zero_N)
=============  ==========  =====================================================

History-dependent effects (``play``, ``viscoelastic``) run per sample in time
order; the play operator is exact and vectorised over the monotone segments of
the stroke (one NumPy call per stroke reversal); the linear filter of
``viscoelastic`` uses :func:`scipy.signal.lfilter` when the sampling is uniform.
"""
from __future__ import annotations

import math
from typing import Callable, Sequence

import numpy as np

from camtube.design.geometry import backbone_angle_rad, centroid_mm
from camtube.model.core.model import Context, Effect, sample_views
from camtube.model.core.noise import white_noise_sd
from camtube.model.core.params import Param
from camtube.model.data.dataset import Dataset, recently_used, rests_of
from camtube.model.effects.history import (  # noqa: F401
    carriage_hold, first_order_lag, monotone_segments, play_operator, relaxed_compiled,
)
from camtube.model.effects.kernels import toe_rows

# ----------------------------------------------------------------------------- helpers

def _stroke_span(data: Dataset) -> float:
    s = np.asarray(data.stroke_mm, float)
    return float(np.ptp(s)) if s.size else 1.0


def _duration(data: Dataset) -> float:
    t = np.asarray(data.time_s, float)
    spans = [float(np.ptp(t[sl])) for _, sl in data.sample_slices()]
    return max(max(spans, default=1.0), 1e-3)


def _period(data: Dataset) -> float:
    """Mean cycle period (s) of the data, from the time span and the cycle count."""
    t = np.asarray(data.time_s, float)
    c = np.asarray(data.cycle)
    per = []
    for _, sl in data.sample_slices():
        n = int(np.unique(c[sl]).size)
        if n:
            per.append(float(np.ptp(t[sl])) / n)
    return max(float(np.median(per)) if per else 1.0, 1e-3)


def _slack_guess(data: Dataset, ctx: Context) -> float:
    """Stroke at which the angle leaves its low plateau (0 if none): a loose starting value."""
    s = np.asarray(data.stroke_mm, float)
    a = np.asarray(data.angle_deg, float)
    if s.size < 10:
        return 0.0
    lo, hi = np.percentile(a, [2, 98])
    moving = a > lo + 0.05 * (hi - lo)
    if not moving.any():
        return 0.0
    s_move = float(np.percentile(s[moving], 1))
    return max(0.5 * (s_move - float(np.min(s))), 0.0)


def _arm_for(ro: float, ri: float, rt: float, ybar: float) -> float:
    return ybar + ri - rt


def _flat_wall_ybar(ro: float, ri: float, arc_mm: float) -> float:
    """Centroid distance (mm) of the backbone left by a notch with one flat (planar) wall.

    The cut plane lies at ``d = r_o cos(s / 2 r_o)`` from the axis so that it
    removes the outer arc ``s``; the annulus part beyond the plane is removed.
    Circular segment beyond a chord at ``d``: area ``R^2 acos(d/R) - d sqrt(R^2 - d^2)``,
    first moment ``2/3 (R^2 - d^2)^(3/2)``.
    """
    d = ro * math.cos(arc_mm / (2.0 * ro))

    def seg(r: float) -> tuple[float, float]:
        if d >= r:
            return 0.0, 0.0
        if d <= -r:
            return math.pi * r * r, 0.0
        q = r * r - d * d
        return r * r * math.acos(d / r) - d * math.sqrt(q), 2.0 / 3.0 * q**1.5

    ao, mo = seg(ro)
    ai, mi = seg(ri)
    area = math.pi * (ro**2 - ri**2) - (ao - ai)
    return (mo - mi) / area


# ----------------------------------------------------------------------------- stroke stage

def _slack(ctx: Context, stroke: np.ndarray, p: dict) -> np.ndarray:
    return np.maximum(stroke - p["deadband_mm"], 0.0)


SLACK = Effect(
    name="slack", stage="stroke", pure=True,
    params=(Param("deadband_mm", "mm", 0.0, 10.0, _slack_guess,
                  "motor stroke taken up before the tendon is taut", kind="length"),),
    apply=_slack,
    meaning="tendon slack: the first part of the stroke only takes up the slack, the joint does not move",
    signature="at low stroke the joint stays straight while the base model already bends it "
              "(negative residual at small stroke, then a constant offset)",
    off={"deadband_mm": 0.0},
)


def _play(ctx: Context, stroke: np.ndarray, p: dict) -> np.ndarray:
    # a negative output is a slack tendon (it cannot push): the joint stays straight
    return np.maximum(play_operator(ctx.data, stroke, p["play_mm"]), 0.0)


PLAY = Effect(
    name="play", stage="stroke", pure=True,
    params=(Param("play_mm", "mm", 0.0, 10.0, lambda d, c: 0.02 * _stroke_span(d),
                  "lost motion between the motor and the tendon (full width of the play)", kind="length"),),
    apply=_play,
    meaning="lost motion (backlash, play) between the motor and the tendon: after each reversal the "
            "motor moves through the play before the tendon follows",
    signature="the residual flips sign with the direction of motion, with a constant size: "
              "loading lags, unloading leads (a parallelogram loop)",
    history=True,
    off={"play_mm": 0.0},
)


def _play_held(ctx: Context, stroke: np.ndarray, p: dict) -> np.ndarray:
    # the carriage moves only when a flank of the nut pushes it: play's operator referred to the pushing flank (a gap
    # above play's), so it starts on the motor and, after an unloading, stands a gap above it
    w = p["play_mm"]
    return np.maximum(play_operator(ctx.data, stroke, w) + w, 0.0)


PLAY_HELD = Effect(
    name="play_held", stage="stroke", pure=True,
    params=(Param("play_mm", "mm", 0.0, 10.0, lambda d, c: 0.02 * _stroke_span(d),
                  "the nut's gap: how far the motor moves after a reversal before the carriage follows",
                  kind="length"),),
    apply=_play_held,
    family="drive",
    meaning="lost motion in the drive, with the carriage held by its rail: it moves only when a flank of the "
            "nut pushes it, so after each unloading it stands a gap above the motor (the tendon keeps that "
            "stroke while the motor rests at zero) and the next pull moves the motor through the gap first",
    signature="the residual flips sign with the direction of motion, with a constant size, and the joint stays "
              "bent after each unloading while the motor rests at zero; the first pull, before any unloading, "
              "differs",
    history=True,
    off={"play_mm": 0.0},
)


def _bottom_tension_N(s: np.ndarray, f: np.ndarray) -> float:
    """The tension the tendon keeps while the motor stands at the bottom of its stroke ``s`` (the 90th percentile
    of the force ``f`` over the rows within 1 % of the stroke's span of its lowest, of those above five times the
    force's white noise there and 0.01 N); 0 when it goes slack there (fewer than a tenth of those rows, or 20,
    keep a tension). One sample's rows."""
    if s.size == 0:
        return 0.0
    bottom = (s - s.min()) <= 0.01 * (float(np.ptp(s)) or 1.0)
    noise = float(white_noise_sd(f[bottom])) if bottom.sum() > 10 else 0.0
    held = f[bottom & (f > max(5.0 * noise, 0.01))]
    return float(np.percentile(held, 90)) if held.size >= max(20, bottom.sum() // 10) else 0.0


def held_tension_N(data: Dataset) -> np.ndarray:
    """(n,) each sample's :func:`_bottom_tension_N`, on its rows (cached per Dataset)."""
    def compute() -> np.ndarray:
        s, f = np.asarray(data.stroke_mm, float), np.asarray(data.force_N, float)
        out = np.zeros(len(data))
        for _, sl in data.sample_slices():
            out[sl] = _bottom_tension_N(s[sl], f[sl])
        out.setflags(write=False)
        return out
    return data.cache.get_or("builtin.held_tension", compute)


def _carriage_hold(ctx: Context, stroke: np.ndarray, p: dict) -> np.ndarray:
    # The nut's gap is taken wider than the stroke the carriage is held at: where it is narrower the far flank
    # pushes the carriage down with the motor, a form this effect leaves out (a gap that does not bind cannot be
    # fitted: the rows do not depend on it). The lift of the carriage above the motor is added to the stroke this
    # stage has so far (the drive is nearer the motor than the tendon's own slack or creep)
    return stroke + carriage_lift_mm(ctx.data, p["ratio"])


#: Lifts kept per record (the most recently used): a fit evaluates a few ratios many times.
CARRIAGE_LIFTS_KEPT = 12


def carriage_lift_mm(data: Dataset, ratio: float, gap_mm: float = math.inf) -> np.ndarray:
    """(n,) how far the held carriage stands above the motor (mm): :func:`carriage_hold` on the measured stroke,
    its hold force ``ratio`` times each sample's :func:`held_tension_N`, within the nut's gap ``gap_mm``. Computed
    on the whole record ``data`` was taken from (in a thinned copy the hold's start would fall between two kept
    rows, where the force bends as the carriage sticks) and kept with it."""
    record, rows = data.rows_of_record()
    ratio, gap = float(ratio), float(gap_mm)
    kept = record.cache.get_or("builtin.carriage_lifts", dict)
    out = np.zeros(rows.size)
    # per sample (speed: a fit with per-sample values evaluates one sample at a time, and the law runs per sample)
    for smp, sl, sub in sample_views(record):
        inside = (rows >= sl.start) & (rows < sl.stop)
        if not inside.any():
            continue

        def compute(sub=sub) -> np.ndarray:
            s = np.asarray(sub.stroke_mm, float)
            return _read_only(carriage_hold(sub, s, ratio * held_tension_N(sub), gap) - s)

        out[inside] = recently_used(kept, (smp, ratio, gap), compute, CARRIAGE_LIFTS_KEPT)[rows[inside] - sl.start]
    return out


CARRIAGE_HOLD = Effect(
    name="carriage_hold", stage="stroke", pure=True,
    params=(Param("ratio", "", 0.0, 3.0, 1.0,
                  "the rail's friction (the tension below which it holds the carriage) over the tension the tendon "
                  "keeps while the motor rests at the bottom of its stroke (each sample's own, from the data)",
                  starts=(1.0, 1.03)),),
    apply=_carriage_hold,
    family="drive",
    meaning="lost motion in the drive: the tendon pulls the carriage onto the nut's flank while its tension "
            "exceeds the rail's friction; on unloading, below it, the rail holds the carriage (within the nut's "
            "gap) while the motor goes on, so the tendon stays taut and the joint bent while the motor rests at "
            "zero, until the carriage lets go and the tension drops",
    signature="after each unloading the joint stays bent, the force at a constant level, while the stroke goes "
              "to zero; then the force drops to zero at once and the joint straightens",
    history=True,
    off={"ratio": 0.0},
)


def _carriage_gap(ctx: Context, stroke: np.ndarray, p: dict) -> np.ndarray:
    # carriage_hold with the nut's gap fitted: held at rest above the motor by at most the gap (the far flank
    # pushes it down with the motor beyond that), and on the next pull the motor takes the gap up first
    return stroke + carriage_lift_mm(ctx.data, p["ratio"], p["gap_mm"])


CARRIAGE_GAP = Effect(
    name="carriage_gap", stage="stroke", pure=True,
    params=(Param("ratio", "", 0.0, 3.0, 1.0,
                  "the rail's friction (the tension below which it holds the carriage) over the tension the tendon "
                  "keeps while the motor rests at the bottom of its stroke (each sample's own, from the data)",
                  starts=(1.0, 1.03)),
            Param("gap_mm", "mm", 0.001, 2.0, lambda d, c: 0.05 * _stroke_span(d),
                  "the gap of the nut's lug: how far the held carriage can stand above the motor", kind="length")),
    apply=_carriage_gap,
    family="drive",
    meaning="lost motion in the drive, within a gap that binds: the tendon pulls the carriage onto the nut's "
            "flank while its tension exceeds the rail's friction; on unloading, below it, the rail holds the "
            "carriage while the motor goes on, until the nut's far flank, a gap away, pushes it down with the "
            "motor; the joint rests bent by what the gap keeps, and the next pull first takes the gap up",
    signature="after each unloading the joint stays bent and the force at a constant level while the motor "
              "rests at zero (the carriage a gap above it); the next pull moves the motor through the gap before "
              "the joint follows",
    history=True,
    off={"ratio": 0.0},
)


def _creep(ctx: Context, stroke: np.ndarray, p: dict) -> np.ndarray:
    t = ctx.data.elapsed_s   # since the sample's record began, whatever the logger's clock counts from
    # a tendon longer than the stroke is slack: the joint stays straight
    return np.maximum(stroke - p["creep_mm"] * -np.expm1(-t / max(p["tau_s"], 1e-9)), 0.0)


CREEP = Effect(
    name="creep", stage="stroke", pure=True,
    params=(Param("creep_mm", "mm", -5.0, 5.0, lambda d, c: 0.01 * _stroke_span(d),
                  "tendon lengthening reached after a long time (stroke lost)", kind="length"),
            Param("tau_s", "s", 1e-2, 1e7, lambda d, c: _duration(d) / 4.0,
                  "time constant of the creep (s since the start of the sample's record)", log=True,
                  kind="time")),
    apply=_creep,
    meaning="creep (drift over cycles): the tendon lengthens slowly under load, so later cycles "
            "bend less for the same stroke; it settles with a time constant",
    signature="the residual trends with cycle number and time: early cycles differ from late ones",
    history=True,
    off={"creep_mm": 0.0},
)


#: Load-time integral (N s) at which ``creep_load.creep_mm`` is the creep reached (1 N carried for 1000 s).
LOAD_TIME_REF_NS = 1000.0


def _same_force(kept: np.ndarray, force: np.ndarray) -> bool:
    """Whether ``force`` is the force array ``kept`` was computed from: the same object, or equal values (speed:
    a force-stage effect such as ``force_zero`` makes a new array every evaluation, though a finite-difference
    step in another effect's parameter leaves its values as they were)."""
    return kept is force or (kept.shape == np.shape(force) and np.array_equal(kept, force))


def load_time_Ns(ctx: Context) -> np.ndarray:
    """(n,) the tension carried so far, integrated over time per sample (trapezoids of the measured force,
    clipped at zero: a slack tendon carries none), in N s. Cached per Dataset and force array."""
    hit = ctx.data.cache.get("builtin.load_time")
    if hit is not None and _same_force(hit[0], ctx.force_N):
        return hit[1]
    t = np.asarray(ctx.data.time_s, float)
    f = np.maximum(np.asarray(ctx.force_N, float), 0.0)
    out = np.zeros(t.size)
    for _, sl in ctx.data.sample_slices():
        ts, fs = t[sl], f[sl]
        if ts.size > 1:
            out[sl] = np.concatenate(([0.0], np.cumsum(0.5 * (fs[1:] + fs[:-1]) * np.diff(ts))))
    ctx.data.cache.set("builtin.load_time", (ctx.force_N, out))
    return out


def _creep_load(ctx: Context, stroke: np.ndarray, p: dict) -> np.ndarray:
    w = load_time_Ns(ctx) / LOAD_TIME_REF_NS
    # a tendon longer than the stroke is slack: the joint stays straight
    return np.maximum(stroke - p["creep_mm"] * w ** p["exponent"], 0.0)


CREEP_LOAD = Effect(
    name="creep_load", stage="stroke", pure=True,
    params=(Param("creep_mm", "mm", 0.0, 5.0, lambda d, c: 0.01 * _stroke_span(d),
                  f"tendon lengthening after {LOAD_TIME_REF_NS:g} N s of load (1 N carried for {LOAD_TIME_REF_NS:g} s)",
                  kind="length"),
            Param("exponent", "", 0.05, 3.0, 0.4,
                  "power of the load-time integral (Findley's creep law: below 1 the creep slows down)",
                  log=True, starts=(0.2, 0.5, 1.0))),
    apply=_creep_load,
    meaning="creep under load (Findley's power law in the load carried over time): the tendon lengthens "
            "only while it carries tension, fast at first and then slower, and does not recover at rest",
    signature="the residual trends with the load carried so far: early cycles differ from late ones, "
              "and more after long dwells under load than after rests",
    history=True,
    off={"creep_mm": 0.0},
)


# ----------------------------------------------------------------------------- elongation stage

def _friction(ctx: Context, elong: np.ndarray, p: dict) -> np.ndarray:
    return elong * (1.0 - p["mu"] * ctx.direction)


FRICTION = Effect(
    name="friction", stage="elongation", pure=True,
    params=(Param("mu", "", -0.9, 0.9, 0.02,
                  "fraction by which the tendon's mean tension falls below (loading) or rises above "
                  "(unloading) the load cell"),),
    apply=_friction,
    meaning="tendon-sheath friction between the load cell and the joint: the tendon's mean tension is "
            "lower than measured while pulling and higher while releasing (friction hysteresis)",
    signature="the residual flips sign with the direction of motion and grows with force",
    family="friction",
    off={"mu": 0.0},
)


def _capstan(ctx: Context, force: np.ndarray, p: dict) -> np.ndarray:
    v = ctx.data.stroke_speed_mm_s
    slide = np.where(v != 0.0, np.tanh(v / max(p["slip_mm_s"], 1e-6)), p["hold"] * ctx.data.direction)
    return force * 0.5 * (1.0 + np.exp(-p["mu_wrap"] * slide))


CAPSTAN = Effect(
    name="capstan", stage="force", pure=True,
    params=(Param("mu_wrap", "", -0.5, 3.0, 0.2,
                  "friction coefficient times the wrap angle (rad) of the guide: the joint-side tension is "
                  "exp(-mu_wrap) times the load cell's while pulling, exp(+mu_wrap) while releasing",
                  starts=(0.1, 0.3, 0.8)),
            Param("slip_mm_s", "mm/s", 1e-6, 10.0, 0.05,
                  "tendon speed at which the friction is 76 % developed (tanh); on its lower bound: a guide "
                  "whose friction switches within a row (Coulomb's step)", log=True, starts=(0.01, 0.1),
                  kind="sharp"),
            Param("hold", "", -0.5, 1.0, 0.5,
                  "share of the sliding friction the guide keeps while the drive rests (1: static friction "
                  "keeps the last motion's state; 0: the guide releases; the range goes below 0 so that a "
                  "guide that releases is not a fit on its bound)", starts=(0.1, 0.9))),
    apply=_capstan,
    meaning="capstan friction where the tendon wraps a guide between the load cell and the joint: the "
            "tension falls by exp(-mu_wrap) across the guide while pulling and rises while releasing, so the "
            "tendon's mean tension (what stretches it) is (1 + exp(-mu_wrap s)) / 2 of the load cell's, "
            "s = tanh(speed / slip_mm_s) the sliding state; while the drive rests, s = hold times the last "
            "motion's direction",
    signature="the residual flips sign with the direction of motion and grows with force; loading and "
              "unloading differ by unequal amounts (exponential), and the state persists through dwells",
    family="friction",
    history=True,
    off={"mu_wrap": 0.0},
)


def _toe(ctx: Context, elong: np.ndarray, p: dict) -> np.ndarray:
    et = max(p["toe_mm"], 0.0)
    if et <= 0.0:
        return elong
    c = ctx.compliance_mm_per_N
    f = np.maximum(ctx.force_N, 0.0)
    f_toe = et / (2.0 * c)
    toe = np.where(f < f_toe, np.sqrt(2.0 * et * c * f), c * f + 0.5 * et) - c * f
    # the toe law is steep at zero force (force noise is amplified there); where the elongation
    # exceeds the stroke the tendon is slack and the joint straight
    return np.minimum(elong + toe, np.maximum(ctx.stroke_mm, elong))


TOE = Effect(
    name="toe", stage="elongation", pure=True,
    params=(Param("toe_mm", "mm", 0.0, 5.0, lambda d, c: 0.05 * _stroke_span(d),
                  "elongation over which the tendon's fibres straighten (end of the toe region)",
                  kind="length"),),
    apply=_toe,
    family="toe",
    meaning="toe region of the tendon: crimped fibres straighten first, so the tendon is soft at low "
            "force (force grows with elongation squared) and reaches its linear stiffness after toe_mm",
    signature="the residual is curved against force: it moves quickly at low force and is constant at "
              "high force (the tendon stretches more than linear at the start)",
    off={"toe_mm": 0.0},
)


#: Lags of the force kept per Dataset and force (the most recently used), for ``viscoelastic``.
FORCE_LAGS_KEPT = 4


def force_lag(ctx: Context, tau_s: float) -> np.ndarray:
    """:func:`first_order_lag` of the force (after the ``force`` stage) with ``tau_s``, kept per Dataset.

    speed: a fit's finite-difference steps in every parameter but ``tau_s`` (E_t, the ratio, the stroke's
    effects) lag the same force with the same time constant; the same computation gives the same numbers, so
    it is reused (read-only). A force of other values starts afresh.
    """
    hit = ctx.data.cache.get("builtin.force_lags")
    if hit is None or not _same_force(hit[0], ctx.force_N):
        hit = ctx.data.cache.set("builtin.force_lags", (ctx.force_N, {}))
    return recently_used(hit[1], float(tau_s),
                         lambda: _read_only(first_order_lag(ctx.data, np.asarray(ctx.force_N, float), tau_s)),
                         FORCE_LAGS_KEPT)


def _read_only(a: np.ndarray) -> np.ndarray:
    """``a``, no longer writable (a kept array is shared by every evaluation that reuses it)."""
    a.setflags(write=False)
    return a


def _visco(ctx: Context, elong: np.ndarray, p: dict) -> np.ndarray:
    lag = force_lag(ctx, p["tau_s"])
    # while the delayed elongation exceeds the stroke the tendon is slack: the joint stays straight
    return np.minimum(elong + p["ratio"] * ctx.compliance_mm_per_N * lag, ctx.stroke_mm)


#: Grid points of the tabulated toe law of ``toe_shape`` (dense near zero: quadratic in the index).
TOE_GRID = 1500


def weibull_toe_force(x: np.ndarray, shape: float) -> np.ndarray:
    """Normalised tension ``tau = C T / lam`` at normalised elongation ``x = e / lam`` of a Weibull-recruited tendon.

    The fibres straighten at elongations distributed as Weibull (scale ``lam``, modulus ``shape``), so the
    stiffness fraction is ``F(x) = 1 - exp(-x^shape)`` and
    ``tau(x) = int_0^x F = x - Gamma(1 + 1/shape) P(1/shape, x^shape)`` (``P``: regularised lower
    incomplete gamma function). Shape ``(n,)`` in, ``(n,)`` out (both dimensionless).
    """
    from scipy.special import gamma, gammainc

    x = np.maximum(np.asarray(x, float), 0.0)
    a = 1.0 / shape
    xk = x**shape
    out = x - gamma(1.0 + a) * gammainc(a, xk)
    # small x: the difference cancels; the series int_0^x (u^k - u^2k / 2) du is exact to x^3k
    small = xk < 1e-3
    out[small] = x[small] * xk[small] * (1.0 / (shape + 1.0) - xk[small] / (2.0 * (2.0 * shape + 1.0)))
    return out


#: Rows whose averaged force is below this many noise standard deviations take the posterior mean of the law.
TOE_LOW_SD = 4.0
#: Quantile nodes of that posterior mean.
TOE_NODES = 16
#: Time over which a toe law averages the measured force, as a fraction of the cycle period (see
#: :func:`local_force_N`).
TOE_FORCE_WINDOW = 1.0 / 20.0


def local_force_N(ctx: Context) -> np.ndarray:
    """(n,) force (N) averaged over a short centred window, per sample: the input of a steep tendon law.

    The measured force is the tension plus white sensor noise. A toe law is steep at low tension
    (its compliance grows without bound as the tension falls to zero), so evaluating it at the noisy
    force turns a few mN of noise into a large, biased elongation error (errors in the variables).
    The tension changes little within a small part of a cycle, so the law is evaluated at the force
    averaged over :data:`TOE_FORCE_WINDOW` of the cycle period (a centred moving average of an odd
    number of rows: no lag, a linear trend kept exactly; one row when the rows are sparser).
    """
    from scipy.ndimage import uniform_filter1d

    f = np.asarray(ctx.force_N, float)
    # speed: a fit evaluates the model many times with the same force array (no force-stage effect)
    hit = ctx.data.cache.get("builtin.local_force")
    if hit is not None and _same_force(hit[0], ctx.force_N):
        return hit[1]
    out = f.copy()
    for sl, rows, _ in _force_windows(ctx.data):
        if rows > 1:
            out[sl] = uniform_filter1d(f[sl], rows, mode="nearest")
    ctx.data.cache.set("builtin.local_force", (ctx.force_N, out))
    return out




def _force_windows(data: Dataset) -> list:
    """Cached per Dataset: ``(slice, rows, sd_N)`` of each sample: the odd window of :func:`local_force_N` and
    the standard deviation of the noise left on the averaged force (white noise / sqrt(rows))."""
    hit = data.cache.get("builtin.force_windows")
    if hit is None:
        f = np.asarray(data.force_N, float)
        window_s = TOE_FORCE_WINDOW * _period(data)
        hit = []
        for (_, sl), dt in zip(data.sample_slices(), data.median_steps_s()):
            rows = 1
            if sl.stop - sl.start >= 3:
                rows = int(round(window_s / dt)) if dt > 0 else 1
                rows = max(rows - (1 - rows % 2), 1)  # odd: centred
            hit.append((sl, rows, white_noise_sd(f[sl]) / math.sqrt(rows)))
        data.cache.set("builtin.force_windows", hit)
    return hit


def local_force_sd_N(data: Dataset) -> np.ndarray:
    """(n,) standard deviation (N) of the noise left on :func:`local_force_N`, per sample."""
    out = np.zeros(len(data))
    for sl, _, sd in _force_windows(data):
        out[sl] = sd
    return out


_TOE_TABLES: dict = {}
#: Toe tables kept (the most recently used).
TOE_TABLES_KEPT = 64


def _toe_table(shape: float, x_min: float) -> tuple[np.ndarray, np.ndarray]:
    """``(x, tau(x))`` of :func:`weibull_toe_force` on ``TOE_GRID + 1`` points from 0 to at least ``x_min``.

    Cached by shape and range (the range rounded up to a power of two): a fit's finite-difference steps in
    the other parameters reuse the table. The least recently used table is dropped (per-sample shapes and a
    fit's trial steps come back to tables used a few evaluations before).
    """
    x_max = 2.0 ** math.ceil(math.log2(max(x_min, 1e-6)))

    def fresh() -> tuple[np.ndarray, np.ndarray]:
        xg = x_max * (np.arange(TOE_GRID + 1) / TOE_GRID) ** 2
        return xg, weibull_toe_force(xg, shape)

    return recently_used(_TOE_TABLES, (float(shape), x_max), fresh, TOE_TABLES_KEPT)




#: Points of the per-sample grid of averaged forces on which the posterior mean of a toe law is computed (the
#: rows near zero force interpolate in it: the posterior depends on the averaged force only, per sample).
TOE_POSTERIOR_GRID = 256


def _toe_forces(ctx: Context) -> tuple[np.ndarray, np.ndarray, tuple]:
    """``(forces, low, (index, weight))``: the averaged force of every row (clipped at zero), then
    :data:`TOE_NODES` quantile nodes of the tension's posterior at each point of a per-sample grid of averaged
    forces (:data:`TOE_POSTERIOR_GRID` points spanning the rows of ``low``, those near zero force), and each low
    row's place in that grid (linear interpolation). Cached per Dataset and force array: they depend on the
    data only, and a fit evaluates the law many times."""
    hit = ctx.data.cache.get("builtin.toe_forces")
    if hit is not None and _same_force(hit[0], ctx.force_N):
        return hit[1], hit[2], hit[3]
    fa = local_force_N(ctx)
    f = np.maximum(fa, 0.0)
    sd = local_force_sd_N(ctx.data)
    low = np.flatnonzero(fa < TOE_LOW_SD * sd)
    index = np.zeros(low.size, np.intp)
    weight = np.zeros(low.size)
    if low.size:
        from scipy.special import ndtr, ndtri

        u = (np.arange(TOE_NODES) + 0.5) / TOE_NODES
        grids = []
        offset = 0
        for _, sl in ctx.data.sample_slices():
            mine = (low >= sl.start) & (low < sl.stop)
            if not mine.any():
                continue
            mu = fa[low[mine]]
            s = float(sd[low[mine]][0])
            lo_mu, hi_mu = float(mu.min()), float(mu.max())
            g = np.linspace(lo_mu, hi_mu if hi_mu > lo_mu else lo_mu + 1e-12, TOE_POSTERIOR_GRID)
            pos = (mu - lo_mu) / (g[1] - g[0])
            i = np.minimum(pos.astype(np.intp), TOE_POSTERIOR_GRID - 2)
            index[mine] = i + offset
            weight[mine] = pos - i
            p0 = ndtr(-g / s)[:, None]
            fq = g[:, None] + s * ndtri(np.minimum(p0 + u[None, :] * (1.0 - p0), 1.0 - 1e-12))
            grids.append(np.maximum(fq, 0.0).ravel())
            offset += TOE_POSTERIOR_GRID
        f = np.concatenate([f, *grids])
    ctx.data.cache.set("builtin.toe_forces", (ctx.force_N, f, low, (index, weight)))
    return f, low, (index, weight)


def toe_elongation(ctx: Context, elong: np.ndarray, extra: Callable[[np.ndarray], np.ndarray],
                   key: tuple | None = None) -> np.ndarray:
    """Add a toe law's elongation ``extra(force_N) -> mm`` (beyond the linear law) to ``elong`` (n,).

    The law is evaluated at :func:`local_force_N`; near zero force, where it is steep, it is averaged
    over the tension's posterior given the averaged force (a normal of the remaining noise's size,
    :func:`local_force_sd_N`, truncated at zero: a tendon cannot push), by :data:`TOE_NODES` quantile
    nodes, on a grid of averaged forces per sample (:data:`TOE_POSTERIOR_GRID` points, interpolated:
    the law is evaluated at a few thousand nodes instead of sixteen per low row). Where the elongation
    would exceed the stroke the tendon is slack and the joint straight.

    ``key`` (hashable, optional): every value ``extra`` depends on. With it the rows' toe elongations are
    kept (:func:`_kept_toe_rows`) and reused while the force is the same.
    """
    f, low, (index, weight) = _toe_forces(ctx)
    n = elong.size

    def rows() -> np.ndarray:
        toe = extra(f)
        if low.size:
            out = toe[:n].copy()
            mean = toe[n:].reshape(-1, TOE_NODES).mean(axis=1)
            out[low] = mean[index] * (1.0 - weight) + mean[index + 1] * weight
            toe = out
        return toe

    toe = rows() if key is None else _kept_toe_rows(ctx, f, key, rows)
    return np.minimum(elong + toe, np.maximum(ctx.stroke_mm, elong))


#: Toe laws' row elongations kept per Dataset (the most recently used).
TOE_ROWS_KEPT = 16


def _kept_toe_rows(ctx: Context, f: np.ndarray, key: tuple, compute: Callable[[], np.ndarray]) -> np.ndarray:
    """``compute()`` for the law ``key`` at the force ``f``, kept per Dataset (least recently used dropped).

    speed: a fit's finite-difference steps in the parameters of other effects (and the cross-validation
    fits, from the same values) evaluate the law again with the same parameters and force; the same
    computation gives the same numbers, so they are reused. A new force array starts afresh.
    """
    hit = ctx.data.cache.get("builtin.toe_rows")
    if hit is None or hit[0] is not f:
        hit = ctx.data.cache.set("builtin.toe_rows", (f, {}))
    return recently_used(hit[1], key, lambda: _read_only(compute()), TOE_ROWS_KEPT)


def _weibull_toe(ctx: Context, elong: np.ndarray, offset_mm: float, k: float, share: float, name: str) -> np.ndarray:
    """``elong`` plus the toe of a tendon whose crimped fibres straighten at Weibull-distributed elongations (modulus
    ``k``) and whose straight ``share`` of the stiffness carries load from zero force (``toe_shape``: none), the linear
    law shifted by ``offset_mm`` at high force (none when it is not positive); ``name`` keys its rows
    (:func:`toe_elongation`)."""
    from scipy.special import gamma

    if offset_mm <= 0.0:
        return elong
    c = ctx.compliance_mm_per_N
    m = float(gamma(1.0 + 1.0 / k))         # mean straightening elongation of a crimped fibre, in Weibull scales
    lam = offset_mm / ((1.0 - share) * m)    # Weibull scale (mm): the crimped share's mean is the offset over (1 - share)

    def extra(f: np.ndarray) -> np.ndarray:
        # normalised tension tau = c f / lam (the linear tendon's elongation / lam); its largest value is that of the
        # largest force (rounding keeps the order)
        t_max = c * max(float(f.max(initial=0.0)), 0.0) / lam
        if t_max <= 0.0:
            return np.zeros(f.shape)
        # the stiffness fraction at normalised elongation x is share + (1 - share)(1 - exp(-x^k)), so the normalised
        # tension is share x + (1 - share) tau_w(x) (tau_w: weibull_toe_force; with no share, tau_w itself, to the
        # bit); it is at least x - m, so a table up to t_max + m + 1 covers every row. Tabulated once, inverted by
        # interpolation. speed: x on a grid uniform in sqrt(tau) (one small interp), then the rows in one compiled pass
        q = np.arange(TOE_GRID + 1) / TOE_GRID
        xg, tg = _toe_table(k, t_max + m + 1.0)
        xj = np.interp(t_max * q**2, share * xg + (1.0 - share) * tg, xg)
        return toe_rows(np.asarray(f, float), c, lam, t_max, xj)  # 0 .. offset_mm

    return toe_elongation(ctx, elong, extra, key=(name, c, offset_mm, k, share))


def _toe_shape(ctx: Context, elong: np.ndarray, p: dict) -> np.ndarray:
    return _weibull_toe(ctx, elong, p["offset_mm"], p["shape"], 0.0, "toe_shape")


TOE_SHAPE = Effect(
    name="toe_shape", stage="elongation", pure=True,
    params=(Param("offset_mm", "mm", 1e-3, 5.0, lambda d, c: 0.03 * _stroke_span(d),
                  "mean elongation at which a fibre straightens: the linear part of the law is shifted by it",
                  log=True, kind="length"),
            Param("shape", "", 0.5, 10.0, 1.5,
                  "Weibull modulus of the fibres' straightening elongations: 1 exponential toe, 2-4 an "
                  "S-shaped (sigmoid) stiffening, large a sharp knee (like slack), below 1 a long, slow toe",
                  log=True, starts=(0.8, 1.5, 3.5))),
    apply=_toe_shape,
    meaning="toe region with a fitted shape: the braid's fibres straighten one after another (their "
            "straightening elongations Weibull-distributed), so the stiffness rises from zero to E_t over the "
            "toe; the shape covers exponential, power-law and S-shaped toes",
    signature="the residual is curved against force: it moves quickly at low force and is constant at "
              "high force (the tendon stretches more than linear at the start)",
    family="toe",
    off={"offset_mm": 1e-3},
)


def _toe_soft(ctx: Context, elong: np.ndarray, p: dict) -> np.ndarray:
    return _weibull_toe(ctx, elong, p["offset_mm"], p["shape"], min(max(p["share"], 0.0), 0.999), "toe_soft")


TOE_SOFT = Effect(
    name="toe_soft", stage="elongation", pure=True,
    params=(Param("offset_mm", "mm", 1e-3, 5.0, lambda d, c: 0.03 * _stroke_span(d),
                  "elongation the toe adds once every fibre is straight: the linear part of the law is shifted by it",
                  log=True, kind="length"),
            Param("shape", "", 0.5, 10.0, 1.5,
                  "Weibull modulus of the crimped fibres' straightening elongations (as toe_shape's)",
                  log=True, starts=(0.8, 1.5, 3.5)),
            # (from a quarter: a smaller share is toe_shape's law within what a bench resolves, and took the place of
            # toe_shape on its toes at a share of 0.04, a parameter more for nothing)
            Param("share", "", 0.25, 0.98, 0.6,
                  "share of the tendon's stiffness that carries load from zero force (its straight fibres): the "
                  "tendon starts at this share of E_t, never slack",
                  starts=(0.4, 0.65, 0.9))),
    apply=_toe_soft,
    meaning="toe region that starts stiff: part of the tendon (a straight core, fibres without crimp) carries load "
            "from zero force, so the tendon starts at a share of its stiffness and stiffens to E_t as the crimped "
            "fibres straighten one after another (Weibull); an exponential or Fung-type toe, soft but never slack",
    signature="the residual is curved against force: it moves quickly at low force and is constant at "
              "high force (the tendon stretches more than linear at the start), without a deadband",
    family="toe",
    off={"offset_mm": 1e-3},
)


VISCOELASTIC = Effect(
    name="viscoelastic", stage="elongation", pure=True,
    params=(Param("ratio", "", 0.0, 20.0, 0.1,
                  "delayed compliance as a fraction of the instantaneous one (standard linear solid)",
                  starts=(0.05, 0.3, 1.5)),
            Param("tau_s", "s", 1e-3, 1e6, lambda d, c: _period(d) / 4.0,
                  "retardation time of the delayed compliance", log=True, kind="time")),
    apply=_visco,
    meaning="viscoelastic tendon (standard linear solid): part of the elongation follows the force "
            "with a delay, so the tendon is stiffer in fast loading and creeps at constant load",
    signature="the residual follows the force history: a loop against force (hysteresis) that depends "
              "on the loading rate",
    history=True,
    off={"ratio": 0.0},
)


def _series(ctx: Context, elong: np.ndarray, p: dict) -> np.ndarray:
    return elong + p["compliance_mm_per_N"] * ctx.force_N


SERIES = Effect(
    name="series", stage="elongation", pure=True,
    params=(Param("compliance_mm_per_N", "mm/N", 0.0, 10.0, 0.02,
                  "extra compliance in series with the tendon (sheath or tube compression)"),),
    apply=_series,
    meaning="an extra compliance in series with the tendon (the sheath or the tube compresses)",
    signature="the residual is proportional to force, like a softer tendon",
    family="compliance",
)


# ----------------------------------------------------------------------------- kinematics stage

def _kerf(ctx: Context, theta: np.ndarray, p: dict) -> np.ndarray:
    g = ctx.geometry
    arc = min(max(g.arc_mm + p["kerf_mm"], 1e-6), 2.0 * math.pi * g.outer_radius_mm - 1e-6)
    ybar = centroid_mm(g.outer_radius_mm, g.inner_radius_mm, backbone_angle_rad(g.outer_radius_mm, arc))
    arm = _arm_for(g.outer_radius_mm, g.inner_radius_mm, g.tendon_radius_mm, ybar)
    return theta * (g.moment_arm_mm / arm)


KERF = Effect(
    name="kerf", stage="kinematics", pure=True,
    params=(Param("kerf_mm", "mm", -0.5, 0.5, 0.02,
                  "widening of the notch arc by the laser kerf (on the outer surface)"),),
    apply=_kerf,
    meaning="the laser kerf widens the notch arc, so the backbone angle phi, its centroid and the moment "
            "arm change",
    signature="the residual is proportional to the angle (a gain error of the joint)",
    family="arm",
)


def _flat(ctx: Context, theta: np.ndarray, p: dict) -> np.ndarray:
    g = ctx.geometry
    arm = _arm_for(g.outer_radius_mm, g.inner_radius_mm, g.tendon_radius_mm,
                   _flat_wall_ybar(g.outer_radius_mm, g.inner_radius_mm, g.arc_mm))
    return theta * (g.moment_arm_mm / arm)


FLAT_WALLS = Effect(
    name="flat_walls", stage="kinematics", pure=True, params=(), apply=_flat,
    meaning="the notch walls are flat (one planar cut) rather than radial, so the backbone and the arm differ",
    signature="the residual is proportional to the angle (a gain error of the joint)",
    family="arm",
)


def _chords(ctx: Context, theta: np.ndarray, p: dict) -> np.ndarray:
    # per notch: dL(t) = a t + (h/t - a)(t - 2 sin(t/2)), solve n dL(t) = l_kin by Newton
    n = max(ctx.n_notches, 1)
    a = ctx.arm_mm
    h = ctx.geometry.notch_width_mm
    target = np.asarray(ctx.l_kin_mm, float) / n
    t = target / a
    for _ in range(6):
        ts = np.where(np.abs(t) < 1e-9, 1e-9, t)
        s = np.sin(ts / 2.0)
        f = h - 2.0 * (h / ts - a) * s - target
        df = 2.0 * h / ts**2 * s - (h / ts - a) * np.cos(ts / 2.0)
        t = t - f / df
    return t * n


CHORDS = Effect(
    name="chords", stage="kinematics", pure=True, params=(), apply=_chords,
    meaning="the tendon crosses each notch as a straight chord, not an arc, so it shortens a little "
            "less than arm x angle",
    signature="a small residual growing with the angle squared",
)


def _hardstop(ctx: Context, theta: np.ndarray, p: dict) -> np.ndarray:
    return np.minimum(theta, math.radians(p["stop_deg"]))


#: At least this many rows at the stop before its plateau is judged; and the measured angle's rise past the stop,
#: as a share of its rise just below it, above which there is no plateau.
PLATEAU_MIN_ROWS = 20
PLATEAU_MAX_SLOPE_SHARE = 0.5


def _within_slope(group: np.ndarray, x: np.ndarray, y: np.ndarray) -> float:
    """Slope of ``y`` on ``x`` within groups (each group's own mean removed); nan without spread in ``x``."""
    _, inv = np.unique(group, return_inverse=True)
    n = np.bincount(inv).astype(float)
    dx = x - (np.bincount(inv, x) / n)[inv]
    dy = y - (np.bincount(inv, y) / n)[inv]
    sxx = float(dx @ dx)
    return float(dx @ dy) / sxx if sxx > 0 else math.nan


def _hardstop_check(data: Dataset, predicted_deg: np.ndarray) -> str:
    """A hard stop levels the measured angle off: refuse a stop past which it keeps rising with the stroke.

    The rows at the stop are those at their sample's largest predicted angle (the clipped ones). Their measured
    angle's slope against the stroke, within each cycle (a drift between cycles does not count), is compared with
    the slope of the quarter of the other rows predicted highest, just below the stop.
    """
    pred = np.asarray(predicted_deg, float)
    meas = np.asarray(data.angle_deg, float)
    stroke = np.asarray(data.stroke_mm, float)
    sample_id = np.unique(np.asarray(data.sample), return_inverse=True)[1]
    group = sample_id * (int(np.max(data.cycle)) + 1) + np.asarray(data.cycle, int)
    top = np.zeros(pred.size, bool)
    for k in np.unique(sample_id):
        rows = sample_id == k
        top |= rows & (pred >= np.max(pred[rows]) - 1e-6)
    below = ~top & (pred >= np.quantile(pred[~top], 0.75)) if (~top).any() else ~top
    if top.sum() < PLATEAU_MIN_ROWS or below.sum() < PLATEAU_MIN_ROWS:
        return ""
    past, under = _within_slope(group[top], stroke[top], meas[top]), _within_slope(group[below], stroke[below],
                                                                                     meas[below])
    if math.isfinite(past) and math.isfinite(under) and under > 0 and past > PLATEAU_MAX_SLOPE_SHARE * under:
        return (f"no plateau: past the stop the measured angle keeps rising with the stroke ({past:.3g} deg/mm, "
                f"{under:.3g} deg/mm just below it)")
    return ""


HARDSTOP = Effect(
    name="hardstop", stage="kinematics", pure=True,
    params=(Param("stop_deg", "deg", 1.0, 720.0,
                  lambda d, c: math.degrees(c.n_notches * c.geometry.closure_angle_rad),
                  "joint angle at which the notches close"),),
    apply=_hardstop,
    meaning="the notches close: beyond this angle the joint stops bending (hard stop)",
    signature="at high stroke the measured angle levels off while the model keeps rising",
    check=_hardstop_check,
)


def _rest_angle(ctx: Context, theta: np.ndarray, p: dict) -> np.ndarray:
    rest = math.radians(max(p["rest_deg"], 0.0))
    if rest <= 0.0:  # off: the paper's model
        return theta
    out = np.asarray(theta, float).copy()
    for _, sl in ctx.data.sample_slices():
        a = out[sl]
        # the joint starts straight; once it has been bent past its rest angle it never comes back below it
        loaded = np.flatnonzero(a > rest)
        if loaded.size:
            a[loaded[0]:] = np.maximum(a[loaded[0]:], rest)
            out[sl] = a
    return out


#: The joint held bent at rest by at least this (deg) and the force at rest at least this many times the load
#: cell's row noise (and :data:`TAUT_AT_REST_N`) above zero: the tendon is taut at rest, which contradicts friction in
#: the joint (it leaves the tendon slack).
BENT_AT_REST_DEG = 0.1
TAUT_AT_REST_NOISE = 5.0
TAUT_AT_REST_N = 0.01


def _rest_angle_check(data: Dataset, predicted_deg: np.ndarray, effects: Sequence[Effect] = ()) -> str:
    """Friction in the joint (``rest_angle``) and its backbone's relaxation (``relaxation``, ``relaxation2``) hold
    the joint bent while the tendon goes slack: refuse such an effect in a sample whose force stays well above zero
    at the rests (motor at the bottom of its stroke) where the effect holds the joint bent (a taut tendon there: a
    carriage its rail holds, lost motion in the drive). Where the model already has the drive's effect (``effects``
    of family ``drive``: carriage_hold, carriage_gap), that effect holds the tendon taut at rest and the joint's own
    resting effects may stand beside it (a backbone relaxes whatever holds the tendon)."""
    if any(e.family == "drive" for e in effects):
        return ""
    pred = np.asarray(predicted_deg, float)
    force = np.asarray(data.force_N, float)
    for smp, sl in data.sample_slices():
        rests = rests_of(data, sl)
        if len(rests.runs) < 3:
            continue
        rows = np.concatenate(rests.runs)
        held_N, bent_deg = float(np.median(force[rows])), float(np.median(pred[rows]))
        if bent_deg >= BENT_AT_REST_DEG and held_N > max(TAUT_AT_REST_NOISE * rests.row_noise_N, TAUT_AT_REST_N):
            return (f"in {smp} it holds the joint bent at rest ({bent_deg:.2g} deg) while the force there stays at "
                    f"{held_N:.3g} N: the tendon is taut at rest, not slack as a joint resting bent by itself (its "
                    "friction, its backbone's relaxation) leaves it; a "
                    "carriage its rail holds keeps it so (carriage_hold, carriage_gap: lost motion in the drive), or "
                    "the load cell was not zeroed")
    return ""


REST_ANGLE = Effect(
    name="rest_angle", stage="kinematics", pure=True,
    params=(Param("rest_deg", "deg", 0.0, 20.0, 0.3,
                  "angle at which the unloaded joint stays bent (friction moment / bending stiffness)",
                  starts=(0.2, 1.0)),),
    apply=_rest_angle,
    family="rest",
    off={"rest_deg": 0.0},
    check=_rest_angle_check,
    meaning="friction in the joint (or a permanent set): once loaded, the joint's spring returns it only until "
            "its moment equals the friction, so the unloaded joint rests bent at rest_deg while the tendon "
            "goes slack",
    signature="after the first load, a positive residual where the tendon is slack or barely pulled (at rest "
              "and at the start of each pull); none before the first load",
)


def _relaxation(ctx: Context, theta: np.ndarray, p: dict) -> np.ndarray:
    c = min(max(p["fraction"], 0.0), 0.99)
    if c <= 0.0:
        return theta
    return _relaxed(ctx, theta, ((c, p["tau_s"]),))


def _relaxed(ctx: Context, theta: np.ndarray, arms: Sequence[tuple[float, float]]) -> np.ndarray:
    """The joint's angle with relaxing arms ``arms`` ((share, time constant s), ...) of its backbone: each arm's
    relaxed angle follows the angle the joint holds above its rest (by a first-order lag); unloaded, the joint
    stands at its rest plus the shares times them. Two passes: the second lets the arms follow the slack joint's
    own recovery (one arm's slack phases then decay by (1 - c) / tau, as the standard linear solid's do)."""
    th = np.asarray(theta, float)
    fast = relaxed_compiled(ctx.data, th, arms)   # speed: the same law compiled, where it applies as written
    if fast is not None:
        return fast
    floor = _rest_floor(ctx.data, th)
    held = np.maximum(th, floor)
    for _ in range(2):
        above = held - floor
        lagged = [c * first_order_lag(ctx.data, above, tau) for c, tau in arms]
        held = np.maximum(th, floor + sum(lagged[1:], lagged[0]))   # one arm: lagged[0] itself
    return held


def _relaxation2(ctx: Context, theta: np.ndarray, p: dict) -> np.ndarray:
    c1 = min(max(p["fraction"], 0.0), 0.99)
    c2 = min(max(p["slow_fraction"], 0.0), 0.99)
    if c1 + c2 > 0.99:  # the relaxing parts together are less than the whole backbone
        c1, c2 = 0.99 * c1 / (c1 + c2), 0.99 * c2 / (c1 + c2)
    arms = tuple((c, tau) for c, tau in ((c1, p["tau_s"]), (c2, p["tau_s"] * p["slow_ratio"])) if c > 0.0)
    return _relaxed(ctx, theta, arms) if arms else theta


def _rest_floor(data: Dataset, theta: np.ndarray) -> np.ndarray:
    """(n,) the angle (rad) the unloaded joint rests at, per sample: 0 until it is first bent, then the lowest
    angle after its largest (a rest angle earlier in the chain, such as ``rest_angle``'s, holds it there)."""
    out = np.zeros_like(theta)
    for _, sl in data.sample_slices():
        a = theta[sl]
        if a.size == 0:
            continue
        top = int(np.argmax(a))
        rest = max(float(a[top:].min()), 0.0)
        loaded = np.flatnonzero(a >= rest)
        if rest > 0.0 and loaded.size:
            out[sl.start + loaded[0]:sl.stop] = rest
    return out


RELAXATION = Effect(
    name="relaxation", stage="kinematics", pure=True,
    params=(Param("fraction", "", 0.0, 0.9, 0.05,
                  "share of the joint's angle its backbone's relaxing part holds when the tendon lets go "
                  "(k1 / (k + k1): the relaxing stiffness over the whole)", starts=(0.02, 0.1, 0.3)),
            Param("tau_s", "s", 1e-2, 1e5, lambda d, c: _period(d) / 8.0,
                  "relaxation time of the backbone (the joint's return to straight while the tendon is slack)",
                  log=True, kind="time")),
    apply=_relaxation,
    family="backbone",
    check=_rest_angle_check,
    meaning="viscoelastic backbone (a spring with a relaxing arm, standard linear solid): while the tendon pulls, "
            "the joint follows the tendon and the force carries the backbone's relaxation; when the tendon goes "
            "slack the joint does not spring straight but stands at a share of the angle it held, and creeps "
            "back with the relaxation time",
    signature="a positive residual where the tendon is slack or barely pulled, largest just after the unloading "
              "and fading during the rest; larger after a long or high dwell",
    history=True,
    off={"fraction": 0.0},
)


RELAXATION2 = Effect(
    name="relaxation2", stage="kinematics", pure=True,
    params=(Param("fraction", "", 0.0, 0.9, 0.1,
                  "share of the joint's angle the backbone's fast relaxing arm holds when the tendon lets go",
                  starts=(0.1, 0.3)),
            Param("tau_s", "s", 1e-2, 1e5, lambda d, c: _period(d) / 8.0,
                  "relaxation time of the fast arm (the joint's quick return while the tendon is slack)", log=True,
                  kind="time"),
            Param("slow_fraction", "", 0.0, 0.9, 0.1,
                  "share of the joint's angle the slow arm holds when the tendon lets go", starts=(0.1,)),
            Param("slow_ratio", "", 2.0, 1e3, 10.0,
                  "the slow arm's relaxation time over the fast arm's (its return over many cycles)", log=True,
                  starts=(10.0,))),
    apply=_relaxation2,
    family="backbone",
    check=_rest_angle_check,
    meaning="viscoelastic backbone relaxing on two time scales (a spring with two relaxing arms, as polymers have "
            "a spectrum of relaxation times): unloaded, the joint stands at the shares of the angle it held that "
            "its fast and slow arms keep, and creeps back quickly, then over many cycles",
    signature="as relaxation's, but the joint's return after the unloading is fast at first and then slow: the "
              "rest angle drifts over cycles while each rest starts with a quick decay",
    history=True,
    off={"fraction": 0.0, "slow_fraction": 0.0},
)


# ----------------------------------------------------------------------------- measurement stages

def _bias(ctx: Context, angle: np.ndarray, p: dict) -> np.ndarray:
    return angle + p["bias_deg"]


ANGLE_BIAS = Effect(
    name="angle_bias", stage="angle", pure=True,
    params=(Param("bias_deg", "deg", -90.0, 90.0, 0.0, "constant offset of the angle sensor"),),
    apply=_bias,
    meaning="the angle sensor (EM tracker) reads a constant offset",
    signature="a constant residual everywhere, also where the joint is straight",
    family="offset",
)


def _zero(ctx: Context, force: np.ndarray, p: dict) -> np.ndarray:
    return force - p["zero_N"]


FORCE_ZERO = Effect(
    name="force_zero", stage="force", pure=True,
    params=(Param("zero_N", "N", -10.0, 10.0, 0.0, "load-cell reading at zero tension"),),
    apply=_zero,
    meaning="the load cell is not zeroed: it reads an offset at zero tension",
    signature="a constant residual (the offset times the tendon compliance over the arm)",
    family="offset",
)

#: The built-in effects, in their documented order.
BUILTIN_EFFECTS = (SLACK, PLAY, PLAY_HELD, CARRIAGE_HOLD, CARRIAGE_GAP, CREEP, CREEP_LOAD, FRICTION, CAPSTAN, TOE, TOE_SHAPE, TOE_SOFT, VISCOELASTIC, SERIES, KERF, FLAT_WALLS, CHORDS,
                   HARDSTOP, REST_ANGLE, RELAXATION, RELAXATION2, ANGLE_BIAS, FORCE_ZERO)
#: Built-in effect names in that order.
BUILTINS = tuple(e.name for e in BUILTIN_EFFECTS)
