"""Measurement CSV files: parse and validate (errors name the file and line), format, and refuse
rows the model cannot be fitted to (see :mod:`camtube.model.data` for the format)."""
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
from camtube.inputfile import read_input_text
from camtube.model.data.dataset import Dataset

#: Required CSV columns, in the order :func:`format_csv` writes them.
COLUMNS = ("sample", "cycle", "time_s", "stroke_mm", "force_N", "angle_deg")
_FLOAT_COLS = ("time_s", "stroke_mm", "force_N", "angle_deg")
_FORMATS = {"time_s": "%.4f", "stroke_mm": "%.6f", "force_N": "%.6f", "angle_deg": "%.5f"}
#: Largest cycle number read (a billion cycles; beyond, the number cannot be a count of cycles).
MAX_CYCLE = 1e9
#: Largest magnitude read in a measured column (time in s, stroke in mm, force in N, angle in deg): beyond it a
#: value is a unit or export mistake, and the arithmetic of a fit would overflow.
#: Largest magnitude a column may hold. The time's covers a clock that counts Unix seconds (1.7e9 in 2023; the physics
#: reads the time since each sample's first row, ``Dataset.elapsed_s``); a clock in ms since 1970 is beyond it.
MAX_VALUE = {"time_s": 1e10, "stroke_mm": 1e6, "force_N": 1e6, "angle_deg": 1e6}


# ----------------------------------------------------------------------------- loading

#: Most rows whose time stamp goes backwards that a reading drops as a logger's glitches: this many, or this share of
#: the rows where that is more (a logger's stamps jittering by half a row's interval go back in about 1 % of the rows
#: at 100 Hz); more are refused, naming the first (rows in another order than time's: about half go back).
BACKWARD_GLITCHES = 10
BACKWARD_SHARE = 0.1


def _err(source: str, line: int | None, msg: str, fix: str = "") -> DataError:
    where = f"{source}:{line}" if line is not None else source
    return DataError(f"{where}: {msg}" + (f"; fix: {fix}" if fix else ""))


def _to_float(col: tuple, name: str, lines: np.ndarray, source: str, finite: bool = True) -> np.ndarray:
    """Column of strings -> (n,) float; the first bad cell raises with its line (``finite=False``: empty
    cells, NaN and inf become NaN)."""
    if not finite:
        col = tuple(c if c.strip() else "nan" for c in col)
    try:
        arr = np.array(col, dtype=float)
    except ValueError:
        for k, cell in enumerate(col):
            try:
                float(cell)
            except ValueError:
                what = "is empty" if not cell.strip() else f"is not a number: {cell!r}"
                comma = re.fullmatch(r"\s*[-+]?\d*,\d+\s*", cell) is not None
                raise _err(source, int(lines[k]), f"column {name!r} {what}" + (" (a decimal comma)" if comma else ""),
                           "write decimal points (0.5, not 0,5): export the file with a point as the decimal separator"
                           if comma else "every cell of the measurement columns must be a number") from None
        raise  # pragma: no cover - numpy and float() disagree
    if finite:
        bad = np.flatnonzero(~np.isfinite(arr))
        if bad.size:
            k = int(bad[0])
            raise _err(source, int(lines[k]), f"column {name!r} is {col[k].strip()!r}",
                       "NaN/inf are not measurements: drop the row or fill the gap")
    return arr


def _is_number(cell: str) -> bool:
    try:
        float(cell)
    except ValueError:
        return False
    return True


def _check_separator(header: list[str], source: str, line: int) -> None:
    """A header of one cell holding ';' or tabs: a spreadsheet's export (often with decimal commas)."""
    if len(header) != 1:
        return
    for sep, name in ((";", "';'"), ("\t", "tabs")):
        if sep in header[0]:
            raise _err(source, line, f"the columns are separated by {name}, not commas",
                       "save the file as comma-separated values with a decimal point (not a decimal comma)")

@dataclass(frozen=True, eq=False)
class Measurements:
    """A measurement file read leniently (:func:`read_measurements`).

    Attributes
    ----------
    data : Dataset
        The rows kept.
    missing_lines : (k,) int
        File lines dropped because a measurement cell was empty, NaN or infinite.
    backward_lines : (m,) int
        File lines dropped because their time stamp went backwards within the sample.
    source : str
    """

    data: Dataset
    missing_lines: np.ndarray
    backward_lines: np.ndarray
    source: str = "<csv>"

    def summary(self) -> str:
        """One line: how many rows were dropped and why (empty when none)."""
        out = []
        if self.missing_lines.size:
            ln = ", ".join(str(int(v)) for v in self.missing_lines[:3]) + (", ..." if self.missing_lines.size > 3 else "")
            out.append(f"{self.missing_lines.size} row(s) with a missing value (nan/empty) dropped (lines {ln})")
        if self.backward_lines.size:
            ln = ", ".join(str(int(v)) for v in self.backward_lines[:3]) + (", ..." if self.backward_lines.size > 3 else "")
            out.append(f"{self.backward_lines.size} row(s) whose time stamp goes backwards dropped (lines {ln})")
        return f"{self.source}: " + "; ".join(out) if out else ""


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
    return _parse(text, source, strict=True).data


def _parse(text: str, source: str, strict: bool) -> Measurements:
    """Parse ``text``; ``strict=False`` drops rows with a missing measurement or a backward time stamp
    (returned in :class:`Measurements`) instead of refusing them."""
    reader = csv.reader(io.StringIO(text))
    header: list[str] | None = None
    header_line = 0
    rows: list[list[str]] = []
    lines: list[int] = []
    comments = 0  # '#' lines after the header
    separators_only: list[int] = []  # lines of empty cells (',,,,,') after the header
    try:
        for rec in reader:
            ln = reader.line_num
            if header is not None and len(rec) > 1 and not any(c.strip() for c in rec):
                separators_only.append(ln)
                continue
            if (header is not None and rec and rec[0].lstrip().startswith("#") and len(rec) == len(header)
                    and len(rec) > 1 and all(_is_number(c) for c in rec[1:] if c.strip())
                    and sum(_is_number(c) for c in rec[1:]) >= len(rec) - 2):
                # a data row whose sample is named '#...': read as a comment, the whole sample would vanish
                raise _err(source, ln, f"the line starts with '#', so it is a comment, yet it holds a data row (sample "
                                       f"{rec[0].strip()!r}?): every row of that sample would be skipped",
                           "rename the sample so that it does not start with '#', e.g. S" + rec[0].strip().lstrip("#"))
            if not rec or not any(c.strip() for c in rec) or rec[0].lstrip().startswith("#"):
                comments += header is not None and bool(rec) and rec[0].lstrip().startswith("#")
                continue
            if header is not None and [c.strip() for c in rec] == header:
                raise _err(source, ln, f"the line repeats the header (line {header_line}): two files joined?",
                           "delete the repeated header line (and check that the rows below it belong to this record)")
            if header is None:
                header = [c.strip() for c in rec]
                header_line = ln
                _check_separator(header, source, ln)
                continue
            if len(rec) != len(header):
                if len(header) < len(rec) and not any(c in header for c in COLUMNS):
                    # (a title or an export note above the header: it was taken as the header)
                    raise _err(source, header_line, f"the first line ({', '.join(header)[:40]!r}) names none of the "
                               f"columns and has {len(header)} cell(s), line {ln} has {len(rec)}: a title above the "
                               "header?", f"delete the lines above the header, which names {', '.join(COLUMNS)}")
                raise _err(source, ln, f"{len(rec)} cells but the header (line {header_line}) has "
                                       f"{len(header)} columns", "one cell per column on every line")
            rows.append(rec)
            lines.append(ln)
    except csv.Error as exc:
        raise _err(source, reader.line_num, f"not valid CSV ({exc})") from None
    if header is None:
        raise _err(source, None, "no header line: the file is empty",
                   f"the first line must name the columns: {', '.join(COLUMNS)}")
    if len(header) > 1 and sum(map(_is_number, header)) >= len(header) - 1:  # a data row (its sample may be a name)
        raise _err(source, header_line, f"no header line: the first line holds numbers ({', '.join(header[:3])}"
                   f"{', ...' if len(header) > 3 else ''})", f"add a first line naming the columns: {', '.join(COLUMNS)}")
    dup = sorted({c for c in header if header.count(c) > 1})
    if dup:
        raise _err(source, header_line, f"duplicate column(s) {', '.join(dup)}",
                   "keep one column of each name (rename or delete the copy)")
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        hints = []
        # a name in other letter case (SAMPLE, TIME_S: the hint was to convert 'TIME_S' from S to s)
        cased = [(h, c) for c in missing for h in header if h.strip().lower() == c.lower()]
        if cased:
            hints.append("rename " + ", ".join(f"{h!r} -> {c!r}" for h, c in cased) + " (the names are written as "
                         f"{', '.join(COLUMNS)}, letter case included)")
        # the name with its unit written after it ('time_s [s]', 'stroke_mm (mm)'): a rename, not a conversion
        suffixed = [(h, c) for c in missing for h in header if c not in {c for _, c in cased}
                    and re.fullmatch(re.escape(c) + r"\s*[\[(].*[\])]\s*", h.strip(), flags=re.IGNORECASE)]
        if suffixed:
            hints.append("rename " + ", ".join(f"{h!r} -> {c!r}" for h, c in suffixed) + " (the unit is in the name)")
        for c in [c for c in missing if c not in {c for _, c in cased} | {c for _, c in suffixed}]:
            quantity, unit = c.rsplit("_", 1) if "_" in c else (c, "")
            other = [h for h in header if "_" in h and h.rsplit("_", 1)[0].lower() == quantity.lower()
                     and h.rsplit("_", 1)[1] != unit]
            if other and unit:
                # the same quantity in another unit: renaming would silently change the numbers
                hints.append(f"convert {other[0]!r} from {other[0].rsplit('_', 1)[1]} to {unit} and name it {c!r}")
                continue
            m = difflib.get_close_matches(c, header, n=1, cutoff=0.5)
            if m:
                hints.append(f"rename {m[0]!r} -> {c!r}")
        if "sample" in missing and not any("'sample'" in h for h in hints):
            hints.append("name the tube each row was measured on in a column 'sample' (S1 for every row of a file "
                         "of one tube)")
        if "cycle" in missing and not any(h.startswith("rename") and "'cycle'" in h for h in hints):
            hints.append("number each sample's pulls in a column 'cycle' (1, 2, 3, ...), or write the file from the "
                         "instruments' logs with camtube model ingest, which numbers them from the stroke")
        raise _err(source, header_line,
                   f"missing column(s) {', '.join(missing)} (found: {', '.join(header)})",
                   "; ".join(hints) if hints else f"the header must contain {', '.join(COLUMNS)}")
    if not rows and comments:
        raise _err(source, header_line, f"no data rows after the header: all {comments} lines below it start with "
                   "'#' and are read as comments (a sample named '#...'?)",
                   "rename the sample so that it does not start with '#', e.g. S1")
    if not rows:
        raise _err(source, header_line, "no data rows after the header",
                   "add the measurements, one row per sample time, below the header")

    # a line of empty cells among the data is a row whose every measurement is missing (one empty cell is
    # refused, or dropped and counted without strict); after the last row it is a spreadsheet's padding
    among = [k for k in separators_only if k < lines[-1]]
    if among and strict:
        raise _err(source, among[0], "every cell is empty (a line of separators only, among the data rows)",
                   "delete the line, or fill in its measurements")
    ln = np.asarray(lines, dtype=np.int64)
    cols = dict(zip(header, zip(*rows)))
    sample = np.array([s.strip() for s in cols["sample"]], dtype=object)
    empty = np.flatnonzero(sample == "")
    if empty.size:
        raise _err(source, int(ln[empty[0]]), "column 'sample' is empty", "give every row a sample id")
    cyc_f = _to_float(cols["cycle"], "cycle", ln, source)
    bad = np.flatnonzero((cyc_f != np.round(cyc_f)) | (cyc_f < 1) | (cyc_f > MAX_CYCLE))
    if bad.size:
        k = int(bad[0])
        raise _err(source, int(ln[k]), f"column 'cycle' must be a whole number from 1 to 10^9, got "
                   f"{cols['cycle'][k].strip()!r}", "number the cycles 1, 2, 3, ...")
    num = {c: _to_float(cols[c], c, ln, source, finite=strict) for c in _FLOAT_COLS}
    for c, v in num.items():
        with np.errstate(invalid="ignore"):
            huge = np.flatnonzero(np.abs(v) > MAX_VALUE[c])
        if huge.size:
            k = int(huge[0])
            raise _err(source, int(ln[k]), f"column {c!r} holds {cols[c][k].strip()!r}, beyond {MAX_VALUE[c]:g} "
                       f"in magnitude: no bench measures that", f"check the column's unit and export ({c})")
    missing_lines = np.zeros(0, np.int64)
    if not strict:
        bad = ~np.all([np.isfinite(v) for v in num.values()], axis=0)
        if bad.any():
            missing_lines = ln[bad]
            keep = ~bad
            if not keep.any():
                raise _err(source, int(ln[0]), "every row has a missing value (nan/empty)",
                           "check the file: no row holds all of time_s, stroke_mm, force_N, angle_deg")
            sample, ln, cyc_f = sample[keep], ln[keep], cyc_f[keep]
            num = {c: v[keep] for c, v in num.items()}
            cols = {c: tuple(np.asarray(v, dtype=object)[keep]) for c, v in cols.items()}
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
    backward_lines = np.zeros(0, np.int64)
    t = num["time_s"]
    starts = np.flatnonzero(np.concatenate(([True], sample[1:] != sample[:-1])))
    ends = np.concatenate((starts[1:], [t.size]))
    for a, b in zip(starts, ends):
        # a time that starts again with each cycle is not a logger's glitch (dropping the rows behind the first
        # cycle's last stamp kept 770 of 59,949 rows), nor rows to sort: a new cycle stamped no later than the cycle
        # before began (a stamp's jitter at a new cycle goes back by ms only)
        new_cycle = np.flatnonzero(cyc_f[a + 1:b] > cyc_f[a:b - 1]) + a + 1
        began = np.concatenate(([a], new_cycle[:-1]))
        restart = new_cycle[(t[new_cycle] < t[new_cycle - 1]) & (t[new_cycle] <= t[began])]
        if restart.size >= 2:
            k = int(restart[0])
            raise _err(source, int(ln[k]), f"column 'time_s' starts again with each cycle in sample {sample[k]!r} "
                       f"({restart.size} times; here cycle {cyc_f[k]:g} starts at {t[k]:g} s after {t[k - 1]:g})",
                       "give the time since the sample's record began (add each cycle's start time to its rows)")
    if not strict:
        # a stamp below the latest one before it (same sample) is set aside; the rest stays in order
        back = np.zeros(t.size, bool)
        for a, b in zip(starts, ends):
            seg = t[a:b]
            back[a + 1:b] = seg[1:] < np.maximum.accumulate(seg)[:-1]
        if back.sum() > max(BACKWARD_GLITCHES, BACKWARD_SHARE * t.size):
            k = int(np.flatnonzero(back)[0])
            raise _err(source, int(ln[k]), f"{int(back.sum())} of {t.size} rows have a time stamp below one before "
                       f"them in their sample (here {t[k]:g} s in sample {sample[k]!r}): more than a logger's glitches",
                       "sort each sample's rows by time (or check the time_s column)")
        if back.any():
            keep = ~back
            backward_lines = ln[back]
            sample, ln, cyc_f = sample[keep], ln[keep], cyc_f[keep]
            num = {c: v[keep] for c, v in num.items()}
            extra = {c: v[keep] for c, v in extra.items()}
    same = sample[1:] == sample[:-1]
    for name, arr, fix in (("time_s", num["time_s"], "sort each sample's rows by time"),
                           ("cycle", cyc_f, "cycles must not decrease with time within a sample")):
        back = np.flatnonzero(same & (np.diff(arr) < 0))
        if back.size:
            k = int(back[0]) + 1
            raise _err(source, int(ln[k]),
                       f"column {name!r} goes backwards within sample {sample[k]!r}: {arr[k]:g} after "
                       f"{arr[k - 1]:g} (line {int(ln[k - 1])})", fix)
    data = Dataset(sample, cyc_f.astype(np.int64), num["time_s"], num["stroke_mm"], num["force_N"],
                   num["angle_deg"], extra)
    _check_time_resolution(data, ln, source)
    if among:
        missing_lines = np.sort(np.concatenate((missing_lines, np.asarray(among, dtype=np.int64))))
    return Measurements(data, missing_lines, backward_lines, source)


#: A time stamp may repeat the one before it (same sample) on at most this share of a sample's rows: a logger's
#: glitches; more is a time column too coarse for the rate (whole seconds), or not the time (as ingest's logs).
MAX_REPEATED_TIME_SHARE = 0.05


def _check_time_resolution(data: Dataset, ln: np.ndarray, source: str) -> None:
    """Refuse a sample whose time stamps repeat on more than :data:`MAX_REPEATED_TIME_SHARE` of its rows (``ln``: the
    file line of each row)."""
    t = data.time_s
    for smp, sl in data.sample_slices():
        a, b = sl.start, sl.stop
        if b - a < 20:
            continue
        rep = np.flatnonzero(t[a + 1:b] == t[a:b - 1]) + a + 1
        if rep.size == b - a - 1:
            raise _err(source, int(ln[a]), f"column 'time_s' never changes: {t[a]:g} s on every row of sample "
                       f"{smp!r}, not a time", "check the time_s column: the time since the record began, in s")
        if rep.size > MAX_REPEATED_TIME_SHARE * (b - a):
            k = int(rep[0])
            raise _err(source, int(ln[k]), f"column 'time_s' repeats the time before it on {rep.size} of {b - a} rows "
                       f"of sample {smp!r} (here {t[k]:g} s again): a time rounded coarser than the sampling "
                       "(whole seconds?)", "write the time with the resolution of the instruments' clock (ms: "
                       "0.020, 0.040, ...)")


def load_csv(path: str | Path) -> Dataset:
    """Load and validate a measurement CSV file (see :func:`parse_csv`)."""
    return _parse(_read_text(Path(path)), str(path), strict=True).data


def read_measurements(path: str | Path, strict: bool = False) -> Measurements:
    """Load a measurement CSV file, dropping (``strict=False``) or refusing (``strict=True``) rows with a
    missing value (nan, empty) or a time stamp that goes backwards; :meth:`Measurements.summary` says how
    many and which lines.

    Raises
    ------
    DataError
        As :func:`load_csv`; with ``strict``, naming the first such line and the column.
    """
    return _parse(_read_text(Path(path)), str(path), strict=strict)


def _read_text(path: Path) -> str:
    try:
        text = read_input_text(path, "utf-8-sig")
    except FileNotFoundError:
        raise DataError(f"{path}: no such measurement file; fix: check the path of the CSV file") from None
    except IsADirectoryError:
        raise DataError(f"{path}: is a directory, not a measurement file; fix: name the CSV file") from None
    except PermissionError:
        raise DataError(f"{path}: cannot read the measurement file (permission denied); fix: make it readable "
                        f"(chmod u+r) or copy it somewhere you can read") from None
    except OSError as exc:
        raise DataError(f"{path}: cannot read the measurement file ({exc.strerror or exc}); fix: give a readable "
                        "CSV file") from None
    except UnicodeDecodeError as exc:
        raise DataError(f"{path}: not a UTF-8 text file ({exc.reason} at byte {exc.start}); fix: give the "
                        "measurement CSV (save it as UTF-8 text)") from None
    if "\x00" in text:  # a logger's unfinished write (NUL padding) or a binary file: the cells would be garbage
        line = text[:text.index("\x00")].count("\n") + 1
        raise DataError(f"{path}:{line}: not a text file: it holds NUL bytes; fix: give the measurement CSV as "
                        "exported (cut the damaged lines if the logger stopped mid-write)")
    return text


#: Fewest rows a fit or a diagnosis takes: fewer say nothing about the joint (two rows of one loading ramp fitted E_t on
#: its bound at 20 deg RMSE, or "near" it, as if it were a result).
MIN_FIT_ROWS = 10


def check_row_count(n_rows: int, what: str = "the selected rows") -> None:
    """Refuse fewer than :data:`MIN_FIT_ROWS` rows (:class:`DataError` naming ``what``)."""
    if n_rows < MIN_FIT_ROWS:
        raise DataError(f"{what}: {n_rows} row{'' if n_rows == 1 else 's'}, too few to fit the joint model "
                        f"(at least {MIN_FIT_ROWS}); fix: give the whole record (check the file and the --cycles "
                        "selection)")


def check_fittable(data: Dataset, what: str = "the selected rows", min_rows: int = MIN_FIT_ROWS) -> None:
    """Refuse rows the joint model cannot be fitted to: fewer than ``min_rows`` (:func:`check_row_count`; 0: not
    checked here), a stroke or an angle that never changes.

    Raises
    ------
    DataError
        Naming the column, its value range and the fix.
    """
    if min_rows or len(data) < 2:   # (one row "never changes": it is too few)
        check_row_count(len(data), what)
    for col, unit in (("stroke_mm", "mm"), ("angle_deg", "deg")):
        v = np.asarray(getattr(data, col), float)
        if v.size and float(np.ptp(v)) <= 1e-12 * max(1.0, float(np.max(np.abs(v)))):
            raise DataError(f"{what}: column {col!r} never changes (every value is {float(v[0]):g} {unit}): "
                            "the model's parameters cannot be identified; fix: give rows where the joint "
                            "is actuated (check the file and the --cycles selection)")


def check_sample_rows(data: Dataset, source: str) -> None:
    """Refuse a sample (of two or more) with fewer than :data:`MIN_FIT_ROWS` rows selected: it was fitted with an RMSE
    of its own, pulling on E_t, and its slack printed as a measured 0.000 mm (a sample cut short to 3 rows, or one
    whose rows were set aside). One sample: :func:`check_fittable`'s row count names it.

    Raises
    ------
    DataError
        Naming ``source``, the sample, its rows and the fix.
    """
    slices = data.sample_slices()
    for smp, sl in slices if len(slices) > 1 else ():
        n = sl.stop - sl.start
        if n < MIN_FIT_ROWS:
            raise DataError(f"{source}: sample {smp!r} has {n} row(s) selected, too few to fit (at least "
                            f"{MIN_FIT_ROWS}); fix: give that sample's whole record (--cycles all --branch both), or "
                            "leave its rows out of the file")


#: A column whose correlation with the tendon's tension is below this (in a sample) runs the opposite way to the
#: model's convention (on the bench records every sample's stroke and angle correlate with the force by 0.74 or more).
SIGN_CORRELATION = -0.3


def _corr(v: np.ndarray, w: np.ndarray) -> float:
    """Pearson's correlation of ``v`` and ``w``; nan where ``v`` is constant or the readings are so small that their
    spread underflows (no evidence either way)."""
    if not np.ptp(v) > 0:
        return math.nan
    with np.errstate(all="ignore"):
        return float(np.corrcoef(v, w)[0, 1])


def reversed_columns(data: Dataset) -> dict[str, list[tuple[str, float]]]:
    """The columns that run the opposite way to the model's convention, per column: ``[(sample, evidence), ...]``.

    The model takes the stroke as the tendon drawn in (rising as the joint bends), the force as its tension (positive)
    and the angle as the bend (positive). A load cell that reads tension negative shows its largest readings below
    zero, and the stroke or the angle falls as they grow (``evidence``: its most negative reading over its most
    positive); a stroke or an angle that runs the other way falls as that tension rises (``evidence``: their
    correlation with it, below :data:`SIGN_CORRELATION`)."""
    out: dict[str, list[tuple[str, float]]] = {}
    for smp, sl in data.sample_slices():
        s, f, a = (np.asarray(getattr(data, c)[sl], float) for c in ("stroke_mm", "force_N", "angle_deg"))
        ok = np.isfinite(s) & np.isfinite(f) & np.isfinite(a)
        s, f, a = s[ok], f[ok], a[ok]
        if s.size < 20 or not np.ptp(f) > 0:
            continue
        lo, hi = float(np.min(f)), float(np.max(f))
        r_s, r_a = _corr(s, f), _corr(a, f)
        # a load cell that reads tension negative: its largest readings below zero, and the stroke or the angle falls
        # as they grow (a zero far off alone does not turn the correlations); against the tension, theirs turn
        if -lo > 2.0 * max(hi, 0.0) and min(r_s, r_a) < SIGN_CORRELATION:
            out.setdefault("force_N", []).append((str(smp), lo / hi if hi > 0 else -math.inf))
            r_s, r_a = -r_s, -r_a
        for col, r in (("stroke_mm", r_s), ("angle_deg", r_a)):
            if r < SIGN_CORRELATION:
                out.setdefault(col, []).append((str(smp), r))
    return out


def check_signs(data: Dataset, what: str) -> None:
    """Refuse rows whose stroke, force or angle runs the opposite way to the model's convention
    (:func:`reversed_columns`), naming each column, its samples and the evidence; the fix is to negate it.

    Raises
    ------
    DataError
    """
    bad = reversed_columns(data)
    if not bad:
        return
    parts = []
    for col, hits in bad.items():
        smp = ", ".join(s for s, _ in hits)
        if col == "force_N":
            parts.append(f"column 'force_N' reads the tension below zero in {smp} (its most negative reading is "
                         f"{-hits[0][1]:.3g} x its most positive)" if math.isfinite(hits[0][1]) else
                         f"column 'force_N' reads the tension below zero in {smp} (never above zero)")
        else:
            parts.append(f"column {col!r} falls as the tension rises in {smp} (correlation {hits[0][1]:+.2f})")
    cols = " and ".join(bad)
    raise DataError(f"{what}: {'; '.join(parts)}: the model takes the stroke as the tendon drawn in, the force as "
                    f"its tension and the angle as the bend, each rising as the joint bends; fix: negate {cols} "
                    "(multiply the column by -1)")


def far_zeros(data: Dataset) -> dict[str, list[tuple[str, float, float]]]:
    """The columns whose zero is not the model's, per column: ``[(sample, value at rest, span), ...]``.

    The model takes the stroke and the angle from the straight, unloaded joint: 0 at rest. A motor that logs its
    absolute position (100.0 to 102.5 mm), or a tracker whose straight joint reads 90 deg, is off by more than the
    record's own span: the stroke's lowest value beyond its span from 0, or the angle at the lowest stroke (the
    median over the rows within 1 % of the stroke's span of it) beyond the angle's span (1st to 99th percentile: a
    spike does not widen it). A joint resting a little bent (a permanent set) is well within. So is the force: a load
    cell not zeroed before the test (every reading below zero, or 100 N at rest) reads at the lowest stroke beyond its
    own span; a cell whose zero drifts a little is well within (the instruments' check re-zeroes it)."""
    out: dict[str, list[tuple[str, float, float]]] = {}
    for smp, sl in data.sample_slices():
        s, f, a = (np.asarray(getattr(data, c)[sl], float) for c in ("stroke_mm", "force_N", "angle_deg"))
        ok = np.isfinite(s) & np.isfinite(a)
        s, f, a = s[ok], f[ok], a[ok]
        if s.size < 20 or not np.ptp(s) > 0:
            continue
        lo, span = float(np.min(s)), float(np.ptp(s))
        if abs(lo) > span:
            out.setdefault("stroke_mm", []).append((str(smp), lo, span))
            continue
        at_rest = s <= lo + 0.01 * span
        for col, v in (("angle_deg", a), ("force_N", f)):
            fine = np.isfinite(v)
            if not (fine & at_rest).any():
                continue
            rest = float(np.median(v[fine & at_rest]))
            v_span = float(np.percentile(v[fine], 99) - np.percentile(v[fine], 1))
            if v_span > 0 and abs(rest) > v_span:
                out.setdefault(col, []).append((str(smp), rest, v_span))
    return out


def check_zeros(data: Dataset, what: str, force_hint: str = "") -> None:
    """Refuse rows whose stroke or angle is not taken from the straight, unloaded joint (:func:`far_zeros`), naming
    the column, each sample's value at rest and the fix (subtract it).

    Raises
    ------
    DataError
    """
    bad = far_zeros(data)
    if not bad:
        return
    parts = []
    for col, hits in bad.items():
        unit = {"stroke_mm": "mm", "angle_deg": "deg", "force_N": "N"}[col]
        at = ", ".join(f"{v:.4g} {unit} in {smp}" for smp, v, _ in hits)
        parts.append(f"column {col!r} reads {at} with the joint at rest, beyond the {hits[0][2]:.3g} {unit} it spans")
    cols = " and ".join(bad)
    cell = "force_N" in bad
    raise DataError(f"{what}: {'; '.join(parts)}: the model takes the stroke{', the angle and the force' if cell else ' and the angle'} "
                    f"from the straight, unloaded joint (0 at rest{': the load cell zeroed before the test' if cell else ''}); "
                    f"fix: subtract each sample's value at rest from {cols}" + (force_hint if cell else ""))


def check_time_varies(data: Dataset, what: str) -> None:
    """Refuse a file whose ``time_s`` column holds one stamp only (``model diagnose`` sets such rows aside).

    Raises
    ------
    DataError
        Naming ``what`` (the file), the column and its value.
    """
    t = np.asarray(data.time_s, float)
    if t.size > 1 and float(np.ptp(t)) == 0.0:
        raise DataError(f"{what}: column 'time_s' never changes (every value is {float(t[0]):g} s): the rows have "
                        "no order in time; fix: check the time_s column (it must count the seconds of the log)")


def check_force_identifies(data: Dataset, what: str, fitted) -> None:
    """Refuse fitting ``E_t`` to rows whose force is zero throughout (E_t acts only through the force).

    Raises
    ------
    DataError
        Naming ``what`` (the file), the column and the fix.
    """
    f = np.asarray(data.force_N, float)
    if "E_t" in fitted and f.size and not np.any(f):
        raise DataError(f"{what}: these rows cannot identify E_t: column 'force_N' is 0 N in every row (E_t acts "
                        "only through the force); fix: hold it (--fix E_t=VALUE), or give rows with the measured "
                        "force")


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
