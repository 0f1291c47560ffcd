"""Fast triangle meshes of the cut tube (manifold3d booleans, returned as trimesh).

The tube is a polygonal annulus (``segments`` sides on the inner and outer
circle) along X, minus one *cutter* per removed region of the unrolled sheet.
A cutter is built flat -- the region (any polygon with holes, in unwrapped
``(x, y)`` mm) extruded over a radial interval a little wider than the wall --
refined so that no edge spans more than a small angle, and then *warped*
onto the cylinder with ``(x, y, r) -> (x, r cos(y/r_o), r sin(y/r_o))``
(see :mod:`camtube.cad.frame`). Every vertical edge of the flat prism becomes
a radial line, so cut walls are radial and lie exactly at the cut's angles;
the warped caps lie outside the wall (chord sag below half the margin), so
they never touch material. One boolean subtracts all cutters at once.

The same function meshes the design (regions = the design rectangles) and the
as-cut result of a kerf simulation (regions = kerf union + freed slugs).
"""
from __future__ import annotations

import math
from typing import Iterable, Sequence

import numpy as np

from camtube.design.contour import Contour, cut_contours
from camtube.design.pattern import Pattern

#: Sides of the polygonal inner and outer circles of the tube mesh (volume error 1.0e-4).
DEFAULT_SEGMENTS = 256
#: Sides used for long patterns (more than :data:`LONG_PATTERN_CUTS` cuts; volume error 4.0e-4):
#: the boolean's cost grows with the output's triangles (~ segments x cuts).
PREVIEW_SEGMENTS = 128
LONG_PATTERN_CUTS = 64


def auto_segments(n_cuts: int) -> int:
    """Polygon sides for a pattern of ``n_cuts`` cuts: exact enough for the checks, fast for long patterns.

    Cut walls lie at their exact angles whatever the polygon, so the backbone
    angle measured from a section does not depend on it; the volume error of
    an inscribed polygon is ``(2 pi / segments)^2 / 6``.
    """
    return DEFAULT_SEGMENTS if n_cuts <= LONG_PATTERN_CUTS else PREVIEW_SEGMENTS


def _rings(region) -> list[np.ndarray]:
    """Closed rings (n, 2) of a Contour or a shapely (Multi)Polygon, holes included."""
    if isinstance(region, Contour):
        return [region.xy]
    from shapely.geometry.polygon import orient

    polys = getattr(region, "geoms", [region])
    rings: list[np.ndarray] = []
    for p in polys:
        if p.is_empty:
            continue
        p = orient(p, 1.0)
        rings.append(np.asarray(p.exterior.coords, dtype=float)[:-1, :2])
        rings.extend(np.asarray(r.coords, dtype=float)[:-1, :2] for r in p.interiors)
    return rings


def _cutter_rings(region, circumference_mm: float) -> list[list[np.ndarray]]:
    """The rings of each cutter of one removed region: one cutter per polygon of the region.

    A cutter is wrapped onto the cylinder, so it must span less than a turn in ``y``.
    Separate polygons of a region (the notches of a bidirectional pattern, say) become
    separate cutters wherever they lie; a single polygon that spans a turn or more (a
    ring cut, or a removed region that joins cuts of several directions) is cut into
    bands of half a turn, whose cutters overlap only on shared edges and together
    remove the same material.
    """
    from shapely.geometry import Polygon, box

    if isinstance(region, Contour):
        polys = [Polygon(region.points)]
    else:
        polys = [p for p in getattr(region, "geoms", [region]) if not p.is_empty]
    out: list[list[np.ndarray]] = []
    for p in polys:
        if p.geom_type != "Polygon":  # a nested collection
            out.extend(_cutter_rings(p, circumference_mm))
            continue
        x0, y0, x1, y1 = p.bounds
        if y1 - y0 < circumference_mm:
            out.append(_rings(p))
            continue
        band = 0.5 * circumference_mm
        k = 0
        while y0 + k * band < y1:
            piece = p.intersection(box(x0 - 1.0, y0 + k * band, x1 + 1.0, y0 + (k + 1) * band))
            for q in getattr(piece, "geoms", [piece]):
                if q.geom_type == "Polygon" and q.area > 0:
                    out.append(_rings(q))
            k += 1
    return out


def tube_manifold(outer_radius_mm: float, inner_radius_mm: float, length_mm: float,
                  regions: Iterable, segments: int = DEFAULT_SEGMENTS):
    """The tube minus radial-walled cuts, as a ``manifold3d.Manifold``.

    Parameters
    ----------
    outer_radius_mm, inner_radius_mm, length_mm : float
        r_o > r_i > 0 and L; the tube spans ``0 <= x <= L`` along X.
    regions : iterable of Contour or shapely Polygon/MultiPolygon
        Removed regions of the unrolled sheet (unwrapped ``y`` allowed: the
        wrap is periodic). Any region is accepted: each of its polygons becomes a cutter,
        one that spans a turn or more is cut into bands first (:func:`_cutter_rings`).
    segments : int
        Sides of the polygonal circles (volume error ~ (2 pi / segments)^2 / 6).
    """
    import manifold3d as m3

    ro, ri, L = float(outer_radius_mm), float(inner_radius_mm), float(length_mm)
    margin = 0.25 * (ro - ri)
    r_out, r_in = ro + margin, max(ri - margin, 0.5 * ri)
    # largest angle step whose chord at r_out stays outside r_o + margin / 2
    dth = 2.0 * math.acos((ro + 0.5 * margin) / r_out)
    step = max(min(dth * ro, ro - ri), 1e-3)
    circ = 2.0 * math.pi * ro

    tube = m3.Manifold.cylinder(L, ro, ro, segments) - m3.Manifold.cylinder(L + 2.0, ri, ri, segments).translate(
        (0.0, 0.0, -1.0))
    tube = tube.rotate((0.0, 90.0, 0.0))  # axis Z -> X, 0 <= x <= L

    def warp(v):
        v = np.asarray(v, dtype=float)
        th = v[:, 1] / ro
        r = -v[:, 2]  # prism built at z = -r keeps the warp orientation-preserving
        return np.column_stack([v[:, 0], r * np.cos(th), r * np.sin(th)])

    cutters = []
    for reg in regions:
        for rings in _cutter_rings(reg, circ):
            cs = m3.CrossSection([np.ascontiguousarray(r) for r in rings], m3.FillRule.EvenOdd)
            prism = m3.Manifold.extrude(cs, r_out - r_in).translate((0.0, 0.0, -r_out)).refine_to_length(step)
            cutters.append(prism.warp_batch(warp))
    if not cutters:
        return tube
    return tube - m3.Manifold.batch_boolean(cutters, m3.OpType.Add)


def to_trimesh(manifold):
    """``manifold3d.Manifold`` -> ``trimesh.Trimesh`` (vertices mm, no re-processing)."""
    import trimesh

    m = manifold.to_mesh()
    verts = np.asarray(m.vert_properties, dtype=float)[:, :3]
    faces = np.asarray(m.tri_verts, dtype=np.int64)
    return trimesh.Trimesh(verts, faces, process=False)


def tube_mesh(outer_radius_mm: float, inner_radius_mm: float, length_mm: float,
              regions: Iterable, segments: int = DEFAULT_SEGMENTS):
    """:func:`tube_manifold` as a ``trimesh.Trimesh``."""
    return to_trimesh(tube_manifold(outer_radius_mm, inner_radius_mm, length_mm, regions, segments))


#: Kerf assumed for a slit's removed region when ``process.kerf`` is 0 (mm), as in the kerf simulation.
DEFAULT_SLIT_KERF_MM = 0.02


def slit_kerf_mm(pattern: Pattern) -> float:
    """Width (mm) of the material a slit removes: ``process.kerf``, or :data:`DEFAULT_SLIT_KERF_MM`."""
    return pattern.process.kerf_mm or DEFAULT_SLIT_KERF_MM


def design_regions(pattern: Pattern) -> Sequence:
    """The removed regions of the design, one per cut, unwrapped.

    A rectangle or drawn outline is its :class:`Contour`; a slit (an open path
    the beam follows) removes the path buffered by half of :func:`slit_kerf_mm`
    (round ends, as a round beam leaves), a shapely Polygon.
    """
    out: list = []
    for con in cut_contours(pattern):
        if con.closed:
            out.append(con)
        else:
            from shapely.geometry import LineString

            out.append(LineString(con.points).buffer(0.5 * slit_kerf_mm(pattern), quad_segs=4))
    return out


def region_area_mm2(region) -> float:
    """Sheet area (mm^2) of a removed region (a Contour or a shapely polygon)."""
    if isinstance(region, Contour):
        return abs(region.area_mm2)
    return float(region.area)


def design_mesh(pattern: Pattern, segments: int | None = None):
    """Mesh of the tube as designed: notches and holes as radial-walled annular sectors.

    ``segments`` defaults to :func:`auto_segments` of the number of cuts.
    """
    t = pattern.tube
    seg = segments or auto_segments(len(pattern.cuts))
    return tube_mesh(t.outer_radius_mm, t.inner_radius_mm, t.length_mm, design_regions(pattern), seg)


def stl_bytes(mesh) -> bytes:
    """Binary STL of a trimesh (mm), deterministic."""
    from trimesh.exchange.stl import export_stl

    return export_stl(mesh)
