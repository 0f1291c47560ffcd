"""Motion-aware time estimate: trapezoidal moves with a machine profile's limits and blending.

The model follows LinuxCNC's trajectory planner for straight moves (``emccanon``
+ ``tp``):

- a move's path length is its XYZ length when it has one, else its rotary (ABC)
  length; the rotary axis is slaved to it;
- its velocity limit is the requested one (G0: the axes' maxima; G1 in G93:
  length x F / 60; in G94: F / 60) capped so that no axis exceeds its maximum
  velocity, ``min_i L v_i / |d_i|``, and, for a move with XYZ motion, at the
  fastest linear axis' velocity (``[TRAJ] MAX_LINEAR_VELOCITY``); its
  acceleration limit likewise ``min_i L a_i / |d_i|``;
- ``exact_stop`` (G61): every move starts and ends at rest (a trapezoid, or a
  triangle when too short to reach speed);
- a path tolerance (G64 P..): consecutive *collinear* pure-XYZ moves join at
  speed (LinuxCNC treats them as tangent); at any other junction the machine
  is taken to stop (a conservative bound: LinuxCNC blends such corners, and
  blends any junction with rotary motion parabolically at half acceleration,
  which this model does not follow).

The velocity along a chain of joined moves is the usual forward/backward pass:
start and end at rest, at each junction the lower of the two limits, limited by
what the acceleration allows over the moves around it. Times in s, lengths in
mm (deg for a pure rotary move).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, replace

import numpy as np

from camtube.machine.bound import time_optimal
from camtube.machine.corners import strategy_moves
from camtube.machine.kinematics import machine_moves
from camtube.plan.moves import FOCUS, LINK, RAPID, Moves, estimate, iter_moves

_LINEAR = "XYZUVW"


@dataclass(frozen=True)
class MotionEstimate:
    """Motion-aware time of a move list or program (s).

    Attributes
    ----------
    total_s : float
        Time of every move, start to end.
    moves : int
        Number of moves.
    stops : int
        Number of junctions where the machine comes to rest.
    """

    total_s: float
    moves: int
    stops: int


def _segment_times(L, v0, v1, vmax, a):
    """Times (s) of moves of length ``L`` entering at ``v0``, leaving at ``v1``, cruising at most at ``vmax``.

    All (m,) arrays; the entry and exit speeds are reachable (checked by the caller's passes).
    """
    # peak speed if the move accelerates then decelerates without a cruise
    vp = np.sqrt(np.maximum(a * L + 0.5 * (v0 * v0 + v1 * v1), 0.0))
    vc = np.minimum(vp, vmax)
    with np.errstate(divide="ignore", invalid="ignore"):
        d_acc = (vc * vc - v0 * v0) / (2 * a)
        d_dec = (vc * vc - v1 * v1) / (2 * a)
        cruise = np.maximum(L - d_acc - d_dec, 0.0)
        t = (vc - v0) / a + (vc - v1) / a + np.where(vc > 0, cruise / vc, 0.0)
    return np.where(L > 0, t, 0.0)


def move_limits(d: np.ndarray, letters, profile, requested_v: np.ndarray):
    """(length, vmax, amax) of straight moves in machine axes.

    Parameters
    ----------
    d : (m, k) float
        Displacement of each move per axis (mm or deg), in the order of ``letters``.
    letters : sequence of str
        Axis letters of the columns.
    profile : MachineProfile
    requested_v : (m,) float
        Requested path velocity (units of the move's length per s); ``inf`` for a rapid.
    """
    lin = np.array([c in _LINEAR for c in letters])
    ad = np.abs(d)
    L_lin = np.sqrt((d[:, lin] ** 2).sum(1)) if lin.any() else np.zeros(len(d))
    L_rot = np.sqrt((d[:, ~lin] ** 2).sum(1)) if (~lin).any() else np.zeros(len(d))
    L = np.where(L_lin > 1e-9, L_lin, L_rot)
    vlim = np.full(len(d), np.inf)
    alim = np.full(len(d), np.inf)
    with np.errstate(divide="ignore", invalid="ignore"):
        for j, c in enumerate(letters):
            lim = profile.axis(c)
            move = ad[:, j] > 0
            vlim = np.where(move, np.minimum(vlim, L * lim.max_velocity / ad[:, j]), vlim)
            alim = np.where(move, np.minimum(alim, L * lim.max_acceleration / ad[:, j]), alim)
    # LinuxCNC's [TRAJ] MAX_LINEAR_VELOCITY (the runner sets it to the fastest linear axis) caps the
    # XYZ path speed of every move that has XYZ motion, e.g. a diagonal rapid
    lin_letters = [c for c in letters if c in _LINEAR]
    if lin_letters:
        v_traj = max(profile.axis(c).max_velocity for c in lin_letters)
        vlim = np.where(L_lin > 1e-9, np.minimum(vlim, v_traj), vlim)
    vmax = np.minimum(vlim, requested_v)
    return L, vmax, alim


#: LinuxCNC 2.9's blend arcs (``tp.h``, ``blendmath.c``): the share of the acceleration a blend arc
#: uses tangentially, and normally (sqrt(1 - 0.5^2)); the share of a line a blend may consume.
BLEND_ACC_RATIO_TANGENTIAL = 0.5
BLEND_ACC_RATIO_NORMAL = math.sqrt(1.0 - BLEND_ACC_RATIO_TANGENTIAL ** 2)
BLEND_DIST_FRACTION = 0.5
BLEND_TOL_FRACTION = 0.25
TP_MIN_SEGMENT_CYCLES = 1.02
#: [TRAJ] ARC_BLEND_GAP_CYCLES, LinuxCNC's default: a line left shorter than this many cycles is consumed.
ARC_BLEND_GAP_CYCLES = 4


def _blend_arcs(L, vmax, a, req, u, blend, tol_mm, a_plane, sample_s=0.0, gap_s=0.0):
    """Lines joined by LinuxCNC's tangent blend arcs: (L, vmax, a, joined) of lines and arcs in turn.

    Follows LinuxCNC 2.9's line-line blend (``blendInit3FromLineLine``, ``blendComputeParameters``):
    at a junction turning by ``phi`` (half-angle ``theta = (pi - phi) / 2``) within tolerance ``T``
    (the G64 P value, at most a quarter of either line), the arc may reach ``d_geom = min(L1, L2,
    cos(theta) T / (1 - sin(theta)))`` along each line (L1: what is left of the first line, at most
    half of it; L2: half the second); its speed is ``v_plan = min(sqrt(a_n tan(theta) d_geom),
    requested)`` with ``a_n = 0.866 a``; its radius ``R = max(v_plan^2 / a_n, R_blend)``; it
    trims ``R / tan(theta)`` off both lines and runs at ``v_plan`` with half the acceleration.

    Parameters
    ----------
    L, vmax, a, req : (m,) float
        Length (mm), velocity limit, acceleration limit and requested velocity of each line.
    u : (m, 3) float
        Unit direction of each line (XYZ).
    blend : (m,) bool
        ``blend[i]``: the junction after line ``i`` is blended (G64 active when it was queued).
    tol_mm : float
        The blending tolerance (G64 P).
    a_plane : float
        Acceleration bound in the plane of the lines (mm/s^2).
    sample_s : float
        LinuxCNC runs a line in no less than ``TP_MIN_SEGMENT_CYCLES`` servo cycles: its speed is
        at most its length over this (s); 0: no such limit.
    gap_s : float
        ``ARC_BLEND_GAP_CYCLES`` servo cycles (s): what is left of a line between two blends, if it
        would take less than this at the next arc's speed, is consumed into that arc (its speed
        and half the acceleration).
    """
    m = len(L)
    trim_start = np.zeros(m)
    out_L, out_v, out_a, out_j = [], [], [], []
    Ll, vl, al, rl = L.tolist(), vmax.tolist(), a.tolist(), req.tolist()
    dots = np.einsum("ij,ij->i", u[:-1], u[1:]).tolist() if m > 1 else []
    a_n = a_plane * BLEND_ACC_RATIO_NORMAL
    a_par = 0.5 * a_plane
    for i in range(m):
        arc = None
        trim_end = 0.0
        if i < m - 1 and blend[i]:
            phi = math.acos(max(-1.0, min(1.0, dots[i])))
            if phi > 1e-9:
                theta = 0.5 * (math.pi - phi)
                T = min(tol_mm, BLEND_TOL_FRACTION * Ll[i], BLEND_TOL_FRACTION * Ll[i + 1])
                L1 = min(Ll[i] - trim_start[i], BLEND_DIST_FRACTION * Ll[i])
                L2 = BLEND_DIST_FRACTION * Ll[i + 1]
                d_tol = math.cos(theta) * T / (1.0 - math.sin(theta))
                d_geom = min(L1, L2, d_tol)
                R_geom = math.tan(theta) * d_geom
                v_plan = min(math.sqrt(a_n * R_geom), max(rl[i], rl[i + 1]))
                v_tri = math.sqrt(2.0 * a_par * d_geom)
                s_blend = min(v_tri, v_plan) / a_par * v_plan
                R_plan = max(v_plan * v_plan / a_n, min(s_blend / phi, R_geom))
                trim_end = R_plan / math.tan(theta)
                trim_start[i + 1] = trim_end
                arc = (R_plan * phi, v_plan)
        left = max(Ll[i] - trim_start[i] - trim_end, 0.0)
        v_i, a_i = (min(vl[i], Ll[i] / sample_s) if sample_s > 0 else vl[i]), al[i]
        if arc is not None and trim_start[i] > 0 and left < gap_s * arc[1]:
            # blendCheckConsume: a line between two blends shorter than ARC_BLEND_GAP_CYCLES cycles at the
            # arc's speed is consumed into the arc: it runs at the arc's speed and tangential acceleration
            v_i, a_i = min(v_i, arc[1]), a_plane * BLEND_ACC_RATIO_TANGENTIAL
        out_L.append(left)
        out_v.append(v_i)
        out_a.append(a_i)
        out_j.append(bool(blend[i]) if i < m - 1 else False)
        if arc is not None:
            out_L.append(arc[0])
            out_v.append(arc[1])
            out_a.append(a_plane * BLEND_ACC_RATIO_TANGENTIAL)
            out_j.append(True)
    Lo = np.array(out_L)
    keep = Lo > 1e-9  # a line the blends on both sides used up entirely is gone
    return Lo[keep], np.array(out_v)[keep], np.array(out_a)[keep], np.array(out_j, dtype=bool)[keep]


def chain_times(L: np.ndarray, vmax: np.ndarray, a: np.ndarray, joined: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Times (s) of a chain of moves (lengths ``L``, speed limits ``vmax``, accelerations ``a``, all (m,)) from rest
    to rest, ``joined[i]``: move ``i`` runs into move ``i + 1`` at the lower of their limits (the last is ignored);
    and each move's exit speed. A backward pass (each move must be able to slow down for the next) and a forward
    pass (it can only speed up so fast) bound the junction speeds."""
    m = len(L)
    joined = np.asarray(joined, bool).copy()
    joined[-1] = False
    vj = np.where(joined, np.minimum(vmax, np.concatenate((vmax[1:], [0.0]))), 0.0)
    vjl = vj.tolist()
    Ll, al = L.tolist(), a.tolist()
    nxt = 0.0
    for i in range(m - 1, -1, -1):
        if vjl[i] > 0:
            vjl[i] = min(vjl[i], math.sqrt(nxt * nxt + 2 * al[i + 1] * Ll[i + 1]))
        nxt = vjl[i]
    prev = 0.0
    for i in range(m):
        if vjl[i] > 0:
            vjl[i] = min(vjl[i], math.sqrt(prev * prev + 2 * al[i] * Ll[i]))
        prev = vjl[i]
    v1 = np.array(vjl)
    v0 = np.concatenate(([0.0], v1[:-1]))
    return _segment_times(L, v0, v1, vmax, a), v1


def trajectory_time(d: np.ndarray, letters, profile, requested_v: np.ndarray, joined: np.ndarray,
                    blend: np.ndarray | None = None) -> MotionEstimate:
    """Time of a sequence of straight moves.

    Parameters
    ----------
    d : (m, k) float
        Per-axis displacement of each move.
    letters : sequence of str
    profile : MachineProfile
    requested_v : (m,) float
        Requested path velocity (``inf`` for rapids).
    joined : (m,) bool
        ``joined[i]``: move ``i`` runs into move ``i + 1`` without stopping (the last is ignored).
    blend : (m,) bool, optional
        ``blend[i]``: the junction after move ``i`` is a LinuxCNC blend arc within the profile's
        tolerance (:func:`_blend_arcs`; pure-XYZ moves only); ``joined`` is then ignored there.
    """
    m = len(d)
    if m == 0:
        return MotionEstimate(0.0, 0, 0)
    L, vmax, a = move_limits(d, letters, profile, requested_v)
    keep = L > 1e-12
    L, vmax, a, joined = L[keep], vmax[keep], a[keep], joined[keep].copy()
    if blend is not None and blend[keep].any():
        lin = np.array([c in _LINEAR for c in letters])
        dk = d[keep][:, lin]
        u = dk / L[:, None]
        plane = min(profile.axis(c).max_acceleration for c in letters[:2])
        req = np.minimum(np.asarray(requested_v, float)[keep], vmax)
        L, vmax, a, joined = _blend_arcs(L, vmax, a, req, u, blend[keep] | joined, float(profile.blending), plane,
                                         TP_MIN_SEGMENT_CYCLES * profile.servo_period_s,
                                         ARC_BLEND_GAP_CYCLES * profile.servo_period_s)
    m = len(L)
    if m == 0:
        return MotionEstimate(0.0, 0, 0)
    t, v1 = chain_times(L, vmax, a, joined)
    return MotionEstimate(float(t.sum()), m, int(np.count_nonzero(v1 == 0)))


def _collinear_cartesian(d: np.ndarray, letters) -> np.ndarray:
    """(m,) bool: move i and move i + 1 are collinear, same direction, and have no rotary motion."""
    lin = np.array([c in _LINEAR for c in letters])
    cart = np.all(d[:, ~lin] == 0, axis=1) if (~lin).any() else np.ones(len(d), bool)
    n = np.linalg.norm(d, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        u = d / n[:, None]
    dot = np.einsum("ij,ij->i", u[:-1], u[1:])
    out = np.zeros(len(d), bool)
    out[:-1] = (dot > 1 - 1e-9) & cart[:-1] & cart[1:] & (n[:-1] > 0) & (n[1:] > 0)
    return out


def estimate_machine_moves(mm, profile) -> MotionEstimate:
    """Motion-aware time of :class:`~camtube.machine.kinematics.MachineMoves` (one chunk or a whole job)."""
    n = mm.neutral
    pos = np.column_stack([mm.ax, mm.ay, mm.az])
    start = np.asarray(mm.start, float)[None, :]
    d = np.diff(np.concatenate([start, pos]), axis=0)
    letters = mm.profile.axes
    rapid = (n.kind == RAPID) | (n.kind == FOCUS)
    req = _requested_velocity(d, letters, mm.feed, ~rapid, mm.profile.feed_mode)
    joined = _joined(d, letters, profile)
    # every pass starts from rest, unless it is entered by a beam-on link from the pass before (a chain
    # of linked passes is one beam-on run; chunks start and end at rest: the estimate does not depend
    # on chunking)
    same_run = (n.pass_index[1:] == n.pass_index[:-1]) | (n.kind[1:] == LINK)
    joined[:-1] &= same_run
    blend = None
    if profile.corner_strategy == "blend":  # the emitter blends beam-on runs and stops where the gate switches
        blend = np.zeros(len(d), bool)
        blend[:-1] = n.laser[:-1] & n.laser[1:] & same_run
        joined &= blend
    return trajectory_time(d, letters, profile, req, joined, blend)


def _joined(d, letters, profile) -> np.ndarray:
    if profile.blending == "exact_stop":
        return np.zeros(len(d), bool)
    return _collinear_cartesian(d, letters)


def _requested_velocity(d, letters, feed, is_feed, feed_mode) -> np.ndarray:
    lin = np.array([c in _LINEAR for c in letters])
    L_lin = np.sqrt((d[:, lin] ** 2).sum(1))
    L_rot = np.sqrt((d[:, ~lin] ** 2).sum(1)) if (~lin).any() else np.zeros(len(d))
    L = np.where(L_lin > 1e-9, L_lin, L_rot)
    with np.errstate(divide="ignore", invalid="ignore"):
        v = L * feed / 60.0 if feed_mode == "inverse_time" else feed / 60.0
    return np.where(is_feed, v, np.inf)


# ---------------------------------------------------------------- G-code programs
_WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")


def estimate_program(text: str, profile) -> MotionEstimate:
    """Motion-aware time of a G-code program (the subset camtube writes).

    Understands ``G0``/``G1`` with the profile's three axis letters and ``F``,
    ``G93``/``G94``, ``G61``/``G64`` (modal), comments in parentheses or after
    ``;``; other words (M-codes, settings) take no time.
    """
    letters = profile.axes
    pos = {c: 0.0 for c in letters}
    mode = "exact_stop" if profile.blending == "exact_stop" else "blend"
    inverse = False
    motion = 0
    feed = 0.0
    rows_d, rows_f, rows_feed, rows_stop, rows_inv = [], [], [], [], []
    for raw in text.splitlines():
        # parenthesised comments first: a ';' inside one (a profile's description) starts no comment
        line = re.sub(r"\(.*?\)", "", raw).split(";", 1)[0].upper()
        if not line.strip():
            continue
        words = _WORD.findall(line)
        target = dict(pos)
        has_axis = False
        for w, v in words:
            val = float(v)
            if w == "G":
                g = round(val, 1)
                if g in (0, 1):
                    motion = int(g)
                elif g == 93:
                    inverse = True
                elif g == 94:
                    inverse = False
                elif g == 61 or g == 61.1:
                    mode = "exact_stop"
                elif g == 64:
                    mode = "blend"
            elif w == "F":
                feed = val
            elif w in target:
                target[w] = val
                has_axis = True
        if not has_axis:
            continue
        rows_d.append([target[c] - pos[c] for c in letters])
        rows_feed.append(motion == 1)
        rows_f.append(feed if motion == 1 else 0.0)
        rows_stop.append(mode == "exact_stop")
        rows_inv.append(inverse)
        pos = target
    if not rows_d:
        return MotionEstimate(0.0, 0, 0)
    d = np.array(rows_d)
    is_feed = np.array(rows_feed)
    f = np.array(rows_f)
    inv = np.array(rows_inv)
    req = np.where(inv, _requested_velocity(d, letters, f, is_feed, "inverse_time"),
                   _requested_velocity(d, letters, f, is_feed, "per_minute"))
    stop = np.array(rows_stop)
    joined = _collinear_cartesian(d, letters) & ~stop
    blend = None
    if profile.corner_strategy == "blend":  # every junction queued under G64 is a blend arc
        blend = ~stop
        blend[-1] = False
        joined &= blend
    return trajectory_time(d, letters, profile, req, joined, blend)


# ---------------------------------------------------------------- jobs
def job_motion_s(job, machine, moves=None) -> float:
    """Motion-aware time (s) of ``job`` on ``machine`` (a profile, or a dialect with one): its limits and blending.

    ``moves``: the move chunks the emitter writes (default: the job's own, or the profile's
    corner strategy); each chunk starts and ends at rest at a pass boundary.
    """
    profile = getattr(machine, "profile", machine)
    if moves is None:
        moves = strategy_moves(job, profile)
    chunks = iter_moves(job) if moves is None else ([moves] if isinstance(moves, Moves) else moves)
    return sum(estimate_machine_moves(machine_moves(job, profile, mv), profile).total_s for mv in chunks)


def job_estimate(job, machine, moves=None):
    """:func:`camtube.plan.moves.estimate` of the moves written for ``machine``, with ``motion_s`` for its profile.

    ``machine``: a :class:`~camtube.machine.MachineProfile` or a dialect with one (None: the
    constant-speed estimate only). Computed once per Job and profile when ``moves`` is None (kept
    in the Job's cache), so the pipeline, the G-code header and the job file share one estimate.
    """
    profile = getattr(machine, "profile", machine)

    def make():
        mv = moves if moves is not None else (strategy_moves(job, profile) if profile is not None else None)
        est = estimate(job) if mv is None else estimate(job, mv)
        if profile is None:
            return est
        return replace(est, motion_s=job_motion_s(job, profile, mv), machine=profile.name)

    if moves is None and profile is not None:
        return job.cache.get(job.cache.motion, profile, make)
    return make()


# ---------------------------------------------------------------- warnings
def slow_job_warning(job, est, profile, short: bool = False) -> str | None:
    """A warning when the estimate exceeds the lower bound by more than ``profile.warn_time_factor``, naming the cause.

    The time above the lower bound (cut length / scan speed) is split into its causes:

    - **segments**: the estimate above the time-optimal bound (:mod:`camtube.machine.bound`): stops
      and slow-downs the machine makes where the path is smooth (a flattened curve cut as
      separate moves under exact stop, or blends slower than its curvature allows);
    - **corners**: the time-optimal bound's path time above the lower bound: braking into the
      true corners and round the curves at the profile's accelerations (the machine cannot do
      better; only higher limits or gentler curves can);
    - **leads**: beam-off lead-ins and lead-outs of an over-travel profile;
    - **rapids**: rapid and focus moves.

    ``short``: one line of at most ~200 characters for a G-code comment (LinuxCNC's interpreter
    refuses lines over 255). Returns None when the estimate is within the factor (or no profile).
    """
    from camtube.fmt import fixed, format_duration_s

    if profile is None or not est.lower_bound_s > 0:
        return None
    factor = profile.warn_time_factor
    if not est.total_s > factor * est.lower_bound_s:
        return None
    opt = time_optimal(job, profile)
    leads = est.lead_s
    parts = {
        "segments": max(est.total_s - opt.total_s - leads, 0.0),
        "corners": max(opt.path_s - est.lower_bound_s, 0.0),
        "leads": leads,
        "rapids": opt.free_s,
    }
    what = {
        "segments": "stops and slow-downs where the path is smooth",
        "corners": f"braking at {opt.stops} true corners and pass ends and round curves at the profile's accelerations",
        "leads": "beam-off lead-ins and lead-outs",
        "rapids": "rapid and focus moves",
    }
    fix = {
        "segments": "a profile that cuts each pass as one blended path (--machine linuxcnc-path) or joins its moves",
        "corners": "higher accelerations in the machine profile, or larger corner and curve radii in the design",
        "leads": "distance gating (laser.gating: distance), which keeps the dose uniform without over-travel",
        "rapids": "fewer, nearer cuts",
    }
    order = sorted(parts, key=lambda k: -parts[k])
    shown = [k for k in order if parts[k] > 0.005 * est.total_s]
    if short:
        return (f"estimate {est.total_s / est.lower_bound_s:.2f} x the lower bound (machine.warn_time_factor "
                f"{fixed(factor)}); above it: " + ", ".join(f"{k} {parts[k]:.1f} s" for k in shown)
                + f"; time-optimal {opt.total_s:.1f} s")
    causes = ", ".join(f"{k} {parts[k]:.1f} s ({what[k]})" for k in shown)
    return (f"the estimated laser time {format_duration_s(est.total_s)} on machine {profile.name} is "
            f"{est.total_s / est.lower_bound_s:.2f} x the lower bound {format_duration_s(est.lower_bound_s)} "
            f"(machine.warn_time_factor = {factor:g}); above the bound: {causes}; the time-optimal motion that stops "
            f"at every true corner takes {format_duration_s(opt.total_s)}; to go faster: {fix[order[0]]}")
