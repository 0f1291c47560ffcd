"""A user's effect: the moment arm changes with the bend angle, a(theta) = a0 (1 + beta theta).

Edited from the starter for "the residual follows the bend angle (quadratic)" (stage kinematics).
The tendon length the joint takes up is then L_kin = a0 (theta + beta theta^2 / 2); the kinematics
stage receives L_kin (ctx.l_kin_mm) and the arm a0 (ctx.arm_mm) and inverts it for theta.
"""
from __future__ import annotations

import numpy as np

from camtube.model.api import Effect, Param


def _apply(ctx, theta_rad: np.ndarray, p: dict) -> np.ndarray:
    b = p["beta_per_rad"]
    u = np.asarray(ctx.l_kin_mm, float) / ctx.arm_mm           # theta of the constant arm
    if abs(b) < 1e-9:
        return u
    # a0 (t + b t^2 / 2) = l_kin  ->  t = (sqrt(1 + 2 b u) - 1) / b, the root through zero
    return 2.0 * u / (1.0 + np.sqrt(np.maximum(1.0 + 2.0 * b * u, 1e-12)))


ARM_CHANGE = Effect(
    name="arm_change",
    stage="kinematics",
    params=(Param("beta_per_rad", "1/rad", -1.5, 1.5, 0.0, "relative change of the moment arm per radian of bend"),),
    apply=_apply,
    meaning="the moment arm changes with the bend angle (the notches close and the tendon path moves)",
    signature="the residual follows the bend angle, quadratic",
)
