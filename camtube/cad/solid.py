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
ruled face whose rulings are radial. Frame and angle origin: :mod:`camtube.cad.frame`.
"""
from __future__ import annotations

import math
import os
import re
import tempfile

from camtube.design.pattern import Pattern

#: Fixed STEP header timestamp, so the same pattern gives a byte-identical file.
STEP_TIMESTAMP = "2000-01-01T00:00:00"


def _sector_tool(bd, width_mm: float, sweep_deg: float, r0: float, r1: float):
    face = bd.Face.make_rect(width_mm, r1 - r0).moved(bd.Location((width_mm / 2.0, (r0 + r1) / 2.0, 0.0)))
    return bd.Solid.revolve(face, sweep_deg, bd.Axis.X)


def drawn_tool(points, outer_radius_mm: float, r0: float, r1: float):
    """Exact radial-walled prism of a polygon of the unwrapped sheet, between radii ``r0 < r1``.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices ``(x_mm, y_mm)`` (unwrapped; ``y = r_o * angle``), not repeated at the end.
    outer_radius_mm : float
        r_o (maps ``y`` to the angle).
    r0, r1 : float
        Radii of the inner and outer caps (mm).

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
    edges: dict[float, list] = {}
    faces = []
    for r in (r0, r1):
        surface = Geom_CylindricalSurface(axis, r)
        ring = []
        for k in range(n):
            (u1, v1), (u2, v2) = uv[k], uv[(k + 1) % n]
            line = Geom2d_Line(gp_Pnt2d(u1, v1), gp_Dir2d(u2 - u1, v2 - v1))
            edge = BRepBuilderAPI_MakeEdge(line, surface, 0.0, math.hypot(u2 - u1, v2 - v1)).Edge()
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


def cut_tools(pattern: Pattern):
    """One radial-walled solid per cut of ``pattern`` (list of build123d Solids).

    Rectangles are revolved annular sectors; drawn outlines (and slits, as the
    kerf region of :func:`camtube.cad.mesh.design_regions`) are :func:`drawn_tool` prisms.
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
            tools.append(drawn_tool(pts, ro, ri - margin, ro + margin))
            continue
        sweep = math.degrees(c.arc_mm / ro)
        key = (c.width_mm, sweep)
        if key not in cache:
            cache[key] = _sector_tool(bd, c.width_mm, sweep, ri - margin, ro + margin)
        tools.append(cache[key].moved(bd.Location((c.x_start_mm, 0.0, 0.0), (1, 0, 0), c.angle_deg - sweep / 2.0)))
    return tools


def design_solid(pattern: Pattern):
    """The tube with its cuts as one build123d ``Solid`` (mm).

    Raises
    ------
    RuntimeError
        OCCT returned something other than one solid.
    """
    import build123d as bd

    t = pattern.tube
    tube = bd.Solid.make_cylinder(t.outer_radius_mm, t.length_mm, bd.Plane.YZ) - bd.Solid.make_cylinder(
        t.inner_radius_mm, t.length_mm, bd.Plane.YZ)
    tools = cut_tools(pattern)
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


def import_step_volume(path) -> float:
    """Volume (mm^3) of the solids in a STEP file, read back with build123d/OCCT."""
    from build123d import import_step

    return float(import_step(str(path)).volume)
