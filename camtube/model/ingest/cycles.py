"""Actuation cycles from the stroke: where each pull starts.

A cycle is one excursion of the stroke away from its rest and back. With ``lo`` and ``hi`` at 25 % and
75 % of the stroke's range (a Schmitt trigger, so noise at a turning point or a dwell at the top does not
split a cycle), a cycle's rise is a crossing of ``hi`` after the stroke was last below ``lo``. The cycle
starts at the last sample at the bottom before that rise: the last sample within 0.2 % of the range of the
smallest stroke since the previous cycle's peak, so a rest or dwell at the bottom stays with the cycle it
ends, and the next cycle starts where the stroke leaves the bottom (where ``model fit`` looks for the slack).
Rows before the first start belong to cycle 1. No deadband is removed here (``model fit`` does that).
"""
from __future__ import annotations

import numpy as np


def cycle_starts(time_s: np.ndarray, stroke_mm: np.ndarray) -> np.ndarray:
    """(k,) times (s) at which cycles 2, 3, ... start (cycle 1 is everything before the first).

    Parameters
    ----------
    time_s : (n,) float
        Increasing times, s.
    stroke_mm : (n,) float
        Stroke, mm.
    """
    t = np.asarray(time_s, float)
    s = np.asarray(stroke_mm, float)
    lo_s, hi_s = float(np.min(s)), float(np.max(s))
    rng = hi_s - lo_s
    if rng <= 0:
        return np.zeros(0)
    lo, hi = lo_s + 0.25 * rng, lo_s + 0.75 * rng
    rises = []
    armed = True
    for i in np.flatnonzero((s < lo) | (s > hi)):
        if s[i] < lo:
            armed = True
        elif armed:
            rises.append(i)
            armed = False
    starts = []
    prev_peak = 0
    for r in rises:
        seg = s[prev_peak:r + 1]
        bottom = float(seg.min())
        near = np.flatnonzero(seg <= bottom + 0.002 * rng)
        starts.append(prev_peak + int(near[-1]))
        nxt = [q for q in rises if q > r]
        end = nxt[0] if nxt else s.size
        prev_peak = r + int(np.argmax(s[r:end]))
    starts_t = t[np.asarray(starts, dtype=int)] if starts else np.zeros(0)
    return starts_t[1:] if starts_t.size else starts_t


def cycle_numbers(time_s: np.ndarray, starts_s: np.ndarray) -> np.ndarray:
    """(n,) cycle number (1-based) of each time, from the start times of cycles 2, 3, ..."""
    return np.searchsorted(np.asarray(starts_s, float), np.asarray(time_s, float), side="right") + 1
