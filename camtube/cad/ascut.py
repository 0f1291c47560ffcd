"""The tube as the job will cut it: a kerf simulation in the unrolled frame (shapely).

Model (2-D, through-cut):

1. Every laser-on move of the job's move list (:func:`camtube.plan.job_moves`)
   sweeps a round beam of width ``kerf`` (``process.kerf_mm``; if that is 0 --
   no kerf compensation planned -- :data:`DEFAULT_SIM_KERF_MM` is used for the
   simulation only): the segment buffered by ``kerf / 2`` with round caps.
   Passes that repeat a path (repeats, focus levels) add nothing in 2-D, so
   identical segments are swept once. Depth is not simulated: every pass is
   assumed to cut through the wall (the planner's repeats rule is about that).
2. The kerf union ``K`` may enclose material: every hole (interior ring) of
   ``K`` is a *slug* that is detached and falls out. The removed region is
   ``R = K + slugs``. A cut whose design area is not inside ``R`` left its
   slug standing (e.g. the kerf ring does not close).
3. Compared with the design region ``D`` on the sheet (wrapped modulo the
   circumference): *overcut* = ``R - D`` (material lost outside the design),
   *undercut* = ``D - R`` (design material left standing); each connected piece
   is reported with its area, bounding box, centroid, depth and the cut it
   belongs to.

Allowances (what is expected of a correct job, not an error):

- a job planned without kerf compensation (``kerf_mm = 0``) cuts its first
  pass on the design line, so it overcuts by half the beam kerf everywhere;
- a round beam cannot reach a sharp outer corner: ``(sqrt 2 - 1) kerf / 2``
  of material stays in each corner of a rectangular cut;
- plus :data:`DEPTH_TOL_MM` of numerical/positioning slack.

All lengths mm, areas mm^2, in the unrolled frame of
:mod:`camtube.design.pattern` (x from the tip, y arc length on the outer surface).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from camtube.design.pattern import ASSUMED_KERF_MM

#: Beam kerf (mm) assumed by the simulation when the process has none (kerf_mm = 0).
DEFAULT_SIM_KERF_MM = ASSUMED_KERF_MM
#: Slack (mm) on the overcut/undercut depth allowances.
DEPTH_TOL_MM = 0.002
#: Pieces smaller than this (mm^2) are numerical dust, not reported.
AREA_EPS_MM2 = 1e-8
#: Segments per quarter circle of the round beam.
QUAD_SEGS = 8


@dataclass(frozen=True)
class Region:
    """A connected piece of overcut or undercut on the sheet (``0 <= y < C``).

    Attributes
    ----------
    kind : {"overcut", "undercut"}
    cut_index : int
        The cut it belongs to (index into ``Job.design``).
    area_mm2 : float
    bounds : (xmin, ymin, xmax, ymax), mm
    centroid : (x, y), mm
    depth_mm : float
        How far it reaches from the design boundary: for overcut the largest
        distance to the design region, for undercut the largest distance to
        the removed region.
    deepest : (x, y), mm
        Where that depth is reached.
    angle_deg : float
        Rotary angle of the centroid.
    """

    kind: str
    cut_index: int
    area_mm2: float
    bounds: tuple[float, float, float, float]
    centroid: tuple[float, float]
    depth_mm: float
    deepest: tuple[float, float]
    angle_deg: float

    def describe(self) -> str:
        x0, y0, x1, y1 = self.bounds
        return (f"{self.kind} of cut[{self.cut_index}]: {self.area_mm2:.5f} mm^2 in x {x0:.3f}..{x1:.3f} mm, "
                f"y {y0:.3f}..{y1:.3f} mm; deepest {self.depth_mm * 1000:.1f} um at (x {self.deepest[0]:.3f}, "
                f"y {self.deepest[1]:.3f}) mm")


@dataclass(frozen=True)
class CutResult:
    """What the job does to one design cut.

    Attributes
    ----------
    index : int
        Index into ``Job.design``.
    kind : str
    design_area_mm2, removed_area_mm2 : float
        Area of the design cut, and of the region the cut's passes remove
        (kerf + its freed slugs).
    slug_area_mm2 : float
        Area of the slug(s) the cut frees (0 if none).
    status : {"slug freed", "ablated", "not freed", "not cut"}
        ``ablated``: the kerf itself covers the design area (no slug).
    moves : int
        Distinct laser-on segments of the cut.
    overcut_mm2, undercut_mm2 : float
    """

    index: int
    kind: str
    design_area_mm2: float
    removed_area_mm2: float
    slug_area_mm2: float
    status: str
    moves: int
    overcut_mm2: float
    undercut_mm2: float


@dataclass(frozen=True)
class Web:
    """Narrowest bridge of material between two cuts (mm), as cut and as designed."""

    a: int
    b: int
    as_cut_mm: float
    design_mm: float
    where: tuple[float, float]


@dataclass(frozen=True, eq=False)
class AsCut:
    """Result of :func:`simulate`.

    Attributes
    ----------
    kerf_mm : float
        Kerf used by the simulation.
    kerf_from_process : bool
        False when :data:`DEFAULT_SIM_KERF_MM` stood in for ``kerf_mm = 0``.
    outer_radius_mm, length_mm : float
    removed : shapely geometry
        Removed region, unwrapped (the cutters of the as-cut model).
    removed_by_cut : tuple of shapely geometry
        Unwrapped removed region of each cut's passes.
    design : tuple of shapely Polygon
        Unwrapped design region of each cut.
    cuts : tuple[CutResult, ...]
    overcut, undercut : tuple[Region, ...]
        Pieces larger than :data:`AREA_EPS_MM2`, biggest first.
    webs : tuple[Web, ...]
        For each cut, its narrowest web to another cut (pairs listed once).
    allow_overcut_mm, allow_undercut_mm : float
        Depth allowances (see the module docstring).
    expected_overcut_mm : float
        Overcut expected on every edge: ``kerf / 2`` for a job planned without kerf compensation (its first
        pass runs on the design line), 0 for a compensated one. Every web is that much thinner on each side.
    """

    kerf_mm: float
    kerf_from_process: bool
    outer_radius_mm: float
    length_mm: float
    removed: object
    removed_by_cut: tuple
    design: tuple
    cuts: tuple[CutResult, ...]
    overcut: tuple[Region, ...]
    undercut: tuple[Region, ...]
    webs: tuple[Web, ...]
    allow_overcut_mm: float
    allow_undercut_mm: float
    expected_overcut_mm: float = 0.0

    @property
    def circumference_mm(self) -> float:
        return 2.0 * math.pi * self.outer_radius_mm

    @property
    def overcut_mm2(self) -> float:
        return sum(r.area_mm2 for r in self.overcut)

    @property
    def undercut_mm2(self) -> float:
        return sum(r.area_mm2 for r in self.undercut)

    @property
    def min_web(self) -> Web | None:
        return min(self.webs, key=lambda w: (w.as_cut_mm, w.a, w.b)) if self.webs else None


# ---------------------------------------------------------------- sheet helpers
def _polys(g) -> list:
    if g is None or g.is_empty:
        return []
    if g.geom_type == "Polygon":
        return [g]
    return [p for p in getattr(g, "geoms", []) if p.geom_type == "Polygon" and not p.is_empty] + [
        q for p in getattr(g, "geoms", []) if p.geom_type in ("MultiPolygon", "GeometryCollection") for q in _polys(p)]


def wrap_sheet(g, circumference_mm: float):
    """Fold an unwrapped geometry into the sheet ``0 <= y <= C`` (pieces shifted by multiples of C)."""
    import shapely
    from shapely import affinity
    from shapely.geometry import box

    if g.is_empty:
        return g
    c = circumference_mm
    x0, y0, x1, y1 = g.bounds
    parts = []
    for k in range(math.floor(y0 / c), math.floor(y1 / c) + 1):
        piece = shapely.intersection(g, box(x0 - 1.0, k * c, x1 + 1.0, (k + 1) * c))
        if not piece.is_empty:
            parts.append(affinity.translate(piece, 0.0, -k * c))
    return shapely.union_all(parts)


def _periodic(g, circumference_mm: float):
    """``g`` and its copies shifted by +-C (for distances across the seam)."""
    import shapely
    from shapely import affinity

    return shapely.union_all([g, affinity.translate(g, 0.0, circumference_mm),
                              affinity.translate(g, 0.0, -circumference_mm)])


def _max_distance(piece, to_parts: list, to_tree, step_mm: float) -> tuple[float, tuple[float, float]]:
    """Largest distance from the boundary points of ``piece`` (densified every ``step_mm``) to the
    union of ``to_parts`` (indexed by the STRtree ``to_tree``), and the point where it occurs.

    Only parts within the piece's bounding-box diagonal are considered (the piece touches or
    lies within that reach of its own cut); if there are none, all are.
    """
    import shapely

    pts = shapely.get_coordinates(shapely.segmentize(piece.boundary, step_mm))
    if len(pts) == 0 or not to_parts:
        c = piece.centroid
        return 0.0, (float(c.x), float(c.y))
    x0, y0, x1, y1 = piece.bounds
    reach = math.hypot(x1 - x0, y1 - y0)
    near = to_tree.query(piece, predicate="dwithin", distance=reach)
    local = shapely.union_all([to_parts[int(k)] for k in near]) if len(near) else shapely.union_all(to_parts)
    d = shapely.distance(shapely.points(pts), local)
    k = int(np.argmax(d))
    return float(d[k]), (float(pts[k, 0]), float(pts[k, 1]))


def design_region(contour, kerf_mm: float):
    """The sheet region a design contour asks to remove: its polygon, or for a slit (an open
    path) the band the beam sweeps along it, ``kerf_mm`` wide with round ends."""
    from shapely.geometry import LineString, Polygon

    if getattr(contour, "closed", True):
        return Polygon(contour.points)
    return LineString(contour.points).buffer(kerf_mm / 2.0, quad_segs=QUAD_SEGS)


# ---------------------------------------------------------------- simulation
def _cut_segments(job, moves) -> dict[int, np.ndarray]:
    """Distinct laser-on segments (k, 4) [x0, y0, x1, y1] of each cut."""
    x0, y0, _ = moves.starts()
    on = np.asarray(moves.laser, dtype=bool)
    cut_of_move = np.asarray(job.packed.pass_cut)[np.asarray(moves.pass_index)]
    seg = np.column_stack([x0, y0, moves.x, moves.y])[on]
    cid = cut_of_move[on]
    # a segment and its reverse sweep the same kerf
    rev = (seg[:, 0] > seg[:, 2]) | ((seg[:, 0] == seg[:, 2]) & (seg[:, 1] > seg[:, 3]))
    seg[rev] = seg[rev][:, [2, 3, 0, 1]]
    key = np.column_stack([cid, np.round(seg, 9)])
    # one of each (rounded) segment, with its own coordinates: rounded ones would move a cut's edge by up to
    # 0.5 nm, more than the min_web check's slack (TOL.rule) allows a web at the limit
    _, first = np.unique(key, axis=0, return_index=True)
    uniq = np.column_stack([cid, seg])[first]
    out: dict[int, np.ndarray] = {}
    for c in np.unique(uniq[:, 0]).astype(int).tolist():
        out[c] = uniq[uniq[:, 0] == c][:, 1:]
    return out


def simulate(job, moves=None, kerf_mm: float | None = None) -> AsCut:
    """Sweep the kerf along every laser-on move of ``job`` and compare with its design.

    Parameters
    ----------
    job : camtube.plan.Job
    moves : camtube.plan.Moves, optional
        The move list to simulate (default ``job_moves(job)``); pass an edited
        one to simulate a faulty machine program.
    kerf_mm : float, optional
        Beam kerf; default ``process.kerf_mm`` or :data:`DEFAULT_SIM_KERF_MM` if that is 0.
    """
    import shapely
    from shapely.geometry import Polygon
    from shapely.strtree import STRtree

    from camtube.plan import job_moves

    mv = job_moves(job) if moves is None else moves
    from_process = kerf_mm is None and job.process.kerf_mm > 0
    kerf = float(kerf_mm if kerf_mm is not None else (job.process.kerf_mm or DEFAULT_SIM_KERF_MM))
    if not kerf > 0:
        raise ValueError(f"kerf_mm must be > 0 for the simulation, got {kerf}")
    compensated = job.process.kerf_mm > 0
    expected_over = 0.0 if compensated else kerf / 2.0
    allow_over = expected_over + DEPTH_TOL_MM
    allow_under = (math.sqrt(2.0) - 1.0) * kerf / 2.0 + DEPTH_TOL_MM
    ro, circ = float(job.outer_radius_mm), 2.0 * math.pi * float(job.outer_radius_mm)
    n = len(job.design)
    step = max(kerf / 4.0, 1e-4)

    design = tuple(design_region(c, kerf) for c in job.design)
    segs = _cut_segments(job, mv)
    kerfs = []
    for i in range(n):
        s = segs.get(i)
        if s is None or len(s) == 0:
            kerfs.append(Polygon())
            continue
        lines = shapely.linestrings(s.reshape(-1, 2, 2))
        kerfs.append(shapely.union_all(shapely.buffer(lines, kerf / 2.0, quad_segs=QUAD_SEGS)))
    k_all = shapely.union_all(kerfs)

    # slugs: holes of the kerf union; each to the cut whose design it overlaps most (else nearest)
    slugs = [Polygon(r) for p in _polys(k_all) for r in p.interiors]
    slug_owner = []
    dtree = STRtree(list(design)) if n else None
    for s in slugs:
        cand = dtree.query(s) if dtree is not None else []
        best = max(cand, key=lambda j: (design[j].intersection(s).area, -j), default=None) if len(cand) else None
        if best is None and n:
            best = int(dtree.query_nearest(s)[0]) if n else -1
        slug_owner.append(int(best) if best is not None else -1)
    removed_by_cut = tuple(
        shapely.union_all([kerfs[i]] + [s for s, o in zip(slugs, slug_owner) if o == i]) for i in range(n))
    removed = shapely.union_all([Polygon(p.exterior) for p in _polys(k_all)])

    d_sheet = wrap_sheet(shapely.union_all(design), circ) if n else Polygon()
    r_sheet = wrap_sheet(removed, circ)
    d_per = _periodic(d_sheet, circ)
    r_per = _periodic(r_sheet, circ)
    r_cut_sheet = [wrap_sheet(r, circ) for r in removed_by_cut]
    d_cut_sheet = [wrap_sheet(d, circ) for d in design]

    def regions(kind, geom, owners, depth_to):
        tree = STRtree(owners)
        parts = _polys(depth_to)
        to_tree = STRtree(parts) if parts else None
        out = []
        for p in _polys(geom):
            if p.area <= AREA_EPS_MM2:
                continue
            cand = tree.query(p)
            owner = max(cand, key=lambda j: (owners[j].intersection(p).area, -j), default=None) if len(cand) else None
            if owner is None or owners[owner].intersection(p).area <= 0.0:
                owner = int(tree.query_nearest(p)[0])
            c = p.centroid
            depth, deepest = _max_distance(p, parts, to_tree, step)
            out.append(Region(kind, int(owner), float(p.area), tuple(float(v) for v in p.bounds),
                              (float(c.x), float(c.y)), depth, deepest,
                              math.degrees(float(c.y) / ro) % 360.0))
        out.sort(key=lambda r: (-r.area_mm2, r.cut_index, r.bounds))
        return tuple(out)

    over = regions("overcut", shapely.difference(r_sheet, d_sheet), r_cut_sheet, d_per) if n else ()
    under = regions("undercut", shapely.difference(d_sheet, r_sheet), d_cut_sheet, r_per) if n else ()

    cuts = []
    for i, c in enumerate(job.design):
        ov = sum(r.area_mm2 for r in over if r.cut_index == i)
        un_regions = [r for r in under if r.cut_index == i]
        un = sum(r.area_mm2 for r in un_regions)
        slug_area = sum(s.area for s, o in zip(slugs, slug_owner) if o == i)
        left = any(r.depth_mm > allow_under for r in un_regions)
        if i not in segs:
            status = "not cut"
        elif left:
            status = "not freed"
        elif slug_area >= 0.5 * design[i].area:
            status = "slug freed"
        else:
            status = "ablated"
        cuts.append(CutResult(i, c.kind, float(design[i].area), float(removed_by_cut[i].area), float(slug_area),
                              status, int(len(segs.get(i, ()))), float(ov), float(un)))

    webs = _webs(removed_by_cut, design, circ)
    return AsCut(kerf, from_process, ro, float(job.length_mm), removed, removed_by_cut, design, tuple(cuts),
                 over, under, webs, allow_over, allow_under, expected_over)


def _webs(removed: Sequence, design: Sequence, circ: float) -> tuple[Web, ...]:
    """Each cut's narrowest web to any other cut (across the seam too), pairs once."""
    import shapely
    from shapely import affinity
    from shapely.strtree import STRtree

    n = len(removed)
    if n < 2:
        return ()
    geoms, owner = [], []
    for j, g in enumerate(removed):
        for k in (-1, 0, 1):
            geoms.append(affinity.translate(g, 0.0, k * circ) if k else g)
            owner.append(j)
    tree = STRtree(geoms)
    pairs: dict[tuple[int, int], Web] = {}
    for i, g in enumerate(removed):
        if g.is_empty:
            continue
        best = None
        for radius in (0.5, 2.0, 10.0, math.inf):
            cand = [int(k) for k in (tree.query(g, predicate="dwithin", distance=radius) if math.isfinite(radius)
                                     else range(len(geoms))) if owner[int(k)] != i and not geoms[int(k)].is_empty]
            if cand:
                best = min(cand, key=lambda k: (shapely.distance(g, geoms[k]), owner[k]))
                break
        if best is None:
            continue
        j = owner[best]
        a, b = min(i, j), max(i, j)
        if (a, b) in pairs:
            continue
        d_cut = float(shapely.distance(g, geoms[best]))
        d_des = min(float(shapely.distance(design[i], affinity.translate(design[j], 0.0, k * circ))) for k in (-1, 0, 1))
        p, q = shapely.shortest_line(g, geoms[best]).coords
        pairs[(a, b)] = Web(a, b, d_cut, d_des, (0.5 * (p[0] + q[0]), (0.5 * (p[1] + q[1])) % circ))
    return tuple(pairs[k] for k in sorted(pairs))
