"""A user's effect, edited from the starter `camtube model effect new drive_error --from diag.json` wrote.

The diagnosis found the residual periodic in the motor stroke (period 0.498 mm, 1.03 deg). The physics:
the lead screw's nut rides a thread with a periodic pitch error, so the carriage (and the tendon) is
ahead of or behind the commanded stroke by ``e(x) = a sin(2 pi x / lead) + b cos(2 pi x / lead)`` mm.
The edit from the starter: the error is now in mm of stroke (not degrees of bend), the period is the
screw's lead. Starting values are the starter's, turned into mm (1.03 deg x pi/180 x 1.047 mm arm).

    camtube model diagnose drive.csv --pattern patterns/tube2.yaml --effect-file examples/foreign_effects/lead_screw.py
"""
from __future__ import annotations

import numpy as np

from camtube.model.api import Effect, Param


def _apply(ctx, stroke_mm: np.ndarray, p: dict) -> np.ndarray:
    x = np.asarray(ctx.data.stroke_mm, float)                        # commanded motor position, mm
    w = 2.0 * np.pi * x / p["lead_mm"]
    error_mm = p["sin_mm"] * np.sin(w) + p["cos_mm"] * np.cos(w)     # periodic error of the screw
    return np.maximum(stroke_mm + error_mm, 0.0)                     # a tendon cannot push


LEAD_SCREW = Effect(
    name="lead_screw",
    stage="stroke",
    params=(
        Param("sin_mm", "mm", -0.1, 0.1, 0.0175, "periodic screw error, sine part"),
        Param("cos_mm", "mm", -0.1, 0.1, 0.0067, "periodic screw error, cosine part"),
        Param("lead_mm", "mm", 0.45, 0.55, 0.498, "lead of the screw (one turn)", starts=(0.483, 0.498, 0.513)),
    ),
    apply=_apply,
    meaning="the lead screw's periodic pitch error moves the tendon ahead of or behind the commanded stroke",
    signature="the residual is periodic in the motor stroke, one period per turn of the screw",
)
