"""Exact B-rep (build123d/OCCT) model of the tube as designed, and its STEP file.

The tube is an annulus ``r_i <= r <= r_o`` along X (``0 <= x <= L``). Each cut
(notch or square tendon hole) removes the annular sector of angle
``arc / r_o`` centred on the cut's angle, over its axial width, through the
whole wall: a rectangle ``width x (r_o - r_i + 2 margin)`` in the ``(x, r)``
half-plane revolved about X. Its side walls are radial planes, as cut by a
rotary-stage beam aimed at the axis. All cutters are subtracted in one
boolean; identical cut shapes share one revolved solid, moved into place.
Frame and angle origin: :mod:`camtube.cad.frame`.
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


def cut_tools(pattern: Pattern):
    """One radial-walled annular-sector solid per cut of ``pattern`` (list of build123d Solids)."""
    import build123d as bd

    t = pattern.tube
    ro, ri = t.outer_radius_mm, t.inner_radius_mm
    margin = 0.25 * (ro - ri)
    cache: dict[tuple[float, float], object] = {}
    tools = []
    for c in pattern.cuts:
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
