"""History operators the built-in effects share (and user effects may use): per sample, in time order.

``monotone_segments(data)``: runs of constant direction of motion (cached per Dataset);
``play_operator(data, x, width_mm)``: exact backlash, one NumPy call per run;
``first_order_lag(data, u, tau_s)``: ``tau dv/dt = u - v`` (``scipy.signal.lfilter`` for uniform sampling, the
compiled recursion of :mod:`camtube.model.effects.kernels` for jittered stamps);
``carriage_hold(data, stroke_mm, hold_N, gap_mm)``: a carriage its rail holds within a nut's gap (compiled, row by row).
"""
from __future__ import annotations

import math

import numpy as np

from camtube.model.data.dataset import Dataset, recently_used
from camtube.model.effects.kernels import hold_rows, lag_rows, relaxed_rows

# speed: derived per-Dataset data, cached (fits evaluate the model hundreds of times on the same rows)


def monotone_segments(data: Dataset) -> list[tuple[int, int, int, bool]]:
    """``(start, stop, direction, first_of_sample)`` of every run of constant direction.

    Cached per :class:`Dataset` object (the fit evaluates the model many times on the same rows).
    """
    hit = data.cache.get("history.segments")
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
    data.cache.set("history.segments", out)
    return out


def _segment_arrays(data: Dataset) -> tuple:
    """Cached ``(starts, stops, dirs, firsts, lengths, row_dir)`` of :func:`monotone_segments` as arrays/lists."""
    hit = data.cache.get("history.segment_arrays")
    if hit is None:
        segs = monotone_segments(data)
        starts = np.array([s[0] for s in segs], np.int64)
        stops = np.array([s[1] for s in segs], np.int64)
        dirs = [s[2] for s in segs]
        firsts = [s[3] for s in segs]
        hit = (starts, stops, dirs, firsts, stops - starts, np.repeat(np.array(dirs, np.int64), stops - starts))
        data.cache.set("history.segment_arrays", hit)
    return hit


def play_operator(data: Dataset, x: np.ndarray, width_mm: float) -> np.ndarray:
    """Play (backlash) operator of width ``width_mm`` on ``x`` (n,), per sample, exact.

    The output lags ``width_mm`` behind the input while it grows and stays put
    after a reversal until the input has come back by ``width_mm``:
    ``y_k = clip(y_{k-1}, x_k - w, x_k)``, starting at ``x_0 - w``. Within a
    monotone run of ``x`` the recursion is ``max(y_prev, x - w)`` (growing) or
    ``min(y_prev, x)`` (shrinking), so only the value carried from one run to the
    next needs a (scalar) loop over the runs; the rows are then filled by three
    NumPy calls (speed: see ``scripts/bench_diagnose.py``).
    """
    w = float(width_mm)
    x = np.asarray(x, float)
    if x.size == 0:
        return x.copy()
    starts, stops, dirs, firsts, lengths, row_dir = _segment_arrays(data)
    x_first = x[starts].tolist()
    x_last = x[stops - 1].tolist()
    carry = [0.0] * len(dirs)
    prev = 0.0
    for k, dirn in enumerate(dirs):
        if firsts[k]:
            prev = x_first[k] - (w if dirn > 0 else 0.0)
        carry[k] = prev
        prev = max(x_last[k] - w, prev) if dirn > 0 else min(x_last[k], prev)
    prev_row = np.repeat(np.asarray(carry), lengths)
    return np.where(row_dir > 0, np.maximum(x - w, prev_row), np.minimum(x, prev_row))


def _sampling(data: Dataset) -> list:
    """Cached per sample: ``(slice, h, uniform, dt)`` (median step, whether the sampling is uniform)."""
    hit = data.cache.get("history.sampling")
    if hit is None:
        t = np.asarray(data.time_s, float)
        hit = []
        for (_, sl), h in zip(data.sample_slices(), data.median_steps_s()):
            dt = np.diff(t[sl])
            uniform = bool(dt.size and h > 0 and np.all(np.abs(dt - h) <= 1e-6 * h + 1e-12))
            hit.append((sl, h, uniform, dt))
        data.cache.set("history.sampling", hit)
    return hit


def _lag_tau(tau_s: float) -> float:
    """A lag's time constant as the laws take it (s): at least 1 ns."""
    return max(float(tau_s), 1e-9)


def first_order_lag(data: Dataset, u: np.ndarray, tau_s: float) -> np.ndarray:
    """``v`` with ``tau dv/dt = u - v`` per sample (exact for piecewise-constant ``u``), ``v_0 = u_0``.

    Uniform sampling uses :func:`scipy.signal.lfilter`; otherwise the recursion
    ``v_k = a_k v_(k-1) + (1 - a_k) u_k``, ``a_k = exp(-dt_k / tau)``, row by row
    (:func:`camtube.model.effects.kernels.lag_rows`), with the steps' decays kept per Dataset and ``tau``.
    """
    from scipy.signal import lfilter

    tau = _lag_tau(tau_s)
    v = np.empty_like(u)
    for sl, h, uniform, dt in _sampling(data):
        us = u[sl]
        if us.size == 0:
            continue
        if dt.size == 0:
            v[sl] = us
            continue
        if uniform:
            a = math.exp(-h / tau)
            v[sl], _ = lfilter([1.0 - a], [1.0, -a], us, zi=[a * us[0]])
        else:
            v[sl] = lag_rows(np.ascontiguousarray(us, float), *_lag_steps(data, sl, dt, tau))
    return v


def relaxed_compiled(data: Dataset, theta: np.ndarray, arms) -> np.ndarray | None:
    """The angle with the relaxing arms ``arms`` ((share, time constant s), one or two) of
    :func:`camtube.model.effects.builtin._relaxed`, by the compiled law
    (:func:`camtube.model.effects.kernels.relaxed_rows`), sample by sample; None where that law does not apply as
    written: a sample sampled uniformly (its lag is :func:`scipy.signal.lfilter`'s), a sample of one row, an angle
    not finite, more than two arms. (speed: the same numbers; the lag's steps kept as :func:`first_order_lag` keeps
    them.)"""
    if not 1 <= len(arms) <= 2 or not np.isfinite(theta).all():
        return None
    sampling = _sampling(data)
    if any(uniform or dt.size == 0 for _, _, uniform, dt in sampling):
        return None
    out = np.empty_like(theta)
    (c1, tau1), (c2, tau2) = arms[0], arms[-1]
    for sl, _, _, dt in sampling:
        a1, g1 = _lag_steps(data, sl, dt, _lag_tau(tau1))
        a2, g2 = _lag_steps(data, sl, dt, _lag_tau(tau2)) if len(arms) == 2 else (a1, g1)
        out[sl] = relaxed_rows(np.ascontiguousarray(theta[sl], float), a1, g1, float(c1), a2, g2, float(c2),
                               len(arms))
    return out


#: Lag steps kept per Dataset (the most recently used): a fit evaluates the lag many times with one ``tau``.
LAG_STEPS_KEPT = 8


def _lag_steps(data: Dataset, sl: slice, dt: np.ndarray, tau: float) -> tuple:
    """``(a, gain)`` (n - 1,) of one sample's steps ``dt`` for ``tau``: ``a = exp(-dt / tau)`` and
    ``gain = 1 - a`` (computed as ``-expm1(-dt / tau)``), kept per Dataset, sample and ``tau`` (speed: a fit's
    finite-difference steps in other parameters, and the two passes of ``relaxation``, use one ``tau`` many times;
    the same computation gives the same numbers)."""
    kept = data.cache.get_or("history.lag_steps", dict)

    def compute() -> tuple:
        decay = np.maximum(dt, 0.0) / tau
        return np.exp(-decay), -np.expm1(-decay)

    return recently_used(kept, (sl.start, sl.stop, tau), compute, LAG_STEPS_KEPT)


#: A held carriage slips when the smoothed force falls below this share of the hold force: the tendon's tension
#: drops at once as the carriage slides back onto the nut's flank (the held tension crept past the rail's friction as
#: the backbone recovered), where the rail holds it again (or, with the motor still going down, the nut's far flank
#: pushes the carriage down with it: carriage_hold takes the gap as wider than the stroke held)
RELEASE_SHARE = 0.5
#: Once held, the carriage stays held while the smoothed force stays below this multiple of the hold force: the
#: held tension creeps up to the rail's friction during a rest, within the cell's noise, and must not let go
#: there (it lets go by :data:`RELEASE_SHARE`; a pull that catches the carriage up raises the force past it).
HOLD_BAND = 1.2


def carriage_hold(data: Dataset, stroke_mm: np.ndarray, hold_N: float | np.ndarray, gap_mm: float) -> np.ndarray:
    """The carriage's position (mm) behind a nut with a gap ``gap_mm``, held by its rail below ``hold_N``.

    While the tension (smoothed: :attr:`Dataset.force_smoothed_N`) exceeds ``hold_N`` the tendon pulls the
    carriage onto the nut's flank: it follows the stroke. Once the tension falls to ``hold_N`` the rail holds it
    where it is (where the tension fell to ``hold_N``, along the unloading from the two rows before: continuous in
    ``hold_N``), within the gap: ``c_k = clip(c_(k-1), s_k, s_k + gap_mm)``. It slips back onto the flank (``c_k = s_k``) where the
    tension falls below :data:`RELEASE_SHARE` of ``hold_N``, and the rail holds it there again (the same clip from
    that row on: the motor's further travel down opens the gap anew, and the next pull takes it up first), until the
    tension has risen past :data:`HOLD_BAND` x ``hold_N`` (the next pull); it stays held while the tension stays
    below that. Per sample;
    ``hold_N`` a number or one per row (a sample's own); ``gap_mm <= 0`` or ``hold_N <= 0``: the stroke itself.

    The law row by row, compiled: :func:`camtube.model.effects.kernels.hold_rows` (speed: it replaced a vectorised
    form, pieces of running minima and maxima around a scalar loop, 18x slower on a 30,000-row sample).
    """
    s = np.asarray(stroke_mm, float)
    gap = float(gap_mm)
    hold = np.broadcast_to(np.asarray(hold_N, float), s.shape)
    if gap <= 0.0 or s.size == 0 or not np.any(hold > 0.0):
        return s.copy()
    gap = min(gap, float(np.ptp(s)) + 1.0)                 # a gap wider than the stroke never binds (and may be inf)
    f = np.ascontiguousarray(data.force_smoothed_N, dtype=float)
    slices = [sl for _, sl in data.sample_slices()]
    starts = np.array([sl.start for sl in slices], np.int64)
    stops = np.array([sl.stop for sl in slices], np.int64)
    return hold_rows(np.ascontiguousarray(s), f, starts, stops, np.ascontiguousarray(hold, dtype=float), gap,
                     HOLD_BAND, RELEASE_SHARE)
