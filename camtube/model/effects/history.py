"""History operators the built-in effects share (and user effects may use): per sample, in time order.

``monotone_segments(data)``: runs of constant direction of motion (cached per Dataset);
``play_operator(data, x, width_mm)``: exact backlash, one NumPy call per run;
``first_order_lag(data, u, tau_s)``: ``tau dv/dt = u - v`` (``scipy.signal.lfilter`` for uniform sampling).
"""
from __future__ import annotations

import math

import numpy as np

from camtube.model.data.dataset import Dataset, recently_used

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
        for _, sl in data.sample_slices():
            dt = np.diff(t[sl])
            h = float(np.median(dt)) if dt.size else 0.0
            uniform = bool(dt.size and h > 0 and np.all(np.abs(dt - h) <= 1e-6 * h + 1e-12))
            hit.append((sl, h, uniform, dt))
        data.cache.set("history.sampling", hit)
    return hit


def first_order_lag(data: Dataset, u: np.ndarray, tau_s: float) -> np.ndarray:
    """``v`` with ``tau dv/dt = u - v`` per sample (exact for piecewise-constant ``u``), ``v_0 = u_0``.

    Uniform sampling uses :func:`scipy.signal.lfilter`; otherwise :func:`_lag_nonuniform` (blocks of NumPy calls).
    """
    from scipy.signal import lfilter

    tau = max(float(tau_s), 1e-9)
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
            v[sl] = _lag_nonuniform(us, dt, tau, plan=_lag_plan(data, sl, dt, tau))
    return v


#: Lag plans kept per Dataset (the most recently used): a fit evaluates the lag many times with one ``tau``.
LAG_PLANS_KEPT = 8


def _lag_plan(data: Dataset, sl: slice, dt: np.ndarray, tau: float) -> tuple:
    """What :func:`_lag_nonuniform` computes from the steps and ``tau`` alone, kept per Dataset, sample and
    ``tau`` (speed: a fit's finite-difference steps in other parameters, and the two passes of ``relaxation``,
    use one ``tau`` many times; the same computation gives the same numbers)."""
    kept = data.cache.get_or("history.lag_plans", dict)
    return recently_used(kept, (sl.start, sl.stop, tau), lambda: _new_lag_plan(dt, tau), LAG_PLANS_KEPT)


def _new_lag_plan(dt: np.ndarray, tau: float) -> tuple:
    """``(gain, scan, levels)`` of :func:`_lag_nonuniform` for the steps ``dt`` and ``tau``: the gains ``1 - a_k``,
    whether it runs the prefix scan (many blocks: ``tau`` short against the record), and then the scan's
    :func:`_scan_levels`, else the :func:`_lag_blocks`."""
    decay = np.maximum(dt, 0.0) / tau                    # -log a_k, k = 1 .. n-1
    cum = np.cumsum(decay)
    scan = bool(decay.size and cum[-1] > _LAG_BLOCK * 16.0)
    return -np.expm1(-decay), scan, (_scan_levels(np.exp(-decay)) if scan else _lag_blocks(cum))


#: Decay (in units of tau) spanned by one block of :func:`_lag_nonuniform`: exp(30) keeps the scaled sums far
#: from overflow and their rounding at ~1e-14 relative.
_LAG_BLOCK = 30.0


def _scan_levels(a: np.ndarray) -> tuple:
    """``(a_0, [multiplier of each pass])`` of the prefix scan :func:`_apply_scan` for ``a``: they depend on ``a``
    alone, so a lag with one ``tau`` computes them once (kept in its plan). The passes stop once every product of
    ``a`` has underflowed (a short ``tau``: a few passes)."""
    A = a.astype(float, copy=True)
    a0 = float(A[0]) if A.size else 0.0
    A[0:1] = 0.0
    levels = []
    d, n = 1, A.size
    while d < n and A.any():
        levels.append(A[d:].copy())
        A[d:] *= A[:-d]
        A[:d] = 0.0
        d *= 2
    return a0, levels


def _apply_scan(levels: tuple, b: np.ndarray, v0: float) -> np.ndarray:
    """``v_k = a_k v_(k-1) + b_k`` (``v_(-1) = v0``) for ``0 <= a_k <= 1`` by a parallel prefix scan, from the
    :func:`_scan_levels` of ``a``: ``log2 n`` passes of whole-array NumPy operations, each composing every step
    with the one ``d`` rows before it (``(a2, b2) o (a1, b1) = (a2 a1, a2 b1 + b2)``, d = 1, 2, 4, ...). No
    exponent grows, so nothing overflows. Replaced a Python loop over every row (issue 19: 15 s of a 34 s
    diagnosis on a jittered 60,000-row file)."""
    a0, mult = levels
    B = b.astype(float, copy=True)
    if B.size:
        B[0] += a0 * v0
    d = 1
    for m in mult:
        B[d:] += m * B[:-d]
        d *= 2
    return B


def _lag_nonuniform(u: np.ndarray, dt: np.ndarray, tau: float, plan: tuple | None = None) -> np.ndarray:
    """``v_k = a_k v_(k-1) + (1 - a_k) u_k``, ``a_k = exp(-dt_k / tau)``, ``v_0 = u_0``, for uneven steps ``dt``
    ((n - 1,) s), in blocks of NumPy calls (speed: a logger's jittered stamps made this a Python loop over every
    row). Within a block ``v_k = A_k (v_start + sum_j b_j / A_j)``, ``A_k`` the product of the ``a`` so far,
    computed through the cumulative sum of ``dt / tau``; a block ends once that sum has grown by
    :data:`_LAG_BLOCK`. Agrees with the row-by-row recursion to ~1e-14 relative."""
    gain, scan, levels = _new_lag_plan(dt, tau) if plan is None else plan
    b = gain * u[1:]                                     # (1 - a_k) u_k
    out = np.empty_like(u)
    out[0] = u[0]
    prev = float(u[0])
    if scan:
        out[1:] = _apply_scan(levels, b, prev)
        return out
    blocks, table = levels
    if table is not None:
        # speed: every block's sums in one cumulative sum along the rows of a table (each row a block, the same
        # sums in the same order); only the value carried from block to block is a (scalar) loop
        pos, grow2, shrink2, last, shrink_last = table
        x = np.zeros(grow2.size)
        x[pos] = b
        sums = np.cumsum(grow2 * x.reshape(grow2.shape), axis=1)
        sums_last = sums.ravel()[last].tolist()
        if all(map(math.isfinite, sums_last)):
            starts = []
            for sh, c in zip(shrink_last, sums_last):
                starts.append(prev)
                prev = sh * (prev + c)
            out[1:] = (shrink2 * (np.array(starts)[:, None] + sums)).ravel()[pos]
            return out
    for s, e, grow, shrink in blocks:    # one block at a time (a non-finite sum: the padding would see it)
        block = shrink * (prev + np.cumsum(grow * b[s:e]))
        out[s + 1:e + 1] = block
        prev = float(block[-1])
    return out


#: The table of :func:`_lag_blocks` is used when its blocks have at most this many rows on average (measured:
#: below, the few NumPy calls on the table cost less than four per block; above, the per-block calls win).
_TABLE_ROWS_PER_BLOCK = 600


def _lag_blocks(cum: np.ndarray) -> tuple:
    """``(blocks, table)``: ``[(s, e, 1 / A_k, A_k)]`` of the blocks of :func:`_lag_nonuniform` (``A_k`` the
    product of the ``a`` within the block), and the same laid out as a table, one block a row (zeros after
    its end): ``(flat positions of the rows' values, 1 / A_k, A_k, flat position of each block's last value,
    [A_k at each block's end])``, None when the blocks are few, long or uneven. They depend on the steps and ``tau`` alone (kept
    in a lag's plan)."""
    out, s, m = [], 0, cum.size
    while s < m:
        base = cum[s - 1] if s else 0.0
        e = max(int(np.searchsorted(cum, base + _LAG_BLOCK, side="right")), s + 1)
        log_a = -(cum[s:e] - base)                       # log A_k within the block
        out.append((s, e, np.exp(-log_a), np.exp(log_a)))
        s = e
    lengths = np.array([e - s for s, e, _, _ in out], np.intp)
    width = int(lengths.max()) if out else 0
    if len(out) < 3 or m > _TABLE_ROWS_PER_BLOCK * len(out) or len(out) * width > 1.5 * m:
        return out, None   # few, long or uneven blocks: the NumPy calls per block cost less than the table
    rows = np.repeat(np.arange(len(out)), lengths)
    pos = rows * width + (np.arange(m) - np.repeat(np.array([s for s, _, _, _ in out], np.intp), lengths))
    grow2 = np.zeros(len(out) * width)
    shrink2 = np.zeros(len(out) * width)
    grow2[pos] = np.concatenate([g for _, _, g, _ in out])
    shrink2[pos] = np.concatenate([h for _, _, _, h in out])
    last = np.arange(len(out)) * width + lengths - 1
    table = (pos, grow2.reshape(len(out), width), shrink2.reshape(len(out), width), last,
             [float(h[-1]) for _, _, _, h in out])
    return out, table


#: A held carriage slips when the smoothed force falls below this share of the hold force: the tendon's tension
#: drops at once as the carriage slides back onto the nut's flank (the held tension crept past the rail's friction as
#: the backbone recovered), where the rail holds it again (or, with the motor still going down, the nut's far flank
#: pushes the carriage down with it: carriage_hold takes the gap as wider than the stroke held)
RELEASE_SHARE = 0.5
#: Once held, the carriage stays held while the smoothed force stays below this multiple of the hold force: the
#: held tension creeps up to the rail's friction during a rest, within the cell's noise, and must not let go
#: there (it lets go by :data:`RELEASE_SHARE`; a pull that catches the carriage up raises the force past it).
HOLD_BAND = 1.2


def _sticks(s: np.ndarray, f: np.ndarray, first_of_sample: np.ndarray, a: np.ndarray,
            hold: np.ndarray) -> np.ndarray:
    """Where the carriage stuck, for holds that start at rows ``a``: the stroke at which the force fell to
    ``hold``, extrapolated along the unloading from the two rows before (the force there still follows the
    stroke; past the stick it stays near ``hold``, so a line to row ``a`` would cut the corner, and more so the
    fewer rows are kept), within the stroke of rows ``a`` and ``a - 1``; row ``a``'s stroke where there is no
    crossing to follow (the record's or a sample's first row, or a force already at ``hold`` the row before)."""
    p1 = np.maximum(a - 1, 0)
    p2 = np.maximum(a - 2, 0)
    crossed = (a > 0) & ~first_of_sample[a] & (f[p1] > hold)
    along = crossed & (a >= 2) & ~first_of_sample[p1] & (f[p2] > f[p1])
    with np.errstate(divide="ignore", invalid="ignore"):
        c_along = s[p1] + (s[p1] - s[p2]) * (f[p1] - hold) / (f[p2] - f[p1])
        c_line = s[p1] + (s[a] - s[p1]) * (f[p1] - hold) / (f[p1] - f[a])
    c = np.where(along, c_along, c_line)
    c = np.clip(c, np.minimum(s[a], s[p1]), np.maximum(s[a], s[p1]))
    return np.where(crossed, c, s[a])


def carriage_hold(data: Dataset, stroke_mm: np.ndarray, hold_N: float | np.ndarray, gap_mm: float) -> np.ndarray:
    """The carriage's position (mm) behind a nut with a gap ``gap_mm``, held by its rail below ``hold_N``.

    While the tension (smoothed: :attr:`Dataset.force_smoothed_N`) exceeds ``hold_N`` the tendon pulls the
    carriage onto the nut's flank: it follows the stroke. Once the tension falls to ``hold_N`` the rail holds it
    where it is (where the tension fell to ``hold_N``: :func:`_sticks`, continuous in ``hold_N``), within the
    gap: ``c_k = clip(c_(k-1), s_k, s_k + gap_mm)``. It slips back onto the flank (``c_k = s_k``) where the
    tension falls below :data:`RELEASE_SHARE` of ``hold_N``, and the rail holds it there again (the same clip from
    that row on: the motor's further travel down opens the gap anew, and the next pull takes it up first), until the
    tension has risen past :data:`HOLD_BAND` x ``hold_N`` (the next pull); it stays held while the tension stays
    below that. Per sample;
    ``hold_N`` a number or one per row (a sample's own); ``gap_mm <= 0`` or ``hold_N <= 0``: the stroke itself.

    Exact and vectorised: inside a run of held rows the recursion is a running minimum of
    ``s + gap`` where the stroke falls and a running maximum of ``s`` where it rises or stands, so only the value
    carried from one such piece to the next needs a scalar loop (as in :func:`play_operator`).
    """
    s = np.asarray(stroke_mm, float)
    out = s.copy()
    gap = float(gap_mm)
    hold = np.broadcast_to(np.asarray(hold_N, float), s.shape)
    if gap <= 0.0 or s.size == 0 or not np.any(hold > 0.0):
        return out
    gap = min(gap, float(np.ptp(s)) + 1.0)                 # a gap wider than the stroke never binds (and may be inf)
    f = np.asarray(data.force_smoothed_N, float)
    starts_of_samples = np.zeros(s.size, bool)
    for _, sl in data.sample_slices():
        if sl.stop > sl.start:
            starts_of_samples[sl.start] = True
    # held rows: in a run of rows below HOLD_BAND x hold_N, from its first row at or below hold_N on
    band = (f <= HOLD_BAND * hold) & (hold > 0.0)
    run = np.cumsum(band & ~(np.concatenate(([False], band[:-1])) & ~starts_of_samples))
    seen = np.maximum.accumulate((f <= hold) + 2 * run) - 2 * run
    # ... where the force falls below RELEASE_SHARE x hold_N the carriage slips back onto the nut's flank (c = s: the
    # tension crept past the rail's friction as the backbone recovered) and the rail holds it there again: the
    # motor's further travel down opens the gap anew (within the same run of rows)
    gone = np.maximum.accumulate((f < RELEASE_SHARE * hold) + 2 * run) - 2 * run
    low = band & (seen >= 1)
    # the first row of a run past that share (a run starts anew at each sample's first row, so does its count)
    prev_gone = np.concatenate(([0], gone[:-1]))
    slip = low & (gone >= 1) & ((prev_gone < 1) | (run != np.concatenate(([0], run[:-1]))))
    ds = np.diff(s, prepend=s[:1])
    up = ds >= 0.0
    prev_low = np.concatenate(([False], low[:-1])) & ~starts_of_samples
    entry = low & ~prev_low                               # the first row of a held run
    prev_up = np.concatenate(([True], up[:-1]))
    turn = low & prev_low & (up != prev_up)
    rows = np.flatnonzero(low)
    if rows.size == 0:
        return out
    first = np.flatnonzero(entry | turn | slip)           # every piece starts at one of these rows
    piece = np.searchsorted(first, rows, side="right") - 1
    at = np.searchsorted(rows, first)                     # where each piece starts among the held rows
    lo_s = np.minimum.reduceat(s[rows], at)
    hi_s = np.maximum.reduceat(s[rows], at)
    # the value each piece starts from: a stick, or what the piece before ended with (a scalar loop over the pieces)
    fresh = np.where(slip[first], s[first], _sticks(s, f, starts_of_samples, first, hold[first])).tolist()
    restart = (entry | slip)[first].tolist()
    rise = up[first].tolist()
    los, his = lo_s.tolist(), hi_s.tolist()
    begin = [0.0] * first.size
    c = 0.0
    for j in range(first.size):
        if restart[j]:
            c = fresh[j]
        begin[j] = c
        c = max(c, his[j]) if rise[j] else min(c, los[j] + gap)
    begin = np.asarray(begin)
    # the rows: a running maximum (rising) or minimum (falling) within each piece, offset per piece so that
    # one accumulate over all held rows never carries a value from one piece into the next
    sr = s[rows]
    span = float(sr.max() - sr.min()) + gap + 1.0
    rising = up[first][piece]
    cmax = np.maximum.accumulate(sr + piece * span) - piece * span
    cmin = np.minimum.accumulate(sr + gap - piece * span) + piece * span
    b = begin[piece]
    out[rows] = np.where(rising, np.maximum(b, cmax), np.minimum(b, cmin))
    return out
