"""Laser safety check, run on the move list a writer is about to emit.

Every writer (G-code of each dialect, job file, toolpath DXF) calls
:func:`check_moves` on every chunk of moves it writes *before* it formats that
chunk, so no unsafe move is ever formatted; the file layer writes into temporary
files and publishes none if a writer raises. The job file and the toolpath DXF,
which do not print moves, first check the whole neutral move list
(:func:`check_job`, chunk by chunk, once per Job). The check (vectorised,
~0.1 s per 10^6 moves):

1. the beam is off on every rapid, focus (Z) and lead move; the beam is on only
   during cutting moves and the links between chained passes (``LINK``), which are
   checked like cutting moves (rule 3: inside the cut region of the pass they enter,
   the cut of the pass they leave);
2. a focus move changes only z; rapid, lead and laser-on moves keep z;
3. every laser-on move lies inside the design cut region of its pass, grown
   by :data:`camtube.tol.TOL.safety` (both ends inside an axis-aligned
   rectangle; ``covers`` of the segment for other polygons); for a slit (an open
   path) the region is the path itself: the move lies on it within the tolerance;
4. nothing leaves the tube: ``0 <= x <= length`` for every move (lead moves,
   which may leave the cut region, included);
5. the rotary axis cannot wind up: ``-C <= y <= 2C`` (C = 2 pi r_o), i.e.
   ``-360 <= A <= 720`` deg, for every move.
"""
from __future__ import annotations

import math

import numpy as np

from camtube.errors import SafetyError
from camtube.plan.moves import BEAM_KINDS, CUT, FOCUS, KIND_NAMES, LEAD, LINK, RAPID, Moves, iter_moves
from camtube.plan.packed import is_axis_rectangle
from camtube.tol import TOL

MAX_REPORTED = 5


class _Regions:
    """The cut regions of a job as arrays (once per Job): bounds, which are rectangles, shapes of the others."""

    def __init__(self, design, tol: float) -> None:
        n = len(design)
        self.design, self.tol = design, tol
        self.bounds = np.array([c.bounds for c in design], dtype=float).reshape(n, 4)
        self.rect = np.fromiter((is_axis_rectangle(c) for c in design), dtype=bool, count=n)
        self._shapes = np.full(n, None, dtype=object)

    def shapes(self, cuts: np.ndarray) -> np.ndarray:
        """Prepared shapely regions grown by ``tol`` of ``cuts`` (polygon, or the slit's path)."""
        import shapely

        missing = [i for i in np.unique(cuts).tolist() if self._shapes[i] is None]
        for i in missing:
            c = self.design[i]
            geom = (shapely.Polygon(c.points).buffer(self.tol, join_style="mitre") if c.closed
                    else shapely.LineString(c.points).buffer(self.tol))
            shapely.prepare(geom)
            self._shapes[i] = geom
        return self._shapes[cuts]


def _regions(job, tol: float) -> _Regions:
    return job.cache.get(job.cache.regions, tol, lambda: _Regions(job.design, tol))


def _outside_rect(b, x0, y0, x1, y1, tol):
    """Largest distance (mm) by which either end leaves its rectangle (<= 0: inside)."""
    out = np.zeros(len(x0))
    for xs, ys in ((x0, y0), (x1, y1)):
        out = np.maximum.reduce([out, b[:, 0] - xs, xs - b[:, 2], b[:, 1] - ys, ys - b[:, 3]])
    return out - tol


def check_moves(job, moves: Moves, tol: float = TOL.safety) -> None:
    """Raise :class:`SafetyError` naming the pass and place of the first unsafe moves.

    Parameters
    ----------
    job : Job
        The job the moves were emitted from (design regions, tube length, radius).
    moves : Moves
        The emitted moves in the unrolled frame (mm).
    tol : float
        Allowance (mm) for numerical noise, :data:`camtube.tol.TOL.safety`.
    """
    if len(moves) == 0:
        return
    x, y, z = moves.x, moves.y, moves.z
    x0, y0, z0 = moves.starts()
    kind, laser = moves.kind, moves.laser
    reasons: list[tuple[np.ndarray, str]] = []

    reasons.append((laser & ~np.isin(kind, BEAM_KINDS), "the laser is on during a {kind} move"))
    reasons.append(((kind == LINK) & ~laser, "a link between chained passes runs with the laser off"))
    reasons.append(((kind == FOCUS) & ((np.abs(x - x0) > tol) | (np.abs(y - y0) > tol)),
                    "a focus move also moves x or y"))
    reasons.append((((kind == RAPID) | (kind == LEAD)) & (np.abs(z - z0) > tol), "a {kind} move changes the focus"))
    reasons.append((~np.isin(kind, (RAPID, FOCUS, CUT, LEAD, LINK)), "unknown move kind"))
    reasons.append((laser & (np.abs(z - z0) > tol), "the focus changes while the laser is on"))
    length = job.length_mm
    reasons.append(((x < -tol) | (x > length + tol), f"x leaves the tube 0 <= x <= {length:g} mm"))
    circ = 2.0 * math.pi * job.outer_radius_mm
    reasons.append(((y < -circ - tol) | (y > 2 * circ + tol),
                    "the rotary axis winds up beyond -360..720 deg (y outside -C..2C)"))

    on = np.flatnonzero(laser)
    if len(on):
        reg = _regions(job, tol)
        b, rect = reg.bounds, reg.rect
        cut = job.packed.pass_cut[moves.pass_index[on]]
        bad_on = np.zeros(len(on), dtype=bool)
        bad_cut = (cut < 0) | (cut >= len(b))
        bad_on |= bad_cut
        cut = np.where(bad_cut, 0, cut)
        is_rect = rect[cut]
        r = on[is_rect]
        if len(r):
            bad_on[is_rect] |= _outside_rect(b[cut[is_rect]], x0[r], y0[r], x[r], y[r], tol) > 0
        if not is_rect.all():
            import shapely

            g = ~is_rect
            rr = on[g]
            segs = shapely.linestrings(np.stack([np.stack([x0[rr], y0[rr]], 1), np.stack([x[rr], y[rr]], 1)], 1))
            bad_on[g] |= ~shapely.covers(reg.shapes(cut[g]), segs)
        mask = np.zeros(len(moves), dtype=bool)
        mask[on[bad_on]] = True
        reasons.append((mask, "a laser-on move leaves the cut region of its pass"))
        # a link joins two passes of one cut: the pass it leaves must be of the cut it enters
        lk = np.flatnonzero(kind == LINK)
        if len(lk):
            prev = moves.pass_index[lk] - 1
            pk = job.packed
            bad = (prev < 0) | (pk.pass_cut[np.maximum(prev, 0)] != pk.pass_cut[moves.pass_index[lk]])
            mask = np.zeros(len(moves), dtype=bool)
            mask[lk[bad]] = True
            reasons.append((mask, "a link joins passes of different cuts"))

    bad_any = np.zeros(len(moves), dtype=bool)
    for m, _ in reasons:
        bad_any |= m
    if not bad_any.any():
        return
    rows = np.flatnonzero(bad_any)
    first_row = moves.pass_rows()
    p_first = moves.first_pass
    where = "" if p_first == 0 and int(moves.pass_index[-1]) == len(job.passes) - 1 else \
        f" in passes {p_first}..{int(moves.pass_index[-1])}"
    lines = [f"{job.name}: {len(rows)} unsafe move(s){where}; nothing was written"]
    for i in rows[:MAX_REPORTED].tolist():
        p = int(moves.pass_index[i])
        ps = job.passes[p]
        why = "; ".join(msg.format(kind=KIND_NAMES.get(int(kind[i]), "?")) for m, msg in reasons if m[i])
        region = ""
        if 0 <= ps.cut_index < len(job.design):
            bx0, by0, bx1, by1 = job.design[ps.cut_index].bounds
            region = f"; cut region x {bx0:.4f}..{bx1:.4f}, y {by0:.4f}..{by1:.4f} mm"
        lines.append(
            f"pass {p} (cut {ps.cut_index} {ps.kind}, repeat {ps.repeat}, focus {ps.focus_level}, drill "
            f"{ps.drill_index}), move {i - int(first_row[p - p_first])} ({KIND_NAMES.get(int(kind[i]), '?')}) from "
            f"({x0[i]:.4f}, {y0[i]:.4f}, z {z0[i]:.4f}) to ({x[i]:.4f}, {y[i]:.4f}, z {z[i]:.4f}) mm: {why}{region}")
    if len(rows) > MAX_REPORTED:
        lines.append(f"... and {len(rows) - MAX_REPORTED} more")
    raise SafetyError("\n".join(lines))


def check_job(job) -> None:
    """Check the neutral move list of ``job``, chunk by chunk (raises :class:`SafetyError`).

    A Job is immutable, so a passed check is remembered on it: the job file and the
    toolpath DXF of one job share one check.
    """
    if job.cache.checked:
        return
    for mv in iter_moves(job):
        check_moves(job, mv)
    job.cache.checked = True
