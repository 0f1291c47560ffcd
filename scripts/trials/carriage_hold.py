"""A trial effect, not a built-in: lost motion in the drive as a carriage that its rail's friction holds.

Issue 19's bench files with lost motion (``python scripts/bench_real.py --write bench "lost motion" LM.csv``)
are missed in every batch. On the bench the tendon pulls the carriage onto the nut's flank while its tension
exceeds the rail's friction; on unloading, below it, the carriage stays where it is while the nut retreats
(within the nut's gap), so the joint rests bent with the tendon taut, until the carriage lets go and the
force drops to zero. This file writes that law, read from the measured force:

* on the flank the carriage follows the stroke;
* it is held once the (smoothed) force falls to ``hold_N`` and then stays within the gap:
  ``c = clip(c_prev, s, s + gap_mm)``;
* it lets go (back onto the flank) when the force falls below half of ``hold_N``: the release is seen
  after the fact, as the force's drop, because the crossing that causes it (the held tension creeping up to
  the rail's friction during the rest) is smaller than the load cell's noise.

Measured with it (docs/diagnose.md, "Lost motion in the drive: a trial, not built"): ``hold_N`` is a threshold
the least-squares fit cannot move (a step in the objective), so it is given per sample:

    camtube model fit LM.csv --pattern patterns/tube1.yaml --cycles all --branch both --no-deadband \\
        --set-aside --lag-ms 0 --effect-file scripts/trials/carriage_hold.py \\
        --effects carriage_hold,slack,capstan,relaxation --per-sample carriage_hold.hold_N \\
        --init carriage_hold.hold_N@S1=0.175 --init carriage_hold.hold_N@S2=0.15 \\
        --fit E_t,slack.deadband_mm,capstan.mu_wrap,capstan.slip_mm_s,capstan.hold,relaxation.fraction,relaxation.tau_s
"""
from __future__ import annotations

import numpy as np

from camtube.model.api import Effect, Param


def _smoothed(data, force_N: np.ndarray, window_s: float) -> np.ndarray:
    """Centred running mean of the force over ``window_s``, per sample."""
    out = np.empty_like(force_N)
    for _, sl in data.sample_slices():
        t = np.asarray(data.time_s[sl], float)
        x = force_N[sl]
        dt = float(np.median(np.diff(t))) if t.size > 1 else 1.0
        half = max(int(round(window_s / dt)), 1) // 2
        csum = np.concatenate([[0.0], np.cumsum(x)])
        i = np.arange(x.size)
        lo = np.clip(i - half, 0, x.size)
        hi = np.clip(i + half + 1, 0, x.size)
        out[sl] = (csum[hi] - csum[lo]) / (hi - lo)
    return out


def _hold_guess(data, ctx) -> float:
    """The force the tendon holds while the motor rests at the bottom of the stroke (its 90th percentile)."""
    s = np.asarray(data.stroke_mm, float)
    f = np.asarray(data.force_N, float)
    low = (s - s.min()) < 0.01 * (float(np.ptp(s)) or 1.0)
    held = f[low & (f > 0.02)]
    return float(np.percentile(held, 90)) if held.size > 20 else 0.1


def _carriage(ctx, stroke_mm: np.ndarray, p: dict) -> np.ndarray:
    s = np.asarray(stroke_mm, float)
    f = _smoothed(ctx.data, np.asarray(ctx.force_N, float), p["window_s"])
    hold, gap = p["hold_N"], p["gap_mm"]
    out = np.empty_like(s)
    for _, sl in ctx.data.sample_slices():
        ss, ff = s[sl].tolist(), f[sl].tolist()
        c, held, col = (ss[0] if ss else 0.0), False, [0.0] * len(ss)
        for i, (x, fi) in enumerate(zip(ss, ff)):
            if held and fi < 0.5 * hold:       # let go: the force dropped, the carriage is back on the flank
                c, held = x, False
            elif held or fi <= hold:            # held by the rail, within the nut's gap
                c = min(max(c, x), x + gap)
                held = c > x
            else:                               # pulled onto the flank
                c = x
            col[i] = c
        out[sl] = col
    return out


CARRIAGE_HOLD = Effect(
    name="carriage_hold", stage="stroke",
    params=(Param("gap_mm", "mm", 0.0, 2.0, 0.2, "gap of the nut's lug (lost motion at most)", kind="length"),
            Param("hold_N", "N", 0.0, 2.0, _hold_guess, "tension below which the rail's friction holds the carriage"),
            Param("window_s", "s", 0.0, 2.0, 0.1, "the force is smoothed over this window before it is compared")),
    apply=_carriage,
    meaning="lost motion in the drive: below the rail's friction the carriage stays while the nut retreats, "
            "within the nut's gap, until it lets go",
    signature="the joint stays bent with the tendon taut while the motor rests at zero, then drops at once",
    history=True,
)
