"""Measurement files: load and validate CSV, select cycles and branch, remove the slack deadband.

CSV format
----------
One row per instant, a header line with at least the columns
``sample, cycle, time_s, stroke_mm, force_N, angle_deg`` (any order; more
columns are kept in :attr:`Dataset.extra`). Several samples per file are
allowed; blank lines and lines starting with ``#`` are skipped. Rows of one
sample need not be contiguous (they are gathered by sample in order of first
appearance, keeping file order within a sample), but within a sample
``time_s`` must not decrease and ``cycle`` (a whole number >= 1) must not
decrease. Any violation, a missing column, a non-numeric, empty, NaN or
infinite cell raises :class:`~camtube.errors.DataError` naming the file and
line; nothing is returned half-loaded.

Selection (the paper compares the *last loading* cycle, slack removed)
----------------------------------------------------------------------
* :func:`select_cycles` with a spec: ``all``, ``last`` (each sample's last
  cycle), ``last20`` (each sample's last 20), ``5``, ``31-50``, ``2-``, ``-10``,
  or a comma list of these.
* :func:`select_branch`: ``loading`` (stroke growing, :attr:`Dataset.direction` +1),
  ``unloading`` (-1) or ``both``.
* :func:`remove_deadband`: per sample and cycle, the slack is the stroke at
  which the joint starts to move on loading (:func:`find_slack`); it is
  subtracted from that cycle's stroke and the rows inside the deadband are
  dropped.
* :func:`prepare` chains the three; its defaults are the paper's comparison.

API
---
``parse_csv(text, source="<csv>") -> Dataset``, ``load_csv(path) -> Dataset``,
``format_csv(data) -> str``, ``parse_cycles(spec) -> CycleSpec``,
``select_cycles(data, spec) -> Dataset``, ``select_branch(data, branch) -> Dataset``,
``find_slack(data, threshold_deg=None) -> dict[(sample, cycle), Slack]``,
``remove_deadband(data, threshold_deg=None) -> Dataset``,
``prepare(data, cycles="last", branch="loading", deadband=True) -> Dataset``.
"""
from __future__ import annotations

import csv
import difflib
import io
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from camtube.errors import DataError
from camtube.model.dataset import Dataset

#: Required CSV columns, in the order :func:`format_csv` writes them.
COLUMNS = ("sample", "cycle", "time_s", "stroke_mm", "force_N", "angle_deg")
_FLOAT_COLS = ("time_s", "stroke_mm", "force_N", "angle_deg")
_FORMATS = {"time_s": "%.4f", "stroke_mm": "%.6f", "force_N": "%.6f", "angle_deg": "%.5f"}
BRANCHES = ("loading", "unloading", "both")


# ----------------------------------------------------------------------------- loading

def _err(source: str, line: int | None, msg: str, fix: str = "") -> DataError:
    where = f"{source}:{line}" if line is not None else source
    return DataError(f"{where}: {msg}" + (f"; fix: {fix}" if fix else ""))


def _to_float(col: tuple, name: str, lines: np.ndarray, source: str, finite: bool = True) -> np.ndarray:
    """Column of strings -> (n,) float; the first bad cell raises with its line."""
    try:
        arr = np.array(col, dtype=float)
    except ValueError:
        for k, cell in enumerate(col):
            try:
                float(cell)
            except ValueError:
                what = "is empty" if not cell.strip() else f"is not a number: {cell!r}"
                raise _err(source, int(lines[k]), f"column {name!r} {what}",
                           "every cell of the measurement columns must be a number") from None
        raise  # pragma: no cover - numpy and float() disagree
    if finite:
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            k = int(bad[0])
            raise _err(source, int(lines[k]), f"column {name!r} is {col[k].strip()!r}",
                       "NaN/inf are not measurements: drop the row or fill the gap")
    return arr


def parse_csv(text: str, source: str = "<csv>") -> Dataset:
    """Parse measurement CSV text into a :class:`Dataset` (see the module docstring).

    Parameters
    ----------
    text : str
        The file's content.
    source : str
        Name used in error messages (the file path).

    Raises
    ------
    DataError
        Naming ``source:line`` and the column.
    """
    reader = csv.reader(io.StringIO(text))
    header: list[str] | None = None
    header_line = 0
    rows: list[list[str]] = []
    lines: list[int] = []
    try:
        for rec in reader:
            ln = reader.line_num
            if not rec or not any(c.strip() for c in rec) or rec[0].lstrip().startswith("#"):
                continue
            if header is None:
                header = [c.strip() for c in rec]
                header_line = ln
                continue
            if len(rec) != len(header):
                raise _err(source, ln, f"{len(rec)} cells but the header (line {header_line}) has "
                                       f"{len(header)} columns", "one cell per column on every line")
            rows.append(rec)
            lines.append(ln)
    except csv.Error as exc:
        raise _err(source, reader.line_num, f"not valid CSV ({exc})") from None
    if header is None:
        raise _err(source, None, "no header line: the file is empty",
                   f"the first line must name the columns: {', '.join(COLUMNS)}")
    dup = sorted({c for c in header if header.count(c) > 1})
    if dup:
        raise _err(source, header_line, f"duplicate column(s) {', '.join(dup)}")
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        hints = []
        for c in missing:
            m = difflib.get_close_matches(c, header, n=1, cutoff=0.5)
            if m:
                hints.append(f"{m[0]!r} -> {c!r}")
        raise _err(source, header_line,
                   f"missing column(s) {', '.join(missing)} (found: {', '.join(header)})",
                   ("rename " + ", ".join(hints)) if hints else f"the header must contain {', '.join(COLUMNS)}")
    if not rows:
        raise _err(source, header_line, "no data rows after the header")

    ln = np.asarray(lines, dtype=np.int64)
    cols = dict(zip(header, zip(*rows)))
    sample = np.array([s.strip() for s in cols["sample"]], dtype=object)
    empty = np.flatnonzero(sample == "")
    if empty.size:
        raise _err(source, int(ln[empty[0]]), "column 'sample' is empty", "give every row a sample id")
    cyc_f = _to_float(cols["cycle"], "cycle", ln, source)
    bad = np.flatnonzero((cyc_f != np.round(cyc_f)) | (cyc_f < 1))
    if bad.size:
        k = int(bad[0])
        raise _err(source, int(ln[k]), f"column 'cycle' must be a whole number >= 1, got {cols['cycle'][k].strip()!r}",
                   "number the cycles 1, 2, 3, ...")
    num = {c: _to_float(cols[c], c, ln, source) for c in _FLOAT_COLS}
    extra: dict[str, np.ndarray] = {}
    for c in header:
        if c in COLUMNS:
            continue
        try:
            extra[c] = np.array(cols[c], dtype=float)
        except ValueError:
            extra[c] = np.array([s.strip() for s in cols[c]], dtype=object)

    # gather rows by sample (first appearance), keep file order within a sample
    uniq, first, inv = np.unique(sample, return_index=True, return_inverse=True)
    rank = np.empty(len(uniq), dtype=np.int64)
    rank[np.argsort(first)] = np.arange(len(uniq))
    order = np.argsort(rank[inv], kind="stable")
    if np.any(order != np.arange(len(order))):
        sample = sample[order]
        ln = ln[order]
        cyc_f = cyc_f[order]
        num = {c: v[order] for c, v in num.items()}
        extra = {c: v[order] for c, v in extra.items()}
    same = sample[1:] == sample[:-1]
    for name, arr, fix in (("time_s", num["time_s"], "sort each sample's rows by time"),
                           ("cycle", cyc_f, "cycles must not decrease with time within a sample")):
        back = np.flatnonzero(same & (np.diff(arr) < 0))
        if back.size:
            k = int(back[0]) + 1
            raise _err(source, int(ln[k]),
                       f"column {name!r} goes backwards within sample {sample[k]!r}: {arr[k]:g} after "
                       f"{arr[k - 1]:g} (line {int(ln[k - 1])})", fix)
    return Dataset(sample, cyc_f.astype(np.int64), num["time_s"], num["stroke_mm"], num["force_N"],
                   num["angle_deg"], extra)


def load_csv(path: str | Path) -> Dataset:
    """Load and validate a measurement CSV file (see :func:`parse_csv`)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except FileNotFoundError:
        raise DataError(f"{path}: no such measurement file") from None
    except IsADirectoryError:
        raise DataError(f"{path}: is a directory, not a measurement file; fix: name the CSV file") from None
    except PermissionError:
        raise DataError(f"{path}: cannot read the measurement file (permission denied)") from None
    except OSError as exc:
        raise DataError(f"{path}: cannot read the measurement file ({exc.strerror or exc})") from None
    except UnicodeDecodeError as exc:
        raise DataError(f"{path}: not a UTF-8 text file ({exc.reason} at byte {exc.start})") from None
    return parse_csv(text, str(path))


def check_fittable(data: Dataset, what: str = "the selected rows") -> None:
    """Refuse rows the joint model cannot be fitted to: a stroke or an angle that never changes.

    Raises
    ------
    DataError
        Naming the column, its value range and the fix.
    """
    for col, unit in (("stroke_mm", "mm"), ("angle_deg", "deg")):
        v = np.asarray(getattr(data, col), float)
        if v.size and float(np.ptp(v)) <= 1e-12 * max(1.0, float(np.max(np.abs(v)))):
            raise DataError(f"{what}: column {col!r} never changes (every value is {float(v[0]):g} {unit}): "
                            "the model's parameters cannot be identified; fix: give rows where the joint "
                            "is actuated (check the file and the --cycles selection)")


def format_csv(data: Dataset) -> str:
    """CSV text of ``data``: the required columns, then extra columns (deterministic, ``\\n`` endings).

    Floats are written with fixed decimals: time 1e-4 s, stroke 1e-6 mm,
    force 1e-6 N, angle 1e-5 deg; extra float columns with 9 significant digits.
    """
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    names = list(COLUMNS) + list(data.extra)
    w.writerow(names)
    cols = [data.sample.astype(str), np.char.mod("%d", np.asarray(data.cycle, np.int64))]
    for c in _FLOAT_COLS:
        cols.append(np.char.mod(_FORMATS[c], np.asarray(getattr(data, c), float)))
    for v in data.extra.values():
        v = np.asarray(v)
        cols.append(np.char.mod("%.9g", v) if v.dtype.kind in "fiu" else v.astype(str))
    w.writerows(zip(*cols))
    return out.getvalue()


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


_ITEM = re.compile(r"^(?:(?P<all>all)|last\s*(?P<last>\d+)?|(?P<lo>\d+)?\s*(?P<dash>-)?\s*(?P<hi>\d+)?)$")


def parse_cycles(spec: str | None) -> CycleSpec:
    """Parse ``all``, ``last``, ``last20``, ``5``, ``31-50``, ``2-``, ``-10`` or a comma list.

    Raises
    ------
    DataError
        For anything else.
    """
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
                        "use all, last, last20, 5, 31-50, 2- or -10 (comma lists allowed)")
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
                        f"{int(cyc.min())}-{int(cyc.max())}")
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
        raise DataError("every row lies inside the slack deadband; try --no-deadband")
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
