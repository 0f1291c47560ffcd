"""The move list of a Job, in chunks of passes, and its time estimate.

A :class:`Moves` is the machine-neutral sequence every post-processor writes
and the safety check inspects: one row per straight move, in the unrolled
frame (x along the tube, y arc length on the outer surface, z focus offset
into the material, all mm). Per pass: a rapid to the path's start (laser off,
at the previous focus), a focus move if the focus changes (laser off), then
one laser-on move per edge of the path at the pass's scan speed (a closed path
returns to its start; an open one, a slit, ends at its last point).
The machine starts at x = y = z = 0.

Move kinds: ``RAPID`` (G0, laser off), ``FOCUS`` (G0 Z, laser off), ``CUT``
(G1, laser on, inside the cut region of its pass), ``LEAD`` (G1 at the
row's speed with the laser off: a lead-in or over-travel that may leave the cut
region but never the tube; a post-processor or a corner strategy adds them) and
``LINK`` (G1 at the scan speed with the laser on, in place of the rapid of a pass
that is chained to the one before it, ``Packed.pass_link``: from the end of that
pass to the start of this one, across the strip between the two drill offsets of
one cut, inside its cut region; the ``chained`` ordering).

Large jobs are never held as one move list: :func:`iter_moves` yields the moves
of :data:`CHUNK_PASSES` passes at a time (each chunk starts where the previous
one ended, :attr:`Moves.start`), and every writer builds, checks and formats one
chunk, then drops it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Iterable, Iterator

import numpy as np

RAPID, FOCUS, CUT, LEAD, LINK = 0, 1, 2, 3, 4
KIND_NAMES = {RAPID: "rapid", FOCUS: "focus", CUT: "cut", LEAD: "lead", LINK: "link"}
#: Kinds of the beam-on moves.
BEAM_KINDS = (CUT, LINK)

#: Passes per chunk of the streaming writers (a few MB of arrays and text).
CHUNK_PASSES = 4096


@dataclass(frozen=True, eq=False)
class Moves:
    """Straight moves; move ``i`` runs from target ``i - 1`` (or :attr:`start`) to target ``i``.

    Attributes
    ----------
    x, y, z : (m,) float
        Target of each move (mm; z = focus offset into the material, >= 0).
    kind : (m,) int8
        RAPID, FOCUS, CUT, LEAD or LINK.
    laser : (m,) bool
        Beam gate during the move (the post-processor switches it where it changes).
    pass_index : (m,) int
        Pass of the job the move belongs to (non-decreasing).
    vertex : (m,) int
        Row of ``job.packed.vertices`` a move ends at (-1 if none, e.g. a lead move).
    speed : (m,) float
        Speed on the outer surface (mm/s) of CUT, LINK and LEAD moves; 0 for rapid and focus moves.
    start : tuple[float, float, float]
        (x, y, z) where the first move starts: the origin, or the end of the previous chunk.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    kind: np.ndarray
    laser: np.ndarray
    pass_index: np.ndarray
    vertex: np.ndarray
    speed: np.ndarray
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def __len__(self) -> int:
        return len(self.x)

    def starts(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x0, y0, z0): the start point of every move, (m,) each."""
        sh = lambda a, s: np.concatenate(([s], a[:-1]))  # noqa: E731
        return sh(self.x, self.start[0]), sh(self.y, self.start[1]), sh(self.z, self.start[2])

    @property
    def end(self) -> tuple[float, float, float]:
        """(x, y, z) after the last move (the start of the next chunk)."""
        if len(self) == 0:
            return self.start
        return float(self.x[-1]), float(self.y[-1]), float(self.z[-1])

    @property
    def first_pass(self) -> int:
        """Pass index of the first row (0 if empty)."""
        return int(self.pass_index[0]) if len(self) else 0

    def pass_rows(self) -> np.ndarray:
        """(n + 1,) int: the chunk's ``k``-th pass (``first_pass + k``) owns rows ``[r[k], r[k + 1])``."""
        if len(self) == 0:
            return np.zeros(1, dtype=np.int64)
        p0, p1 = self.first_pass, int(self.pass_index[-1])
        return np.searchsorted(self.pass_index, np.arange(p0, p1 + 2))

    @classmethod
    def concat(cls, chunks: Iterable["Moves"]) -> "Moves":
        """One move list of consecutive chunks (for small jobs and tests)."""
        chunks = list(chunks)
        if not chunks:
            return empty_moves()
        cat = lambda f: np.concatenate([getattr(c, f) for c in chunks])  # noqa: E731
        return cls(*(cat(f) for f in ("x", "y", "z", "kind", "laser", "pass_index", "vertex", "speed")),
                   start=chunks[0].start)

    def rows(self, lo: int, hi: int) -> "Moves":
        """Rows ``[lo, hi)`` as a chunk (starting where row ``lo - 1`` ends)."""
        start = self.start if lo == 0 else (float(self.x[lo - 1]), float(self.y[lo - 1]), float(self.z[lo - 1]))
        s = slice(lo, hi)
        return Moves(self.x[s], self.y[s], self.z[s], self.kind[s], self.laser[s], self.pass_index[s],
                     self.vertex[s], self.speed[s], start)


def empty_moves(start=(0.0, 0.0, 0.0)) -> Moves:
    e = np.zeros(0)
    return Moves(e, e, e, np.zeros(0, np.int8), np.zeros(0, bool), np.zeros(0, np.int64), np.zeros(0, np.int64), e,
                 start)


def _pass_end_state(pk, p: int) -> tuple[float, float, float]:
    """(x, y, z) of the beam after pass ``p`` (the origin for p < 0)."""
    if p < 0:
        return 0.0, 0.0, 0.0
    x, y = pk.pass_end(p)
    return x, y, float(pk.pass_z[p])


def job_moves(job, lo: int = 0, hi: int | None = None) -> Moves:
    """The neutral move list of passes ``[lo, hi)`` of ``job`` (default: all), vectorised over passes.

    The chunk starts where pass ``lo - 1`` ended (the origin for ``lo = 0``).
    """
    pk = job.packed
    n_all = pk.n_pass
    hi = n_all if hi is None else min(int(hi), n_all)
    lo = max(0, int(lo))
    sx, sy, sz = _pass_end_state(pk, lo - 1)
    if hi <= lo:
        return empty_moves((sx, sy, sz))
    g = pk.pass_geom[lo:hi]
    size = pk.geom_size[g]
    closed = pk.geom_closed[g]
    n_cut = size - (~closed)  # closed: back to the first vertex; open: first to last
    first = pk.geom_offset[g]
    z = pk.pass_z[lo:hi]
    z_prev = np.concatenate(([sz], z[:-1]))
    foc = (z != z_prev).astype(np.int64)
    cnt = 1 + foc + n_cut
    row0 = np.cumsum(cnt) - cnt
    m = int(cnt.sum())
    n_pass = hi - lo
    pidx = np.repeat(np.arange(n_pass), cnt)
    kind = np.full(m, CUT, dtype=np.int8)
    # a chained pass is entered by a beam-on link from the end of the one before (same focus: no focus row)
    kind[row0] = np.where(pk.pass_link[lo:hi], LINK, RAPID)
    kind[(row0 + 1)[foc == 1]] = FOCUS
    j = np.arange(m) - np.repeat(row0 + 1 + foc, cnt)  # 0.. on cut rows, negative before
    fp, sp_ = first[pidx], size[pidx]
    vtx = np.where(j >= 0, fp + (j + 1) % sp_, fp)
    laser = np.isin(kind, BEAM_KINDS)
    zz = z[pidx]
    zz[row0] = z_prev
    v = pk.vertices[vtx]
    speed = np.where(laser, pk.pass_speed[lo:hi][pidx], 0.0)
    return Moves(v[:, 0].copy(), v[:, 1].copy(), zz, kind, laser, pidx + lo, vtx, speed, (sx, sy, sz))


def iter_moves(job, chunk_passes: int = CHUNK_PASSES) -> Iterator[Moves]:
    """The job's moves, about :data:`CHUNK_PASSES` passes at a time (consecutive chunks, no gaps).

    A chunk never splits a chain of linked passes: each starts with a pass entered by a rapid,
    so every chunk starts and ends at rest with the gate closed.
    """
    for lo, hi in job.packed.chunk_bounds(chunk_passes):
        yield job_moves(job, lo, hi)


@dataclass(frozen=True)
class Estimate:
    """Time estimate of a job (s) and its lower bound.

    Attributes
    ----------
    cut_s : float
        Laser-on time: every edge at its scan speed on the outer surface.
    rapid_s : float
        Laser-off traverses: surface distance sqrt(dx^2 + dy^2) at ``process.rapid_speed_mm_s``.
    focus_s : float
        Z moves: |dz| at ``process.focus_speed_mm_s``.
    lower_bound_s : float
        Total cut length / scan speed: no job cutting these passes can be faster.
    cut_length_mm : float
        Total length of every pass.
    passes, cuts : int
    lead_s : float
        Laser-off feed moves (LEAD) at their own speed.
    link_length_mm, link_s : float
        Beam-on links between chained passes (LINK): their length (not part of ``cut_length_mm``,
        so not of the lower bound) and their time at the scan speed.
    motion_s : float or None
        The motion-aware time for a machine profile (trapezoidal moves with its axis limits
        and blending, :mod:`camtube.machine.motion_time`); when set it is :attr:`total_s`.
    machine : str or None
        Name of the profile ``motion_s`` was computed for.
    """

    cut_s: float
    rapid_s: float
    focus_s: float
    lower_bound_s: float
    cut_length_mm: float
    passes: int
    cuts: int
    lead_s: float = 0.0
    motion_s: float | None = None
    machine: str | None = None
    link_length_mm: float = 0.0
    link_s: float = 0.0

    @property
    def constant_speed_s(self) -> float:
        """Every move at its nominal speed (no acceleration): cut + link + rapid + focus + lead."""
        return self.cut_s + self.link_s + self.rapid_s + self.focus_s + self.lead_s

    @property
    def total_s(self) -> float:
        return self.constant_speed_s if self.motion_s is None else self.motion_s

    @property
    def ratio(self) -> float:
        """Estimated time / lower bound (>= 1)."""
        return self.total_s / self.lower_bound_s if self.lower_bound_s > 0 else float("nan")


def _estimate_of(job, chunks: Iterable[Moves]) -> Estimate:
    length = cut_s = rapid_d = focus_d = lead_s = link_mm = link_s = 0.0
    for mv in chunks:
        x0, y0, z0 = mv.starts()
        d = np.hypot(mv.x - x0, mv.y - y0)
        cut = mv.kind == CUT
        length += float(d[cut].sum())
        cut_s += float((d[cut] / mv.speed[cut]).sum()) if cut.any() else 0.0
        link = mv.kind == LINK
        if link.any():
            link_mm += float(d[link].sum())
            link_s += float((d[link] / mv.speed[link]).sum())
        lead = mv.kind == LEAD
        if lead.any():
            lead_s += float((d[lead] / mv.speed[lead]).sum())
        rapid_d += float(d[mv.kind == RAPID].sum())
        focus_d += float(np.abs(mv.z - z0)[mv.kind == FOCUS].sum())
    pr = job.process
    lower = length / pr.scan_speed_mm_s
    return Estimate(cut_s, rapid_d / pr.rapid_speed_mm_s, focus_d / pr.focus_speed_mm_s, lower, length,
                    len(job.passes), len(job.design), lead_s, link_length_mm=link_mm, link_s=link_s)


def estimate(job, moves: Moves | Iterable[Moves] | None = None) -> Estimate:
    """Cutting, rapid, focus and lead time of ``job`` from its move list.

    Parameters
    ----------
    moves : Moves or iterable of consecutive Moves chunks, optional
        Default: the job's own moves, chunk by chunk (computed once per Job and cached).
    """
    if moves is None:
        if job.cache.estimate is None:
            job.cache.estimate = _estimate_of(job, iter_moves(job))
        return job.cache.estimate
    return _estimate_of(job, [moves] if isinstance(moves, Moves) else moves)


def time_warning(job, est: Estimate) -> str | None:
    """A warning when the estimated laser time exceeds ``job.process.max_time_h``, else None."""
    from camtube.fmt import fixed, format_duration_s

    limit_h = getattr(job.process, "max_time_h", None)
    if limit_h is None or not est.total_s > limit_h * 3600.0:
        return None
    return (f"the estimated laser time {format_duration_s(est.total_s)} exceeds process.max_time_h = {fixed(limit_h)} h "
            f"({format_duration_s(limit_h * 3600.0)}) for {est.passes} passes of {est.cuts} cuts; split the job "
            f"(fewer notches per file) or raise process.max_time_h")
