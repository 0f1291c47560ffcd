"""The planner: cuts (a pattern, or the closed contours of any DXF) + a process -> a :class:`Job`.

The paper's process, for every cut contour (notch or tendon hole)::

    repeat R times:                          # R from the thickness rule (4/6/8 for tubes 1-3)
        for focus in (surface, defocused 0.1 mm into the material):
            for drill in range(4):           # each cut offset 0.005 mm further into the removed region
                cut the contour once at 25 mm/s, 2.0 W, 60 kHz

Two orderings of those passes (see ``docs/plan.md``):

- ``sequential``: all passes of one cut, then the next cut (the paper's wording).
- ``interleaved`` (default): one round per (repeat, focus, drill); a round visits
  every cut, so each notch cools for a whole round between two of its passes.

Travel order inside a round is a serpentine ("boustrophedon") tour: cuts whose
circumferential ranges overlap form one band; bands are visited in ``y`` order,
alternately forward and backward in ``x``; interleaved rounds run the tour
alternately forwards and backwards so a round starts where the previous ended.
Every pass starts at the vertex of its path nearest the end of the previous
cut in the tour (for rectangles: the nearest corner).
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from camtube.design.contour import Contour, cut_contours
from camtube.design.geometry import beam_depth_mm
from camtube.design.pattern import Pattern, Process
from camtube.errors import Issue, PatternError
from camtube.plan.job import Job, Pass
from camtube.plan.packed import Packed, is_axis_rectangle, no_gc, points_bounds
from camtube.tol import TOL

ORDERINGS = ("interleaved", "sequential")
DEFAULT_ORDERING = "interleaved"


# ---------------------------------------------------------------- repeats
def depth_for_contours(outer_radius_mm: float, contours: Sequence[Contour]) -> float:
    """Beam depth (mm) of the deepest cut: ``beam_depth_mm(r_o, largest circumferential extent)``."""
    arc = max(b[3] - b[1] for b in map(points_bounds, (c.points for c in contours)))
    arc = min(arc, 2.0 * math.pi * outer_radius_mm)
    return beam_depth_mm(outer_radius_mm, arc)


def repeats_for(process: Process, depth_mm: float) -> int:
    """Repeats of the focus+defocus group: ``process.repeats`` or the first rule row covering ``depth_mm``.

    Raises
    ------
    PatternError
        No row of ``process.repeat_rule`` has ``max_depth >= depth_mm``.
    """
    if process.repeats is not None:
        if process.repeats < 1:
            raise PatternError([Issue("process.repeats", "must be a positive integer", process.repeats,
                                      ">= 1 or auto", "set process.repeats to 1 or more, or to auto")])
        return int(process.repeats)
    for row in process.repeat_rule:
        if depth_mm <= row.max_depth_mm:
            return int(row.repeats)
    deepest = max((r.max_depth_mm for r in process.repeat_rule), default=0.0)
    raise PatternError([Issue(
        "process.repeat_rule", f"no row covers the beam depth {depth_mm:.3f} mm", deepest,
        f"max_depth up to {deepest:g} mm", "add a repeat_rule row with a larger max_depth, or set process.repeats")])


# ---------------------------------------------------------------- offsets
def _describe(contour: Contour, index: int) -> str:
    x0, y0, x1, y1 = contour.bounds
    return f"cut[{index}] ({contour.kind} at x {x0:.4f}..{x1:.4f} mm, y {y0:.4f}..{y1:.4f} mm)"


def offset_contour(contour: Contour, offset_mm: float, index: int = -1) -> Contour:
    """The contour moved ``offset_mm`` into the region it bounds (the material removed).

    Rectangles shrink exactly; other polygons use shapely's mitred inward
    buffer (exterior ring, counter-clockwise). ``offset_mm = 0`` returns the
    contour unchanged.

    Raises
    ------
    PatternError
        The contour vanishes (or splits) at that offset.
    """
    if offset_mm <= 0.0:
        return contour
    if is_axis_rectangle(contour):
        x0, y0, x1, y1 = points_bounds(contour.points)
        if x1 - x0 - 2 * offset_mm <= TOL.zero or y1 - y0 - 2 * offset_mm <= TOL.zero:
            raise _vanish(contour, offset_mm, index)
        o = offset_mm  # each corner moves diagonally inward; vertex order and start are kept
        pts = tuple((x0 + o if x == x0 else x1 - o, y0 + o if y == y0 else y1 - o) for x, y in contour.points)
        return Contour(pts, contour.kind, contour.cut_index)
    import shapely
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    poly = Polygon(contour.points)
    if not poly.is_valid:
        poly = shapely.make_valid(poly)
    shrunk = poly.buffer(-offset_mm, join_style="mitre")
    if shrunk.is_empty or shrunk.geom_type != "Polygon" or shrunk.area <= TOL.zero:
        raise _vanish(contour, offset_mm, index)
    ring = list(orient(shrunk, 1.0).exterior.coords)[:-1]
    return Contour(tuple((float(x), float(y)) for x, y in ring), contour.kind, contour.cut_index)


def _vanish(contour: Contour, offset_mm: float, index: int) -> PatternError:
    return PatternError([Issue(
        _describe(contour, index), f"the contour vanishes (or splits) when offset {offset_mm:.4f} mm inward",
        offset_mm, "kerf/2 + (drill_passes - 1) * drill_offset below half the cut's smallest width",
        "reduce process.drill_passes, process.drill_offset or process.kerf, or enlarge the cut")])


def pass_offsets_mm(process: Process) -> tuple[float, ...]:
    """Inward offset of drill cut ``d``: ``kerf/2 + d * drill_offset`` (mm)."""
    return tuple(process.kerf_mm / 2.0 + d * process.drill_offset_mm for d in range(process.drill_passes))


# ---------------------------------------------------------------- travel order
def tour(contours: Sequence[Contour]) -> list[int]:
    """Serpentine visiting order of contours (indices).

    Contours whose ``y`` ranges overlap form a band; bands in increasing ``y``;
    inside a band by ``x`` centre, alternately ascending and descending.
    """
    n = len(contours)
    b = np.array([points_bounds(c.points) for c in contours], dtype=float).reshape(n, 4)
    xc = 0.5 * (b[:, 0] + b[:, 2])
    by_y = np.lexsort((xc, b[:, 1]))
    band = np.empty(n, dtype=np.int64)
    top, k = -np.inf, -1
    for i in by_y.tolist():
        if b[i, 1] > top + TOL.merge:
            k += 1
            top = b[i, 3]
        else:
            top = max(top, b[i, 3])
        band[i] = k
    sign = np.where(band % 2 == 0, 1.0, -1.0)
    order = np.lexsort((np.arange(n), sign * xc, band))
    return order.tolist()


def _nearest_vertex(points, p: tuple[float, float]) -> int:
    """Index of the vertex of ``points`` ((n, 2) sequence) nearest to ``p`` (first on ties)."""
    px, py = p
    d = [(q[0] - px) ** 2 + (q[1] - py) ** 2 for q in points]
    return d.index(min(d))


def _chain_starts(design: Sequence[Contour], order: Sequence[int], start: tuple[float, float]) -> dict[int, int]:
    """Start vertex of each contour in ``order``: nearest to the previous contour's start."""
    out: dict[int, int] = {}
    p = start
    for i in order:
        pts = design[i].points
        k = _nearest_vertex(pts, p)
        out[i] = k
        p = pts[k]
    return out


def _rotate(contour: Contour, k: int) -> Contour:
    if k == 0:
        return contour
    pts = contour.points
    return Contour(pts[k:] + pts[:k], contour.kind, contour.cut_index)


# ---------------------------------------------------------------- the planner
@dataclass(frozen=True)
class _Source:
    name: str
    contours: tuple[Contour, ...]
    outer_radius_mm: float
    length_mm: float
    process: Process


def _source(source, process, outer_radius_mm, length_mm, name) -> _Source:
    if isinstance(source, Pattern):
        t = source.tube
        return _Source(name or source.name, cut_contours(source), t.outer_radius_mm,
                       length_mm if length_mm is not None else t.length_mm, process or source.process)
    if isinstance(source, (str, bytes, os.PathLike)):
        raise PatternError([Issue(str(source), "plan_job takes a Pattern or contours, not a file", None, "",
                                  "load a drawing with camtube.design.source.load_source first")])
    if outer_radius_mm is None or outer_radius_mm <= 0:
        raise PatternError([Issue("outer_radius_mm", "contours need the tube's outer radius", outer_radius_mm,
                                  "> 0 mm", "pass outer_radius_mm")])
    contours = tuple(source)
    label = name or "contours"
    if not contours:
        raise PatternError([Issue(str(label), "no closed contours to cut", None, "",
                                  "draw the cuts as closed polylines on a layer not named CONSTRUCTION*")])
    length = length_mm
    if length is None:
        raise PatternError([Issue("length_mm", "contours need the tube length", None, "> 0 mm", "pass length_mm")])
    contours = tuple(replace(c, cut_index=i) for i, c in enumerate(contours))
    return _Source(label, contours, float(outer_radius_mm), float(length), process or Process())


def plan_job(
    source,
    process: Process | None = None,
    *,
    ordering: str = DEFAULT_ORDERING,
    outer_radius_mm: float | None = None,
    length_mm: float | None = None,
    name: str | None = None,
) -> Job:
    """Plan the multi-pass laser job of a pattern or of a DXF's closed contours.

    Parameters
    ----------
    source : Pattern | sequence of Contour
        A pattern (cut from ``cut_contours(pattern)``, unwrapped across the
        seam; a drawing is read into one by :mod:`camtube.design.drawing`), or contours.
    process : Process, optional
        Defaults to the pattern's process (or the paper's for a DXF).
    ordering : {"interleaved", "sequential"}
        Pass ordering (see the module docstring).
    outer_radius_mm, length_mm : float, optional
        Tube outer radius and length; required for a DXF (the length may come
        from the DXF's construction outline).
    name : str, optional
        Job name; defaults to the pattern name or the DXF's file stem.

    Returns
    -------
    Job
        ``len(cuts) * repeats * 2 * drill_passes`` passes in execution order.
    """
    with no_gc():
        return _plan(source, process, ordering, outer_radius_mm, length_mm, name)


def _plan(source, process, ordering, outer_radius_mm, length_mm, name) -> Job:
    if ordering not in ORDERINGS:
        raise PatternError([Issue("ordering", "unknown ordering", ordering, " | ".join(ORDERINGS),
                                  f"use one of {', '.join(ORDERINGS)}")])
    src = _source(source, process, outer_radius_mm, length_mm, name)
    proc = src.process
    if proc.drill_passes < 1:
        raise PatternError([Issue("process.drill_passes", "must be at least 1", proc.drill_passes, ">= 1",
                                  "set process.drill_passes to 1 or more")])
    design = src.contours
    repeats = repeats_for(proc, depth_for_contours(src.outer_radius_mm, design))
    offsets = pass_offsets_mm(proc)
    focus = (0.0, float(proc.defocus_mm))
    n_cut, n_drill = len(design), len(offsets)

    fwd = tour(design)
    starts = [_chain_starts(design, fwd, (0.0, 0.0))]
    if ordering == "interleaved":
        # backward rounds start where forward rounds end and vice versa
        starts.append(_chain_starts(design, fwd[::-1], design[fwd[-1]].points[starts[0][fwd[-1]]]))
        starts[0] = _chain_starts(design, fwd, design[fwd[0]].points[starts[1][fwd[0]]])

    geom_list: list[Contour] = []  # index (direction * n_cut + cut) * n_drill + drill
    shifted = [[offset_contour(c, o, i) for o in offsets] for i, c in enumerate(design)]
    for direction, st in enumerate(starts):
        for i in range(n_cut):
            k0 = st[i]
            p0 = design[i].points[k0]
            for d in range(n_drill):
                c = shifted[i][d]
                k = k0 if (c is design[i] or is_axis_rectangle(design[i])) else _nearest_vertex(c.points, p0)
                geom_list.append(_rotate(c, k))

    # the pass sequence as arrays: cut, repeat, focus level, drill, tour direction (one row per pass)
    order = np.asarray(fwd, dtype=np.int64)
    per_cut = repeats * 2 * n_drill
    k = np.arange(per_cut)
    r_k, f_k, d_k = k // (2 * n_drill), (k // n_drill) % 2, k % n_drill
    if ordering == "sequential":
        cut_a = np.repeat(order, per_cut)
        rep_a, foc_a, dri_a = (np.tile(a, n_cut) for a in (r_k, f_k, d_k))
        dir_a = np.zeros(len(cut_a), dtype=np.int64)
    else:  # round k visits every cut, forwards on even rounds, backwards on odd ones
        dir_k = k % 2
        cut_a = np.where(dir_k[:, None] == 0, order[None, :], order[::-1][None, :]).ravel()
        rep_a, foc_a, dri_a, dir_a = (np.repeat(a, n_cut) for a in (r_k, f_k, d_k, dir_k))
    gid = (dir_a * n_cut + cut_a) * n_drill + dri_a  # index into geom_list (built direction, cut, drill)

    pw, fq, sp = float(proc.power_w), float(proc.frequency_khz), float(proc.scan_speed_mm_s)
    kinds = [c.kind for c in design]
    new = object.__new__
    passes = []
    append = passes.append
    for g, i, r, f, d in zip(gid.tolist(), cut_a.tolist(), rep_a.tolist(), foc_a.tolist(), dri_a.tolist()):
        p = new(Pass)
        # Pass is frozen: fill its fields directly (2x faster than __init__ for 10^5+ passes).
        p.__dict__.update(contour=geom_list[g], cut_index=i, kind=kinds[i], repeat=r, focus_level=f,
                          focus_offset_mm=focus[f], drill_index=d, offset_mm=offsets[d], power_w=pw,
                          frequency_khz=fq, speed_mm_s=sp)
        append(p)
    job = Job(src.name, src.outer_radius_mm, src.length_mm, design, tuple(passes), proc, repeats, ordering)
    n = len(passes)
    packed = Packed.build(
        geoms=geom_list, pass_geom=gid, pass_cut=cut_a, pass_z=np.asarray(focus)[foc_a],
        pass_speed=np.full(n, sp), pass_power=np.full(n, pw), pass_freq=np.full(n, fq))
    job.__dict__["packed"] = packed  # seed Job.packed (a cache of arrays derived from the passes)
    return job
