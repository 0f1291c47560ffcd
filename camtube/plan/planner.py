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
from camtube.plan.packed import Packed, is_axis_rectangle
from camtube.tol import TOL

ORDERINGS = ("interleaved", "sequential")
DEFAULT_ORDERING = "interleaved"


# ---------------------------------------------------------------- repeats
def depth_for_contours(outer_radius_mm: float, contours: Sequence[Contour]) -> float:
    """Beam depth (mm) of the deepest cut: ``beam_depth_mm(r_o, largest circumferential extent)``."""
    arc = max(c.bounds[3] - c.bounds[1] for c in contours)
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
        x0, y0, x1, y1 = contour.bounds
        if x1 - x0 - 2 * offset_mm <= TOL.zero or y1 - y0 - 2 * offset_mm <= TOL.zero:
            raise _vanish(contour, offset_mm, index)
        pts = ((x0 + offset_mm, y0 + offset_mm), (x1 - offset_mm, y0 + offset_mm),
               (x1 - offset_mm, y1 - offset_mm), (x0 + offset_mm, y1 - offset_mm))
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
    b = np.array([c.bounds for c in contours], dtype=float).reshape(n, 4)
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


def _nearest_vertex(points: np.ndarray, p: tuple[float, float]) -> int:
    d = (points[:, 0] - p[0]) ** 2 + (points[:, 1] - p[1]) ** 2
    return int(np.argmin(d))


def _chain_starts(design: Sequence[Contour], order: Sequence[int], start: tuple[float, float]) -> dict[int, int]:
    """Start vertex of each contour in ``order``: nearest to the previous contour's start."""
    out: dict[int, int] = {}
    p = start
    for i in order:
        pts = design[i].xy
        k = _nearest_vertex(pts, p)
        out[i] = k
        p = (float(pts[k, 0]), float(pts[k, 1]))
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
    from camtube.export.dxf import DxfContours, read_contours

    if outer_radius_mm is None or outer_radius_mm <= 0:
        raise PatternError([Issue("outer_radius_mm", "a DXF input needs the tube's outer radius", outer_radius_mm,
                                  "> 0 mm", "pass outer_radius_mm (CLI: --outer-radius)")])
    circ = 2.0 * math.pi * outer_radius_mm
    outline_len = None
    if isinstance(source, DxfContours):
        contours, outline_len = source.contours, source.length_mm
        label = name or "dxf"
    elif isinstance(source, (str, os.PathLike)):
        read = read_contours(source, circumference_mm=circ)
        contours, outline_len = read.contours, read.length_mm
        label = name or os.path.splitext(os.path.basename(os.fspath(source)))[0]
    else:
        contours = tuple(source)
        label = name or "contours"
    if not contours:
        raise PatternError([Issue(str(label), "no closed contours to cut", None, "",
                                  "draw the cuts as closed polylines on a layer not named CONSTRUCTION*")])
    length = length_mm if length_mm is not None else outline_len
    if length is None:
        raise PatternError([Issue("length_mm", "the tube length is unknown (no CONSTRUCTION outline in the DXF)",
                                  None, "> 0 mm", "pass length_mm (CLI: --length)")])
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
    source : Pattern | str | os.PathLike | DxfContours | sequence of Contour
        A pattern (cut from ``cut_contours(pattern)``, unwrapped across the
        seam), or a DXF file / its contours (a drawing made by hand).
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
        last = design[fwd[-1]].points[starts[0][fwd[-1]]]
        starts.append(_chain_starts(design, fwd[::-1], last))

    # geometry[(cut, drill, direction)] -> Contour starting at its chosen vertex
    geoms: dict[tuple[int, int, int], Contour] = {}
    geom_ids: dict[tuple[int, int, int], int] = {}
    geom_list: list[Contour] = []
    shifted = [[offset_contour(c, o, i) for o in offsets] for i, c in enumerate(design)]
    for direction, st in enumerate(starts):
        for i in range(n_cut):
            k0 = st[i]
            p0 = design[i].points[k0]
            for d in range(n_drill):
                c = shifted[i][d]
                k = k0 if (c is design[i] or is_axis_rectangle(design[i])) else _nearest_vertex(c.xy, p0)
                key = (i, d, direction)
                geoms[key] = _rotate(c, k)
                geom_ids[key] = len(geom_list)
                geom_list.append(geoms[key])

    # pass sequence as (cut, repeat, focus, drill, direction)
    seq: list[tuple[int, int, int, int, int]] = []
    if ordering == "sequential":
        for i in fwd:
            for r in range(repeats):
                for f in range(2):
                    for d in range(n_drill):
                        seq.append((i, r, f, d, 0))
    else:
        k = 0
        for r in range(repeats):
            for f in range(2):
                for d in range(n_drill):
                    direction = k % 2
                    for i in (fwd if direction == 0 else fwd[::-1]):
                        seq.append((i, r, f, d, direction))
                    k += 1

    pw, fq, sp = float(proc.power_w), float(proc.frequency_khz), float(proc.scan_speed_mm_s)
    new = object.__new__
    passes = []
    for i, r, f, d, direction in seq:
        p = new(Pass)
        # Pass is frozen: fill its fields directly (3x faster than __init__ for 10^5+ passes).
        p.__dict__.update(contour=geoms[(i, d, direction)], cut_index=i, kind=design[i].kind, repeat=r,
                          focus_level=f, focus_offset_mm=focus[f], drill_index=d, offset_mm=offsets[d],
                          power_w=pw, frequency_khz=fq, speed_mm_s=sp)
        passes.append(p)
    job = Job(src.name, src.outer_radius_mm, src.length_mm, design, tuple(passes), proc, repeats, ordering)
    seq_a = np.asarray(seq, dtype=np.int64).reshape(-1, 5)
    gid = np.fromiter((geom_ids[(i, d, di)] for i, _, _, d, di in seq), dtype=np.int64, count=len(seq))
    packed = Packed.build(
        geoms=geom_list, pass_geom=gid, pass_cut=seq_a[:, 0], pass_z=np.asarray(focus)[seq_a[:, 2]],
        pass_speed=np.full(len(seq), sp), pass_power=np.full(len(seq), pw), pass_freq=np.full(len(seq), fq))
    job.__dict__["packed"] = packed  # seed Job.packed (a cache of arrays derived from the passes)
    return job
