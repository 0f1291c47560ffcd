"""The move list of a Job, and its time estimate.

A :class:`Moves` is the machine-neutral sequence every post-processor writes
and the safety check inspects: one row per straight move, in the unrolled
frame (x along the tube, y arc length on the outer surface, z focus offset
into the material, all mm). Per pass: a rapid to the path's start (laser off,
at the previous focus), a focus move if the focus changes (laser off), then
one laser-on move per edge of the closed path at the pass's scan speed.
The machine starts at x = y = z = 0.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

RAPID, FOCUS, CUT = 0, 1, 2
KIND_NAMES = {RAPID: "rapid", FOCUS: "focus", CUT: "cut"}


@dataclass(frozen=True, eq=False)
class Moves:
    """Straight moves; move ``i`` runs from target ``i - 1`` (or the origin) to target ``i``.

    Attributes
    ----------
    x, y, z : (m,) float
        Target of each move (mm; z = focus offset into the material, >= 0).
    kind : (m,) int8
        RAPID, FOCUS or CUT.
    laser : (m,) bool
        Beam gate during the move (the post-processor switches it where it changes).
    pass_index : (m,) int
        Pass the move belongs to.
    vertex : (m,) int
        Row of ``job.packed.vertices`` a move ends at (all kinds).
    speed : (m,) float
        Cutting speed on the outer surface (mm/s); 0 for laser-off moves.
    """

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    kind: np.ndarray
    laser: np.ndarray
    pass_index: np.ndarray
    vertex: np.ndarray
    speed: np.ndarray

    def __len__(self) -> int:
        return len(self.x)

    def starts(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(x0, y0, z0): the start point of every move, (m,) each."""
        sh = lambda a: np.concatenate(([0.0], a[:-1]))  # noqa: E731
        return sh(self.x), sh(self.y), sh(self.z)

    def pass_rows(self) -> np.ndarray:
        """(P + 1,) int: pass ``p`` owns rows ``[r[p], r[p + 1])``."""
        n_pass = int(self.pass_index[-1]) + 1 if len(self) else 0
        return np.searchsorted(self.pass_index, np.arange(n_pass + 1))


def job_moves(job) -> Moves:
    """The neutral move list of ``job`` (vectorised over passes)."""
    pk = job.packed
    n_pass = len(pk.pass_geom)
    if n_pass == 0:
        e = np.zeros(0)
        return Moves(e, e, e, np.zeros(0, np.int8), np.zeros(0, bool), np.zeros(0, np.int64),
                     np.zeros(0, np.int64), e)
    size = pk.geom_size[pk.pass_geom]
    first = pk.geom_offset[pk.pass_geom]
    z = pk.pass_z
    z_prev = np.concatenate(([0.0], z[:-1]))
    foc = (z != z_prev).astype(np.int64)
    cnt = 1 + foc + size
    row0 = np.cumsum(cnt) - cnt
    m = int(cnt.sum())
    pidx = np.repeat(np.arange(n_pass), cnt)
    kind = np.full(m, CUT, dtype=np.int8)
    kind[row0] = RAPID
    kind[(row0 + 1)[foc == 1]] = FOCUS
    j = np.arange(m) - np.repeat(row0 + 1 + foc, cnt)  # 0.. on cut rows, negative before
    vtx = np.where(j >= 0, first[pidx] + (j + 1) % size[pidx], first[pidx])
    laser = kind == CUT
    zz = z[pidx].copy()
    zz[row0] = z_prev
    v = pk.vertices[vtx]
    speed = np.where(laser, pk.pass_speed[pidx], 0.0)
    return Moves(v[:, 0].copy(), v[:, 1].copy(), zz, kind, laser, pidx, vtx, speed)


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
    """

    cut_s: float
    rapid_s: float
    focus_s: float
    lower_bound_s: float
    cut_length_mm: float
    passes: int
    cuts: int

    @property
    def total_s(self) -> float:
        return self.cut_s + self.rapid_s + self.focus_s

    @property
    def ratio(self) -> float:
        """Estimated time / lower bound (>= 1)."""
        return self.total_s / self.lower_bound_s if self.lower_bound_s > 0 else float("nan")


def estimate(job, moves: Moves | None = None) -> Estimate:
    """Cutting, rapid and focus time of ``job`` from its move list."""
    mv = job_moves(job) if moves is None else moves
    x0, y0, z0 = mv.starts()
    d = np.hypot(mv.x - x0, mv.y - y0)
    cut = mv.kind == CUT
    length = float(d[cut].sum())
    cut_s = float((d[cut] / mv.speed[cut]).sum()) if cut.any() else 0.0
    pr = job.process
    rapid_s = float(d[mv.kind == RAPID].sum()) / pr.rapid_speed_mm_s
    focus_s = float(np.abs(mv.z - z0)[mv.kind == FOCUS].sum()) / pr.focus_speed_mm_s
    lower = length / pr.scan_speed_mm_s
    return Estimate(cut_s, rapid_s, focus_s, lower, length, len(job.passes), len(job.design))
