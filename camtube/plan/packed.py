"""Packed arrays of a Job: the pass geometry and settings as NumPy arrays.

Posting, estimating and checking 10^5-10^6 moves needs arrays, not objects.
:class:`Packed` holds, once per distinct path (passes of different repeats and
focus levels share the same Contour object), its vertices, and per pass the
index of its path and its settings. ``Job.packed`` computes it from the passes
(and caches it); the planner seeds that cache with the arrays it built anyway.
"""
from __future__ import annotations

import gc
from contextlib import contextmanager
from dataclasses import dataclass
from typing import Iterator, Sequence

import numpy as np

from camtube.design.contour import Contour


@contextmanager
def no_gc() -> Iterator[None]:
    """Pause the cyclic garbage collector while building 10^5-10^6 small objects.

    The objects made (passes, tuples, strings) hold no reference cycles; without
    this, each generational collection re-walks every object made so far and
    planning 10,000 notches takes twice as long.
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
    """True for a 4-vertex contour whose edges are parallel to x and y."""
    pts = contour.points
    if len(pts) != 4:
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
        starting at its start point.
    geom_offset : (G + 1,) int
        Path ``g`` owns ``vertices[geom_offset[g]:geom_offset[g + 1]]``.
    pass_geom, pass_cut : (P,) int
        Path and design-cut index of each pass.
    pass_z : (P,) float
        Focus offset into the material (mm, >= 0).
    pass_speed, pass_power, pass_freq : (P,) float
        mm/s on the outer surface, W, kHz.
    """

    vertices: np.ndarray
    geom_offset: np.ndarray
    pass_geom: np.ndarray
    pass_cut: np.ndarray
    pass_z: np.ndarray
    pass_speed: np.ndarray
    pass_power: np.ndarray
    pass_freq: np.ndarray

    @classmethod
    def build(cls, geoms: Sequence[Contour], pass_geom, pass_cut, pass_z, pass_speed, pass_power, pass_freq) -> "Packed":
        sizes = np.fromiter((len(g.points) for g in geoms), dtype=np.int64, count=len(geoms))
        off = np.zeros(len(geoms) + 1, dtype=np.int64)
        np.cumsum(sizes, out=off[1:])
        verts = np.array([p for g in geoms for p in g.points], dtype=float).reshape(-1, 2)
        arr = lambda a, t: np.ascontiguousarray(a, dtype=t)  # noqa: E731
        return cls(verts, off, arr(pass_geom, np.int64), arr(pass_cut, np.int64), arr(pass_z, float),
                   arr(pass_speed, float), arr(pass_power, float), arr(pass_freq, float))

    @property
    def geom_size(self) -> np.ndarray:
        """(G,) int: vertices per path."""
        return np.diff(self.geom_offset)


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
                        col("speed_mm_s", float), col("power_w", float), col("frequency_khz", float))
