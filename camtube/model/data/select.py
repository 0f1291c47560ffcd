"""Which rows a comparison uses: cycles, direction of motion (branch), and the slack deadband.

The paper compares the *last loading* cycle with the slack removed; :func:`prepare` chains the
three steps with those defaults (see :mod:`camtube.model.data` for the whole API).
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np

from camtube.errors import DataError
from camtube.model.data.dataset import Dataset

BRANCHES = ("loading", "unloading", "both")


# ----------------------------------------------------------------------------- selection

@dataclass(frozen=True)
class CycleSpec:
    """Parsed cycle selection: ranges ``(lo, hi)`` (inclusive, ``hi`` None = open) and last-N counts."""

    ranges: tuple[tuple[int, int | None], ...] = ()
    last: tuple[int, ...] = ()
    everything: bool = False
    text: str = "all"

    def mask(self, data: Dataset) -> np.ndarray:
        """(n,) bool: rows of ``data`` whose cycle is selected (``last`` counted per sample)."""
        cyc = np.asarray(data.cycle)
        if self.everything:
            return np.ones(len(data), bool)
        m = np.zeros(len(data), bool)
        for lo, hi in self.ranges:
            m |= (cyc >= lo) & (cyc <= (hi if hi is not None else np.iinfo(np.int64).max))
        for k in self.last:
            for _, sl in data.sample_slices():
                top = int(cyc[sl].max())
                m[sl] |= cyc[sl] > top - k
        return m


#: Cycle numbers of up to 18 digits (a count of cycles; Python refuses to convert thousands of digits).
_ITEM = re.compile(r"^(?:(?P<all>all)|last\s*(?P<last>\d{1,18})?"
                   r"|(?P<lo>\d{1,18})?\s*(?P<dash>-)?\s*(?P<hi>\d{1,18})?)$")


def parse_cycles(spec: str | None) -> CycleSpec:
    """Parse ``all``, ``last``, ``last20``, ``5``, ``31-50``, ``2-``, ``-10`` or a comma list.

    Raises
    ------
    DataError
        For anything else, also an empty ``spec`` (``--cycles ''``, an unset shell variable: not "all"; None is).
    """
    if spec is not None and not spec.strip():
        raise DataError(f"--cycles {spec!r}: an empty cycle selection; fix: e.g. --cycles last (or all, last20, "
                        "31-50, 2-)")
    text = (spec or "all").strip().lower()
    ranges, last, everything = [], [], False
    for item in (s.strip() for s in text.split(",")):
        mt = _ITEM.match(item)
        ok = bool(item) and mt is not None
        if ok and mt["all"]:
            everything = True
            continue
        if ok and item.startswith("last"):
            n = int(mt["last"] or 1)
            ok = n >= 1
            if ok:
                last.append(n)
                continue
        if ok:
            lo, hi, dash = mt["lo"], mt["hi"], mt["dash"]
            ok = bool(lo or hi)
            if ok and not dash:
                ok = lo is not None and hi is None
                lo_i = hi_i = int(lo) if ok else 0
            elif ok:
                lo_i = int(lo) if lo else 1
                hi_i = int(hi) if hi else None
                ok = hi_i is None or hi_i >= lo_i
            if ok:
                ranges.append((lo_i, hi_i))
                continue
        raise DataError(f"cycle selection {spec!r}: cannot read {item!r}; "
                        "fix: use all, last, last20, 5, 31-50, 2- or -10 (comma lists allowed)")
    return CycleSpec(tuple(ranges), tuple(last), everything, text)


def select_cycles(data: Dataset, spec: str | CycleSpec | None) -> Dataset:
    """Rows of the selected cycles (``spec`` as in :func:`parse_cycles`).

    Raises
    ------
    DataError
        If nothing is selected (the message lists the cycles present).
    """
    cs = spec if isinstance(spec, CycleSpec) else parse_cycles(spec)
    m = cs.mask(data)
    if len(data) and not m.any():
        cyc = np.asarray(data.cycle)
        raise DataError(f"cycle selection {cs.text!r} matches no rows; the data have cycles "
                        f"{int(cyc.min())}-{int(cyc.max())}; fix: select cycles in that range, e.g. --cycles all")
    return data if m.all() else data.take(m)


def select_branch(data: Dataset, branch: str) -> Dataset:
    """Rows of the ``loading`` (stroke growing), ``unloading`` branch, or ``both``."""
    if branch not in BRANCHES:
        raise DataError(f"branch {branch!r}: use one of {', '.join(BRANCHES)}")
    if branch == "both":
        return data
    want = 1 if branch == "loading" else -1
    m = data.direction == want
    if not m.any():
        raise DataError(f"the data have no {branch} rows")
    return data.take(m)


# ----------------------------------------------------------------------------- deadband

@dataclass(frozen=True)
class Slack:
    """Deadband of one cycle: slack stroke (mm), baseline angle (deg), noise estimate (deg)."""

    stroke_mm: float
    baseline_deg: float
    noise_deg: float


def _noise(signal: np.ndarray) -> float:
    """Noise standard deviation of a sampled signal from the MAD of its second differences.

    A smooth signal sampled densely has nearly zero second differences, so what
    is left is ``sqrt(6)`` times the white noise.
    """
    if signal.size < 5:
        return 0.0
    d2 = np.diff(signal, 2)
    return float(1.4826 * np.median(np.abs(d2 - np.median(d2))) / math.sqrt(6.0))


@np.errstate(over="ignore", invalid="ignore")  # an absurd value (angle 1e300) overflows: inf, and no warning
def _hinge_sse(cand: np.ndarray, s: np.ndarray, y: np.ndarray) -> np.ndarray:
    """SSE of the best ``b + k max(s - s0, 0)`` (k > 0) for each knee ``s0`` in ``cand`` ``(c,)``."""
    h = np.clip(s[None, :] - cand[:, None], 0.0, None)  # (c, m)
    m = s.size
    sh, shh = h.sum(1), (h * h).sum(1)
    sy, shy = y.sum(), h @ y
    det = m * shh - sh * sh
    ok = det > 1e-12 * max(1.0, float(np.max(np.abs(det))))
    k = np.where(ok, (m * shy - sh * sy) / np.where(ok, det, 1.0), 0.0)
    b = (sy - k * sh) / m
    sse = ((y[None, :] - b[:, None] - k[:, None] * h) ** 2).sum(1)
    return np.where(ok & (k > 0), sse, np.inf)


def _first_rise(s: np.ndarray, y: np.ndarray, thr: float, head: int) -> float:
    """First stroke from which ``y`` stays above its start + ``thr`` for three rows (``s`` sorted)."""
    above = y > float(np.median(y[:head])) + thr
    run = above[:-2] & above[1:-1] & above[2:]
    idx = np.flatnonzero(run)
    return float(s[idx[0]]) if idx.size else float(s[-1])


def _cycle_slack(stroke: np.ndarray, angle: np.ndarray, force: np.ndarray,
                 threshold_deg: float | None) -> Slack:
    """Slack of one loading branch (rows in time order)."""
    sig_a, sig_f = _noise(angle), _noise(force)
    if not sig_f * sig_f > 0.0:   # (forces of 1e-200 N: a noise whose square underflows cannot weigh the force)
        sig_f = 0.0
    order = np.argsort(stroke, kind="stable")
    s, a, f = stroke[order], angle[order], force[order]
    s_min, s_max = float(s[0]), float(s[-1])
    if s.size < 8 or s_max - s_min <= 0:
        return Slack(s_min, float(np.median(a)) if a.size else 0.0, sig_a)
    head = max(3, s.size // 50)
    thr_a = max(threshold_deg if threshold_deg is not None else 0.5, 4.0 * sig_a)
    s_thr = _first_rise(s, a, thr_a, head)
    if sig_f > 0:
        s_thr = min(s_thr, _first_rise(s, f, 4.0 * sig_f, head))
    win = s <= s_thr + 0.3 * (s_max - s_thr)
    sw = s[win]
    cand = np.unique(np.concatenate((np.linspace(s_min, s_thr, 64), sw[sw <= s_thr])))
    # one knee for both signals, each weighted by its noise (a joint likelihood)
    cost = _hinge_sse(cand, sw, a[win]) / max(sig_a, 1e-9) ** 2
    if sig_f > 0:
        cost = cost + _hinge_sse(cand, sw, f[win]) / sig_f**2
    if not np.isfinite(cost).any():
        return Slack(s_min, float(np.median(a[:head])), sig_a)
    j = int(np.argmin(cost))
    # refine between the neighbouring candidates
    lo, hi = cand[max(j - 1, 0)], cand[min(j + 1, cand.size - 1)]
    fine = np.linspace(lo, hi, 41)
    cost_f = _hinge_sse(fine, sw, a[win]) / max(sig_a, 1e-9) ** 2
    if sig_f > 0:
        cost_f = cost_f + _hinge_sse(fine, sw, f[win]) / sig_f**2
    s0 = float(fine[int(np.argmin(cost_f))]) if np.isfinite(cost_f).any() else float(cand[j])
    base = a[s <= s0]
    return Slack(s0, float(np.median(base)) if base.size else float(a[0]), sig_a)


def find_slack(data: Dataset, threshold_deg: float | None = None) -> dict[tuple[str, int], Slack]:
    """Slack of every (sample, cycle) from its loading rows.

    Method (per cycle, the rows from its start to its peak stroke, sorted by stroke): the noise of the angle
    and of the force is estimated from their second differences; a first guess
    of the slack is the smallest stroke from which the angle stays above its
    starting value by ``max(threshold_deg (default 0.5), 4 sigma_angle)`` (or
    the force by ``4 sigma_force``) for three rows. The slack is then the knee
    ``s0`` of ``b + k max(stroke - s0, 0)`` fitted to the foot of the curve
    (strokes up to the guess plus 30% of the rest) for the angle and the
    force at once, each weighted by its noise; the knee does not lag behind by
    the threshold as the first crossing does. A cycle with fewer than 8
    loading rows gets its smallest stroke.

    Returns
    -------
    dict
        ``(sample, cycle) -> Slack``.
    """
    out: dict[tuple[str, int], Slack] = {}
    for smp, sl in data.sample_slices():
        cyc = np.asarray(data.cycle[sl])
        st = np.asarray(data.stroke_mm[sl], float)
        an = np.asarray(data.angle_deg[sl], float)
        fo = np.asarray(data.force_N[sl], float)
        bounds = np.flatnonzero(np.diff(cyc)) + 1
        for a, b in zip(np.concatenate(([0], bounds)), np.concatenate((bounds, [cyc.size]))):
            # the loading branch: from the start of the cycle to its peak stroke
            # (includes a dwell or the tail of the last descent at the bottom)
            load = np.zeros(b - a, bool)
            load[: int(np.argmax(st[a:b])) + 1] = True
            if load.sum() < 2:
                load[:] = True
            out[(smp, int(cyc[a]))] = _cycle_slack(st[a:b][load], an[a:b][load], fo[a:b][load],
                                                   threshold_deg)
    return out


def _deadband(data: Dataset, threshold_deg: float | None) -> tuple[Dataset, np.ndarray]:
    """``data`` with the slack subtracted (all rows) and the (n,) bool mask of rows past the slack."""
    slack = find_slack(data, threshold_deg)
    per_row = np.empty(len(data))
    for smp, sl in data.sample_slices():
        cyc = np.asarray(data.cycle[sl])
        lut = {c: slack[(smp, int(c))].stroke_mm for c in np.unique(cyc)}
        per_row[sl] = np.vectorize(lut.__getitem__, otypes=[float])(cyc)
    shifted = np.asarray(data.stroke_mm, float) - per_row
    keep = shifted >= 0.0
    if not keep.any():
        raise DataError("every row lies inside the slack deadband (the stroke never passes the slack found in its "
                        "cycle); fix: keep those rows with --no-deadband, or check the stroke column (and --lag-ms)")
    out = Dataset(data.sample, data.cycle, data.time_s, shifted, data.force_N, data.angle_deg,
                  {**data.extra, "slack_mm": per_row})
    return out, keep


def remove_deadband(data: Dataset, threshold_deg: float | None = None) -> Dataset:
    """Subtract each cycle's slack from its stroke and drop the rows inside the deadband.

    The slack per row is kept in ``extra["slack_mm"]`` (mm). See :func:`find_slack`.
    """
    out, keep = _deadband(data, threshold_deg)
    return out.take(keep)


def prepare(data: Dataset, cycles: str | CycleSpec | None = "last", branch: str = "loading",
            deadband: bool = True, threshold_deg: float | None = None) -> Dataset:
    """The rows a comparison uses: cycles, then deadband removal, then branch.

    The branch is taken from the stroke direction *before* the deadband rows
    are dropped (so the first row past the slack keeps its true direction).
    The defaults are the paper's comparison: the last loading cycle of each
    sample with the slack deadband removed.
    """
    if branch not in BRANCHES:
        raise DataError(f"branch {branch!r}: use one of {', '.join(BRANCHES)}")
    d = select_cycles(data, cycles)
    keep = np.ones(len(d), bool)
    if deadband:
        d, keep = _deadband(d, threshold_deg)
    if branch != "both":
        keep &= d.direction == (1 if branch == "loading" else -1)
        if not keep.any():
            raise DataError(f"the selected rows have no {branch} part")
    return d if keep.all() else d.take(keep)
