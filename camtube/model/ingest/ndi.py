"""Read the tool-tracking CSV that NDI's tracking software (NDI Track / ToolBox) exports for an
Aurora (electromagnetic) or Polaris (optical) tracker.

The layout, one line per frame::

    Tools,Port 0x0A: 610029  s/n:3B1F0A01,Frame,Time [sec],Face,State,Q0,Qx,Qy,Qz,Tx,Ty,Tz,Error,Port 0x0B: ...
    2,Port 0x0A: 610029  s/n:3B1F0A01,18230,1778067471.318767,1,OK,0.707,0.0,0.707,0.0,12.5,-3.1,-150.2,0.12,...

* ``Tools``: the number of tool groups on the line;
* per tool a group of columns that starts with the tool's label (``Port <handle>: <tool id>  s/n:<serial>``,
  repeated in every data line), then ``Frame``, ``Time [sec]`` (not in every version), ``Face``,
  ``State`` (``OK``, ``Missing``, ``Out of Volume``, ``Partially Out of Volume``, ``Disabled``,
  ``Too Few Markers``, ...), the orientation quaternion ``Q0`` (scalar) ``Qx Qy Qz``, the position
  ``Tx Ty Tz`` (mm) and ``Error`` (the fit's RMS error, mm);
* optical (Polaris) tools add ``Markers`` and per marker ``State, Tx, Ty, Tz``; they are skipped here.

A pose that could not be measured is written with NDI's "bad float" ``-3.697314E28`` or left empty; such
cells are read as NaN. A frame counts as valid only with state ``OK`` and a finite, unit-length quaternion.
Header names are matched without case and with the variants other NDI writers use (``Frame#``,
``TransformStatus``, ``Face#``, ``RMS``). Every problem raises :class:`~camtube.errors.DataError` naming
the file, line and column.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from camtube.errors import DataError
from camtube.inputfile import read_input_text
from camtube.model.ingest.table import read_table

#: NDI's marker for a value that could not be measured; anything below ``-3e28`` is treated as missing.
BAD_FLOAT_LIMIT = -3.0e28

#: Field names of one tool group, after normalisation (lower case, no spaces/``#``), to the canonical name.
_FIELDS = {
    "frame": "frame", "frame#": "frame", "framenumber": "frame",
    "time[sec]": "time", "time[s]": "time", "time": "time", "timestamp": "time",
    "face": "face", "face#": "face",
    "state": "state", "transformstatus": "state", "status": "state",
    "q0": "q0", "qx": "qx", "qy": "qy", "qz": "qz",
    "tx": "tx", "ty": "ty", "tz": "tz",
    "error": "error", "rms": "error", "rmserror": "error",
    "markers": "markers", "#markers": "markers",
}
_POSE = ("q0", "qx", "qy", "qz", "tx", "ty", "tz")
_LABEL = re.compile(r"^\s*port\s*(?:handle)?\s*[:#]?\s*(?P<port>(0x)?[0-9a-f]+)?\s*(?::\s*(?P<rest>.*))?$", re.I)


def _err(source: str, line: int | None, msg: str, fix: str = "") -> DataError:
    where = f"{source}:{line}" if line is not None else source
    return DataError(f"{where}: {msg}" + (f"; fix: {fix}" if fix else ""))


@dataclass(frozen=True, eq=False)
class ToolTrack:
    """The frames of one tracked tool (sensor coil).

    Attributes
    ----------
    label : str
        The tool's label as written (``Port 0x0A: 610029  s/n:3B1F0A01``).
    port : str
        Port handle, upper-case hex without ``0x`` (``"0A"``), or ``""`` if the label has none.
    name : str
        The rest of the label (tool id and serial number).
    frame : (n,) int
        Tracker frame number.
    time_s : (n,) float
        Frame time, tracker clock, s (NaN where the export has no time column).
    state : (n,) str (object array)
        Tracking state as written (``OK``, ``Missing``, ``Out of Volume``, ...).
    quat_wxyz : (n, 4) float
        Orientation quaternion, scalar first (NDI's ``Q0 Qx Qy Qz``); NaN where not measured.
    position_mm : (n, 3) float
        Position ``Tx Ty Tz`` in the tracker's frame, mm (converted if the export is in m); NaN where not measured.
    error_mm : (n,) float
        The tracker's RMS fit error, mm (NaN if absent).
    """

    label: str
    port: str
    name: str
    frame: np.ndarray
    time_s: np.ndarray
    state: np.ndarray
    quat_wxyz: np.ndarray
    position_mm: np.ndarray
    error_mm: np.ndarray

    @property
    def state_ok(self) -> np.ndarray:
        """(n,) bool: the tracker's state is ``OK``."""
        return np.array([str(s).strip().lower() == "ok" for s in self.state], dtype=bool)

    @property
    def valid(self) -> np.ndarray:
        """(n,) bool: state ``OK`` and a finite quaternion of length 1 (+- 1 %)."""
        ok = self.state_ok
        q = self.quat_wxyz
        with np.errstate(invalid="ignore"):
            norm = np.sqrt(np.sum(q * q, axis=1))
            return ok & np.isfinite(norm) & (np.abs(norm - 1.0) < 0.01)

    def port_is(self, key: str) -> bool:
        """True if ``key`` is this tool's port handle (``0A``, ``0x0A``, or decimal ``10``)."""
        k = key.strip()
        if not self.port:
            return False
        try:
            return int(k, 16 if k.lower().startswith("0x") or re.search("[a-f]", k, re.I) else 10) == int(self.port, 16)
        except ValueError:
            return False

    def matches(self, key: str) -> bool:
        """True if ``key`` names this tool: its port handle or a part of its label."""
        k = key.strip()
        return self.port_is(k) or (bool(k) and k.lower() in self.label.lower())


@dataclass(frozen=True, eq=False)
class TrackerLog:
    """All tools of one NDI export.

    Attributes
    ----------
    source : str
        File name (for messages).
    tools : tuple of ToolTrack
        In the order of the file's column groups; every tool has the same ``n`` frames (lines).
    lines : (n,) int
        The file line of each frame (for messages).
    """

    source: str
    tools: tuple
    lines: np.ndarray

    def tool(self, key: str, role: str = "tool") -> ToolTrack:
        """The tool named by ``key`` (port or part of the label).

        Raises
        ------
        DataError
            No tool or more than one matches; the message lists the tools.
        """
        hits = [t for t in self.tools if t.port_is(key)] or [t for t in self.tools if t.matches(key)]
        listing = "; ".join(t.label for t in self.tools)
        if not hits:
            raise _err(self.source, None, f"no tool {key!r} for the {role} (tools: {listing})",
                       "name the tool by its port (e.g. 0A) or a part of its label")
        if len(hits) > 1:
            raise _err(self.source, None, f"{key!r} names {len(hits)} tools for the {role} ({listing})",
                       "name the tool by its port handle or its full serial number")
        return hits[0]


def _norm(name: str) -> str:
    return re.sub(r"\s+", "", name.strip().lower())


def _group_starts(header: list[str]) -> list[int]:
    names = [_norm(h) for h in header]
    return [i for i, h in enumerate(names)
            if (h.startswith("port") and h != "porthandle") or h in ("toolinfo", "tool")]


def _cell_float(cell: str) -> float:
    s = cell.strip()
    if not s:
        return float("nan")
    v = float(s)
    return float("nan") if v < BAD_FLOAT_LIMIT else v


def parse_ndi(text: str, source: str = "<ndi>", *, unit: str = "mm", rate_hz: float | None = None) -> TrackerLog:
    """Parse the text of an NDI tool-tracking CSV export (see the module docstring).

    Parameters
    ----------
    text : str
        The file's content.
    source : str
        Name used in error messages.
    unit : {"mm", "m"}
        Unit of ``Tx Ty Tz`` in the file; positions are returned in mm.
    rate_hz : float, optional
        Frame rate, used for the time (``(frame - first frame) / rate``) when the export has no time column.

    Raises
    ------
    DataError
        Naming ``source:line`` and the column.
    """
    if unit not in ("mm", "m"):
        raise _err(source, None, f"tracker unit {unit!r} is not known", "use mm (NDI's default) or m")
    table = read_table(text, source)
    if table is None:
        raise _err(source, None, "the file is empty", "export the tracking data from NDI Track as CSV")
    header, hline, rows, lines = table.header, table.header_line, table.rows, table.lines
    starts = _group_starts(header)
    if not starts:
        raise _err(source, hline, "no tool column group (a header cell starting with 'Port')",
                   "this reader expects NDI Track's CSV export: Tools,Port ...,Frame,State,Q0,Qx,Qy,Qz,Tx,Ty,Tz,Error")
    if not rows:
        raise _err(source, hline, "no frames after the header",
                   "export the recording with its frames from NDI Track (was the export cut short?)")
    groups = []
    for g, s in enumerate(starts):
        end = starts[g + 1] if g + 1 < len(starts) else len(header)
        fields: dict[str, int] = {}
        for j in range(s + 1, end):
            key = _FIELDS.get(_norm(header[j]).replace("_", ""))
            if key == "markers":
                break  # marker sub-groups of optical tools follow; not needed
            if key and key not in fields:
                fields[key] = j
        missing = [f for f in ("state",) + _POSE if f not in fields]
        if missing:
            raise _err(source, hline, f"tool group {header[s]!r} (column {s + 1}) has no column(s) "
                                      f"{', '.join(m.capitalize() for m in missing)}",
                       "export the full transform (Q0 Qx Qy Qz Tx Ty Tz) and the state of every tool")
        groups.append((s, fields))

    n = len(rows)
    width = len(header)
    longer = [k for k, r in enumerate(rows) if len(r) > width and any(c.strip() for c in r[width:])]
    if longer:
        k = longer[0]
        raise _err(source, lines[k], f"{len(rows[k])} cells but the header (line {hline}) has {width}",
                   "export with one column group per tool in the header (NDI Track's CSV export does)")
    tools = []
    for s, fields in groups:
        label_cells = [r[s].strip() if s < len(r) else "" for r in rows]
        label = next((c for c in label_cells if c), header[s])
        num = {}
        for key in _POSE + ("error", "time", "frame"):
            j = fields.get(key)
            out = np.full(n, np.nan)
            if j is not None:
                for k, r in enumerate(rows):
                    if len(r) != width and len(r) <= j:
                        raise _err(source, lines[k], f"{len(r)} cells but the header (line {hline}) has {width}",
                                   "one cell per header column on every line (is the file cut short?)")
                    try:
                        out[k] = _cell_float(r[j])
                    except ValueError:
                        raise _err(source, lines[k], f"column {j + 1} ({header[j]!r} of {label!r}) is not a number: "
                                                     f"{r[j].strip()!r}", "every pose cell must be a number or empty") from None
            num[key] = out
        state = np.array([r[fields["state"]].strip() for r in rows], dtype=object)
        quat = np.column_stack([num[k] for k in ("q0", "qx", "qy", "qz")])
        pos = np.column_stack([num[k] for k in ("tx", "ty", "tz")]) * (1000.0 if unit == "m" else 1.0)
        frame = num["frame"]
        if "frame" in fields and not np.all(np.isfinite(frame)):
            k = int(np.flatnonzero(~np.isfinite(frame))[0])
            raise _err(source, lines[k], f"column {fields['frame'] + 1} ('Frame' of {label!r}) is empty",
                       "every line needs its frame number")
        if "frame" not in fields:
            frame = np.arange(n, dtype=float)
        time = num["time"]
        if not np.all(np.isfinite(time)):
            if "time" in fields:
                k = int(np.flatnonzero(~np.isfinite(time))[0])
                what = "is empty" if np.isnan(time[k]) else f"is not a finite number ({float(time[k])})"
                raise _err(source, lines[k], f"column {fields['time'] + 1} ('Time' of {label!r}) {what}",
                           "every line needs its time, a number of seconds")
            if rate_hz is None or not rate_hz > 0:
                raise _err(source, hline, "the export has no time column",
                           "give the tracker's frame rate (--map tracker.rate_hz=40), or export with time stamps")
            time = (frame - frame[0]) / rate_hz
        m = _LABEL.match(label)
        port, name = "", label
        if m and m.group("port"):
            p = m.group("port")
            port = f"{int(p, 16):02X}" if p.lower().startswith("0x") or re.search("[a-f]", p, re.I) else f"{int(p):02X}"
            name = (m.group("rest") or "").strip()
        tools.append(ToolTrack(label, port, name, frame.astype(np.int64), time, state, quat, pos, num["error"]))
    if len(lines) < 2:
        # (it spans no time: aligned with the logs it overlapped nothing, and numpy warned of an empty mean)
        raise _err(source, lines[0], "the export holds one frame: it spans no time",
                   "give the whole export of the run, every frame of the recording")
    back = np.flatnonzero(np.diff(tools[0].time_s) <= 0)
    if back.size:
        k = int(back[0]) + 1
        raise _err(source, lines[k], f"the time does not increase: {tools[0].time_s[k]:.6f} s after "
                                     f"{tools[0].time_s[k - 1]:.6f} s (line {lines[k - 1]})",
                   "export one recording per file, frames in order")
    return TrackerLog(source, tuple(tools), np.asarray(lines, dtype=np.int64))


def load_ndi(path: str | Path, *, unit: str = "mm", rate_hz: float | None = None) -> TrackerLog:
    """Read an NDI tool-tracking CSV export (see :func:`parse_ndi`)."""
    return parse_ndi(read_text(path, "tracker export"), str(path), unit=unit, rate_hz=rate_hz)


def read_text(path: str | Path, what: str) -> str:
    """The text of ``path``; an unreadable file raises :class:`DataError` naming it."""
    path = Path(path)
    try:
        return read_input_text(path, "utf-8-sig")
    except FileNotFoundError:
        raise DataError(f"{path}: no such {what}; fix: give the path of an existing {what}") from None
    except IsADirectoryError:
        raise DataError(f"{path}: is a directory, not a {what}; fix: name the file") from None
    except UnicodeDecodeError as exc:
        raise DataError(f"{path}: not a UTF-8 text file ({exc.reason} at byte {exc.start}); "
                        "fix: export the log as CSV text") from None
    except OSError as exc:
        raise DataError(f"{path}: cannot read the {what} ({exc.strerror or exc}); fix: give the {what} as a "
                        "readable file") from None
