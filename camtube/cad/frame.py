"""The 3-D frame of the CAD models and the wrap of the unrolled sheet onto the tube.

- The tube axis is the X axis; ``x = 0`` is the tip, the tube occupies
  ``0 <= x <= L`` (same ``x`` as the unrolled frame).
- Rotary angle ``theta = y / r_o`` (rad) is measured about +X, right-handed,
  from +Y towards +Z: the surface point of the unrolled sheet ``(x, y)`` at
  radius ``r`` is ``(x, r cos(y / r_o), r sin(y / r_o))``.
  So ``y = 0`` (rotary angle 0) is the +Y side of the tube, 90 deg is +Z,
  180 deg (where the presets put their notches) is -Y.
- Every cut wall is *radial*: a point ``(x, y)`` of a cut boundary becomes the
  radial segment ``r_i <= r <= r_o`` at angle ``y / r_o`` (what a beam aimed at
  the axis of a rotary stage cuts).

Note the handedness: seen from *outside* the tube, the sheet's ``(x, y)`` axes
appear mirrored (``x`` along +X, ``y`` running clockwise); seen from inside
(the lumen) they read like the DXF.
"""
from __future__ import annotations

import math

import numpy as np


def wrap_points(x_mm: np.ndarray, y_mm: np.ndarray, r_mm: np.ndarray, outer_radius_mm: float) -> np.ndarray:
    """Sheet points ``(x, y)`` at radius ``r`` -> 3-D points.

    Parameters
    ----------
    x_mm, y_mm, r_mm : (n,) float
        Axial position, arc length on the outer surface, radius.
    outer_radius_mm : float
        r_o (the unrolled ``y`` is arc length at this radius).

    Returns
    -------
    (n, 3) float
        ``(x, r cos(y / r_o), r sin(y / r_o))``.
    """
    th = np.asarray(y_mm, dtype=float) / outer_radius_mm
    r = np.asarray(r_mm, dtype=float)
    return np.column_stack([np.asarray(x_mm, dtype=float), r * np.cos(th), r * np.sin(th)])


def angle_rad(y_mm: float, outer_radius_mm: float) -> float:
    """Rotary angle (rad, in [0, 2 pi)) of the unrolled ``y``."""
    return (y_mm / outer_radius_mm) % (2.0 * math.pi)


def angles_of(points: np.ndarray) -> np.ndarray:
    """(n,) rotary angles in [0, 2 pi) of 3-D points ``(n, 3)`` (inverse of :func:`wrap_points`)."""
    p = np.asarray(points, dtype=float)
    return np.mod(np.arctan2(p[:, 2], p[:, 1]), 2.0 * math.pi)
