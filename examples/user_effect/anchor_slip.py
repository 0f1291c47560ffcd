"""A user's effect: the tendon slips in its anchor once the force passes a threshold, and stays slipped.

Use it like a built-in effect:

    camtube model diagnose anchor_slip.csv --pattern patterns/tube2.yaml --effect-file examples/user_effect/anchor_slip.py
    camtube model fit anchor_slip.csv --pattern patterns/tube2.yaml --cycles all --branch both --no-deadband \
        --effect-file examples/user_effect/anchor_slip.py --effects anchor_slip \
        --fit E_t,anchor_slip.slip_mm,anchor_slip.force_N,anchor_slip.scale_N

The API (camtube.model.api): an Effect has a name, a stage (force | stroke | elongation |
kinematics | angle), Params (name, unit, bounds, initial value, meaning) and
``apply(ctx, signal, p) -> signal``; ``ctx.data`` holds the rows (per sample, in time order),
``ctx.force_N`` the force, ``ctx.direction`` the direction of motion. A module-level Effect is
registered when the file is loaded with --effect-file.
"""
from __future__ import annotations

import numpy as np

from camtube.model.api import Effect, Param


def _lost_stroke(ctx, stroke_mm: np.ndarray, p: dict) -> np.ndarray:
    force = np.asarray(ctx.force_N, float)
    peak = np.empty_like(force)
    for _, sl in ctx.data.sample_slices():  # the largest force so far, per sample
        peak[sl] = np.maximum.accumulate(force[sl])
    lost = p["slip_mm"] * -np.expm1(-np.maximum(peak - p["force_N"], 0.0) / p["scale_N"])
    return np.maximum(stroke_mm - lost, 0.0)


ANCHOR_SLIP = Effect(
    name="anchor_slip",
    stage="stroke",
    params=(
        Param("slip_mm", "mm", 0.0, 2.0, 0.05, "largest slip of the tendon in its anchor"),
        Param("force_N", "N", 0.0, 20.0, 0.5, "tension at which the anchor starts to slip"),
        Param("scale_N", "N", 0.01, 20.0, 1.0, "tension over which the slip saturates"),
    ),
    apply=_lost_stroke,
    meaning="the tendon slips in its anchor once the tension passes a threshold, and stays slipped",
    signature="the residual steps down each time the force reaches a new maximum, then stays",
)
