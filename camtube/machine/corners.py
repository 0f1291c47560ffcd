"""Corner strategies: how a machine turns the corners of a laser path.

``none``
    The job's moves unchanged: the edges of a path run back to back with the gate
    open. Under exact stop (G61) the machine stops at every corner and the gate
    switches at rest, so every corner is cut exactly and the beam never leaves the
    path, but each edge accelerates and decelerates with the beam on (a higher
    dose near corners).
``overtravel`` (uniform dose)
    Every cut edge runs at the scan speed from end to end: the machine accelerates
    on a beam-off lead-in along the edge's own line, the gate opens where the edge
    starts, closes where it ends, and the machine decelerates on a beam-off
    lead-out beyond it; a beam-off rapid then brings it to the next edge's lead-in.
    Lead-ins and lead-outs are ``LEAD`` moves (gate closed, may leave the cut
    region, never the tube: they are clipped to ``0 <= x <= length``, where the
    edge then starts below the scan speed). Their length is the braking distance
    ``v^2 / (2 a)`` along the edge's direction (``a`` the path acceleration the
    profile's axis limits allow in that direction) times :data:`LEAD_MARGIN`, plus
    :data:`LEAD_CYCLES` servo cycles at speed. The machine must join collinear moves
    at speed (LinuxCNC does for pure-XYZ lines under G64; it blends any move with
    rotary motion parabolically, so a rotary-A profile cannot use this strategy:
    see ``docs/motion.md``).
"""
from __future__ import annotations

import math
from typing import Iterator

import numpy as np

from camtube.plan.moves import CUT, FOCUS, LEAD, LINK, RAPID, Moves, iter_moves

LEAD_MARGIN = 1.25
LEAD_CYCLES = 4


def surface_accel_limits(profile, outer_radius_mm: float) -> tuple[float, float]:
    """(axial, circumferential) acceleration limits on the outer surface (mm/s^2)."""
    ax, ay, _ = profile.axes
    a_c = profile.axis(ay).max_acceleration
    if profile.rotary:
        a_c = math.radians(a_c) * outer_radius_mm
    return profile.axis(ax).max_acceleration, a_c


def lead_length_mm(ux: np.ndarray, uy: np.ndarray, speed: np.ndarray, profile, outer_radius_mm: float) -> np.ndarray:
    """Lead length (mm) for edges with unit directions (ux, uy) cut at ``speed`` (mm/s)."""
    a_x, a_y = surface_accel_limits(profile, outer_radius_mm)
    with np.errstate(divide="ignore"):
        a = np.minimum(np.where(np.abs(ux) > 1e-12, a_x / np.abs(ux), np.inf),
                       np.where(np.abs(uy) > 1e-12, a_y / np.abs(uy), np.inf))
    return LEAD_MARGIN * speed * speed / (2.0 * a) + LEAD_CYCLES * profile.servo_period_s * speed


def overtravel(job, mv: Moves, profile, final: bool = False) -> Moves:
    """The moves of a chunk with every CUT edge given a lead-in and a lead-out (see the module docstring).

    ``final``: the chunk ends the job; a beam-off rapid back to the last edge's end follows the
    last lead-out (LinuxCNC brakes the last edge of a program early when its lead-out is the
    program's last move).
    """
    if len(mv) == 0:
        return mv
    if (mv.kind == LINK).any():  # every edge gets its own leads: a chained pass is entered by a rapid again
        link = mv.kind == LINK
        mv = Moves(mv.x, mv.y, mv.z, np.where(link, RAPID, mv.kind).astype(np.int8), mv.laser & ~link,
                   mv.pass_index, mv.vertex, np.where(link, 0.0, mv.speed), mv.start)
    x0, y0, z0 = mv.starts()
    length = job.length_mm
    cut = np.flatnonzero(mv.kind == CUT)
    dx, dy = mv.x[cut] - x0[cut], mv.y[cut] - y0[cut]
    L = np.hypot(dx, dy)
    with np.errstate(invalid="ignore", divide="ignore"):
        ux, uy = dx / L, dy / L
    d = lead_length_mm(ux, uy, mv.speed[cut], profile, job.outer_radius_mm)

    def clip(px, py, ex, ey):  # shorten a lead so that x stays on the tube
        t = np.ones(len(px))
        with np.errstate(invalid="ignore", divide="ignore"):
            t = np.where(ex < 0, (px - 0.0) / (px - ex), t)
            t = np.where(ex > length, (length - px) / (ex - px), t)
        t = np.clip(np.nan_to_num(t, nan=0.0), 0.0, 1.0)
        return px + (ex - px) * t, py + (ey - py) * t

    sx, sy = clip(x0[cut], y0[cut], x0[cut] - ux * d, y0[cut] - uy * d)
    ex, ey = clip(mv.x[cut], mv.y[cut], mv.x[cut] + ux * d, mv.y[cut] + uy * d)
    lead_in = {int(r): (float(a), float(b)) for r, a, b in zip(cut, sx, sy)}
    lead_out = {int(r): (float(a), float(b)) for r, a, b in zip(cut, ex, ey)}
    cols: list[list] = [[] for _ in range(8)]

    def add(x, y, z, kind, laser, p, v, speed):
        for c, val in zip(cols, (x, y, z, kind, laser, p, v, speed)):
            c.append(val)

    X, Y, Z = mv.x.tolist(), mv.y.tolist(), mv.z.tolist()
    K, P, V, S = mv.kind.tolist(), mv.pass_index.tolist(), mv.vertex.tolist(), mv.speed.tolist()
    X0, Y0 = x0.tolist(), y0.tolist()
    n = len(mv)
    i = 0
    while i < n:
        p = P[i]
        j = i
        while j < n and P[j] == p:
            j += 1
        cuts = [r for r in range(i, j) if K[r] == CUT]
        first = lead_in[cuts[0]] if cuts else None
        for r in range(i, j):
            k = K[r]
            if k in (RAPID, FOCUS) and not cuts:
                add(X[r], Y[r], Z[r], k, False, p, V[r], 0.0)
            elif k == RAPID and r < cuts[0]:
                add(first[0], first[1], Z[r], RAPID, False, p, -1, 0.0)
            elif k == FOCUS and r < cuts[0]:
                add(first[0], first[1], Z[r], FOCUS, False, p, -1, 0.0)
            elif k == CUT:
                lx, ly = lead_in[r]
                if r != cuts[0]:
                    add(lx, ly, Z[r], RAPID, False, p, -1, 0.0)
                if math.hypot(X0[r] - lx, Y0[r] - ly) > 1e-9:
                    add(X0[r], Y0[r], Z[r], LEAD, False, p, -1, S[r])
                add(X[r], Y[r], Z[r], CUT, True, p, V[r], S[r])
                ox, oy = lead_out[r]
                if math.hypot(ox - X[r], oy - Y[r]) > 1e-9:
                    add(ox, oy, Z[r], LEAD, False, p, -1, S[r])
            else:  # a rapid, focus or lead row between cuts: keep it
                add(X[r], Y[r], Z[r], k, bool(mv.laser[r]), p, V[r], S[r])
        i = j
    if final and cuts:
        r = cuts[-1]
        add(X[r], Y[r], Z[r], RAPID, False, P[r], V[r], 0.0)
    f = lambda c, t: np.asarray(c, dtype=t)  # noqa: E731
    return Moves(f(cols[0], float), f(cols[1], float), f(cols[2], float), f(cols[3], np.int8), f(cols[4], bool),
                 f(cols[5], np.int64), f(cols[6], np.int64), f(cols[7], float), mv.start)


class StrategyMoves:
    """The job's moves under ``profile``'s corner strategy, chunk by chunk; iterable more than once."""

    def __init__(self, job, profile) -> None:
        self.job, self.profile = job, profile

    def __iter__(self) -> Iterator[Moves]:
        start = None
        it = iter_moves(self.job)
        nxt = next(it, None)
        while nxt is not None:
            mv, nxt = nxt, next(it, None)
            if start is not None:  # the previous chunk ended at a lead-out, not at the pass's last vertex
                mv = Moves(mv.x, mv.y, mv.z, mv.kind, mv.laser, mv.pass_index, mv.vertex, mv.speed, start)
            if self.profile.corner_strategy == "overtravel":
                mv = overtravel(self.job, mv, self.profile, final=nxt is None)
            start = mv.end
            yield mv


def strategy_moves(job, profile):
    """The job's moves under the profile's corner strategy (None: the job's own moves, unchanged)."""
    if profile is None or profile.corner_strategy == "none":
        return None
    return StrategyMoves(job, profile)
