"""History operators the built-in effects share (and user effects may use): per sample, in time order.

``monotone_segments(data)``: runs of constant direction of motion (cached per Dataset);
``play_operator(data, x, width_mm)``: exact backlash, one NumPy call per run;
``first_order_lag(data, u, tau_s)``: ``tau dv/dt = u - v`` (``scipy.signal.lfilter`` for uniform sampling).
"""
from __future__ import annotations

import math
import weakref

import numpy as np

from camtube.model.data.dataset import Dataset

_SEGMENTS: "weakref.WeakKeyDictionary[Dataset, list]" = weakref.WeakKeyDictionary()


def monotone_segments(data: Dataset) -> list[tuple[int, int, int, bool]]:
    """``(start, stop, direction, first_of_sample)`` of every run of constant direction.

    Cached per :class:`Dataset` object (the fit evaluates the model many times on the same rows).
    """
    hit = _SEGMENTS.get(data)
    if hit is not None:
        return hit
    d = data.direction
    out = []
    for _, sl in data.sample_slices():
        dd = d[sl]
        cut = np.flatnonzero(np.diff(dd)) + 1
        starts = np.concatenate(([0], cut))
        stops = np.concatenate((cut, [dd.size]))
        for k, (a, b) in enumerate(zip(starts, stops)):
            out.append((sl.start + int(a), sl.start + int(b), int(dd[a]), k == 0))
    _SEGMENTS[data] = out
    return out


def play_operator(data: Dataset, x: np.ndarray, width_mm: float) -> np.ndarray:
    """Play (backlash) operator of width ``width_mm`` on ``x`` (n,), per sample, exact.

    The output lags ``width_mm`` behind the input while it grows and stays put
    after a reversal until the input has come back by ``width_mm``:
    ``y_k = clip(y_{k-1}, x_k - w, x_k)``, starting at ``x_0 - w``. Within a
    monotone run of ``x`` the recursion is ``max(y_prev, x - w)`` (growing) or
    ``min(y_prev, x)`` (shrinking), so each run is one NumPy call.
    """
    w = float(width_mm)
    y = np.empty_like(x)
    prev = 0.0
    for a, b, dirn, first in monotone_segments(data):
        xs = x[a:b]
        if first:
            prev = float(xs[0]) - (w if dirn > 0 else 0.0)
        if dirn > 0:
            seg = np.maximum(xs - w, prev)
        else:
            seg = np.minimum(xs, prev)
        y[a:b] = seg
        prev = float(seg[-1])
    return y


def first_order_lag(data: Dataset, u: np.ndarray, tau_s: float) -> np.ndarray:
    """``v`` with ``tau dv/dt = u - v`` per sample (exact for piecewise-constant ``u``), ``v_0 = u_0``.

    Uniform sampling uses :func:`scipy.signal.lfilter`; otherwise a loop.
    """
    from scipy.signal import lfilter

    tau = max(float(tau_s), 1e-9)
    v = np.empty_like(u)
    t = np.asarray(data.time_s, float)
    for _, sl in data.sample_slices():
        us, ts = u[sl], t[sl]
        if us.size == 0:
            continue
        dt = np.diff(ts)
        if dt.size == 0:
            v[sl] = us
            continue
        h = float(np.median(dt))
        if h > 0 and np.all(np.abs(dt - h) <= 1e-6 * h + 1e-12):
            a = math.exp(-h / tau)
            v[sl], _ = lfilter([1.0 - a], [1.0, -a], us, zi=[a * us[0]])
        else:
            a = np.exp(-np.maximum(dt, 0.0) / tau)
            out = np.empty_like(us)
            out[0] = us[0]
            acc = float(us[0])
            for k in range(1, us.size):
                acc = a[k - 1] * acc + (1.0 - a[k - 1]) * float(us[k])
                out[k] = acc
            v[sl] = out
    return v
