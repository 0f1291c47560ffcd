"""Row-by-row recursions of the history operators, compiled (numba): the laws as written, one row after another.

Why compiled: a fit evaluates the model thousands of times, and a law whose state carries from row to row (a lag on
jittered stamps, a carriage its rail holds) has no NumPy form but a parallel scan or a piecewise trick around a
scalar loop (what :mod:`camtube.model.effects.history` had before: up to half of a lost-motion file's diagnosis, about a
quarter of a typical bench file's). The loop itself, compiled, is the law written once, checked against itself, and faster: on a 30,000-row
sample 64 us for the lag (243 before), 124 us for the carriage (2,245 before).

``lag_rows(u, a, gain)``: ``v_0 = u_0``, ``v_k = a_(k-1) v_(k-1) + gain_(k-1) u_k``.
``hold_rows(s, f, starts, stops, hold, gap, band, release)``: the held carriage of
:func:`camtube.model.effects.history.carriage_hold`.
``toe_rows(f, c, lam, t_max, xj)``: the Weibull toe's extra elongation of
:func:`camtube.model.effects.builtin.weibull_toe_force`, inverted by a table (no recursion: one pass over the rows
instead of about ten NumPy passes, each writing an array; a toe file's fits spend a fifth of their time there).
``relaxed_rows(th, a1, g1, c1, a2, g2, c2, arms)``: the relaxing backbone of
:func:`camtube.model.effects.builtin._relaxed` (its rest floor and both passes of its lags in one loop per sample).

The functions compile on the first import of this module (or load from numba's cache beside it, or in the user's
cache when the package folder cannot be written, or compile in each process when neither can be), so that worker
processes forked later inherit them compiled.
"""
from __future__ import annotations

import numpy as np
from numba import njit

__all__ = ["hold_rows", "lag_rows", "relaxed_rows", "toe_rows"]


def _compiled(fn):
    """``fn`` compiled, its machine code cached on disk for the next process; where numba finds no folder it may
    write the cache to (a read-only install, no writable home), compiled in each process instead."""
    try:
        return njit(cache=True, nogil=True)(fn)
    except RuntimeError:   # numba: "cannot cache function ...: no locator available"
        return njit(nogil=True)(fn)


@_compiled
def lag_rows(u: np.ndarray, a: np.ndarray, gain: np.ndarray) -> np.ndarray:  # pragma: no cover (compiled)
    """(n,) ``v_0 = u_0``, ``v_k = a_(k-1) v_(k-1) + gain_(k-1) u_k`` (``a``, ``gain`` (n - 1,): the decay and
    the gain ``1 - a`` of each step, the gain computed as ``-expm1(-dt / tau)`` by the caller)."""
    n = u.size
    v = np.empty(n)
    if n == 0:
        return v
    prev = u[0]
    v[0] = prev
    for k in range(1, n):
        prev = a[k - 1] * prev + gain[k - 1] * u[k]
        v[k] = prev
    return v


@_compiled
def hold_rows(s: np.ndarray, f: np.ndarray, starts: np.ndarray, stops: np.ndarray, hold: np.ndarray,
              gap: float, band: float, release: float) -> np.ndarray:  # pragma: no cover (compiled)
    """(n,) the carriage's position behind a nut with a gap ``gap`` (mm), held by its rail below ``hold`` (N, one
    per row), from the stroke ``s`` and the smoothed force ``f``, per sample (rows ``starts[j]:stops[j]``).

    Row by row: above ``band x hold`` the tendon pulls the carriage onto the flank (``c = s``) and a new run of
    held rows may start; within a run, from the first row at or below ``hold``, the rail holds it:
    ``c = clip(c_prev, s, s + gap)``, starting where the force fell to ``hold`` (along the unloading from the two
    rows before, within the stroke of this row and the one before); the first row below ``release x hold`` in a
    run slips onto the flank (``c = s``) and is held there again."""
    out = s.copy()
    for j in range(starts.size):
        a, b = starts[j], stops[j]
        low_prev = False
        seen = False
        gone = False
        c = 0.0
        for k in range(a, b):
            h = hold[k]
            if not h > 0.0:          # no hold in this row: the carriage on the flank, and a run starts anew
                low_prev = seen = gone = False
                continue
            first = k == a
            slip = False
            if f[k] > band * h:      # pulled onto the flank: a new run may start
                seen = gone = False
            else:
                seen = seen or f[k] <= h
                slip = (not gone) and f[k] < release * h
                gone = gone or slip
            if not seen or f[k] > band * h:
                c = s[k]
                low_prev = False
                continue
            if slip:
                c = s[k]
            else:
                if not low_prev:     # held from here: where the force fell to the hold force
                    if first or f[k - 1] <= h:
                        c = s[k]
                    elif k - 2 >= a and f[k - 2] > f[k - 1]:
                        c = s[k - 1] + (s[k - 1] - s[k - 2]) * (f[k - 1] - h) / (f[k - 2] - f[k - 1])
                    else:
                        c = s[k - 1] + (s[k] - s[k - 1]) * (f[k - 1] - h) / (f[k - 1] - f[k])
                    if not first:
                        c = min(max(c, min(s[k], s[k - 1])), max(s[k], s[k - 1]))
                c = min(max(c, s[k]), s[k] + gap)
            out[k] = c
            low_prev = True
    return out


@_compiled
def toe_rows(f: np.ndarray, c: float, lam: float, t_max: float, xj: np.ndarray) -> np.ndarray:  # pragma: no cover
    """(m,) ``lam (x(tau) - tau)`` at the normalised tensions ``tau = c f / lam``, ``x(tau)`` read linearly from
    ``xj``, its values at ``tau = t_max (j / G)^2`` (``G = xj.size - 1``; ``t_max > 0``, the largest tension). Each
    row as the NumPy expression computes it, operation for operation (the same numbers):
    ``pos = sqrt(tau (1 / t_max)) G``, ``i = min(int(pos), G - 1)``. (Compiled.)"""
    m = f.size
    out = np.empty(m)
    g = xj.size - 1
    inv = 1.0 / t_max
    for k in range(m):
        t = c * f[k] / lam
        pos = np.sqrt(t * inv) * g
        i = int(pos)
        if i > g - 1:
            i = g - 1
        lo = xj[i]
        out[k] = lam * (lo + (pos - i) * (xj[i + 1] - lo) - t)
    return out


@_compiled
def relaxed_rows(th: np.ndarray, a1: np.ndarray, g1: np.ndarray, c1: float, a2: np.ndarray, g2: np.ndarray,
                 c2: float, arms: int) -> np.ndarray:  # pragma: no cover (compiled)
    """(n,) one sample's angle with one or two relaxing arms of its backbone (``arms``; shares ``c1``, ``c2``; each
    arm's steps' decay ``a`` and gain ``g`` (n - 1,), as :func:`lag_rows` takes them): the law of
    :func:`camtube.model.effects.builtin._relaxed` for finite angles, operation for operation (the same numbers).

    The rest floor: from the first row at or above the lowest angle after the largest (when that is above 0), that
    angle; then two passes of ``held = max(th, floor + sum(c_j lag_j(held - floor)))``. (Compiled: a relaxing
    backbone's evaluation was some twenty NumPy passes and four lag calls.)"""
    n = th.size
    out = np.empty(n)
    if n == 0:
        return out
    top = 0
    for k in range(1, n):
        if th[k] > th[top]:
            top = k
    low = th[top]
    for k in range(top + 1, n):
        if th[k] < low:
            low = th[k]
    rest = low if low >= 0.0 else 0.0
    first = n
    if rest > 0.0:
        for k in range(n):
            if th[k] >= rest:
                first = k
                break
    floor = np.zeros(n)
    for k in range(first, n):
        floor[k] = rest
    held = np.empty(n)
    for k in range(n):
        held[k] = th[k] if th[k] >= floor[k] else floor[k]
    for _ in range(2):
        u0 = held[0] - floor[0]
        v1 = u0
        v2 = u0
        tot = c1 * v1
        if arms == 2:
            tot = tot + c2 * v2
        out[0] = tot
        for k in range(1, n):
            u = held[k] - floor[k]
            v1 = a1[k - 1] * v1 + g1[k - 1] * u
            tot = c1 * v1
            if arms == 2:
                v2 = a2[k - 1] * v2 + g2[k - 1] * u
                tot = tot + c2 * v2
            out[k] = tot
        for k in range(n):
            y = floor[k] + out[k]
            held[k] = th[k] if th[k] >= y else y
    return held


def _warm() -> None:
    """Compile (or load) every law now, in this process: forked workers then inherit them ready."""
    x = np.zeros(3)
    lag_rows(x, x[:2], x[:2])
    idx = np.zeros(1, np.int64)
    hold_rows(x, x, idx, idx + 3, x + 1.0, 1.0, 1.2, 0.5)
    toe_rows(x, 1.0, 1.0, 1.0, x)
    relaxed_rows(x, x[:2], x[:2], 0.5, x[:2], x[:2], 0.5, 2)


_warm()
