"""One clock for three instruments: offset and drift of an instrument's clock against the tracker's.

Every instrument keeps its own clock; two crystal clocks differ by an offset and drift apart by tens of
ppm. The map from an instrument's clock ``t`` to the reference (tracker) clock is taken as linear:

    t_ref = t + offset_s + drift_ppm 1e-6 (t - t_mid_s)

with ``t_mid_s`` the middle of the instrument's recording (so the offset and its uncertainty refer to the
recording, not to an extrapolated clock zero).

**From a shared trigger** (:func:`align_trigger`): the rising edges of a trigger line recorded by both
instruments, each edge timed by linear interpolation between samples, matched in order; a straight-line fit
of one clock's edge times against the other's gives offset and drift, with standard errors from the scatter
plus the edges' timing resolution (a sample interval / sqrt(12) per log: a trigger logged at 100 Hz is good to
a few ms, not better).

**From the shared motion** (:func:`align_xcorr`): the tracker's bend angle, the load cell's force and the
motor's stroke all follow the same actuation. A coarse lag is the peak of the full cross-correlation of both
signals on a 20 ms grid (``scipy.signal.correlate``); then, in windows along the recording, the lag that
best explains the tracker's own samples (no interpolation of the noisy signal) by a piecewise-linear
function of the instrument's signal interpolated at those instants (straight line plus hinges doubling from
the bottom of its range, from 0.5 % or five times its noise, to 32 %, then at 50, 70 and 90 %: a static
nonlinearity such as the slack deadband between stroke and angle does not bias the lag the way a
straight-line correlation would), on a 1 ms grid refined by a parabola through the minimum's +-5 ms. A log sampled much faster than the
tracker is first averaged over a centred window of one tracker frame (no lag, less noise). Reference samples that fall in a gap of the log
(or within the lag search of one) are left out rather than compared with a bridged signal. A straight-line fit of the window lags against time gives offset and drift: weighted by each window's
standard error (from the curvature of the residual sum of squares at its minimum), scaled up when the windows
scatter more than that. A periodic motion is ambiguous by whole periods: the recording's
rests at its start and end break the tie, and ``max_lag_s`` bounds the search.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from camtube.errors import DataError


@dataclass(frozen=True, eq=False)
class ClockFit:
    """The map of one instrument's clock onto the reference clock.

    Attributes
    ----------
    name : str
        The instrument (``daq``, ``motor``).
    method : str
        ``trigger``, ``xcorr``, or ``a+b`` for a map composed of two.
    offset_s, drift_ppm : float
        ``t_ref = t + offset_s + drift_ppm 1e-6 (t - t_mid_s)``.
    t_mid_s : float
        The instrument's clock at the middle of its recording, s.
    offset_err_s, drift_err_ppm : float
        Standard errors (NaN when they cannot be estimated, e.g. fewer than three windows).
    sign : int
        Sign of the correlation between the instrument's signal and the reference (+1 expected).
    window_t_s, window_lag_s : (k,) float
        Per-window lags (instrument clock, s) the fit was made from, for the report.
    runner_up, runner_up_lag_s : float
        The best other local maximum of the coarse cross-correlation, as a fraction of the chosen one's,
        and its offset (s). Close to 1 means the motion barely fixes the offset.
    """

    name: str
    method: str
    offset_s: float
    drift_ppm: float
    t_mid_s: float
    offset_err_s: float = float("nan")
    drift_err_ppm: float = float("nan")
    sign: int = 1
    window_t_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    window_lag_s: np.ndarray = field(default_factory=lambda: np.zeros(0))
    runner_up: float = float("nan")
    runner_up_lag_s: float = float("nan")

    def to_ref(self, t: np.ndarray) -> np.ndarray:
        """(n,) reference-clock times of the instrument's times ``t`` (s)."""
        t = np.asarray(t, float)
        return t + self.offset_s + self.drift_ppm * 1e-6 * (t - self.t_mid_s)

    def then(self, other: "ClockFit") -> "ClockFit":
        """This map followed by ``other`` (this maps onto ``other``'s instrument clock)."""
        a = 1.0 + self.drift_ppm * 1e-6
        b = 1.0 + other.drift_ppm * 1e-6
        off_mid = float(other.to_ref(self.to_ref(self.t_mid_s))) - self.t_mid_s
        err_off = float(np.hypot(self.offset_err_s * b, other.offset_err_s))
        return ClockFit(self.name, f"{self.method}+{other.method}", off_mid, (a * b - 1.0) * 1e6, self.t_mid_s,
                        err_off, float(np.hypot(self.drift_err_ppm, other.drift_err_ppm)), self.sign * other.sign,
                        self.window_t_s, self.window_lag_s)


def _line_fit(x: np.ndarray, y: np.ndarray, x_mid: float) -> tuple[float, float, float, float]:
    """Straight line ``y = c + d (x - x_mid)``: (c, d, se_c, se_d); NaN errors with < 3 points."""
    x = np.asarray(x, float) - x_mid
    y = np.asarray(y, float)
    if x.size < 3 or np.ptp(x) <= 0:
        c = float(np.mean(y))
        se = float(np.std(y, ddof=1) / np.sqrt(y.size)) if y.size >= 2 else float("nan")
        return c, 0.0, se, float("nan")
    a = np.column_stack([np.ones_like(x), x])
    coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    res = y - a @ coef
    s2 = float(res @ res) / (x.size - 2)
    cov = s2 * np.linalg.inv(a.T @ a)
    return float(coef[0]), float(coef[1]), float(np.sqrt(cov[0, 0])), float(np.sqrt(cov[1, 1]))


def rising_edges(time_s: np.ndarray, level: np.ndarray) -> np.ndarray:
    """(k,) times (s) where ``level`` rises through the middle of its range, interpolated between samples."""
    t = np.asarray(time_s, float)
    v = np.asarray(level, float)
    mid = 0.5 * (np.nanmin(v) + np.nanmax(v))
    k = np.flatnonzero((v[:-1] < mid) & (v[1:] >= mid))
    f = (mid - v[k]) / (v[k + 1] - v[k])
    return t[k] + f * (t[k + 1] - t[k])


def align_trigger(name: str, t: np.ndarray, trig: np.ndarray, ref_t: np.ndarray, ref_trig: np.ndarray,
                  what: str = "trigger") -> ClockFit:
    """Map ``t`` onto ``ref_t``'s clock from the rising edges both trigger columns recorded.

    Raises
    ------
    DataError
        Fewer than two edges, or a different number of edges in the two logs.
    """
    ea = rising_edges(t, trig)
    eb = rising_edges(ref_t, ref_trig)
    if ea.size != eb.size or ea.size < 2:
        raise DataError(f"{what}: the {name} log shows {ea.size} trigger edge(s), the other log {eb.size}; fix: "
                        "record the same trigger pulses (at least two) in both logs, or drop the trigger from the "
                        "bench map to align from the motion")
    t_mid = 0.5 * (t[0] + t[-1])
    c, d, sc, sd = _line_fit(ea, eb - ea, t_mid)
    # an edge is timed only to within its sample interval; when the pulses keep one phase against the
    # sampling that error does not average out, so it is added to the fit's scatter
    quant = float(np.hypot(np.median(np.diff(t)), np.median(np.diff(ref_t)))) / np.sqrt(12.0)
    return ClockFit(name, "trigger", c, d * 1e6, t_mid, float(np.hypot(sc, quant)), sd * 1e6, 1, ea, eb - ea)


def _fill(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    ok = np.isfinite(y)
    return t[ok], y[ok]


def _uniform(t: np.ndarray, y: np.ndarray, t0: float, dt: float, n: int) -> np.ndarray:
    g = t0 + dt * np.arange(n)
    out = np.interp(g, t, y)
    out[(g < t[0]) | (g > t[-1])] = np.nan
    return out


def coarse_lag(ref_t: np.ndarray, ref_y: np.ndarray, t: np.ndarray, y: np.ndarray, dt: float = 0.02,
               max_lag_s: float | None = None) -> tuple[float, int, float, float]:
    """Coarse lag (s, ``t_ref = t + lag``), correlation sign, and the best other local maximum of the
    cross-correlation: its score as a fraction of the peak's, and its lag (s).

    Both signals are put on a ``dt`` grid (the reference's gaps bridged linearly), their means removed, and
    correlated over every overlap; outside a recording a signal counts as zero (so a shift by a whole period
    of a periodic motion loses the overlap of the rests and scores lower).
    """
    from scipy.signal import correlate, correlation_lags

    rt, ry = _fill(ref_t, ref_y)
    n_r = int((rt[-1] - rt[0]) / dt) + 1
    n_i = int((t[-1] - t[0]) / dt) + 1
    a = _uniform(rt, ry, rt[0], dt, n_r)
    b = _uniform(t, y, t[0], dt, n_i)
    a = np.nan_to_num((a - np.nanmean(a)) / (np.nanstd(a) or 1.0))
    b = np.nan_to_num((b - np.nanmean(b)) / (np.nanstd(b) or 1.0))
    c = correlate(a, b, mode="full", method="fft")
    lags = correlation_lags(a.size, b.size, mode="full") * dt + (rt[0] - t[0])
    if max_lag_s is not None:
        keep = np.abs(lags) <= max_lag_s
        c, lags = c[keep], lags[keep]
    k = int(np.argmax(np.abs(c)))
    sign = 1 if c[k] >= 0 else -1
    # the best other local maximum (a periodic motion scores again one period off)
    from scipy.signal import find_peaks

    peaks, _ = find_peaks(sign * c)
    peaks = peaks[peaks != k]
    if not peaks.size or c[k] == 0:
        return float(lags[k]), sign, 0.0, float("nan")
    j = int(peaks[np.argmax(sign * c[peaks])])
    return float(lags[k]), sign, float(sign * c[j] / (sign * c[k])), float(lags[j])


def align_xcorr(name: str, ref_t: np.ndarray, ref_y: np.ndarray, t: np.ndarray, y: np.ndarray, *,
                window_s: float | None = None, max_lag_s: float | None = None, step_s: float = 0.001) -> ClockFit:
    """Map ``t`` onto the reference clock by correlating the shared motion (see the module docstring).

    Parameters
    ----------
    name : str
        The instrument, for messages.
    ref_t, ref_y : (m,) float
        Reference (tracker) times (s) and signal; NaN where not measured.
    t, y : (n,) float
        The instrument's times (s, its clock) and signal.
    window_s : float, optional
        Window length, s (default: an eighth of the overlap, 10-60 s).
    max_lag_s : float, optional
        Largest offset to consider, s.
    step_s : float
        Lag grid of the fine search, s.

    Raises
    ------
    DataError
        The recordings do not overlap, or no window holds enough motion.
    """
    ref_t = np.asarray(ref_t, float)
    ref_y = np.asarray(ref_y, float)
    t = np.asarray(t, float)
    y = np.asarray(y, float)
    lag0, sign, runner_up, alt = coarse_lag(ref_t, ref_y, t, y, max_lag_s=max_lag_s)
    if runner_up > 0.995:
        raise DataError(f"the motion does not fix the {name} log's clock: offsets of {lag0:.2f} s and {alt:.2f} s "
                        f"fit the tracker within {100 * (1 - runner_up):.1f} % of each other; fix: --max-lag S (the "
                        "largest offset the clocks can have), a rest at the start and end of the recording, or a "
                        "trigger column")
    ok = np.isfinite(ref_y)
    rt, ry = ref_t[ok], ref_y[ok]
    lo, hi = max(rt[0], t[0] + lag0), min(rt[-1], t[-1] + lag0)
    if hi - lo <= 0:
        raise DataError(f"the {name} log and the tracker export do not overlap in time after alignment; fix: "
                        "give logs of the same run")
    span = hi - lo
    half = 3 * 0.02
    w = window_s or float(np.clip(span / 8.0, 10.0, 60.0))
    nw = max(int(span // w), 1)
    edges = lo + span * np.arange(nw + 1) / nw
    deltas = np.arange(-half, half + step_s / 2, step_s)
    sd_all = float(np.std(ry))
    dti = np.diff(t)
    gap = np.flatnonzero(dti > 1.5 * np.median(dti))
    if gap.size:                # reference samples that would see the log bridged across a gap are left out
        at = rt - lag0
        hole = np.zeros(rt.size, bool)
        for k in gap:
            hole |= (at > t[k] - 2 * half) & (at < t[k + 1] + 2 * half)
        rt, ry = rt[~hole], ry[~hole]
    y = _smooth_to(t, y, float(np.median(np.diff(rt))))
    knots = _knots(y)
    wt, wl, ws = [], [], []
    for a, b in zip(edges[:-1], edges[1:]):
        m = (rt >= a) & (rt < b)
        if m.sum() < 20 or np.std(ry[m]) < 0.05 * sd_all:
            continue
        tr, yr = rt[m], ry[m]
        sse = np.empty(deltas.size)
        for j, dl in enumerate(deltas):
            x = np.interp(tr - lag0 - dl, t, y)
            basis = np.column_stack([np.ones_like(x), x, np.maximum(x[:, None] - knots[None, :], 0.0)])
            coef, *_ = np.linalg.lstsq(basis, yr, rcond=None)
            r = yr - basis @ coef
            sse[j] = r @ r
        j = int(np.argmin(sse))
        frac, se = 0.0, float("nan")
        near = slice(max(j - 5, 0), min(j + 6, deltas.size))
        if near.stop - near.start >= 5 and 0 < j < deltas.size - 1:
            # a parabola through the minimum's neighbourhood (+-5 ms): robust to a jagged SSE curve
            cf = np.polyfit(deltas[near] - deltas[j], sse[near], 2)
            if cf[0] > 0:
                frac = float(np.clip(-cf[1] / (2 * cf[0]), -5 * step_s, 5 * step_s)) / step_s
                # var(lag) = 2 s^2 / SSE'' with s^2 the residual variance at the minimum
                s2 = float(sse[j]) / max(yr.size - knots.size - 2, 1)
                se = float(np.sqrt(2.0 * s2 / (2.0 * cf[0])))
        if not np.isfinite(se):
            continue                       # the minimum is at the edge of the search: no estimate here
        lag = lag0 + deltas[j] + frac * step_s
        wt.append(0.5 * (a + b) - lag)
        wl.append(lag)
        ws.append(se)
    if not wt:
        raise DataError(f"no stretch of the recording where the tracker and the {name} log both show motion; fix: "
                        "check that both logs belong to the same run (or add a trigger column)"
                        + ("" if max_lag_s is None else f"; if their clocks start more than --max-lag {max_lag_s:g} s "
                           "apart, give a larger --max-lag"))
    wt_a, wl_a = np.asarray(wt), np.asarray(wl)
    t_mid = 0.5 * (t[0] + t[-1])
    c, d, sc, sd = _weighted_line(wt_a, wl_a, np.asarray(ws), t_mid)
    return ClockFit(name, "xcorr", c, d * 1e6, t_mid, sc, sd * 1e6, sign, wt_a, wl_a, runner_up, alt)


def _smooth_to(t: np.ndarray, y: np.ndarray, dt_ref: float) -> np.ndarray:
    """``y`` averaged over a centred window as long as the reference's frame interval (no lag), when the
    log samples much faster than the reference: its noise then no longer makes the fit jagged in the lag."""
    dt = float(np.median(np.diff(t)))
    k = int(round(dt_ref / dt))
    if k < 3:
        return y
    k += 1 - k % 2
    pad = np.pad(y, k // 2, mode="edge")
    return np.convolve(pad, np.ones(k) / k, mode="valid")


def _knots(y: np.ndarray) -> np.ndarray:
    """Hinge positions for the piecewise-linear map: doubling from the bottom of ``y``'s range (from 0.5 %,
    or from 5 noise standard deviations when the signal is noisier) to 32 %, then 50, 70 and 90 %."""
    lo, hi = np.quantile(y, [0.001, 0.999])
    span = float(hi - lo) or 1.0
    noise = float(np.std(np.diff(y, 2)) / np.sqrt(6.0)) if y.size > 3 else 0.0
    first = max(0.005, 5.0 * noise / span)
    steps = [f for f in first * 2.0 ** np.arange(12) if f < 0.32]
    return lo + span * np.array(steps + [0.32, 0.5, 0.7, 0.9])


def _weighted_line(x: np.ndarray, y: np.ndarray, se: np.ndarray, x_mid: float) -> tuple[float, float, float, float]:
    """Offset and drift from window lags with standard errors: ``y = c + d (x - x_mid)``.

    Weighted least squares; the errors are scaled up by the scatter when it exceeds what the windows'
    own errors say (reduced chi-square > 1). With fewer than three windows the drift is taken as 0 and
    the offset is the weighted mean. Returns (c, d, se_c, se_d); se_d is NaN with fewer than three windows.
    """
    w = 1.0 / se ** 2
    xm = x - x_mid
    mean = float(np.sum(w * y) / np.sum(w))
    chi0 = float(np.sum(w * (y - mean) ** 2) / (y.size - 1)) if y.size > 1 else 1.0
    se_mean = float(np.sqrt(1.0 / np.sum(w) * max(1.0, chi0)))
    if y.size < 3:
        return mean, 0.0, se_mean, float("nan")
    a = np.column_stack([np.ones_like(xm), xm])
    aw = a * w[:, None]
    cov = np.linalg.inv(a.T @ aw)
    coef = cov @ (aw.T @ y)
    r = y - a @ coef
    chi = float(np.sum(w * r * r) / (y.size - 2))
    cov = cov * max(1.0, chi)
    return float(coef[0]), float(coef[1]), float(np.sqrt(cov[0, 0])), float(np.sqrt(cov[1, 1]))
