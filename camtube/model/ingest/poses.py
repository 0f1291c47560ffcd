"""The joint's bend angle from the poses of two sensor coils (or one).

With ``R_b`` and ``R_t`` the orientations of the base and tip coils in the tracker's frame, the tip's
orientation relative to the base is ``Q = R_b^-1 R_t``. A coil is never mounted exactly along the joint's
axes: with mounting rotations ``A`` (base) and ``B`` (tip) and a bend ``theta`` about the joint's axis ``z``,
``Q(theta) = A Rot_z(theta) B``. Against the rest pose ``Q0 = Q(0)`` (the mean over the rest at the start),

    D = Q Q0^-1 = A Rot_z(theta) A^-1,

a rotation by exactly ``theta`` about the fixed axis ``A z``, whatever the mountings. Its rotation vector
``v = theta n`` therefore lies on one line: that line (the bend axis ``n``, the normal of the bend plane) is
found from the data as the first principal direction of all ``v``; the angle is ``v . n`` and the part of
``v`` off that line is reported as the out-of-plane rotation (a quality figure: noise, a twisting joint, or a
coil that moved on its mount). The sign is chosen so that the larger excursion is positive.

A quaternion and its negative are the same rotation; scipy's :class:`~scipy.spatial.transform.Rotation`
composes them as rotations, so sign flips between frames (which NDI's software does emit) do not show.
With one coil, ``R_b`` is the identity and the bend is taken against the coil's own rest pose.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class BendAngle:
    """The bend angle per tracker frame.

    Attributes
    ----------
    time_s : (n,) float
        Tracker clock, s.
    angle_deg : (n,) float
        Bend angle in the bend plane, deg; NaN where a coil was not tracked.
    out_of_plane_deg : (n,) float
        Rotation off the bend axis, deg; NaN where not tracked.
    axis : (3,) float
        Unit bend axis in the base coil's frame (the tracker's frame with one coil).
    valid : (n,) bool
        Both coils tracked (state OK).
    n_rest : int
        Frames averaged for the rest pose.
    """

    time_s: np.ndarray
    angle_deg: np.ndarray
    out_of_plane_deg: np.ndarray
    axis: np.ndarray
    valid: np.ndarray
    n_rest: int

    @property
    def out_of_plane_rms_deg(self) -> float:
        """RMS of the out-of-plane rotation over the valid frames, deg."""
        v = self.out_of_plane_deg[self.valid]
        return float(np.sqrt(np.mean(v * v))) if v.size else float("nan")


def _rotations(quat_wxyz: np.ndarray):
    from scipy.spatial.transform import Rotation

    q = np.asarray(quat_wxyz, float)
    return Rotation.from_quat(q[:, [1, 2, 3, 0]])


def bend_angle(time_s: np.ndarray, tip_wxyz: np.ndarray, tip_valid: np.ndarray,
               base_wxyz: np.ndarray | None = None, base_valid: np.ndarray | None = None,
               rest_s: float = 1.0) -> BendAngle:
    """Bend angle from the tip coil's (and base coil's) orientation, see the module docstring.

    Parameters
    ----------
    time_s : (n,) float
        Frame times, s.
    tip_wxyz, base_wxyz : (n, 4) float
        Quaternions, scalar first (NDI's ``Q0 Qx Qy Qz``); ``base_wxyz`` None for one coil.
    tip_valid, base_valid : (n,) bool
        Frames where the coil was tracked.
    rest_s : float
        The rest at the start of the recording: valid frames within ``rest_s`` of the first valid frame
        define zero bend (at least one frame).

    Returns
    -------
    BendAngle

    Raises
    ------
    ValueError
        No frame where all coils are tracked.
    """
    t = np.asarray(time_s, float)
    valid = np.asarray(tip_valid, bool).copy()
    if base_wxyz is not None:
        valid &= np.asarray(base_valid, bool)
    n = t.size
    if not valid.any():
        raise ValueError("no frame in which every coil is tracked")
    idx = np.flatnonzero(valid)
    rel = _rotations(np.asarray(tip_wxyz)[idx])
    if base_wxyz is not None:
        rel = _rotations(np.asarray(base_wxyz)[idx]).inv() * rel
    rest = t[idx] <= t[idx[0]] + rest_s
    rest[0] = True
    q0 = rel[rest].mean()
    v = (rel * q0.inv()).as_rotvec()                       # (m, 3) rad, theta * axis
    big = np.linalg.norm(v, axis=1)
    w = v[big >= np.quantile(big, 0.5)] if v.shape[0] >= 4 else v
    _, _, vt = np.linalg.svd(w, full_matrices=False)
    axis = vt[0]
    ang = v @ axis
    if abs(ang.max()) < abs(ang.min()):
        axis, ang = -axis, -ang
    off = np.linalg.norm(v - ang[:, None] * axis[None, :], axis=1)
    angle = np.full(n, np.nan)
    oop = np.full(n, np.nan)
    angle[idx] = np.degrees(ang)
    oop[idx] = np.degrees(off)
    return BendAngle(t, angle, oop, axis, valid, int(rest.sum()))
