"""The planner: cuts (a pattern, or a sequence of contours) + a process -> a :class:`Job`.

The paper's process, for every cut contour (notch or tendon hole)::

    repeat R times:                          # R from the thickness rule (4/6/8 for tubes 1-3)
        for focus in (surface, defocused 0.1 mm into the material):
            for drill in range(4):           # each cut offset 0.005 mm further into the removed region
                cut the contour once at 25 mm/s, 2.0 W, 60 kHz

Three orderings of those passes (see ``docs/plan.md``):

- ``sequential``: all passes of one cut, then the next cut (the paper's wording).
- ``interleaved`` (default): one round per (repeat, focus, drill); a round visits
  every cut, so each notch cools for a whole round between two of its passes.
- ``chained``: one round per (repeat, focus); a round visits every cut and cuts its
  drill passes one after the other (the paper's inner loop) as one beam-on path:
  each drill pass of a closed cut is entered from the end of the one before by a
  beam-on *link* (:data:`camtube.plan.moves.LINK`) across the strip between the two
  offsets, inside the cut region, so the machine neither stops, rapids nor switches
  the gate between them. Each notch cools for a round between two of its groups.
  A closed cut's passes start at a vertex where the drawing is smooth (no drawn
  corner) and most curved when it has one (:func:`smooth_vertices`), so the links
  lie on a smooth part of the path where the machine runs slowly anyway.

Travel order inside a round is a serpentine ("boustrophedon") tour: cuts whose
circumferential ranges overlap form one band; bands are visited in ``y`` order,
alternately forward and backward in ``x``; interleaved rounds run the tour
alternately forwards and backwards so a round starts where the previous ended.
Every pass starts at the vertex of its path nearest the end of the previous
cut in the tour (for rectangles: the nearest corner). A slit (an open contour) is
cut end to end on its path (no offset), from the end nearer the beam.

The passes are built as arrays (:func:`assemble`, vectorised for axis-aligned
rectangles) and the Job's ``passes`` is a lazy view over them, so 10^6 passes cost
no Python object each; the job-file reader regenerates them with the same function.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, replace
from typing import Sequence

import numpy as np

from camtube.design.contour import Contour, cut_contours, depth_for_contours
from camtube.design.pattern import Pattern, Process
from camtube.errors import Issue, PatternError
from camtube.plan.job import Job
from camtube.plan.packed import Packed, PassView, is_axis_rectangle, no_gc, points_bounds
from camtube.plan.paths import simplify_closed
from camtube.progress import NO_PROGRESS, Progress
from camtube.tol import TOL

ORDERINGS = ("interleaved", "sequential", "chained")
DEFAULT_ORDERING = "interleaved"


# ---------------------------------------------------------------- repeats
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


def cut_of_key(key: str) -> tuple[int, str] | None:
    """``(index, where)`` of an issue key :func:`_describe` wrote (``cut[3] (notch at x ...)``), else None: the caller
    that knows where cut ``index`` came from (a drawing's entity, a YAML key) names it so."""
    import re

    m = re.match(r"cut\[(\d+)\] \((.*)\)$", key or "")
    return (int(m.group(1)), m.group(2)) if m else None


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


def _nearest_vertex(points, p: tuple[float, float], allowed=None) -> int:
    """Index of the vertex of ``points`` ((n, 2) sequence) nearest to ``p`` (first on ties).

    ``allowed``: (n,) bool, the vertices that may be chosen (None or none allowed: all).
    """
    px, py = p
    d = [(q[0] - px) ** 2 + (q[1] - py) ** 2 for q in points]
    if allowed is not None and any(allowed):
        d = [v if ok else math.inf for v, ok in zip(d, allowed)]
    return d.index(min(d))


#: A chained group starts on the most curved smooth stretch of its contour: where the curvature is at least
#: this share of the contour's largest (smooth) curvature.
LINK_CURVATURE_SHARE = 0.5


def smooth_vertices(contour: Contour) -> np.ndarray | None:
    """(n,) bool: the vertices of a closed curved contour where a chained group may start (and its links lie).

    Where the drawing is smooth (a turn of at most ``TOL.corner_deg`` at the vertex and both neighbours),
    so no link is at a drawn corner; and of those, where it is most curved (curvature at least
    :data:`LINK_CURVATURE_SHARE` of the largest), where the machine runs slowly anyway, so the near-stop a
    5 um link costs is short (on a straight or a flat flank it would brake from the scan speed). None for
    a rectangle, a polygon without a smooth vertex or a slit (every start is then allowed).
    """
    from camtube.plan.paths import turn_angles_deg

    if not contour.closed or len(contour.points) <= 4:
        return None
    p = np.asarray(contour.points, dtype=float)
    turn = turn_angles_deg(p, True)
    ok = turn <= TOL.corner_deg
    ok = ok & np.roll(ok, 1) & np.roll(ok, -1)
    if not ok.any():
        return None
    seg = np.hypot(*(np.roll(p, -1, axis=0) - p).T)  # edge i -> i + 1
    with np.errstate(divide="ignore", invalid="ignore"):
        curv = np.radians(turn) / (0.5 * (seg + np.roll(seg, 1)))
    k_max = float(np.nanmax(np.where(ok, curv, np.nan)))
    if k_max > 0:
        ok = ok & (curv >= LINK_CURVATURE_SHARE * k_max)
    return ok


def _chain_starts(design: Sequence[Contour], order: Sequence[int], start: tuple[float, float],
                  slit_returns: bool = False, smooth: Sequence | None = None
                  ) -> tuple[dict[int, int], tuple[float, float]]:
    """Start vertex of each contour in ``order`` (nearest to where the previous one left the beam).

    A closed contour starts at its vertex nearest the previous end and ends there; an
    open one (a slit) starts at its nearer end (index 0 or n - 1) and ends at the other
    (or at the same end if ``slit_returns``: an even number of alternating passes).
    ``smooth``: per contour, the vertices a closed contour may start at (:func:`smooth_vertices`;
    None: any). Returns the starts and the point where the last contour leaves the beam.
    """
    out: dict[int, int] = {}
    p = start
    for i in order:
        c = design[i]
        pts = c.points
        if c.closed:
            k = _nearest_vertex(pts, p, None if smooth is None else smooth[i])
            p = pts[k]
        else:
            last = len(pts) - 1
            k = 0 if _nearest_vertex((pts[0], pts[last]), p) == 0 else last
            p = pts[k] if slit_returns else pts[last - k]
        out[i] = k
    return out, p


def _rotate(contour: Contour, k: int) -> Contour:
    if k == 0:
        return contour
    pts = contour.points
    return Contour(pts[k:] + pts[:k], contour.kind, contour.cut_index, contour.closed)


def pass_path(design: Contour, offset_mm: float, start: int, drill_index: int = 0, index: int = -1,
              alternate: bool = False) -> Contour:
    """The path of one pass over ``design``: the planner's (and the job-file reader's) one rule.

    Closed contour: moved ``offset_mm`` inward (:func:`offset_contour`) and started at the
    vertex matching ``design.points[start]`` (the same vertex for a rectangle, else the
    nearest one). Open contour (a slit): the path itself, no offset, cut from the end
    ``start`` (0 or n - 1) to the other; with ``alternate`` (sequential ordering, where a
    slit's passes follow each other) odd drill passes run back, so consecutive passes
    need no long rapid.
    """
    if not design.closed:
        pts = design.points
        if (start != 0) != (alternate and drill_index % 2 == 1):
            pts = pts[::-1]
        return Contour(tuple(pts), design.kind, design.cut_index, False)
    c = offset_contour(design, offset_mm, index)
    k = start if (c is design or is_axis_rectangle(design)) else _nearest_vertex(c.points, design.points[start])
    c = _rotate(c, k)
    if len(c.points) > 4 and not is_axis_rectangle(design):
        # a curve's flattened chords as few chords within TOL.path, all inside the region (plan.paths)
        pts = simplify_closed(c.points, TOL.path, 0.5 * offset_mm)
        if len(pts) < len(c.points):
            c = Contour(tuple(map(tuple, pts.tolist())), c.kind, c.cut_index, c.closed)
    return c


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
    progress: Progress = NO_PROGRESS,
) -> Job:
    """Plan the multi-pass laser job of a pattern or of a DXF's closed contours.

    Parameters
    ----------
    source : Pattern | sequence of Contour
        A pattern (cut from ``cut_contours(pattern)``, unwrapped across the
        seam; a drawing is read into one by :mod:`camtube.design.drawing`), or contours.
    process : Process, optional
        Defaults to the pattern's process (or the paper's for a DXF).
    ordering : {"interleaved", "sequential", "chained"}
        Pass ordering (see the module docstring).
    outer_radius_mm, length_mm : float, optional
        Tube outer radius and length; required for a DXF (the length may come
        from the DXF's construction outline).
    name : str, optional
        Job name; defaults to the pattern name or the DXF's file stem.
    progress : camtube.progress.Progress, optional
        Reports the planning (default: nothing).

    Returns
    -------
    Job
        ``len(cuts) * repeats * 2 * drill_passes`` passes in execution order, kept as
        arrays (``job.packed``; ``job.passes`` builds Pass objects on demand).
    """
    with no_gc():
        return _plan(source, process, ordering, outer_radius_mm, length_mm, name, progress)


def _plan(source, process, ordering, outer_radius_mm, length_mm, name, progress) -> Job:
    if ordering not in ORDERINGS:
        raise PatternError([Issue("ordering", "unknown ordering", ordering, " | ".join(ORDERINGS),
                                  f"use one of {', '.join(ORDERINGS)}")])
    src = _source(source, process, outer_radius_mm, length_mm, name)
    proc = src.process
    if proc.drill_passes < 1:
        raise PatternError([Issue("process.drill_passes", "must be at least 1", proc.drill_passes, ">= 1",
                                  "set process.drill_passes to 1 or more")])
    design = src.contours
    if not design:
        # (a pattern of notch.count 0 and no holes: max() of an empty sequence, a traceback)
        raise PatternError([Issue("cuts", "the pattern has no cuts: nothing to plan", 0, ">= 1 cut",
                                  "set notch.count to 1 or more, or add holes or cuts")])
    for i, c in enumerate(design):
        if len(c.points) < (3 if c.closed else 2):
            raise PatternError([Issue(_describe(c, i), "too few points for a " + ("closed contour" if c.closed
                                      else "slit"), len(c.points), ">= 3 (closed) or >= 2 (slit)",
                                      "draw the cut with more points or remove it")])
    repeats = repeats_for(proc, depth_for_contours(src.outer_radius_mm, design))
    n_total = len(design) * repeats * 2 * proc.drill_passes
    with progress.task("planning", total=n_total) as task:
        fwd = tour(design)
        # sequential, chained: a slit's passes alternate direction; an even number of them ends where it began
        returns = ordering in ("sequential", "chained") and proc.drill_passes % 2 == 0
        # chained: the links between a cut's drill passes lie where the drawing is smooth and most curved
        smooth = [smooth_vertices(c) for c in design] if ordering == "chained" else None
        s0, end = _chain_starts(design, fwd, (0.0, 0.0), returns, smooth)
        starts = [s0]
        if ordering in ("interleaved", "chained"):
            # backward rounds start where forward rounds end and vice versa
            s1, end = _chain_starts(design, fwd[::-1], end, returns, smooth)
            starts = [_chain_starts(design, fwd, end, returns, smooth)[0], s1]
        task.advance(n_total // 4)
        start_arr = np.array([[st[i] for i in range(len(design))] for st in starts], dtype=np.int64)
        packed = assemble(design, fwd, start_arr, repeats, ordering, proc)
        task.advance(n_total - n_total // 4)
    view = PassView(packed, design, np.asarray(fwd, dtype=np.int64), start_arr)
    return Job(src.name, src.outer_radius_mm, src.length_mm, design, view, proc, repeats, ordering)


def pass_sequence(order: Sequence[int], n_cut: int, repeats: int, n_drill: int, ordering: str):
    """The pass order as arrays (one row per pass): cut, repeat, focus level, drill, tour direction.

    ``sequential``: every pass of a cut (repeat, focus, drill), then the next cut in ``order``.
    ``interleaved``: round ``k`` = (repeat, focus, drill) visits every cut, along ``order``
    on even rounds and backwards on odd ones.
    ``chained``: round ``k`` = (repeat, focus) visits every cut, along ``order`` on even rounds
    and backwards on odd ones, and cuts its drill passes one after the other.
    """
    order = np.asarray(order, dtype=np.int32)
    per_cut = repeats * 2 * n_drill
    k = np.arange(per_cut, dtype=np.int32)
    r_k, f_k, d_k = k // (2 * n_drill), (k // n_drill) % 2, k % n_drill
    if ordering == "sequential":
        cut_a = np.repeat(order, per_cut)
        rep_a, foc_a, dri_a = (np.tile(a, n_cut) for a in (r_k, f_k, d_k))
        dir_a = np.zeros(len(cut_a), dtype=np.int32)
    elif ordering == "chained":
        rounds = np.arange(2 * repeats, dtype=np.int32)
        dir_r = rounds % 2
        cut_r = np.where(dir_r[:, None] == 0, order[None, :], order[::-1][None, :])  # (rounds, n_cut)
        cut_a = np.repeat(cut_r.ravel(), n_drill)
        rep_a = np.repeat(rounds // 2, n_cut * n_drill)
        foc_a = np.repeat(rounds % 2, n_cut * n_drill)
        dri_a = np.tile(np.arange(n_drill, dtype=np.int32), 2 * repeats * n_cut)
        dir_a = np.repeat(dir_r, n_cut * n_drill)
    else:
        dir_k = k % 2
        cut_a = np.where(dir_k[:, None] == 0, order[None, :], order[::-1][None, :]).ravel()
        rep_a, foc_a, dri_a, dir_a = (np.repeat(a, n_cut) for a in (r_k, f_k, d_k, dir_k))
    return cut_a, rep_a, foc_a, dri_a, dir_a


def _round_pairs(repeats: int, n_drill: int, ordering: str) -> set[tuple[int, int]]:
    """The (tour direction, drill) pairs the rounds of :func:`pass_sequence` use."""
    if ordering == "sequential":
        return {(0, d) for d in range(n_drill)}
    if ordering == "chained":
        return {(k % 2, d) for k in range(2 * repeats) for d in range(n_drill)}
    return {(k % 2, k % n_drill) for k in range(repeats * 2 * n_drill)}


def assemble(design: Sequence[Contour], order: Sequence[int], starts: np.ndarray, repeats: int, ordering: str,
             process: Process) -> Packed:
    """The passes of a job as :class:`Packed` arrays, from its cuts, tour and start vertices.

    Parameters
    ----------
    design : sequence of Contour
        The cut regions (closed) and slits (open), indexed by cut.
    order : (n,) int
        Tour (visiting order of the cuts).
    starts : (n_dir, n) int
        Start vertex of each cut per tour direction (1 row for sequential, 2 for interleaved).
    repeats : int
    ordering : str
    process : Process
        Drill passes and offsets, defocus, kerf, power, frequency, speed.

    Vectorised for axis-aligned rectangles (the patterns' cuts); other contours and slits
    go through :func:`pass_path` one path at a time. Only paths some pass uses are built.
    """
    offsets = np.asarray(pass_offsets_mm(process), dtype=float)
    focus = np.array([0.0, float(process.defocus_mm)])
    n_cut, n_drill = len(design), len(offsets)
    cut_a, rep_a, foc_a, dri_a, dir_a = pass_sequence(order, n_cut, repeats, n_drill, ordering)
    # paths used: (tour direction t, cut i, drill d) for every cut and every (t, d) some round uses,
    # numbered in (t, i, d) order without sorting the passes
    n_dir = int(dir_a.max()) + 1 if len(dir_a) else 1
    used_d = [sorted({int(d) for t, d in _round_pairs(repeats, n_drill, ordering) if t == tt}) for tt in range(n_dir)]
    n_d = np.array([len(ds) for ds in used_d], dtype=np.int64)
    base = np.concatenate(([0], np.cumsum(n_d * n_cut)[:-1])).astype(np.int64)
    rank = np.zeros((n_dir, n_drill), dtype=np.int64)
    for tt, ds in enumerate(used_d):
        rank[tt, ds] = np.arange(len(ds))
    pass_geom = (base[dir_a] + cut_a.astype(np.int64) * n_d[dir_a] + rank[dir_a, dri_a]).astype(np.int32)
    del dir_a
    t_u = np.concatenate([np.full(n_cut * len(ds), tt, dtype=np.int64) for tt, ds in enumerate(used_d)])
    i_u = np.concatenate([np.repeat(np.arange(n_cut, dtype=np.int64), len(ds)) for ds in used_d])
    d_u = np.concatenate([np.tile(np.asarray(ds, dtype=np.int64), n_cut) for ds in used_d])

    is_rect = np.fromiter((is_axis_rectangle(c) for c in design), dtype=bool, count=n_cut)
    closed = np.fromiter((c.closed for c in design), dtype=bool, count=n_cut)
    sizes = np.where(is_rect[i_u], 4, 0)
    rect_rows = np.flatnonzero(is_rect[i_u])
    other: dict[int, np.ndarray] = {}
    for r in np.flatnonzero(~is_rect[i_u]).tolist():
        t, i, d = int(t_u[r]), int(i_u[r]), int(d_u[r])
        path = pass_path(design[i], float(offsets[d]), int(starts[t, i]), d, i, ordering in ("sequential", "chained"))
        other[r] = np.asarray(path.points, dtype=float).reshape(-1, 2)
        sizes[r] = len(path.points)
    geom_offset = np.zeros(len(t_u) + 1, dtype=np.int64)
    np.cumsum(sizes, out=geom_offset[1:])
    vertices = np.empty((int(geom_offset[-1]), 2))
    if len(rect_rows):
        rect_cuts = np.flatnonzero(is_rect)
        pts = np.zeros((n_cut, 4, 2))
        pts[rect_cuts] = np.array([design[i].points for i in rect_cuts.tolist()], dtype=float).reshape(-1, 4, 2)
        lo, hi = pts.min(axis=1), pts.max(axis=1)  # (n, 2) each
        width = np.minimum(hi[:, 0] - lo[:, 0], hi[:, 1] - lo[:, 1])
        vanish = is_rect[:, None] & (width[:, None] - 2 * offsets[None, :] <= TOL.zero)
        if vanish.any():
            i, d = np.argwhere(vanish)[0].tolist()
            raise _vanish(design[i], float(offsets[d]), i)
        ii, o = i_u[rect_rows], offsets[d_u[rect_rows]][:, None]
        p, a, b = pts[ii], lo[ii][:, None, :], hi[ii][:, None, :]
        # each corner moves diagonally inward; vertex order kept, then started at the start vertex
        moved = np.where(p == a, a + o[..., None], b - o[..., None])
        k = starts[t_u[rect_rows], ii]
        idx = (k[:, None] + np.arange(4)[None, :]) % 4
        moved = np.take_along_axis(moved, idx[..., None], axis=1)
        rows = geom_offset[rect_rows][:, None] + np.arange(4)[None, :]
        vertices[rows.ravel()] = moved.reshape(-1, 2)
    for r, v in other.items():
        vertices[geom_offset[r]:geom_offset[r + 1]] = v
    n = len(cut_a)
    pass_offset = offsets[dri_a] if closed.all() else np.where(closed[cut_a], offsets[dri_a], 0.0)
    pass_z = focus[foc_a]
    link = np.zeros(n, dtype=bool)
    if ordering == "chained" and n > 1:
        # a drill pass of a closed cut follows the one before it (same cut, repeat and focus) with the beam on
        link[1:] = ((cut_a[1:] == cut_a[:-1]) & (rep_a[1:] == rep_a[:-1]) & (foc_a[1:] == foc_a[:-1])
                    & closed[cut_a[1:]])
    foc_a = foc_a.astype(np.int8)
    const = lambda v: np.broadcast_to(np.float64(v), (n,))  # noqa: E731  (read-only, no memory per pass)
    return Packed.of_arrays(vertices, geom_offset, closed[i_u], pass_geom, cut_a, pass_z,
                            const(process.scan_speed_mm_s), const(process.power_w), const(process.frequency_khz),
                            rep_a, foc_a, dri_a, pass_offset, link)
