"""Packed arrays of a Job: the pass geometry and settings as NumPy arrays.

Posting, estimating and checking 10^6-10^7 moves needs arrays, not objects.
:class:`Packed` holds, once per distinct path (passes of different repeats and
focus levels share the same path), its vertices, and per pass the index of its
path and its settings. The planner builds a Packed directly (no Python object per
pass) and gives the Job a lazy :class:`PassView` over it; a Job made from a tuple of
:class:`~camtube.plan.job.Pass` objects (tests, hand-edited jobs) is packed by
:func:`pack`.
"""
from __future__ import annotations

import gc
from collections.abc import Sequence as SequenceABC
from contextlib import contextmanager
from dataclasses import dataclass
from functools import cached_property
from typing import Iterator, Sequence

import numpy as np

from camtube.design.contour import Contour
from camtube.plan.passes import Pass


@contextmanager
def no_gc() -> Iterator[None]:
    """Pause the cyclic garbage collector while building many small objects.

    The objects made (tuples, strings) hold no reference cycles; without this, each
    generational collection re-walks every object made so far. Speed hack, used by the
    planner and the G-code emitter only (``scripts/bench_plan.py`` measures it).
    """
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


def points_bounds(points) -> tuple[float, float, float, float]:
    """(xmin, ymin, xmax, ymax) of a point tuple, without NumPy (fast for a few points)."""
    xs = [p[0] for p in points]
    ys = [p[1] for p in points]
    return min(xs), min(ys), max(xs), max(ys)


def is_axis_rectangle(contour: Contour) -> bool:
    """True for a closed 4-vertex contour whose edges are parallel to x and y."""
    pts = contour.points
    if len(pts) != 4 or not getattr(contour, "closed", True):
        return False
    for k in range(4):
        (ax, ay), (bx, by) = pts[k], pts[(k + 1) % 4]
        if ax != bx and ay != by:
            return False
    return True


@dataclass(frozen=True, eq=False)
class Packed:
    """Pass geometry and settings as arrays.

    Attributes
    ----------
    vertices : (nv, 2) float
        Vertices (x_mm, y_mm) of every distinct path, path after path, each
        starting at its start point (an open path in the direction it is cut).
    geom_offset : (G + 1,) int
        Path ``g`` owns ``vertices[geom_offset[g]:geom_offset[g + 1]]``.
    geom_closed : (G,) bool
        True: closed path (the beam returns to its first vertex); False: an open
        path (a slit) cut from its first vertex to its last.
    pass_geom, pass_cut : (P,) int32
        Path and design-cut index of each pass.
    pass_z : (P,) float
        Focus offset into the material (mm, >= 0).
    pass_speed, pass_power, pass_freq : (P,) float
        mm/s on the outer surface, W, kHz (may be read-only broadcast views).
    pass_repeat, pass_focus, pass_drill : (P,) int32, int8, int32
        Repeat, focus level (0 surface, 1 defocused) and drill index of each pass.
    pass_offset : (P,) float
        Inward offset of the pass's path from its design line (mm).
    pass_link : (P,) bool
        Pass ``p`` is entered from the end of pass ``p - 1`` with the beam on, by a link across
        the strip between their paths (the ``chained`` ordering: drill passes of one closed cut
        at one focus); False: entered by a rapid with the gate closed.
    """

    vertices: np.ndarray
    geom_offset: np.ndarray
    geom_closed: np.ndarray
    pass_geom: np.ndarray
    pass_cut: np.ndarray
    pass_z: np.ndarray
    pass_speed: np.ndarray
    pass_power: np.ndarray
    pass_freq: np.ndarray
    pass_repeat: np.ndarray
    pass_focus: np.ndarray
    pass_drill: np.ndarray
    pass_offset: np.ndarray
    pass_link: np.ndarray

    @classmethod
    def build(cls, geoms: Sequence[Contour], pass_geom, pass_cut, pass_z, pass_speed, pass_power, pass_freq,
              pass_repeat, pass_focus, pass_drill, pass_offset) -> "Packed":
        """Pack from a list of path Contours and per-pass columns."""
        sizes = np.fromiter((len(g.points) for g in geoms), dtype=np.int64, count=len(geoms))
        off = np.zeros(len(geoms) + 1, dtype=np.int64)
        np.cumsum(sizes, out=off[1:])
        verts = np.array([p for g in geoms for p in g.points], dtype=float).reshape(-1, 2)
        closed = np.fromiter((g.closed for g in geoms), dtype=bool, count=len(geoms))
        return cls.of_arrays(verts, off, closed, pass_geom, pass_cut, pass_z, pass_speed, pass_power, pass_freq,
                             pass_repeat, pass_focus, pass_drill, pass_offset)

    @classmethod
    def of_arrays(cls, vertices, geom_offset, geom_closed, pass_geom, pass_cut, pass_z, pass_speed, pass_power,
                  pass_freq, pass_repeat, pass_focus, pass_drill, pass_offset, pass_link=None) -> "Packed":
        arr = lambda a, t: a if isinstance(a, np.ndarray) and a.dtype == t else np.ascontiguousarray(a, dtype=t)  # noqa: E731
        if pass_link is None:
            pass_link = np.zeros(len(pass_geom), dtype=bool)
        return cls(arr(vertices, float).reshape(-1, 2), arr(geom_offset, np.int64), arr(geom_closed, bool),
                   arr(pass_geom, np.int32), arr(pass_cut, np.int32), arr(pass_z, float), arr(pass_speed, float),
                   arr(pass_power, float), arr(pass_freq, float), arr(pass_repeat, np.int32),
                   arr(pass_focus, np.int8), arr(pass_drill, np.int32), arr(pass_offset, float),
                   arr(pass_link, bool))

    @property
    def n_pass(self) -> int:
        return len(self.pass_geom)

    @cached_property
    def geom_size(self) -> np.ndarray:
        """(G,) int: vertices per path."""
        return np.diff(self.geom_offset)

    @cached_property
    def edge_mm(self) -> np.ndarray:
        """(nv, 2) float: from each vertex to the next of its path, mm (a closed path's last vertex to its first; an
        open path's last vertex: 0, no edge). Read only: the machine's feed and speed checks read it too."""
        v = self.vertices
        if len(v) == 0:
            return np.zeros((0, 2))
        nxt = np.arange(1, len(v) + 1)
        last = self.geom_offset[1:] - 1
        nxt[last] = self.geom_offset[:-1]  # closed paths return to their first vertex
        d = v[nxt] - v
        d[last[~self.geom_closed]] = 0.0  # open paths do not
        d.flags.writeable = False
        return d

    @cached_property
    def geom_length_mm(self) -> np.ndarray:
        """(G,) float: length of each path (perimeter if closed), mm."""
        if len(self.vertices) == 0:
            return np.zeros(len(self.geom_size))
        seg = np.hypot(*self.edge_mm.T)
        c = np.concatenate(([0.0], np.cumsum(seg)))
        return c[self.geom_offset[1:]] - c[self.geom_offset[:-1]]

    def link_length_mm(self) -> float:
        """Total length (mm) of the beam-on links between chained passes (:attr:`pass_link`)."""
        p = np.flatnonzero(self.pass_link)
        if len(p) == 0:
            return 0.0
        g_prev, g = self.pass_geom[p - 1], self.pass_geom[p]
        end = np.where(self.geom_closed[g_prev], self.geom_offset[g_prev], self.geom_offset[g_prev + 1] - 1)
        return float(np.hypot(*(self.vertices[self.geom_offset[g]] - self.vertices[end]).T).sum())

    def chunk_bounds(self, chunk_passes: int) -> list[tuple[int, int]]:
        """[(lo, hi), ...]: consecutive ranges of about ``chunk_passes`` passes that never split a chain
        of linked passes (each range starts with a pass entered by a rapid)."""
        n = self.n_pass
        out = []
        lo = 0
        link = self.pass_link
        while lo < n:
            hi = min(n, lo + chunk_passes)
            while hi < n and link[hi]:
                hi += 1
            out.append((lo, hi))
            lo = hi
        return out

    def pass_end(self, p: int) -> tuple[float, float]:
        """Where pass ``p`` leaves the beam: its first vertex (closed path) or its last (open)."""
        g = int(self.pass_geom[p])
        k = int(self.geom_offset[g]) if self.geom_closed[g] else int(self.geom_offset[g + 1]) - 1
        return float(self.vertices[k, 0]), float(self.vertices[k, 1])

    def path_points(self, g: int) -> tuple[tuple[float, float], ...]:
        """Vertices of path ``g`` as a point tuple."""
        a, b = int(self.geom_offset[g]), int(self.geom_offset[g + 1])
        return tuple(map(tuple, self.vertices[a:b].tolist()))


def pack(job) -> Packed:
    """Packed arrays of ``job.passes`` (distinct Contour objects become distinct paths)."""
    ids: dict[int, int] = {}
    geoms: list[Contour] = []
    passes = job.passes
    gid = np.empty(len(passes), dtype=np.int64)
    for k, p in enumerate(passes):
        c = p.contour
        g = ids.get(id(c))
        if g is None:
            g = ids[id(c)] = len(geoms)
            geoms.append(c)
        gid[k] = g
    n = len(passes)
    col = lambda name, t: np.fromiter((getattr(p, name) for p in passes), dtype=t, count=n)  # noqa: E731
    return Packed.build(geoms, gid, col("cut_index", np.int64), col("focus_offset_mm", float),
                        col("speed_mm_s", float), col("power_w", float), col("frequency_khz", float),
                        col("repeat", np.int32), col("focus_level", np.int8), col("drill_index", np.int32),
                        col("offset_mm", float))


class PassView(SequenceABC):
    """The passes of a planned job as a lazy, read-only sequence of :class:`~camtube.plan.passes.Pass`.

    ``len``, indexing, slicing and iteration build Pass objects on demand from the
    :class:`Packed` arrays; passes over the same path share one Contour object (made
    when first needed). Nothing is kept per pass, so a job of 10^6 passes stays arrays.
    """

    def __init__(self, packed: Packed, design: Sequence[Contour], tour: np.ndarray | None = None,
                 starts: np.ndarray | None = None) -> None:
        self.packed = packed
        self._design = design
        self._contours: dict[int, Contour] = {}
        #: The planner's recipe (visiting order of the cuts, (n_dir, n_cut) start vertices): with
        #: the process it regenerates every pass (:func:`camtube.plan.planner.assemble`).
        self.tour, self.starts = tour, starts

    def __len__(self) -> int:
        return self.packed.n_pass

    def _contour(self, g: int, cut: int) -> Contour:
        c = self._contours.get(g)
        if c is None:
            d = self._design[cut]
            c = self._contours[g] = Contour(self.packed.path_points(g), d.kind, d.cut_index,
                                            bool(self.packed.geom_closed[g]))
        return c

    def _make(self, lo: int, hi: int, step: int = 1) -> list:
        pk = self.packed
        s = slice(lo, hi, step)
        cols = [pk.pass_geom[s], pk.pass_cut[s], pk.pass_repeat[s], pk.pass_focus[s], pk.pass_z[s],
                pk.pass_drill[s], pk.pass_offset[s], pk.pass_power[s], pk.pass_freq[s], pk.pass_speed[s]]
        out = []
        design = self._design
        for g, i, r, f, z, d, o, pw, fq, sp in zip(*(c.tolist() for c in cols)):
            out.append(Pass(self._contour(g, i), i, design[i].kind, r, f, z, d, o, pw, fq, sp))
        return out

    def __getitem__(self, k):
        n = len(self)
        if isinstance(k, slice):
            lo, hi, step = k.indices(n)
            return tuple(self._make(lo, hi, step))
        k = int(k)
        if k < 0:
            k += n
        if not 0 <= k < n:
            raise IndexError("pass index out of range")
        return self._make(k, k + 1)[0]

    def __iter__(self):
        step = 4096
        for lo in range(0, len(self), step):
            yield from self._make(lo, min(len(self), lo + step))

    def __eq__(self, other) -> bool:
        if not isinstance(other, SequenceABC) or len(other) != len(self):
            return False
        return all(a == b for a, b in zip(self, other))

    __hash__ = None  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"<{len(self)} passes>"
