"""A user's effect: the tendon yields once, in the first cycle (a permanent set and a softer tendon later).

Edited from the starter for "the residual follows the first cycle (step)". Above a yield tension the
tendon stretches plastically in proportion to the largest tension of its first cycle and its compliance
grows; later cycles keep both. One effect on two stages (the set shortens the stroke, the softening
lengthens the elongation), with the ready-made signals ctx.first_cycle and ctx.peak_force_N.
"""
from __future__ import annotations

import numpy as np

from camtube.model.api import Effect, Param


def _progress(ctx, p: dict) -> np.ndarray:
    """0 .. 1: how far the first cycle's yielding has gone (frozen after the first cycle), per row."""
    peak = np.asarray(ctx.peak_force_N, float)
    first = ctx.first_cycle
    out = np.empty_like(peak)
    for _, sl in ctx.data.sample_slices():
        pk, fc = peak[sl].copy(), first[sl]
        top = pk[fc].max() if fc.any() else pk.max()
        pk = np.where(fc, pk, top)                     # the first cycle's largest tension, kept afterwards
        y = p["yield_frac"] * top
        out[sl] = np.clip((pk - y) / max(top - y, 1e-9), 0.0, 1.0)
    return out


def _stroke(ctx, stroke_mm: np.ndarray, p: dict) -> np.ndarray:
    return np.maximum(stroke_mm - p["set_mm"] * _progress(ctx, p), 0.0)


def _elongation(ctx, elongation_mm: np.ndarray, p: dict) -> np.ndarray:
    return elongation_mm * (1.0 + p["soften"] * _progress(ctx, p))


FIRST_CYCLE_SET = Effect(
    name="first_cycle_set",
    stage=("stroke", "elongation"),
    params=(
        Param("set_mm", "mm", 0.0, 1.0, 0.05, "permanent stretch after the first cycle"),
        Param("soften", "", 0.0, 2.0, 0.1, "relative growth of the tendon compliance after the first cycle"),
        Param("yield_frac", "", 0.0, 0.95, 0.3, "yield tension as a fraction of the first cycle's peak"),
    ),
    apply={"stroke": _stroke, "elongation": _elongation},
    meaning="the tendon yields once in the first cycle: a permanent set and a softer tendon afterwards",
    signature="the residual follows the first cycle: the first loading differs from every later cycle",
)
