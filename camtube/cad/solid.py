"""Exact B-rep (build123d/OCCT) model of the tube as designed, and its STEP file.

The tube is an annulus ``r_i <= r <= r_o`` along X (``0 <= x <= L``). Each cut
(notch or square tendon hole) removes the annular sector of angle
``arc / r_o`` centred on the cut's angle, over its axial width, through the
whole wall: a rectangle ``width x (r_o - r_i + 2 margin)`` in the ``(x, r)``
half-plane revolved about X. Its side walls are radial planes, as cut by a
rotary-stage beam aimed at the axis. All cutters are subtracted in one
boolean; identical cut shapes share one revolved solid, moved into place.

A drawn cut (any polygon in the unwrapped sheet; a slit as its kerf region)
becomes an exact radial-walled prism: its outline's edges, straight lines in
the cylinder's ``(angle, x)`` parameter plane, are laid on the cylinders
``r_i - margin`` and ``r_o + margin`` (helices, circles or lines), the two
faces bounded by them are the caps, and each pair of edges is joined by a
ruled face whose rulings are radial. A run of chords that a drawn curve was flattened to (an arc,
circle, fillet, ellipse, spline: hundreds of chords 25 nm from the curve) is one edge along a
B-spline through them, within the pass tolerance, and one ruled face: a face per chord made the
boolean cost minutes and gigabytes for a drawing of many round holes. Volumes are integrated
adaptively (:func:`volume_mm3`). Frame and angle origin: :mod:`camtube.cad.frame`.
"""
from __future__ import annotations

import math
import os
import re
import tempfile

import numpy as np

from camtube.design.pattern import Pattern
from camtube.tol import TOL

#: Fixed STEP header timestamp, so the same pattern gives a byte-identical file.
STEP_TIMESTAMP = "2000-01-01T00:00:00"


def _sector_tool(bd, width_mm: float, sweep_deg: float, r0: float, r1: float):
    face = bd.Face.make_rect(width_mm, r1 - r0).moved(bd.Location((width_mm / 2.0, (r0 + r1) / 2.0, 0.0)))
    return bd.Solid.revolve(face, sweep_deg, bd.Axis.X)


#: A vertex of a drawn outline where the outline turns by at most this (deg), between edges of like length
#: (within :data:`LIKE_LENGTH`), lies inside a curve the drawing's reader flattened to chords (an arc, circle,
#: fillet, ellipse, spline): :func:`drawn_tool` walls such a run with one smooth face, not a face per chord.
SMOOTH_TURN_DEG = 20.0
#: Two edges meeting at a vertex are of like length when neither is longer than this times the other (a line
#: running into a fillet's chords is a run's end, not part of the curve).
LIKE_LENGTH = 3.0
#: A run's smooth curve must stay within this of its chords (mm): the pass tolerance (``TOL.path``), the
#: distance the laser's own passes keep from the drawing; a run it does not fit keeps its chords.
SMOOTH_TOL_MM = TOL.path
#: Fewest chords a run needs to be walled by a curve (fewer: the chords' faces cost nothing).
SMOOTH_MIN_CHORDS = 4


def smooth_runs(points) -> list[list[int]]:
    """The runs of a closed polygon ``points`` (n, 2) that lie along one smooth curve, as vertex indices in order
    (ends included, each run's last vertex the next run's first); every other edge is a run of its own (two
    indices). A polygon smooth all round (a circle) is two runs, halves joined at vertices 0 and n/2."""
    from camtube.plan.paths import turn_angles_deg

    pts = np.asarray(points, float)
    n = len(pts)
    length = np.hypot(*(np.roll(pts, -1, axis=0) - pts).T)   # edge k joins vertex k to k + 1
    before = np.roll(length, 1)
    smooth = (turn_angles_deg(pts) <= SMOOTH_TURN_DEG) & \
        (np.maximum(before, length) <= LIKE_LENGTH * np.minimum(before, length))
    ends = [0, n // 2] if smooth.all() else [int(k) for k in np.flatnonzero(~smooth)]
    runs = []
    for j, start in enumerate(ends):
        stop = ends[(j + 1) % len(ends)]
        count = (stop - start) % n or n
        runs.append([(start + i) % n for i in range(count + 1)])
    return runs


def _run_curve(sheet: np.ndarray, uv: np.ndarray, run: list[int], outer_radius_mm: float):
    """A Geom2d B-spline through the ``uv`` vertices of ``run`` if it stays within :data:`SMOOTH_TOL_MM` of the
    run's chords on the sheet (its ends the run's end vertices), else None."""
    from OCP.collections import Array1_gp_Pnt2d
    from OCP.Geom2dAPI import Geom2dAPI_PointsToBSpline
    from OCP.GeomAbs import GeomAbs_C2
    from OCP.gp import gp_Pnt2d

    if len(run) - 1 < SMOOTH_MIN_CHORDS:
        return None
    arr = Array1_gp_Pnt2d(1, len(run))
    for j, k in enumerate(run):
        arr.SetValue(j + 1, gp_Pnt2d(float(uv[k, 0]), float(uv[k, 1])))
    # a compact B-spline (few poles: its 3-D images and the boolean stay cheap), its ends on the run's ends; in
    # (u, v) a sheet distance d is at least d / max(1, r_o)
    fit = Geom2dAPI_PointsToBSpline(arr, 3, 8, GeomAbs_C2, 0.1 * SMOOTH_TOL_MM / max(1.0, outer_radius_mm))
    if not fit.IsDone():
        return None
    curve = fit.Curve()
    ts = np.linspace(curve.FirstParameter(), curve.LastParameter(), 8 * len(run))
    on = np.array([(curve.Value(t).Y(), curve.Value(t).X() * outer_radius_mm) for t in ts])   # back to (x, y)
    a, d = sheet[run[:-1]], sheet[run[1:]] - sheet[run[:-1]]
    rel = on[:, None, :] - a[None]
    t = np.clip(np.einsum("ijk,jk->ij", rel, d) / np.maximum(np.einsum("jk,jk->j", d, d), 1e-300), 0.0, 1.0)
    gap = np.hypot(*(rel - t[..., None] * d[None]).transpose(2, 0, 1)).min(axis=1)
    return curve if float(gap.max()) <= SMOOTH_TOL_MM else None


def drawn_tool(points, outer_radius_mm: float, r0: float, r1: float, smooth: bool = True):
    """Exact radial-walled prism of a polygon of the unwrapped sheet, between radii ``r0 < r1``.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices ``(x_mm, y_mm)`` (unwrapped; ``y = r_o * angle``), not repeated at the end.
    outer_radius_mm : float
        r_o (maps ``y`` to the angle).
    r0, r1 : float
        Radii of the inner and outer caps (mm).
    smooth : bool
        Wall each run of chords that a drawn curve was flattened to (:func:`smooth_runs`) with one face along a
        B-spline through its vertices, within :data:`SMOOTH_TOL_MM` of the chords; False: a face per chord.
        Speed: a drawn circle flattened to 256 chords is a tool of 258 faces, and the boolean cost of a face is
        its intersections with the tube's walls: ten such holes took 13 s and 2.3 GB to cut, a hundred 9 min and
        19 GB; walled by curves, 0.2 s and 0.5 GB for ten (``python scripts/bench_cad.py``).

    Returns
    -------
    build123d.Solid
    """
    import build123d as bd
    from OCP.BRepBuilderAPI import (BRepBuilderAPI_MakeEdge, BRepBuilderAPI_MakeFace, BRepBuilderAPI_MakeSolid,
                                    BRepBuilderAPI_MakeWire, BRepBuilderAPI_Sewing)
    from OCP.BRepFill import BRepFill
    from OCP.BRepLib import BRepLib
    from OCP.Geom import Geom_CylindricalSurface
    from OCP.Geom2d import Geom2d_Line
    from OCP.gp import gp_Ax3, gp_Dir, gp_Dir2d, gp_Pnt, gp_Pnt2d
    from OCP.ShapeFix import ShapeFix_Solid
    from OCP.TopAbs import TopAbs_SHELL
    from OCP.TopExp import TopExp_Explorer
    from OCP.TopoDS import TopoDS

    # cylinder parameters (u, v) = (angle from +Y towards +Z, x): the frame of camtube.cad.frame
    axis = gp_Ax3(gp_Pnt(0.0, 0.0, 0.0), gp_Dir(1.0, 0.0, 0.0), gp_Dir(0.0, 1.0, 0.0))
    uv: list[tuple[float, float]] = []
    for x, y in points:
        p = (float(y) / outer_radius_mm, float(x))
        if not uv or math.hypot(p[0] - uv[-1][0], p[1] - uv[-1][1]) > 1e-12:
            uv.append(p)
    if math.hypot(uv[0][0] - uv[-1][0], uv[0][1] - uv[-1][1]) <= 1e-12:
        uv.pop()
    n = len(uv)
    uv_arr = np.array(uv)
    sheet = np.column_stack([uv_arr[:, 1], uv_arr[:, 0] * outer_radius_mm])
    # the outline's pieces in (u, v): (2-D curve, first, last parameter), a line per chord where no curve fits
    pieces = []
    for run in (smooth_runs(sheet) if smooth and n >= 3 else [[k, (k + 1) % n] for k in range(n)]):
        curve = _run_curve(sheet, uv_arr, run, outer_radius_mm)
        if curve is not None:
            pieces.append((curve, curve.FirstParameter(), curve.LastParameter()))
            continue
        for k0, k1 in zip(run[:-1], run[1:]):
            (u1, v1), (u2, v2) = uv[k0], uv[k1]
            pieces.append((Geom2d_Line(gp_Pnt2d(u1, v1), gp_Dir2d(u2 - u1, v2 - v1)), 0.0,
                           math.hypot(u2 - u1, v2 - v1)))
    edges: dict[float, list] = {}
    faces = []
    for r in (r0, r1):
        surface = Geom_CylindricalSurface(axis, r)
        ring = []
        for curve, first, last in pieces:
            edge = BRepBuilderAPI_MakeEdge(curve, surface, first, last).Edge()
            BRepLib.BuildCurves3d_s(edge)
            ring.append(edge)
        wire = BRepBuilderAPI_MakeWire()
        for edge in ring:
            wire.Add(edge)
        faces.append(BRepBuilderAPI_MakeFace(surface, wire.Wire(), True).Face())
        edges[r] = ring
    faces += [BRepFill.Face_s(a, b) for a, b in zip(edges[r0], edges[r1])]  # ruled: radial rulings
    sewing = BRepBuilderAPI_Sewing(1e-7)
    for f in faces:
        sewing.Add(f)
    sewing.Perform()
    shells = TopExp_Explorer(sewing.SewedShape(), TopAbs_SHELL)
    if not shells.More():
        raise RuntimeError("the drawn cut's faces do not close into a solid")
    fix = ShapeFix_Solid(BRepBuilderAPI_MakeSolid(TopoDS.Shell(shells.Current())).Solid())
    fix.Perform()
    return bd.Solid(fix.Solid())


def cut_tools(pattern: Pattern, smooth: bool = True):
    """One radial-walled solid per cut of ``pattern`` (list of build123d Solids).

    Rectangles are revolved annular sectors; drawn outlines (and slits, as the
    kerf region of :func:`camtube.cad.mesh.design_regions`) are :func:`drawn_tool` prisms
    (``smooth``: see there).
    """
    import build123d as bd

    t = pattern.tube
    ro, ri = t.outer_radius_mm, t.inner_radius_mm
    margin = 0.25 * (ro - ri)
    cache: dict[tuple[float, float], object] = {}
    tools = []
    regions = None
    for i, c in enumerate(pattern.cuts):
        if c.is_drawn:
            if regions is None:
                from camtube.cad.mesh import design_regions

                regions = design_regions(pattern)
            reg = regions[i]
            pts = reg.points if hasattr(reg, "points") else list(reg.exterior.coords)[:-1]
            tools.append(drawn_tool(pts, ro, ri - margin, ro + margin, smooth=smooth))
            continue
        sweep = math.degrees(c.arc_mm / ro)
        key = (c.width_mm, sweep)
        if key not in cache:
            cache[key] = _sector_tool(bd, c.width_mm, sweep, ri - margin, ro + margin)
        tools.append(cache[key].moved(bd.Location((c.x_start_mm, 0.0, 0.0), (1, 0, 0), c.angle_deg - sweep / 2.0)))
    return tools


def design_solid(pattern: Pattern, smooth: bool = True):
    """The tube with its cuts as one build123d ``Solid`` (mm); ``smooth`` as :func:`drawn_tool`'s (False: a face per
    chord of a drawn curve, for the benchmark's comparison).

    Raises
    ------
    RuntimeError
        OCCT returned something other than one solid.
    """
    import build123d as bd

    t = pattern.tube
    tube = bd.Solid.make_cylinder(t.outer_radius_mm, t.length_mm, bd.Plane.YZ) - bd.Solid.make_cylinder(
        t.inner_radius_mm, t.length_mm, bd.Plane.YZ)
    tools = cut_tools(pattern, smooth)
    out = tube.cut(*tools) if tools else tube
    solids = out.solids()
    if len(solids) != 1:
        raise RuntimeError(f"{pattern.name}: the cut tube has {len(solids)} solids, expected 1")
    return solids[0]


def step_bytes(shape, name: str) -> bytes:
    """STEP AP214 text (mm) of ``shape``, byte-identical for the same shape and ``name``.

    OCCT writes to a file; this exports into a private temporary directory,
    reads the bytes back and puts ``name`` in the header's FILE_NAME.
    """
    from build123d import Unit, export_step

    with tempfile.TemporaryDirectory(prefix="camtube-step-") as tmp:
        path = os.path.join(tmp, "model.step")
        if not export_step(shape, path, unit=Unit.MM, timestamp=STEP_TIMESTAMP):
            raise RuntimeError(f"STEP export of {name} failed")
        with open(path, "rb") as fh:
            data = fh.read()
    return re.sub(rb"FILE_NAME\('[^']*'", b"FILE_NAME('" + name.encode("ascii", "replace") + b"'", data, count=1)


def volume_mm3(shape) -> float:
    """The volume (mm^3) of a build123d shape, integrated to a relative error of 1e-9.

    Why not ``shape.volume``: that integrates each face at a fixed number of points, which on a B-spline face
    (a drawn curve's wall, :func:`drawn_tool`) can be off by percents (a spline-walled notch read 3 % small);
    OCCT's adaptive integration, given a tolerance, refines until it holds.
    """
    from OCP.BRepGProp import BRepGProp
    from OCP.GProp import GProp_GProps

    props = GProp_GProps()
    BRepGProp.VolumeProperties_s(shape.wrapped, props, 1e-9, True)
    return float(props.Mass())


def import_step_volume(path) -> float:
    """Volume (mm^3) of the solids in a STEP file, read back with build123d/OCCT."""
    from build123d import import_step

    return volume_mm3(import_step(str(path)))
