"""The one neutral path type: closed contours in the unrolled frame.

A :class:`Contour` is a closed polygon in (x, y) mm on the unrolled outer
surface (see :mod:`camtube.design.pattern` for the frame). Every output of
camtube (design DXF, toolpaths, G-code, job file, previews) is written from
contours. The wrap to a rotary axis happens only in the post-processor.

Two forms of the same cut exist:

- *unwrapped*: one contour per cut, ``y`` may leave ``[0, 2 pi r_o)`` when
  the cut straddles the seam ``y = 0``. This is what a rotary stage cuts (A is
  continuous) and what the planner uses.
- *seam-split*: the pieces of the cut inside ``0 <= y <= 2 pi r_o`` (the seam
  line ``y = 2 pi r_o`` is the same line as ``y = 0``). This is the drawing a
  CAD user would make on a flat sheet, and what the design DXF holds.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camtube.design.pattern import Cut, Pattern
from camtube.tol import TOL


@dataclass(frozen=True)
class Contour:
    """A closed polygon (last point joins the first; not repeated), or an open path (a slit).

    Attributes
    ----------
    points : tuple[tuple[float, float], ...]
        Vertices (x_mm, y_mm), counter-clockwise.
    kind : str
        ``notch``, ``hole``, ``slit`` (an open path) or ``cut`` (contours given without a pattern).
    cut_index : int
        Index of the cut in ``Pattern.cuts`` it comes from (-1 if unknown).
    closed : bool
        True (the default) for a closed polygon; False for an open path the beam
        follows from the first point to the last (a slit: its kerf is the cut).
    """

    points: tuple[tuple[float, float], ...]
    kind: str = "cut"
    cut_index: int = -1
    closed: bool = True

    @property
    def xy(self) -> np.ndarray:
        """(n, 2) float array of the vertices."""
        return np.asarray(self.points, dtype=float)

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """(xmin, ymin, xmax, ymax) in mm."""
        a = self.xy
        return float(a[:, 0].min()), float(a[:, 1].min()), float(a[:, 0].max()), float(a[:, 1].max())

    @property
    def area_mm2(self) -> float:
        """Signed area (positive for counter-clockwise)."""
        a = self.xy
        x, y = a[:, 0], a[:, 1]
        return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))

    @property
    def length_mm(self) -> float:
        """Perimeter of the closed polygon, or the length of the open path."""
        a = self.xy
        if not self.closed:
            return float(np.linalg.norm(np.diff(a, axis=0), axis=1).sum())
        return float(np.linalg.norm(np.roll(a, -1, axis=0) - a, axis=1).sum())


def rectangle(x0: float, y0: float, x1: float, y1: float, kind: str = "cut", cut_index: int = -1) -> Contour:
    """Axis-aligned rectangle, counter-clockwise from (x0, y0)."""
    return Contour(((x0, y0), (x1, y0), (x1, y1), (x0, y1)), kind, cut_index)


def cut_contour(cut: Cut, outer_radius_mm: float, cut_index: int = -1) -> Contour:
    """Unwrapped contour of one cut (``y`` may leave ``[0, 2 pi r_o)``).

    A drawn cut gives its outline (an open path, ``closed=False``, for a slit);
    any other cut its rectangle.
    """
    if cut.outline is not None:
        return Contour(cut.outline, cut.kind, cut_index, cut.kind != "slit")
    y0, y1 = cut.y_range_mm(outer_radius_mm)
    return rectangle(cut.x_start_mm, y0, cut.x_end_mm, y1, cut.kind, cut_index)


def deepest_arc_mm(outer_radius_mm: float, contours) -> float:
    """The largest circumferential extent of ``contours`` (mm on the outer surface), at most the circumference: the
    cut the beam goes deepest for (:func:`depth_for_contours`)."""
    arc = max(max(p[1] for p in c.points) - min(p[1] for p in c.points) for c in contours)
    return min(arc, 2.0 * math.pi * outer_radius_mm)


def depth_for_contours(outer_radius_mm: float, contours) -> float:
    """Beam depth (mm) of the deepest cut: ``beam_depth_mm(r_o, largest circumferential extent)``; the depth the
    repeat rule must cover (read by the planner for the repeats, and by the design rules before it)."""
    from camtube.design.geometry import beam_depth_mm

    return beam_depth_mm(outer_radius_mm, deepest_arc_mm(outer_radius_mm, contours))


def cut_contours(pattern: Pattern) -> tuple[Contour, ...]:
    """Unwrapped contours of every cut of ``pattern``, in ``pattern.cuts`` order."""
    ro = pattern.tube.outer_radius_mm
    return tuple(cut_contour(c, ro, i) for i, c in enumerate(pattern.cuts))


def _is_rectangle(contour: Contour) -> bool:
    if len(contour.points) != 4 or not contour.closed:
        return False
    x0, y0, x1, y1 = contour.bounds
    z = TOL.zero
    return all((abs(x - x0) <= z or abs(x - x1) <= z) and (abs(y - y0) <= z or abs(y - y1) <= z)
               for x, y in contour.points)


def split_at_seam(contour: Contour, circumference_mm: float) -> tuple[Contour, ...]:
    """Pieces of a contour inside ``0 <= y <= C``.

    A rectangle that crosses ``y = 0`` (or ``y = C``) becomes two closed
    rectangles, one ending on ``y = C`` and one starting on ``y = 0``. A
    rectangle inside the sheet is returned unchanged (shifted by a multiple of
    C if needed). Any other polygon (or open path) is cut by the seam lines
    with shapely, each piece shifted onto the sheet.
    """
    if not _is_rectangle(contour):
        return _split_general(contour, circumference_mm)
    x0, y0, x1, y1 = contour.bounds
    c = circumference_mm
    shift = math.floor(y0 / c) * c
    y0, y1 = y0 - shift, y1 - shift
    if abs(y0 - c) <= TOL.merge:  # starts on the seam: same as starting at 0
        y0, y1 = 0.0, y1 - c
    if y1 <= c + TOL.merge:
        return (rectangle(x0, y0, x1, min(y1, c), contour.kind, contour.cut_index),)
    return (
        rectangle(x0, y0, x1, c, contour.kind, contour.cut_index),
        rectangle(x0, 0.0, x1, y1 - c, contour.kind, contour.cut_index),
    )


def _split_general(contour: Contour, c: float) -> tuple[Contour, ...]:
    import shapely
    from shapely.geometry import LineString, Polygon, box
    from shapely.geometry.polygon import orient

    x0, y0, x1, y1 = contour.bounds
    geom = Polygon(contour.points) if contour.closed else LineString(contour.points)
    out: list[Contour] = []
    for k in range(math.floor(y0 / c), math.floor(y1 / c) + 1):
        piece = shapely.intersection(geom, box(x0 - 1.0, k * c, x1 + 1.0, (k + 1) * c))
        piece = shapely.affinity.translate(piece, 0.0, -k * c)
        for g in getattr(piece, "geoms", [piece]):
            if contour.closed and g.geom_type == "Polygon" and g.area > TOL.zero:
                ring = list(orient(g, 1.0).exterior.coords)[:-1]
                out.append(Contour(tuple((float(x), float(y)) for x, y in ring), contour.kind, contour.cut_index))
            elif not contour.closed and g.geom_type == "LineString" and g.length > TOL.zero:
                out.append(Contour(tuple((float(x), float(y)) for x, y in g.coords), contour.kind,
                                   contour.cut_index, False))
    return tuple(out)


def sheet_contours(pattern: Pattern) -> tuple[Contour, ...]:
    """Seam-split contours of every cut (what the design DXF draws)."""
    c = pattern.tube.circumference_mm
    out: list[Contour] = []
    for con in cut_contours(pattern):
        out.extend(split_at_seam(con, c))
    return tuple(out)


def outline(pattern: Pattern) -> Contour:
    """The unrolled tube surface [0, L] x [0, 2 pi r_o] (construction, never cut)."""
    return rectangle(0.0, 0.0, pattern.tube.length_mm, pattern.tube.circumference_mm, "outline")


def merge_seam_polygons(contours, circumference_mm: float, tol_mm: float) -> list[tuple[Contour, tuple[int, ...]]]:
    """Join seam-split pieces of any shape back into unwrapped contours.

    A closed piece touching ``y = C`` and one of the same kind touching
    ``y = 0`` are one cut when, moved up by C, the second shares an edge of
    positive length with the first (both within ``tol_mm`` of the seam). Open
    paths (slits) are joined when one ends on ``y = C`` where the other starts
    (or ends) on ``y = 0``. Chains of pieces (a cut spanning more than a turn)
    are not joined.

    Returns
    -------
    list of (Contour, tuple[int, ...])
        Each joined or untouched contour and the indices of the input pieces it is made of.
    """
    import shapely
    from shapely.geometry import Polygon
    from shapely.geometry.polygon import orient

    c = circumference_mm
    items = list(contours)
    used = [False] * len(items)
    out: list[tuple[Contour, tuple[int, ...]]] = []

    def on_line(con: Contour, y: float) -> list[tuple[float, float]]:
        pts = con.points
        n = len(pts)
        segs = []
        for k in range(n if con.closed else n - 1):
            (xa, ya), (xb, yb) = pts[k], pts[(k + 1) % n]
            if abs(ya - y) <= tol_mm and abs(yb - y) <= tol_mm and abs(xa - xb) > tol_mm:
                segs.append((min(xa, xb), max(xa, xb)))
        return segs

    for i, a in enumerate(items):
        if used[i]:
            continue
        ax0, ay0, ax1, ay1 = a.bounds
        joined = None
        if abs(ay1 - c) <= tol_mm and ay0 > tol_mm:
            top = on_line(a, c) if a.closed else []
            for j, b in enumerate(items):
                if used[j] or j == i or b.kind != a.kind or b.closed != a.closed:
                    continue
                bx0, by0, bx1, by1 = b.bounds
                if abs(by0) > tol_mm or by1 >= c - tol_mm:
                    continue
                if a.closed:
                    bottom = on_line(b, 0.0)
                    if not any(min(p1, q1) - max(p0, q0) > tol_mm for p0, p1 in top for q0, q1 in bottom):
                        continue
                    up = Polygon([(x, y + c) for x, y in b.points])
                    snapped = shapely.snap(up, Polygon(a.points), tol_mm)
                    u = shapely.union(Polygon(a.points), snapped).buffer(0)
                    if u.geom_type != "Polygon" or u.interiors:
                        continue
                    u = shapely.simplify(u, tol_mm * 1e-3)
                    ring = list(orient(u, 1.0).exterior.coords)[:-1]
                    joined = Contour(tuple((float(x), float(y)) for x, y in ring), a.kind, a.cut_index)
                else:
                    pa, pb = a.points, [(x, y + c) for x, y in b.points]
                    ends_a = [pa[-1], pa[0]]
                    for ea in ends_a:
                        for eb in (pb[0], pb[-1]):
                            if max(abs(ea[0] - eb[0]), abs(ea[1] - eb[1]), abs(ea[1] - c)) <= tol_mm:
                                la = list(pa) if ea == pa[-1] else list(reversed(pa))
                                lb = list(pb) if eb == pb[0] else list(reversed(pb))
                                joined = Contour(tuple(la + lb[1:]), a.kind, a.cut_index, False)
                                break
                        if joined:
                            break
                    if joined is None:
                        continue
                used[i] = used[j] = True
                out.append((joined, (i, j)))
                break
        if not used[i]:
            used[i] = True
            out.append((a, (i,)))
    return out


def merge_seam_pieces(contours, circumference_mm: float) -> list[Contour]:
    """Join seam-split rectangles back into unwrapped ones.

    A piece ending on ``y = C`` and a piece starting on ``y = 0`` with the same
    x-range (within :data:`camtube.tol.TOL.merge`) and kind are one cut; the
    joined rectangle spans ``[y0 - C, y1']`` is returned as ``[y0, C + y1']``.
    Non-rectangles and unmatched pieces pass through unchanged.
    """
    c = circumference_mm
    tol = 1e-6
    items = list(contours)
    used = [False] * len(items)
    out: list[Contour] = []
    for i, a in enumerate(items):
        if used[i]:
            continue
        ax0, ay0, ax1, ay1 = a.bounds
        if len(a.points) == 4 and abs(ay1 - c) <= tol and ay0 > tol:
            for j, b in enumerate(items):
                if used[j] or j == i or len(b.points) != 4 or b.kind != a.kind:
                    continue
                bx0, by0, bx1, by1 = b.bounds
                if abs(by0) <= tol and abs(bx0 - ax0) <= tol and abs(bx1 - ax1) <= tol and by1 < c - tol:
                    used[i] = used[j] = True
                    out.append(rectangle(ax0, ay0, ax1, c + by1, a.kind, a.cut_index))
                    break
        if not used[i]:
            used[i] = True
            out.append(a)
    return out
