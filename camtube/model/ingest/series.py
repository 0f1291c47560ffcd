"""Generic time-series logs (the load cell's DAQ, the motor's controller) and the bench map that says how
to read them.

A log is a CSV with a header line; lines starting with ``#`` and blank lines are skipped. The bench map
names, per instrument, the time column and its unit, the value column and its calibration, and an
optional trigger column shared with another instrument::

    tracker:  {tip: "0B", base: "0A", unit: mm, rest_s: 1.0}
    daq:      {time: t_ms, time_unit: ms, force: load_V, force_unit: V, N_per_V: 2.2, offset_V: rest, trigger: sync}
    motor:    {time: t_us, time_unit: us, stroke: counts, stroke_unit: counts, counts_per_rev: 512,
               gear_ratio: 64, lead_mm_per_rev: 0.5, sign: 1, trigger: sync}
    angle:    {time: t, time_unit: s, angle: theta, unit: rad}     # only for --angle-log (no tracker)

:func:`load_bench_map` reads such a YAML file; ``--map KEY=VALUE`` pairs (``daq.N_per_V=2.2``) override it.
Unknown keys are errors with a "did you mean" hint.
"""
from __future__ import annotations

import difflib
from dataclasses import dataclass, field, fields, replace
from pathlib import Path

import numpy as np

from camtube.errors import DataError
from camtube.model.ingest.table import read_table

#: Seconds per unit of a time column.
TIME_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "min": 60.0}


@dataclass(frozen=True)
class TrackerMap:
    """How to read the tracker export.

    Attributes
    ----------
    tip : str
        The tool on the joint's tip: port handle (``0B``) or a part of its label.
    base : str
        The tool on the joint's base; ``""`` for one sensor (the bend is then taken against the first frames).
    unit : str
        Unit of the positions in the export: ``mm`` (NDI's default) or ``m``.
    rate_hz : float
        Frame rate, only needed when the export has no time column (0: not given).
    rest_s : float
        Length of the rest at the start of the recording that defines zero bend, s.
    """

    tip: str = ""
    base: str = ""
    unit: str = "mm"
    rate_hz: float = 0.0
    rest_s: float = 1.0


@dataclass(frozen=True)
class DaqMap:
    """How to read the load cell's DAQ log.

    Attributes
    ----------
    time, time_unit : str
        Time column and its unit (s, ms, us, ns, min).
    force : str
        The force column.
    force_unit : str
        ``V`` (converted with ``N_per_V``) or ``N``.
    N_per_V : float
        Load cell calibration, N per V (negative for a load cell that reads tension as a falling voltage).
    offset_V : float or "rest"
        Output at zero force (V, or N for ``force_unit: N``); ``rest``: the median over the first ``rest_s``.
    trigger : str
        A trigger column shared with the motor log (``""``: none).
    """

    time: str = "time_s"
    time_unit: str = "s"
    force: str = "force_N"
    force_unit: str = "N"
    N_per_V: float = 1.0
    offset_V: float | str = 0.0
    trigger: str = ""


@dataclass(frozen=True)
class MotorMap:
    """How to read the motor's log.

    Attributes
    ----------
    time, time_unit : str
        Time column and its unit.
    stroke : str
        The position column.
    stroke_unit : str
        ``counts`` (encoder counts on the motor shaft), ``rev`` (motor revolutions) or ``mm`` (stroke).
    counts_per_rev : float
        Encoder counts per motor revolution (after quadrature).
    gear_ratio : float
        Motor revolutions per lead-screw revolution (the paper's gearbox: 64).
    lead_mm_per_rev : float
        Lead of the screw, mm per revolution.
    sign : int
        +1, or -1 when the position counts down as the tendon is pulled.
    trigger : str
        A trigger column shared with the DAQ log (``""``: none).
    """

    time: str = "time_s"
    time_unit: str = "s"
    stroke: str = "stroke_mm"
    stroke_unit: str = "mm"
    counts_per_rev: float = 1.0
    gear_ratio: float = 1.0
    lead_mm_per_rev: float = 1.0
    sign: int = 1
    trigger: str = ""

    @property
    def mm_per_unit(self) -> float:
        """Stroke (mm) per unit of the position column, sign included."""
        per = {"mm": 1.0, "rev": self.lead_mm_per_rev / self.gear_ratio,
               "counts": self.lead_mm_per_rev / (self.gear_ratio * self.counts_per_rev)}[self.stroke_unit]
        return self.sign * per


@dataclass(frozen=True)
class AngleMap:
    """How to read a log of the joint angle itself (instead of a tracker export).

    Attributes
    ----------
    time, time_unit : str
        Time column and its unit.
    angle : str
        The angle column.
    unit : str
        ``deg`` or ``rad``; left empty, the angle is read in deg and refused if it looks like radians.
    """

    time: str = "time_s"
    time_unit: str = "s"
    angle: str = "angle_deg"
    unit: str = ""


@dataclass(frozen=True)
class BenchMap:
    """The instruments' maps (see the module docstring)."""

    tracker: TrackerMap = field(default_factory=TrackerMap)
    daq: DaqMap = field(default_factory=DaqMap)
    motor: MotorMap = field(default_factory=MotorMap)
    angle: AngleMap = field(default_factory=AngleMap)


_ALLOWED = {
    ("tracker", "unit"): ("mm", "m"),
    ("daq", "time_unit"): tuple(TIME_UNITS), ("motor", "time_unit"): tuple(TIME_UNITS),
    ("angle", "time_unit"): tuple(TIME_UNITS), ("angle", "unit"): ("", "deg", "rad"),
    ("daq", "force_unit"): ("V", "N"), ("motor", "stroke_unit"): ("counts", "rev", "mm"),
}
#: Longest rest at the start of a recording a bench map may give (``tracker.rest_s``), s.
MAX_REST_S = 600.0
_POSITIVE = {("motor", "counts_per_rev"), ("motor", "gear_ratio"), ("motor", "lead_mm_per_rev")}


def _map_err(source: str, key: str, msg: str, fix: str) -> DataError:
    return DataError(f"{source}: {key}: {msg}; fix: {fix}")


def _coerce(section: str, name: str, value, default, source: str):
    key = f"{section}.{name}"
    if name == "offset_V" and isinstance(value, str) and value.strip().lower() == "rest":
        return "rest"
    if isinstance(default, bool) or isinstance(default, int) and name == "sign":
        try:
            v = int(float(value))
        except (TypeError, ValueError):
            raise _map_err(source, key, f"{value!r} is not a number", "sign: 1 or -1") from None
        if v not in (1, -1):
            raise _map_err(source, key, f"{value!r} is not allowed", "sign: 1 or -1")
        return v
    if isinstance(default, float):
        try:
            v = float(value)
        except (TypeError, ValueError):
            raise _map_err(source, key, f"{value!r} is not a number", f"give a number (default {default:g})") from None
        if (not np.isfinite(v) or ((section, name) in _POSITIVE and v <= 0) or (v < 0 and name == "rate_hz")
                or (v < 0 and name == "rest_s")
                or (name == "N_per_V" and v == 0)):
            raise _map_err(source, key, f"{value!r} is out of range", "give a positive number")
        if (section, name) == ("motor", "counts_per_rev") and (v < 1 or v != round(v)):
            raise _map_err(source, key, f"{value!r} is not a count: an encoder gives a whole number of counts per "
                           "revolution", "give the encoder's counts per revolution from its data sheet, e.g. 512")
        if name == "rest_s" and v <= 0:   # (0 took the first frame alone as the rest: its noise in every angle)
            raise _map_err(source, key, f"{value!r} is out of range: the rest before the first pull takes some time",
                           f"give it in s (e.g. {default:g})")
        if name == "rest_s" and v > MAX_REST_S:   # (1e9 read the whole record as the rest: zero bend, zero force)
            raise _map_err(source, key, f"{value!r} is out of range: a rest of more than {MAX_REST_S:g} s at the "
                           "start of the recording", f"give the rest before the first pull, in s (e.g. {default:g})")
        return v
    v = "" if value is None else str(value).strip()
    allowed = _ALLOWED.get((section, name))
    if allowed and v not in allowed:
        raise _map_err(source, key, f"{v!r} is not allowed", f"one of {', '.join(allowed)}")
    return v


def bench_map_from_dict(doc: dict, source: str = "<bench map>", overrides: list[str] = ()) -> BenchMap:
    """A :class:`BenchMap` from a nested mapping plus ``KEY=VALUE`` overrides (``daq.N_per_V=2.2``).

    Raises
    ------
    DataError
        An unknown section or key (with a "did you mean"), a value of the wrong type or out of range.
    """
    if doc is not None and not isinstance(doc, dict):
        raise DataError(f"{source}: the bench map must be a mapping of tracker/daq/motor; fix: see docs/bench.md")
    doc = dict(doc or {})
    for sec, body in doc.items():
        if not hasattr(BenchMap(), str(sec)):
            hint = difflib.get_close_matches(str(sec), ["tracker", "daq", "motor", "angle"], n=1)
            raise _map_err(source, sec, "unknown section", f"did you mean {hint[0]!r}?" if hint
                           else "use tracker, daq, motor and angle")
        if body is not None and not isinstance(body, dict):
            raise _map_err(source, sec, f"expected a mapping of keys, got {body!r}",
                           f"write '{sec}: {{key: value, ...}}' (see docs/bench.md)")
        doc[sec] = dict(body or {})
    for item in overrides:
        if "=" not in item:
            raise DataError(f"--map {item!r}: expected KEY=VALUE; fix: e.g. --map daq.N_per_V=2.2")
        k, v = item.split("=", 1)
        parts = k.strip().split(".")
        if len(parts) != 2:
            raise DataError(f"--map {item!r}: the key must be SECTION.NAME; fix: e.g. --map motor.gear_ratio=64 "
                            "(sections: tracker, daq, motor, angle)")
        given = [o for o in overrides if "=" in o and o.split("=", 1)[0].strip() == k.strip()]
        if len(given) > 1:
            # (the last one won without a word: a gear ratio of 64 then 32 halved the stroke, E_t read 12 GPa)
            raise DataError(f"--map {k.strip()} is given {len(given)} times ("
                            + ", ".join(repr(o.split('=', 1)[1].strip()) for o in given) + "); fix: give it once")
        doc.setdefault(parts[0], {})[parts[1]] = v
    base = BenchMap()
    sections = {}
    for sec, body in doc.items():
        if not hasattr(base, sec):
            hint = difflib.get_close_matches(sec, ["tracker", "daq", "motor", "angle"], n=1)
            raise _map_err(source, sec, "unknown section", f"did you mean {hint[0]!r}?" if hint
                           else "use tracker, daq, motor and angle")
        default = getattr(base, sec)
        names = {f.name: getattr(default, f.name) for f in fields(default)}
        vals = {}
        for name, value in body.items():
            if name not in names:
                hint = (difflib.get_close_matches(name, list(names), n=1, cutoff=0.5)
                        or [k for k in names if k.startswith(name) or name.startswith(k)])
                raise _map_err(source, f"{sec}.{name}", "unknown key",
                               f"did you mean {hint[0]!r}?" if hint else f"known keys: {', '.join(names)}")
            vals[name] = _coerce(sec, name, value, names[name], source)
        sections[sec] = replace(default, **vals)
    out = replace(base, **sections)
    # keys that would be read without a word and then not used
    if bool(out.daq.trigger) != bool(out.motor.trigger):
        given, other = ("daq", "motor") if out.daq.trigger else ("motor", "daq")
        raise _map_err(source, f"{given}.trigger", f"{getattr(out, given).trigger!r} is given, but {other}.trigger is "
                       "not: a trigger aligns the two logs by a column both hold (the clocks were aligned by the "
                       "motion instead, and the trigger ignored)",
                       f"name the trigger column of the {other} log too ({other}.trigger: ...), or drop {given}.trigger")
    if out.daq.force_unit == "N" and "N_per_V" in (doc.get("daq") or {}):
        raise _map_err(source, "daq.N_per_V", f"{doc['daq']['N_per_V']!r} is given, but daq.force_unit is N: the "
                       "column holds newtons and the calibration is not used",
                       "drop daq.N_per_V, or set daq.force_unit: V if the column holds volts")
    return out


def load_bench_map(path: str | Path | None, overrides: list[str] = ()) -> BenchMap:
    """Read a bench map YAML (``None``: defaults) and apply ``--map`` overrides."""
    doc: dict = {}
    source = "--map"
    if path is not None:
        import yaml

        from camtube.model.ingest.ndi import read_text
        from camtube.yamltext import parse_yaml

        source = str(path)
        try:
            doc = parse_yaml(read_text(path, "bench map")) or {}
        except yaml.YAMLError as exc:
            mark = getattr(exc, "problem_mark", None)
            where = f"{path}:{mark.line + 1}" if mark else str(path)
            raise DataError(f"{where}: not valid YAML ({getattr(exc, 'problem', exc)}); fix: correct the bench map "
                            "there (a mapping of tracker/daq/motor keys, see docs/bench.md)") from None
    return bench_map_from_dict(doc, source, list(overrides))


@dataclass(frozen=True, eq=False)
class Series:
    """One column of a log over time, its own clock.

    Attributes
    ----------
    source : str
        File name.
    column : str
        The value column's name.
    time_s : (n,) float
        The instrument's clock, s, strictly increasing.
    value : (n,) float
        The column as read (not yet calibrated).
    trigger : (n,) float or None
        The trigger column, if mapped.
    lines : (n,) int
        File line of each sample.
    repeated : (k,) int
        File lines set aside because their time stamp repeats the line's before (the first at each stamp is kept).
    """

    source: str
    column: str
    time_s: np.ndarray
    value: np.ndarray
    trigger: np.ndarray | None
    lines: np.ndarray
    repeated: np.ndarray = field(default_factory=lambda: np.zeros(0, np.int64))

    def with_value(self, value: np.ndarray) -> "Series":
        """The same samples with another value column (e.g. calibrated)."""
        return replace(self, value=np.asarray(value, float))


#: Most lines of a log whose time stamp may repeat the one before (set aside); more is refused.
MAX_REPEATED_SHARE = 0.05


def parse_series(text: str, source: str, time: str, time_unit: str, value: str, trigger: str = "",
                 role: str = "log") -> Series:
    """Read the time, value and trigger columns of a CSV log.

    Raises
    ------
    DataError
        A missing column (with a "did you mean" and the map key to change), a non-numeric or empty cell
        (file, line and column), a time that goes back, or that repeats on more than 5 % of the lines (a repeat
        on fewer is set aside: :attr:`Series.repeated`).
    """
    table = read_table(text, source, comments=True)
    log = role if role == "log" else f"{role} log"
    if table is None:
        raise DataError(f"{source}: the file is empty; fix: give the {log} as exported (a header line naming the "
                        "columns, then one line per sample time)")
    header, hline, rows, lines = table.header, table.header_line, table.rows, table.lines
    if len(header) == 1 and (";" in header[0] or "\t" in header[0]):
        raise DataError(f"{source}:{hline}: the columns are not separated by commas; fix: save the log as "
                        "comma-separated values with a decimal point")
    wanted = [("time", time), ("value", value)] + ([("trigger", trigger)] if trigger else [])
    twice = [col for _, col in wanted if header.count(col) > 1]
    if twice:
        # (the first of two same-named columns was read without a word; the measurement reader refuses them)
        raise DataError(f"{source}:{hline}: the header names column {twice[0]!r} {header.count(twice[0])} times; fix: "
                        "keep one column of each name (rename or delete the copy)")
    idx = {}
    for what, col in wanted:
        if col not in header:
            key = {"time": f"{role}.time", "value": f"{role}.{ {'daq': 'force', 'angle': 'angle'}.get(role, 'stroke')}",
                   "trigger": f"{role}.trigger"}[what]
            hint = difflib.get_close_matches(col, header, n=1, cutoff=0.4)
            fix = f"set {key}: {hint[0]} in the bench map" if hint else f"set {key} to one of: {', '.join(header)}"
            raise DataError(f"{source}:{hline}: no column {col!r} for the {what} (found: {', '.join(header)}); fix: {fix}")
        idx[what] = header.index(col)
    if not rows:
        raise DataError(f"{source}:{hline}: no data lines after the header; fix: give the whole {log} (was the "
                        "recording stopped before it started, or the export cut short?)")
    ln = np.asarray(lines, dtype=np.int64)
    out = {}
    for what, j in idx.items():
        col = np.empty(len(rows))
        for k, r in enumerate(rows):
            cell = r[j].strip() if j < len(r) else ""
            try:
                col[k] = float(cell)
            except ValueError:
                bad = "is empty" if not cell else f"is not a number: {cell!r}"
                raise DataError(f"{source}:{lines[k]}: column {header[j]!r} {bad}; fix: every cell of the "
                                "time, value and trigger columns must be a number") from None
            if not np.isfinite(col[k]):
                raise DataError(f"{source}:{lines[k]}: column {header[j]!r} is {cell!r}; fix: drop the line "
                                "(a gap is found from the time stamps)")
        out[what] = col
    t = out["time"] * TIME_UNITS[time_unit]
    step = np.diff(t)
    back = np.flatnonzero(step < 0)
    if back.size:
        k = int(back[0]) + 1
        raise DataError(f"{source}:{lines[k]}: column {time!r} does not increase ({out['time'][k]:g} after "
                        f"{out['time'][k - 1]:g} on line {lines[k - 1]}); fix: one recording per file, in time order")
    # a stamp that repeats the one before (a logger writing a line twice, a clock coarser than the sampling now and
    # then): the later lines set aside and counted, the first kept; a clock that repeats often is refused (the wrong
    # column or unit, or a clock too coarse to align the logs by)
    same = np.flatnonzero(step == 0) + 1
    if same.size > MAX_REPEATED_SHARE * len(t):
        k = int(same[0])
        raise DataError(f"{source}:{lines[k]}: column {time!r} repeats its time stamp on {same.size} of {len(t)} "
                        f"lines ({out['time'][k]:g} again; at most {100 * MAX_REPEATED_SHARE:g} % are set aside); fix: "
                        f"map the {log}'s time column with its finest resolution (is it the right column and unit?)")
    keep = np.ones(len(t), bool)
    keep[same] = False
    return Series(source, value, t[keep], out["value"][keep],
                  out["trigger"][keep] if "trigger" in out else None, ln[keep], ln[same])


def load_series(path: str | Path, time: str, time_unit: str, value: str, trigger: str = "",
                role: str = "log") -> Series:
    """Read a CSV log (see :func:`parse_series`)."""
    from camtube.model.ingest.ndi import read_text

    return parse_series(read_text(path, f"{role} log"), str(path), time, time_unit, value, trigger, role)


def force_N(series: Series, m: DaqMap, rest_s: float) -> np.ndarray:
    """(n,) force, N, from the DAQ column: ``(value - offset) * N_per_V`` (or ``value - offset`` in N)."""
    v = series.value
    if m.offset_V == "rest":
        at_rest = series.time_s <= series.time_s[0] + max(rest_s, 0.0)
        off = float(np.median(v[at_rest])) if at_rest.any() else float(v[0])
    else:
        off = float(m.offset_V)
    return (v - off) * (m.N_per_V if m.force_unit == "V" else 1.0)


def stroke_mm(series: Series, m: MotorMap) -> np.ndarray:
    """(n,) stroke, mm, from the motor's position column, zero at the first sample."""
    return (series.value - series.value[0]) * m.mm_per_unit
