"""Synthesis: the notch pattern that meets a goal under the forward model of :mod:`camtube.joint`.

Per bending direction, for a notch count ``n``:

1. the goal's distribution gives each notch's target angle ``theta*_i`` (from the tip);
2. with friction the tension reaching notch ``i`` is ``T_i = F (1 - loss) exp(-mu W_i)``, ``W_i`` the
   target angles between it and the base, so every notch sees a known fraction of ``F``;
3. for a force ``F`` each notch's arc ``s_i`` is the largest whose backbone stays below
   :data:`STRAIN_DESIGN` of ``limits.max_strain`` (the moment ``T_i arm_i`` is fixed, so the strain
   ``M e / (E I)`` depends on the arc only), its width then follows from ``theta*_i = M h / (E I)``,
   and must stay above the smallest feature and far enough from closure (:data:`CLOSE_MARGIN`);
4. ``F`` is the root of the stroke equation ``slack + sum arm_i theta*_i + elongation(F) = stroke``
   (a scan for the bracket, then ``brentq``);
5. the widths are rounded up to 1 um and the arcs and ``F`` are polished with bounded
   ``scipy.optimize.least_squares`` on the forward model itself (``n + 1`` residuals: every notch's
   angle and the stroke).

A 3-D ``goal.centerline`` is solved piece by piece: each piece is one direction's constant-curvature curve over
its own length (as a planar ``goal.curve``), its pitch lengthened by the axis's shortening
(:func:`_axis_pitch`), the pieces laid out one after the other from the base (:mod:`camtube.synthesis.centerline`).

The notch count is tried from ``ceil(bend / max_notch_bend_deg)`` outwards; the first count that
keeps every limit wins. A goal no count meets raises :class:`InfeasibleGoal` naming the limit and the
nearest feasible target (found by bisection on the bend or the stroke, whichever the limit calls for).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from camtube.design.geometry import joint_geometry
from camtube.design.pattern import ASSUMED_KERF_MM, Pattern, Process, Rules, Tube, hole, sort_cuts
from camtube.design.schema import SCHEMA as PATTERN_SCHEMA
from camtube.errors import CamtubeError
from camtube.joint.forward import Mechanics, hinge_root_mm, hinge_side_factor, notch_set
from camtube.synthesis.goal import BendTarget, Goal, shares_from_tip
from camtube.tol import TOL

#: Backbone strain aimed at, as a fraction of ``limits.max_strain`` (room for the laser's tolerance).
STRAIN_DESIGN = 0.85
#: A notch's target angle is at most this fraction of its closure angle (no contact at the design stroke).
CLOSE_MARGIN = 0.75
#: Points of the arc grid the first pass chooses from.
ARC_GRID = 400
#: Widths are rounded up to this step (mm), arcs written to ARC_STEP.
WIDTH_STEP_MM = 0.001
ARC_STEP_MM = 0.0001
#: Tendon anchor hole (mm): side, and its centre's distance from the tip as a fraction of first_offset.
HOLE_MM = 0.3


class InfeasibleGoal(CamtubeError):
    """No pattern meets the goal: ``limit`` (a goal key) forbids it; ``nearest`` is a feasible target."""

    def __init__(self, message: str, limit: str, nearest: str):
        self.limit, self.nearest = limit, nearest
        super().__init__(message)


def _len(x: float, decimals: int = 2) -> str:
    """A length (or force) for a message: fixed decimals, or 4 digits when it is huge (a goal of 1e300 mm printed
    300 digits)."""
    return f"{x:.{decimals}f}" if abs(x) < 1e6 else f"{x:.4g}"


@dataclass(frozen=True)
class _Fail:
    limit: str  # goal key of the limit
    why: str  # the sentence saying what it forbids
    knob: str  # "bend" or "stroke": what to lower to get a feasible target


@dataclass(frozen=True)
class DirectionDesign:
    """One direction's notches, from the tip.

    Attributes
    ----------
    target : BendTarget
    widths_mm, arcs_mm : tuple[float, ...]
        Per-notch width h and arc s (arcs after rounding to :data:`ARC_STEP_MM`).
    shares : tuple[float, ...]
        Target share of the bend of each notch.
    force_N : float
        Motor-side force at the design stroke (from the polish).
    pitch_mm : float or None
        Centre-to-centre pitch when the goal is a curve (uniform pitch), else None.
    """

    target: BendTarget
    widths_mm: tuple[float, ...]
    arcs_mm: tuple[float, ...]
    shares: tuple[float, ...]
    force_N: float
    pitch_mm: float | None = None

    @property
    def count(self) -> int:
        return len(self.widths_mm)

    @property
    def notched_length_mm(self) -> float:
        return float(sum(self.widths_mm))


@dataclass(frozen=True)
class Design:
    """A synthesized pattern and how it was reached.

    Attributes
    ----------
    goal : Goal
    pattern : Pattern
        The pattern (cuts from the tip; one anchor hole per direction).
    directions : tuple[DirectionDesign, ...]
        In the order of ``goal.bends``.
    mechanics : Mechanics
    notch_section : dict
        The ``notch:`` section of the pattern YAML (per-notch lists, from the tip).
    """

    goal: Goal
    pattern: Pattern
    directions: tuple[DirectionDesign, ...]
    mechanics: Mechanics
    notch_section: dict


def expected_overcut_mm(process, calibration: Mechanics | None = None) -> float:
    """How much wider than drawn the laser cuts each notch (mm, in arc and in width).

    A process with kerf compensation (``process.kerf > 0``) cuts the drawing; without it the first pass
    runs on the design line and the cut is one kerf wider: the calibration's fitted ``kerf.kerf_mm`` when
    given, else the kerf the CAD verification assumes (:data:`camtube.design.pattern.ASSUMED_KERF_MM`).
    """
    if process is not None and process.kerf_mm > 0:
        return 0.0
    if calibration is not None and calibration.kerf_mm:
        return max(calibration.kerf_mm, 0.0)
    return ASSUMED_KERF_MM


def goal_mechanics(goal: Goal, calibration: Mechanics | None = None, process=None) -> Mechanics:
    """The mechanics a goal is designed with: the goal's tube modulus and friction, a calibration, and the
    expected overcut (:func:`expected_overcut_mm`): notches are drawn that much narrower than the cut."""
    m = calibration or Mechanics()
    return replace(m, tube_modulus_gpa=goal.tube_modulus_gpa if goal.tube_modulus_gpa is not None
                   else m.tube_modulus_gpa,
                   friction=goal.tendon.friction if m.friction is None else m.friction,
                   kerf_mm=expected_overcut_mm(process, calibration), hinge=goal.hinge)


class _Grid:
    """Section properties of one tube over a grid of notch arcs (mm)."""

    def __init__(self, goal: Goal, mech: Mechanics, process=None):
        t = goal.tube
        ro, ri = t.outer_radius_mm, t.inner_radius_mm
        k = mech.kerf_mm  # grid arcs are as cut; the drawing is k narrower
        self.kerf = k
        self.s_lo = max(goal.limits.min_feature_mm + k, 2.0 * ro * math.acos(ri / ro) * 1.02)  # reaches the lumen
        self.s_hi = t.circumference_mm - max(goal.limits.min_backbone_arc_mm, 1e-3)
        if process is not None and process.repeats is None and process.repeat_rule:
            # the process cuts at most this beam depth r_o (1 - cos(s / 2 r_o)): a bound on the arc
            deepest = max(r.max_depth_mm for r in process.repeat_rule)
            if deepest < 2.0 * ro:
                self.s_hi = min(self.s_hi, 2.0 * ro * math.acos(1.0 - deepest / ro) - 1e-4 + k)
        s = np.linspace(self.s_lo, self.s_hi, ARC_GRID) if self.s_hi > self.s_lo else np.array([self.s_lo])
        geos = [joint_geometry(ro, ri, float(x), 1.0, goal.tendon.radius_mm) for x in s]
        self.s = s
        self.ei = mech.modulus_gpa(t.material) * 1e3 * np.array([g.second_moment_mm4 for g in geos])
        self.arm = np.array([g.moment_arm_mm for g in geos]) * mech.arm_scale
        self.e = np.array([g.extreme_fibre_mm for g in geos])
        self.ybar = np.array([g.ybar_mm for g in geos])
        # beyond h: a lone notch's root length (times each notch's side factor, 1 but for the fe_row hinge)
        self.extra = np.array([hinge_root_mm(ro, g.phi_rad, mech.hinge, ri) for g in geos])
        self.ro = ro


def _elongation(goal: Goal, mech: Mechanics, f: float) -> float:
    probe = Pattern("goal", goal.tube, (), tendon=goal.tendon)
    return mech.elongation_mm(f, probe)


def _choose(grid: _Grid, goal: Goal, th: np.ndarray, tension: np.ndarray, side: np.ndarray):
    """Per notch (base to tip) the grid index of the largest arc that keeps the limits, or -1; and h there.
    ``side``: per notch the share of the root length its webs leave (:func:`hinge_side_factor`)."""
    lim = goal.limits
    m = tension[:, None] * grid.arm[None, :]  # (n, m) moment N mm
    strain = m * grid.e[None, :] / grid.ei[None, :]
    h = th[:, None] * grid.ei[None, :] / np.maximum(m, 1e-300) - grid.extra[None, :] * side[:, None]  # as cut
    h_close = th[:, None] * (grid.ro + grid.ybar[None, :]) / CLOSE_MARGIN
    ok = (strain <= STRAIN_DESIGN * lim.max_strain) & (h >= lim.min_feature_mm + grid.kerf) & (h >= h_close)
    idx = np.where(ok.any(axis=1), ok.shape[1] - 1 - np.argmax(ok[:, ::-1], axis=1), -1)
    return idx, h, strain, h_close


def _pairs(gaps) -> list[tuple[float, float]]:
    """Per notch (base to tip) its webs to the previous and the next notch from the gaps between them."""
    n = len(gaps) + 1
    return [(gaps[i - 1] if i > 0 else math.inf, gaps[i] if i < n - 1 else math.inf) for i in range(n)]


def _solve_count(goal: Goal, mech: Mechanics, grid: _Grid, target: BendTarget, n: int,
                 budget_mm: float, gaps_fn=None) -> DirectionDesign | _Fail:
    """The design of one direction with ``n`` notches, or why there is none.

    With the ``fe_row`` hinge a notch's stiffness depends on the webs to its neighbours (as cut), which
    ``gaps_fn(widths from the tip)`` gives (base to tip) in the pattern's layout: on a curve they depend on the
    widths, so the solve is repeated with the webs of the widths found until they no longer change.
    """
    if mech.hinge != "fe_row" or gaps_fn is None or n < 2:
        return _solve_count_at(goal, mech, grid, target, n, budget_mm, None)
    widths = (goal.curve_length_mm / n / 2.0 if goal.curve_deg_per_mm else 0.5,) * n
    gaps = [max(x, 0.0) for x in gaps_fn(widths)]  # overlapping notches: no web, no root (and no design)
    for _ in range(30):  # the widths (first pass, before the polish) and the webs they leave, until they settle
        w = _solve_count_at(goal, mech, grid, target, n, budget_mm, _pairs(gaps), widths_only=True)
        if not isinstance(w, tuple):
            return w
        new = [max(x, 0.0) for x in gaps_fn(w)]
        if max(abs(a - b) for a, b in zip(new, gaps)) < 1.5e-3:  # widths are rounded to 1 um
            break
        gaps = [(a + b) / 2.0 for a, b in zip(gaps, new)]  # damped: a wider notch leaves a shorter web
    return _solve_count_at(goal, mech, grid, target, n, budget_mm, _pairs(gaps))


def _solve_count_at(goal: Goal, mech: Mechanics, grid: _Grid, target: BendTarget, n: int,
                    budget_mm: float, webs, widths_only: bool = False) -> DirectionDesign | _Fail | tuple:
    """:func:`_solve_count` at given webs (per notch base to tip, as cut; None: the goal's web inside the row);
    ``widths_only``: just the drawn widths from the tip (the first pass: the polish keeps them)."""
    from scipy.optimize import brentq, least_squares

    if webs is None:
        webs = _pairs([goal.web_mm - mech.kerf_mm] * (n - 1)) if n > 1 else [(math.inf, math.inf)]
    side = np.array([hinge_side_factor(goal.tube.outer_radius_mm, w, mech.hinge) for w in webs])

    lim = goal.limits
    if not grid.s_hi > grid.s_lo:   # the backbone's smallest arc leaves no notch that reaches the lumen
        return _Fail("limits.min_backbone_arc", f"a notch must reach the lumen (an arc of {grid.s_lo:.3f} mm or more), "
                     f"and limits.min_backbone_arc = {lim.min_backbone_arc_mm:g} mm (or the process's deepest cut) "
                     f"leaves at most {grid.s_hi:.3f} mm of the tube's {goal.tube.circumference_mm:.3f} mm", "bend")
    shares = np.array(shares_from_tip(goal, n))
    th = np.radians(target.bend_deg) * shares[::-1]  # base to tip
    wrap = np.cumsum(th) - th
    mu = mech.friction or 0.0
    keep = (1.0 - mech.sheath_loss) * np.exp(-mu * wrap)
    stroke = target.stroke_mm - mech.slack_mm
    if stroke <= 0.0:
        return _Fail("goal.bends[].stroke_mm", f"the stroke {target.stroke_mm:g} mm is taken up by the tendon slack "
                     f"{mech.slack_mm:g} mm", "bend")

    def state(f: float):
        idx, h, strain, h_close = _choose(grid, goal, th, f * keep, side)
        if (idx < 0).any():
            return None, idx, h, strain, h_close
        kin = float(np.sum(grid.arm[idx] * th))
        return kin + _elongation(goal, mech, f) - stroke, idx, h, strain, h_close

    f_top = max(10.0 * lim.max_force_N, 1.0)
    fs = np.geomspace(1e-6, f_top, 100)
    prev = None
    g_prev = 0.0
    bracket = None
    first_bad = None
    for f in fs:
        g, idx, h, strain, h_close = state(float(f))
        if g is None:
            if first_bad is None:
                first_bad = (float(f), idx, h, strain, h_close)
            if prev is not None:
                # the notches bear no more force, and the stroke is not taken up yet: more stroke than this bend uses
                return _stroke_surplus(goal, grid, (float(f), idx, h, strain, h_close), th, target, prev,
                                       g_prev + stroke + mech.slack_mm)
            continue
        if g >= 0.0:
            if prev is None:
                return _Fail("goal.bends[].stroke_mm", f"the bend needs {_len(g + stroke + mech.slack_mm, 3)} mm of tendon "
                             f"travel even without stretching the tendon"
                             + (f" ({_len(mech.slack_mm, 3)} mm of it the calibration's slack, taken up before the "
                                "tendon pulls)" if mech.slack_mm > 0 else "")
                             + f", more than the stroke {target.stroke_mm:g} mm", "bend")
            bracket = (prev, float(f))
            break
        prev, g_prev = float(f), g
    if bracket is None:
        if first_bad is not None:
            return _row_fail(goal, grid, first_bad, th)
        return _Fail("limits.max_force_N", "the stroke stretches the tendon beyond any force searched", "stroke")

    def gfun(f: float) -> float:
        v = state(f)[0]
        return 1.0 if v is None else v

    f0 = float(brentq(gfun, bracket[0], bracket[1], xtol=1e-10, rtol=1e-10))
    g, idx, h, strain, h_close = state(f0)
    if g is None:
        f0 = bracket[0]
        g, idx, h, strain, h_close = state(f0)
    k = grid.kerf  # drawn = as cut - k
    widths = np.ceil((h[np.arange(n), idx] - k) / WIDTH_STEP_MM - 1e-9) * WIDTH_STEP_MM
    widths = np.maximum(widths, lim.min_feature_mm)
    if widths_only:
        return tuple(float(w) for w in widths[::-1])
    arcs0 = grid.s[idx] - k

    x = np.zeros(n)  # positions do not enter the angles (the webs are given)
    probe = Pattern("goal", goal.tube, (), tendon=goal.tendon)

    def residuals(v: np.ndarray) -> np.ndarray:
        ns = notch_set(goal.tube, goal.tendon.radius_mm, target.angle_deg, x, widths, v[:n], mech, webs_mm=webs)
        ang = ns.angles_at(v[n] * (1.0 - mech.sheath_loss), mu)
        st = float(ns.arm_mm @ ang) + mech.elongation_mm(v[n], probe) - stroke
        return np.concatenate([(ang - th) * 1e3, [st * 1e2]])

    v0 = np.concatenate([arcs0, [f0]])
    res = least_squares(residuals, v0, bounds=(np.r_[np.full(n, grid.s_lo - k), 1e-9],
                                               np.r_[np.full(n, grid.s_hi - k), np.inf]),
                        x_scale=np.r_[np.full(n, 0.1), max(f0, 1e-3)], xtol=1e-12, ftol=1e-12, gtol=1e-12,
                        max_nfev=200)
    arcs = np.round(res.x[:n] / ARC_STEP_MM) * ARC_STEP_MM
    force = float(res.x[n])
    if np.max(np.abs(res.fun)) > 5.0:  # 5 mrad or 0.05 mm: the polish could not meet the targets
        return _Fail("limits.min_backbone_arc", "(or the process's deepest cut, process.repeat_rule) the notches cannot be made compliant enough within the arc range "
                     f"{grid.s_lo:.3f}-{grid.s_hi:.3f} mm", "stroke")
    if force > lim.max_force_N:
        return _Fail("limits.max_force_N", f"the tendon force at {target.stroke_mm:g} mm of stroke would be "
                     f"{force:.2f} N, more than limits.max_force_N = {lim.max_force_N:g} N", "stroke")
    ns = notch_set(goal.tube, goal.tendon.radius_mm, target.angle_deg, x, widths, arcs, mech, webs_mm=webs)
    strain_now = ns.strain(ns.angles_at(force * (1.0 - mech.sheath_loss), mu))
    if float(np.max(strain_now)) > lim.max_strain:
        return _Fail("limits.max_strain", f"the backbone strain would be {float(np.max(strain_now)):.4f}, above "
                     f"limits.max_strain = {lim.max_strain:g}", "stroke")
    w_tip, a_tip = tuple(float(w) for w in widths[::-1]), tuple(float(a) for a in arcs[::-1])
    pitch = None
    if goal.curve_deg_per_mm:
        pitch = goal.curve_length_mm / n
        need = max((w_tip[i] + w_tip[i + 1]) / 2.0 for i in range(n - 1)) + lim.min_web_mm if n > 1 else 0.0
        if pitch < need:
            return _Fail("goal.curve_length", f"{n} notches of up to {_len(max(w_tip), 3)} mm do not fit in "
                         f"goal.curve_length = {goal.curve_length_mm:g} mm with webs of limits.min_web", "bend")
        length = pitch * (n - 1) + (w_tip[0] + w_tip[-1]) / 2.0
    else:
        length = sum(w_tip) + goal.web_mm * (n - 1)
    if length > budget_mm + 1e-9:
        return _Fail("limits.max_length", f"the joint would be {_len(length)} mm long (notches {_len(sum(w_tip))} mm "
                     f"+ webs), more than {_len(budget_mm)} mm", "bend")
    return DirectionDesign(target, w_tip, a_tip, tuple(float(s) for s in shares), force, pitch)


def _stroke_surplus(goal: Goal, grid: _Grid, bad, th: np.ndarray, target: BendTarget, f_ok: float,
                    travel_mm: float) -> _Fail:
    """The stroke is more than the bend takes up: at ``f_ok`` N, the most force the notches bear (above it
    :func:`_row_fail`'s limit), the bend and the tendon's stretch take up ``travel_mm`` of it. The knob is the stroke
    (a bend this small asks for less of it)."""
    above = _row_fail(goal, grid, bad, th)
    return _Fail("goal.bends[].stroke_mm", f"the stroke {target.stroke_mm:g} mm is more than a {target.bend_deg:g} deg "
                 f"bend takes up: at {f_ok:.2f} N, the most its notches bear ({above.limit} above it), the bend and "
                 f"the tendon's stretch take up {_len(travel_mm, 3)} mm", "stroke")


def _row_fail(goal: Goal, grid: _Grid, bad, th: np.ndarray) -> _Fail:
    """Why a notch has no arc at the force where the search stopped."""
    f_at, idx, h, strain, h_close = bad
    lim = goal.limits
    row = int(np.flatnonzero(idx < 0)[0])
    if strain[row, 0] > STRAIN_DESIGN * lim.max_strain:
        return _Fail("limits.max_strain", f"at the force the stroke needs ({f_at:.2f} N or more) even the smallest "
                     f"notch arc {grid.s_lo:.3f} mm strains the backbone above {STRAIN_DESIGN:g} x limits.max_strain "
                     f"= {STRAIN_DESIGN * lim.max_strain:.4f}", "stroke")
    if h[row, 0] < h_close[row, 0]:
        return _Fail("goal.max_notch_bend_deg", f"a notch must bend {math.degrees(th[row]):.2f} deg, more than "
                     f"{CLOSE_MARGIN:g} of its closure angle at any arc", "bend")
    return _Fail("limits.min_feature", f"at {f_at:.2f} N a notch bending {math.degrees(th[row]):.2f} deg would be "
                 f"narrower than limits.min_feature = {lim.min_feature_mm:g} mm", "stroke")


def _counts(goal: Goal, target: BendTarget) -> list[int]:
    if isinstance(goal.distribution, tuple):
        return [len(goal.distribution)]
    if goal.notches is not None:
        return [goal.notches]
    n_min = max(4, 2 * len(goal.curve_deg_per_mm) - 1) if goal.curve_deg_per_mm else 2  # resolve the curve
    n0 = max(n_min, math.ceil(target.bend_deg / goal.max_notch_bend_deg))
    return list(range(n0, n0 + 24))  # fewer notches would bend more than max_notch_bend_deg each


def _solve_direction(goal: Goal, mech: Mechanics, grid: _Grid, target: BendTarget,
                     budget_mm: float, deadline: float = math.inf, gaps_fn=None) -> DirectionDesign | _Fail:
    import time

    first: _Fail | None = None
    tries = 0
    for n in _counts(goal, target):
        if first is not None and time.perf_counter() > deadline:
            break
        r = _solve_count(goal, mech, grid, target, n, budget_mm, gaps_fn)
        if isinstance(r, DirectionDesign):
            return r
        first = first or r
        tries += 1
        if tries >= 6 and first.limit in ("limits.max_force_N", "goal.bends[].stroke_mm"):
            break  # the force and the kinematic travel hardly depend on the notch count
        if tries >= 4 and r.limit == first.limit == "limits.max_length":
            break  # more notches only add webs
    return first


def _piece_goal(goal: Goal, i: int) -> tuple[Goal, float]:
    """The goal one direction is solved for, and its length budget (mm): a 3-D centre line's piece ``i`` is a
    constant-curvature curve over its own length; otherwise the goal itself within ``limits.max_length``."""
    if not goal.centerline:
        return goal, goal.limits.max_length_mm
    b, length = goal.bends[i], goal.centerline[i].length_mm
    k = b.bend_deg / length
    return replace(goal, curve_deg_per_mm=(k, k), curve_length_mm=length, bends=(b,)), length


def _axis_pitch(goal: Goal, mech: Mechanics, d: DirectionDesign, length_mm: float) -> DirectionDesign:
    """A centre-line piece's pitch such that the tube's *axis* is ``length_mm`` long once bent.

    Each notch bends about its backbone's neutral fibre, ``ybar`` from the axis on the backbone side, so over
    a notch bending by ``theta`` the axis is ``ybar theta`` shorter than the straight tube: the cells are
    lengthened by that much (positions do not enter the angles, so nothing else changes).
    """
    t = goal.tube
    k = mech.kerf_mm
    th = np.radians(d.target.bend_deg) * np.asarray(d.shares)
    ybar = np.array([joint_geometry(t.outer_radius_mm, t.inner_radius_mm, a + k, w + k).ybar_mm
                     for w, a in zip(d.widths_mm, d.arcs_mm)])
    return replace(d, pitch_mm=(length_mm + float(ybar @ th)) / d.count)


def _gaps_fn(goal: Goal, piece: Goal, mech: Mechanics, target: BendTarget, dirs: list, i: int,
             pitch_add_mm: float = 0.0):
    """``widths from the tip -> webs as cut (base to tip)`` between the notches of direction ``i`` (its notches of
    ``widths``, the others as in ``dirs``) in the goal's layout: what the forward model will see (a notch's
    neighbours are the notches of its own direction, its tendon's). ``pitch_add_mm``: a centre-line piece's
    lengthening of the pitch (:func:`_axis_pitch`)."""
    def f(widths) -> list[float]:
        n = len(widths)
        pitch = piece.curve_length_mm / n + pitch_add_mm if piece.curve_deg_per_mm else None
        cand = DirectionDesign(target, tuple(float(w) for w in widths), (0.0,) * n, (), 0.0, pitch)
        ds = list(dirs)
        ds[i] = cand
        rows = _layout_rows(goal, ds)
        webs = _webs(goal, rows)
        x, pos = [], 0.0
        for j, r in enumerate(rows):
            pos += (rows[j - 1][0] / 2.0 + webs[j - 1] if j else 0.0) + r[0] / 2.0
            x.append(pos)
        mine = sorted(((xx, r[0]) for xx, r in zip(x, rows) if r[2] == target.angle_deg), key=lambda t: -t[0])
        return [abs(a[0] - b[0]) - (a[1] + b[1]) / 2.0 - mech.kerf_mm for a, b in zip(mine, mine[1:])]
    return f


def _solve_all(goal: Goal, mech: Mechanics, grid: _Grid,
               deadline: float = math.inf) -> tuple[DirectionDesign, ...] | tuple[int, _Fail]:
    out = []
    for i, b in enumerate(goal.bends):
        g, budget = _piece_goal(goal, i)
        r = _solve_direction(g, mech, grid, b, budget, deadline, _gaps_fn(goal, g, mech, b, [None], 0))
        if isinstance(r, _Fail):
            if goal.centerline and r.limit == "goal.curve_length":
                r = replace(r, limit=f"goal.centerline[{i}].length_mm",
                            why=r.why.replace("goal.curve_length", f"goal.centerline[{i}].length_mm"))
            return i, r
        if goal.centerline:
            r = _axis_pitch(goal, mech, r, goal.centerline[i].length_mm)
            for _ in range(4 if mech.hinge == "fe_row" else 0):
                # the webs follow the lengthened pitch: solve again with it until the pitch settles
                add = r.pitch_mm - g.curve_length_mm / r.count
                gaps = _gaps_fn(goal, g, mech, b, [None], 0, add)
                r2 = _solve_count(g, mech, grid, b, r.count, budget, gaps)  # the same count first (fast)
                if isinstance(r2, _Fail):
                    r2 = _solve_direction(g, mech, grid, b, budget, deadline, gaps)
                if isinstance(r2, _Fail):
                    return i, r2
                r2 = _axis_pitch(goal, mech, r2, goal.centerline[i].length_mm)
                settled = r2.count == r.count and abs(r2.pitch_mm - r.pitch_mm) < 1e-7
                r = r2
                if settled:
                    break
        out.append(r)
    for _ in range(4 if (mech.hinge == "fe_row" and len(out) > 1 and not goal.centerline
                         and goal.layout != "sequential") else 0):
        # interleaved directions: a notch's own direction's neighbours are two cells away, across another
        # direction's notch: solve again with the others' widths as the last pass found them, until they settle
        last = list(out)
        for i, b in enumerate(goal.bends):
            g, budget = _piece_goal(goal, i)
            r = _solve_direction(g, mech, grid, b, budget, deadline, _gaps_fn(goal, g, mech, b, last, i))
            if isinstance(r, _Fail):
                return i, r
            out[i] = r
        if all(a.widths_mm == b.widths_mm for a, b in zip(last, out)):
            break
    total = _layout_length(goal, out)
    if total > goal.limits.max_length_mm + 1e-9:
        return 0, _Fail("limits.max_length", f"the {len(out)} directions together make a joint of {_len(total)} mm, "
                        f"more than {goal.limits.max_length_mm:g} mm", "bend")
    if goal.centerline:
        rows = _layout_rows(goal, out)
        for j in range(len(rows) - 1):
            web = (rows[j][3] + rows[j + 1][3]) / 2.0 - (rows[j][0] + rows[j + 1][0]) / 2.0
            if web < goal.limits.min_web_mm - TOL.rule:
                return 0, _Fail("limits.min_web", f"two pieces of the centre line meet with a web of {web:.3f} mm, "
                                f"thinner than limits.min_web = {goal.limits.min_web_mm:g} mm", "bend")
    return tuple(out)


def _layout_rows(goal: Goal, dirs) -> list[tuple[float, float, float, float | None]]:
    """``(width, arc, angle, pitch)`` of every notch from the tip, interleaved or one direction after the other
    (a 3-D centre line: its pieces from the tip, the last piece first); ``pitch`` is the notch's cell on a curve
    (uniform within a piece), else None."""
    rows = []
    if goal.centerline:
        for d in reversed(dirs):
            rows += [(w, a, d.target.angle_deg, d.pitch_mm) for w, a in zip(d.widths_mm, d.arcs_mm)]
        return rows
    if goal.layout == "sequential" or len(dirs) == 1:
        for d in dirs:
            rows += [(w, a, d.target.angle_deg, d.pitch_mm) for w, a in zip(d.widths_mm, d.arcs_mm)]
        return rows
    k = max(d.count for d in dirs)
    for i in range(k):
        for d in dirs:
            if i < d.count:
                rows.append((d.widths_mm[i], d.arcs_mm[i], d.target.angle_deg, None))
    return rows


def _layout(goal: Goal, dirs) -> list[tuple[float, float, float]]:
    """``(width, arc, angle)`` of every notch from the tip (see :func:`_layout_rows`)."""
    return [r[:3] for r in _layout_rows(goal, dirs)]


def _webs(goal: Goal, rows) -> list[float]:
    """Web before each next notch (mm): cells of a curve's pitch touch, otherwise ``goal.web``."""
    out = []
    for a, b in zip(rows, rows[1:]):
        if a[3] is not None and b[3] is not None:
            out.append((a[3] + b[3]) / 2.0 - (a[0] + b[0]) / 2.0)
        else:
            out.append(goal.web_mm)
    return out


def _layout_length(goal: Goal, dirs) -> float:
    rows = _layout_rows(goal, dirs)
    return sum(r[0] for r in rows) + sum(_webs(goal, rows))


def _assemble(goal: Goal, dirs: tuple[DirectionDesign, ...], mech: Mechanics, process=None) -> Design:
    rows = _layout_rows(goal, dirs)
    widths = [r[0] for r in rows]
    webs = [round(w, 4) for w in _webs(goal, rows)]
    section = {
        "layout": "uan", "count": len(rows), "first_offset": goal.first_offset_mm,
        "widths": [round(w, 4) for w in widths], "arcs": [round(r[1], 4) for r in rows],
        "spacings": webs, "angles_deg": [float(round(r[2], 6)) for r in rows],
    }
    length = goal.first_offset_mm + sum(section["widths"]) + sum(webs) + goal.base_length_mm
    longest = PATTERN_SCHEMA["tube"]["length"].hi
    if round(length, 4) > longest:  # (a huge first_offset or base_length: the pattern would be refused, unwritten)
        raise InfeasibleGoal(f"{goal.source + ': ' if goal.source else ''}goal.first_offset = {goal.first_offset_mm:.4g} "
                             f"mm, the joint and goal.base_length = {goal.base_length_mm:.4g} mm make a tube of "
                             f"{length:.4g} mm, longer than a pattern's tube.length may be ({longest:g} mm); fix: "
                             "shorten goal.first_offset or goal.base_length", "goal.base_length", "none")
    from camtube.design.generate import notch_row

    cuts = list(notch_row(len(rows), 0.0, 0.0, 0.0, goal.first_offset_mm, widths_mm=section["widths"],
                          arcs_mm=section["arcs"], spacings_mm=webs, angles_deg=section["angles_deg"]))
    hx = goal.first_offset_mm / 2.0
    cuts += [hole(hx, min(HOLE_MM, goal.first_offset_mm / 2.0), d.target.angle_deg) for d in dirs]
    lim = goal.limits
    tube = Tube(goal.tube.outer_radius_mm, goal.tube.inner_radius_mm, round(length, 4), goal.tube.material)
    rules = Rules(min_backbone_arc_mm=lim.min_backbone_arc_mm, min_web_mm=lim.min_web_mm,
                  max_strain=lim.max_strain, max_stroke_mm=max(b.stroke_mm for b in goal.bends))
    pattern = Pattern(goal.name, tube, sort_cuts(cuts), process or Process(), goal.tendon, rules, goal.source)
    return Design(goal, pattern, dirs, mech, section)


def synthesize(goal: Goal, calibration: Mechanics | None = None, time_limit_s: float = 8.0) -> Design:
    """The pattern that meets ``goal`` (see the module docstring).

    ``time_limit_s`` bounds the search: past it no further notch count is tried and the nearest feasible
    target of an infeasible goal is reported as found so far (still feasible, perhaps not the largest).

    Raises
    ------
    InfeasibleGoal
        One line: the limit that forbids the goal and the nearest feasible target.
    """
    import time

    from camtube.synthesis.goal import goal_process

    deadline = time.perf_counter() + time_limit_s
    process = goal_process(goal)
    mech = goal_mechanics(goal, calibration, process)
    grid = _Grid(goal, mech, process)
    r = _solve_all(goal, mech, grid, deadline - 0.5 * time_limit_s)
    if isinstance(r, tuple) and r and isinstance(r[0], DirectionDesign):
        return _assemble(goal, r, mech, process)
    i, fail = r
    nearest = _nearest(goal, mech, grid, fail.knob, deadline)
    b = goal.bends[i]
    where = f"{goal.source}: " if goal.source else ""
    what = f"goal.centerline[{i}]" if goal.centerline else f"goal.bends[{i}]"
    found = not nearest.startswith("none found")
    knob = "bend_deg" if fail.knob == "bend" else "stroke_mm"
    # (with none found, "lower bend_deg to the nearest target" pointed at a target the same line said was not there)
    lower = f"lower {knob} to the nearest target, or " if found else ""
    raise InfeasibleGoal(f"{where}{what} ({b.bend_deg:g} deg at {b.stroke_mm:g} mm towards {b.angle_deg:g} deg) "
                         f"is infeasible: {fail.limit}: {fail.why}; nearest feasible target: {nearest}; fix: "
                         + (f"{lower}give more stroke or relax {fail.limit}" if fail.knob == "bend" else
                            f"{lower}ask for more bend" if fail.limit == "goal.bends[].stroke_mm" else
                            f"{lower}relax {fail.limit}") + ("" if found else ", or change the stock (the tube)"),
                         fail.limit, nearest)


def _nearest(goal: Goal, mech: Mechanics, grid: _Grid, knob: str, deadline: float = math.inf) -> str:
    """The largest scale of the bends (knob 'bend') or strokes ('stroke') below 1 that is feasible, in words."""
    import time

    def ok(q: float) -> bool:
        g = goal.with_bends(b.scaled(bend=q) if knob == "bend" else b.scaled(stroke=q) for b in goal.bends)
        r = _solve_all(g, mech, grid, deadline)
        return isinstance(r, tuple) and bool(r) and isinstance(r[0], DirectionDesign)

    lo, hi = 0.0, 1.0
    for q in (0.95, 0.85, 0.7, 0.55, 0.4, 0.25, 0.1, 0.03):
        if ok(q):
            lo = q
            break
        hi = q
        if time.perf_counter() > deadline:
            return ("none found within the time limit by scaling the " + ("bends" if knob == "bend" else "strokes")
                    + f" down to {q:g} x")
    else:
        return "none found by scaling the " + ("bends" if knob == "bend" else "strokes") + " down"
    for _ in range(9):
        if time.perf_counter() > deadline:
            break
        mid = 0.5 * (lo + hi)
        if ok(mid):
            lo = mid
        else:
            hi = mid
    parts = []
    for b in goal.bends:
        s = b.scaled(bend=lo) if knob == "bend" else b.scaled(stroke=lo)
        # rounded towards the feasible side
        parts.append(f"{math.floor(s.bend_deg * 10) / 10:.1f} deg at {math.floor(s.stroke_mm * 1000) / 1000:.3f} mm")
    return ", ".join(parts)
