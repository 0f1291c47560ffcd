"""Measurements on a tube mesh from plane sections (trimesh), independent of how it was built.

- Backbone angle at a notch: the section ``x = x_c`` (normal +X) is the
  remaining annular sector(s); the angles of its vertices are sorted and every
  angular gap wider than 1.5 polygon steps is removed material, so
  ``phi = 2 pi - sum(gaps)``. Radial cut walls put section vertices exactly
  at the cut's angles.
- Notch width: the section by the half-plane through the axis at the notch's
  angle; on that half-plane the material is a set of ``x`` intervals, and the
  notch is the empty interval around ``x_c``.
"""
from __future__ import annotations

import math
from typing import Sequence

import numpy as np

from camtube.cad.frame import angles_of


def _sections_3d(mesh, origin, normal, heights) -> list[np.ndarray]:
    """Section segments (n, 2, 3) of ``mesh`` by parallel planes at ``heights`` along ``normal``."""
    from trimesh.intersections import mesh_multiplane

    lines, to_3d, _ = mesh_multiplane(mesh, np.asarray(origin, float), np.asarray(normal, float),
                                      np.asarray(heights, float))
    out = []
    for seg, tf in zip(lines, to_3d):
        seg = np.asarray(seg, dtype=float).reshape(-1, 2)
        if len(seg) == 0:
            out.append(np.zeros((0, 2, 3)))
            continue
        pts = np.column_stack([seg, np.zeros(len(seg)), np.ones(len(seg))]) @ np.asarray(tf).T
        out.append(pts[:, :3].reshape(-1, 2, 3))
    return out


def backbone_angles_rad(mesh, x_mm: Sequence[float], segments: int) -> np.ndarray:
    """Angle of material (rad) left in the cross-sections ``x = x_mm`` of a tube mesh along X.

    Parameters
    ----------
    mesh : trimesh.Trimesh
    x_mm : (m,) float
        Section positions.
    segments : int
        Sides of the mesh's polygonal circles (gaps up to 1.5 steps are not cuts).

    Returns
    -------
    (m,) float
        ``2 pi - (sum of angular gaps between section vertices wider than 1.5 steps)``; NaN for an empty section.
    """
    thr = 1.5 * 2.0 * math.pi / segments
    out = []
    for seg in _sections_3d(mesh, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0), x_mm):
        if len(seg) == 0:
            out.append(float("nan"))
            continue
        a = np.unique(np.round(angles_of(seg.reshape(-1, 3)), 12))
        gaps = np.diff(np.concatenate([a, [a[0] + 2.0 * math.pi]]))
        out.append(2.0 * math.pi - float(gaps[gaps > thr].sum()))
    return np.asarray(out, dtype=float)


def gap_widths_mm(mesh, angle_rad: float, x_mm: Sequence[float], segments: int,
                  radius_mm: float | None = None) -> np.ndarray:
    """Axial width (mm) of the empty interval around each ``x_mm`` on the half-plane at ``angle_rad``.

    The section plane contains the X axis; it is turned by 0.37 polygon steps
    from ``angle_rad`` so it never runs along a mesh edge of the polygonal
    tube. Only material on the ``angle_rad`` side is used (and, if
    ``radius_mm`` is given, only section points farther than that from the
    axis, to skip other cuts' walls).

    Returns
    -------
    (m,) float
        ``min(x > x_c) - max(x < x_c)`` over the section's vertices; NaN if
        ``x_c`` is not in a gap.
    """
    th = angle_rad + 0.37 * 2.0 * math.pi / segments
    u = np.array([0.0, math.cos(th), math.sin(th)])
    normal = np.array([0.0, -math.sin(th), math.cos(th)])
    (seg,) = _sections_3d(mesh, (0.0, 0.0, 0.0), normal, [0.0])
    pts = seg.reshape(-1, 3)
    side = pts @ u
    keep = side > (radius_mm if radius_mm is not None else 0.0) * 0.5
    xs = np.sort(np.unique(np.round(pts[keep, 0], 12)))
    # intervals of material: segments on that side, as x-ranges
    sg = seg[(seg @ u > 0).all(axis=1)]
    lo = np.minimum(sg[:, 0, 0], sg[:, 1, 0])
    hi = np.maximum(sg[:, 0, 0], sg[:, 1, 0])
    out = []
    for xc in np.asarray(x_mm, dtype=float):
        if np.any((lo < xc - 1e-9) & (hi > xc + 1e-9)):  # material crosses x_c
            out.append(float("nan"))
            continue
        below, above = xs[xs < xc], xs[xs > xc]
        out.append(float(above[0] - below[-1]) if len(below) and len(above) else float("nan"))
    return np.asarray(out, dtype=float)
