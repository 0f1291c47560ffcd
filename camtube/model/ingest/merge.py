"""From the three instruments' logs to the measurement rows: check units and signs, align the clocks,
put stroke and force on the tracker's frames, number the cycles.

The tracker's frames are the time base: the angle (the quantity the model is fitted to) is never
interpolated, and a frame in which a coil was not tracked gives no row. Stroke and force are interpolated
linearly at each frame's time once their clocks are mapped onto the tracker's; a frame that falls between
two samples of an instrument further apart than 1.5 of its usual sample interval (a gap in its log), or
outside its recording, gives no row either. Every row left out is counted by cause.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from camtube.errors import DataError
from camtube.model.data.dataset import Dataset, rest_noise
from camtube.model.ingest.clock import align_trigger, align_xcorr
from camtube.model.ingest.cycles import cycle_numbers, cycle_starts
from camtube.model.ingest.ndi import TrackerLog
from camtube.model.ingest.poses import BendAngle, bend_angle
from camtube.model.ingest.series import BenchMap, Series, force_N, stroke_mm


@dataclass(frozen=True, eq=False)
class Ingested:
    """The measurement rows and how they were made.

    Attributes
    ----------
    data : Dataset
        One sample; ``extra["out_of_plane_deg"]`` per row.
    bend : BendAngle
        The angle at every tracker frame (tracker clock from its first frame, s).
    clocks : dict of str -> ClockFit
        ``daq`` and ``motor`` onto the tracker clock (seconds from the tracker's first frame).
    flagged : dict of (str, str) -> int
        Frames a coil was not tracked in, by coil (``tip``, ``base``) and state as written.
    absent_frames : int
        Frames missing from the export (from gaps in its frame times).
    dropped : dict of str -> int
        Frames that gave no row, by cause: ``tracker`` (a coil not tracked), ``daq gap``, ``motor gap``,
        ``outside`` (before or after a log's recording).
    gaps : dict of str -> int
        Gaps (intervals > 1.5 x the usual sample interval) in each log: ``tracker``, ``daq``, ``motor``.
    traces : dict of str -> ndarray
        Signals on the tracker clock for the report: ``motor_t``, ``motor_stroke``, ``daq_t``, ``daq_force``,
        ``tip_state``, ``base_state``.
    sources : dict of str -> str
        The files.
    set_aside : dict of str -> (k,) int
        Lines of a log (``daq``, ``motor``, ``tracker`` for an angle log) set aside because their time stamp repeats the line's before.
    """

    data: Dataset
    bend: BendAngle
    clocks: dict
    flagged: dict
    absent_frames: int
    dropped: dict
    gaps: dict
    traces: dict = field(default_factory=dict)
    sources: dict = field(default_factory=dict)
    set_aside: dict = field(default_factory=dict)

    @property
    def dropouts(self) -> int:
        """Tracker frames lost: flagged by the tracker (either coil) or absent from the export."""
        return int(np.sum(~self.bend.valid)) + self.absent_frames


#: Largest stroke (mm) and force (N) a notched-tube joint's tendon may show in an ingested log: beyond them a map's
#: unit or scale is wrong (the presets' strokes are 2-5 mm; a UHMWPE tendon of r_t 0.04 mm breaks near 15 N).
MAX_STROKE_MM = 100.0
MAX_FORCE_N = 200.0
#: The rest before the first pull may read below zero by this many times the cell's row noise, or this share of
#: the force's span, before the zero is refused (a slack tendon cannot push).
REST_PUSH_NOISE = 5.0
REST_PUSH_SHARE = 0.05
#: Smallest peak stroke (mm) of a log that moves: below it the motor's scale is wrong (a lead of 1e-12 mm per rev).
MIN_STROKE_MM = 1e-3
#: Fewest rows a motor or DAQ log may hold: a test of cycles logged in fewer is a file cut short.
MIN_LOG_ROWS = 20
#: Fewest tracked frames the rest at the start of a recording (``tracker.rest_s``) must hold: zero bend is their mean.
MIN_REST_FRAMES = 3

def _pick_tools(log: TrackerLog, bm: BenchMap):
    tip_key, base_key = bm.tracker.tip, bm.tracker.base
    if not tip_key:
        if len(log.tools) == 1 and not base_key:
            return log.tools[0], None
        raise DataError(f"{log.source}: {len(log.tools)} tools ({'; '.join(t.label for t in log.tools)}); fix: name "
                        "the tip coil and the base coil (--map tracker.tip=0B --map tracker.base=0A)")
    tip = log.tool(tip_key, "tip")
    base = log.tool(base_key, "base") if base_key else None
    if base is tip:
        raise DataError(f"{log.source}: tracker.tip and tracker.base name the same tool ({tip.label}); "
                        "fix: name two different coils, or leave tracker.base empty for one coil")
    return tip, base


#: Within ``tracker.rest_s`` the joint may bend by at most this share of the record's largest bend (the noise of a
#: still joint is far below it; a rest window that runs into the first pull holds part of it).
REST_MOTION_SHARE = 0.1


def _check_rest_still(bend, source: str, rest_s: float) -> None:
    """Refuse a rest window (``tracker.rest_s``) in which the joint bends: zero bend (and the force's zero with
    ``offset_V: rest``) was read as the median over the first pull (a rest of 10 s over a pull from 4 s: angles -11 to
    21 deg, E_t 24 GPa, exit 0)."""
    t = np.asarray(bend.time_s, float)
    a = np.asarray(bend.angle_deg, float)
    ok = np.isfinite(a)
    if not ok.any():
        return
    t, a = t[ok] - t[ok][0], a[ok]
    window = a[t <= rest_s]
    top = float(np.max(np.abs(a - np.median(window))))
    # (robust to a spike or two of interference: the window's 2nd to 98th percentile)
    spread = float(np.subtract(*np.percentile(window, [98, 2]))) if window.size else 0.0
    if top > 0 and spread > REST_MOTION_SHARE * top:
        moved = np.flatnonzero(np.abs(a - a[0]) > REST_MOTION_SHARE * top)
        first = float(t[moved[0]]) if moved.size else rest_s
        raise DataError(f"{source}: the joint bends by {spread:.3g} deg within tracker.rest_s = {rest_s:g} s (it moves "
                        f"from {first:.3g} s): zero bend would be read over the first pull; fix: give the rest before "
                        f"the first pull (--map tracker.rest_s={max(0.8 * first, 0.1):.2g} or less)")


#: Counter widths whose wrap a motor log may show (an unsigned or a signed 16- or 32-bit position register).
COUNTER_WRAPS = (2 ** 16, 2 ** 32)


def _check_counter_wrap(motor, m) -> None:
    """Refuse a motor log of encoder counts that jumps by about a counter's span between two lines: a 16- or 32-bit
    position register that wrapped (a 16-bit wrap wrote 12 cycles to 1 mm for 3 cycles to 2.5 mm, exit 0; the signed
    one drew the fixes --map motor.sign=-1, then daq.N_per_V=-2.5)."""
    if m.stroke_unit != "counts":
        return
    v = np.asarray(motor.value, float)
    if v.size < 3:
        return
    step = np.diff(v)
    typical = float(np.median(np.abs(step[step != 0]))) if np.any(step != 0) else 0.0
    for span in COUNTER_WRAPS:
        jump = np.flatnonzero((np.abs(np.abs(step) - span) < 0.02 * span) & (np.abs(step) > 20 * max(typical, 1.0)))
        if jump.size:
            k = int(jump[0])
            bits = 16 if span == 2 ** 16 else 32
            raise DataError(f"{motor.source}:{int(motor.lines[k + 1])}: column {motor.column!r} jumps by "
                            f"{step[k]:+.0f} counts from the line before, about 2^{bits}: a {bits}-bit position counter "
                            f"that wrapped ({jump.size} time(s)); fix: unwrap the counts before ingest ({span} added where the "
                            "count falls across the wrap, taken off where it rises across it), or log the position in "
                            "a wider register")


def _angle_from_poses(tracker: TrackerLog, bench: BenchMap):
    tip, base = _pick_tools(tracker, bench)
    tm = bench.tracker
    ok_pos = tip.position_mm[tip.valid]
    if tm.unit == "mm" and ok_pos.size and 0 < float(np.nanmax(np.abs(ok_pos))) < 2.0:
        raise DataError(f"{tracker.source}: columns Tx, Ty, Tz of {tip.label!r} stay below "
                        f"{float(np.nanmax(np.abs(ok_pos))):.3g}: the positions look like metres; "
                        "fix: --map tracker.unit=m (NDI Track writes mm)")
    t0 = float(tip.time_s[0])
    try:
        bend = bend_angle(tip.time_s - t0, tip.quat_wxyz, tip.valid, None if base is None else base.quat_wxyz,
                          None if base is None else base.valid, rest_s=tm.rest_s)
    except ValueError:
        for role, tool in (("tip", tip), ("base", base)):
            if tool is None:
                continue
            ok = tool.state_ok
            if ok.any() and not tool.valid.any():
                # (every frame state OK, but no quaternion of length 1: "check the tool names", which were right)
                k = int(np.flatnonzero(ok)[0])
                with np.errstate(invalid="ignore"):
                    norm = float(np.sqrt(np.sum(tool.quat_wxyz[k] ** 2)))
                raise DataError(f"{tracker.source}:{int(tracker.lines[k])}: the {role} coil's quaternion (Q0, Qx, Qy, "
                                f"Qz of {tool.label!r}) has length {norm:.4g}, not 1, in every frame tracked OK: it is "
                                "not a rotation; fix: export the quaternion columns as the tracker gives them") from None
        raise DataError(f"{tracker.source}: no frame in which the tip{' and the base' if base else ''} coil is "
                        "tracked (state OK); fix: check the tool names (tracker.tip, tracker.base)") from None
    if bend.n_rest < MIN_REST_FRAMES:
        # (a rest of 1e-9 s took the first frame alone as zero bend: its noise an offset in every angle)
        ts = np.asarray(tip.time_s, float)[np.asarray(tip.valid, bool)]
        dt = float(np.median(np.diff(ts))) if ts.size > 1 else 0.0
        every = f" (a frame every {dt * 1e3:.3g} ms)" if dt > 0 else ""
        raise DataError(f"{tracker.source}: tracker.rest_s = {tm.rest_s:g} s holds {bend.n_rest} tracked frame"
                        f"{'' if bend.n_rest == 1 else 's'}{every}: zero bend read from so few carries their noise "
                        f"into every angle; fix: give the rest before the first pull, at least {MIN_REST_FRAMES} "
                        f"frames (--map tracker.rest_s={max(MIN_REST_FRAMES * dt, 0.1):.2g} or more; default 1)")
    _check_rest_still(bend, tracker.source, tm.rest_s)
    flagged: dict = {}
    for role, tool in (("tip", tip), ("base", base)):
        if tool is None:
            continue
        for st in tool.state[~tool.valid]:
            flagged[(role, str(st))] = flagged.get((role, str(st)), 0) + 1
    return bend, t0, flagged, tip, base


def _angle_from_log(log: Series, bench: BenchMap):
    """A joint angle logged directly (an encoder on the joint, a camera): deg, or rad when the map says so."""
    unit = bench.angle.unit
    v = log.value
    peak = float(np.nanmax(np.abs(v))) if v.size else 0.0
    if unit == "" and 0 < peak < 3.2:
        raise DataError(f"{log.source}: column {log.column!r} peaks at {peak:.3g}: an angle in radians? "
                        "fix: --map angle.unit=rad (or --map angle.unit=deg if the bend really stays below 3.2 deg)")
    ang = np.degrees(v) if unit == "rad" else np.asarray(v, float)
    t0 = float(log.time_s[0])
    t = log.time_s - t0
    valid = np.isfinite(ang)
    if abs(np.nanmax(ang)) < abs(np.nanmin(ang)):
        ang = -ang
    bend = BendAngle(t, ang, np.full(t.size, np.nan), np.full(3, np.nan), valid, 0)
    return bend, t0, {}, None, None


def _gap_mask(t: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray, int]:
    """For times ``at``: (outside the recording, inside a gap) masks, and the number of gaps in ``t``."""
    dt = np.diff(t)
    med = float(np.median(dt))
    big = dt > 1.5 * med
    j = np.searchsorted(t, at, side="right")
    outside = (at < t[0]) | (at > t[-1])
    jj = np.clip(j, 1, t.size - 1)
    in_gap = ~outside & big[jj - 1]
    return outside, in_gap, int(big.sum())


def _check_duration(name: str, s: Series, unit: str, key: str, tracker_span: float) -> None:
    span = float(s.time_s[-1] - s.time_s[0])
    if not span > 0.0:
        # one row, or every stamp the same: no time unit makes a recording of it
        raise DataError(f"{s.source}: column {key!r} spans no time ({s.time_s.size} row"
                        f"{'s' if s.time_s.size != 1 else ''}, from {float(s.time_s[0]):g} s to "
                        f"{float(s.time_s[-1]):g} s); fix: give the {name} log of the whole test, one row per "
                        "sample in time order")
    if s.time_s.size < MIN_LOG_ROWS:
        # (a DAQ log cut to 3 rows was told its time unit was wrong; the next unit gave another error)
        raise DataError(f"{s.source}: {s.time_s.size} rows, too few for a {name} log of a test the tracker export "
                        f"spans {tracker_span:g} s (at least {MIN_LOG_ROWS}); fix: give the {name} log of the whole "
                        "test (a file cut short?)")
    ratio = span / tracker_span if tracker_span > 0 else 1.0
    if not 0.05 <= ratio <= 20.0:
        units = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "min": 60.0}
        cur = units[unit]
        best = min(units, key=lambda u: abs(np.log(span / cur * units[u] / tracker_span)))
        raise DataError(f"{s.source}: column {key!r} read in {unit} spans {span:g} s, the tracker export "
                        f"{tracker_span:g} s; fix: {name}.time_unit: {best} in the bench map "
                        f"(--map {name}.time_unit={best})")


def ingest(tracker: TrackerLog | Series, daq: Series, motor: Series, bench: BenchMap, sample: str = "1", *,
           max_lag_s: float | None = None) -> Ingested:
    """Merge the three logs into measurement rows (see the module docstring).

    Parameters
    ----------
    tracker : TrackerLog or Series
        The NDI export, or a log of the joint angle itself (read with the map's ``angle`` section).
    daq, motor : Series
        The load cell's and the motor's logs as read (uncalibrated columns).
    bench : BenchMap
        Which tools and columns, units and calibrations.
    sample : str
        The sample name written in every row.
    max_lag_s : float, optional
        Largest clock offset to consider when aligning from the motion, s.

    Raises
    ------
    DataError
        A unit or sign that cannot be right (one line naming the file, the column and the fix), logs that
        do not overlap, no frame with both coils tracked.
    """
    if max_lag_s is not None and not (max_lag_s > 0 and max_lag_s < float("inf")):
        raise DataError(f"--max-lag {max_lag_s}: the largest clock offset must be a finite number of seconds > 0; "
                        "fix: give e.g. --max-lag 5, or leave it out to consider any offset")
    if isinstance(tracker, Series):
        bend, t0, flagged, tip, base = _angle_from_log(tracker, bench)
    else:
        bend, t0, flagged, tip, base = _angle_from_poses(tracker, bench)
    t_trk = bend.time_s
    dtt = np.diff(t_trk)
    med = float(np.median(dtt))
    absent = int(np.sum(np.maximum(np.round(dtt / med) - 1, 0)[dtt > 1.5 * med]))
    span = float(t_trk[-1] - t_trk[0])

    # ---- units and signs of the motor and the DAQ
    _check_duration("motor", motor, bench.motor.time_unit, bench.motor.time, span)
    _check_duration("daq", daq, bench.daq.time_unit, bench.daq.time, span)
    _check_counter_wrap(motor, bench.motor)
    stroke = stroke_mm(motor, bench.motor)
    if -float(stroke.min()) > float(stroke.max()):
        raise DataError(f"{motor.source}: column {motor.column!r} gives a stroke that runs negative "
                        f"({stroke.max():.3g} to {stroke.min():.3g} mm); fix: --map motor.sign=-1 (the position counts "
                        "down as the tendon is pulled)")
    force = force_N(daq, bench.daq, bench.tracker.rest_s)
    _check_magnitudes(motor, stroke, daq, force, bench)

    # ---- clocks: the motor and the DAQ onto the tracker
    ang = bend.angle_deg
    c_motor = align_xcorr("motor", t_trk, ang, motor.time_s, stroke, max_lag_s=max_lag_s)
    if c_motor.sign < 0:
        bend = BendAngle(bend.time_s, -bend.angle_deg, bend.out_of_plane_deg, -bend.axis, bend.valid, bend.n_rest)
        ang = bend.angle_deg
        c_motor = align_xcorr("motor", t_trk, ang, motor.time_s, stroke, max_lag_s=max_lag_s)
    if bench.daq.trigger and bench.motor.trigger:
        c_daq = align_trigger("daq", daq.time_s, daq.trigger, motor.time_s, motor.trigger,
                              f"{daq.source} / {motor.source}").then(c_motor)
        c_check = align_xcorr("daq", t_trk, ang, daq.time_s, force, max_lag_s=max_lag_s)
        sign = c_check.sign
    else:
        c_daq = align_xcorr("daq", t_trk, ang, daq.time_s, force, max_lag_s=max_lag_s)
        sign = c_daq.sign
    if sign < 0:
        what = "N_per_V" if bench.daq.force_unit == "V" else "force_unit"
        raise DataError(f"{daq.source}: column {daq.column!r} falls as the stroke rises (the load cell reads "
                        f"compression); fix: negate the calibration (--map daq.{what}={-bench.daq.N_per_V:g})"
                        if what == "N_per_V" else
                        f"{daq.source}: column {daq.column!r} falls as the stroke rises; fix: log the tension as positive")

    # ---- onto the tracker's frames
    m_t = c_motor.to_ref(motor.time_s)
    d_t = c_daq.to_ref(daq.time_s)
    frames = t_trk
    out_m, gap_m, n_gap_m = _gap_mask(m_t, frames)
    out_d, gap_d, n_gap_d = _gap_mask(d_t, frames)
    valid = bend.valid
    keep = valid & ~out_m & ~out_d & ~gap_m & ~gap_d
    dropped = {"tracker": int(np.sum(~valid)),
               "outside": int(np.sum(valid & (out_m | out_d))),
               "motor gap": int(np.sum(valid & ~out_m & ~out_d & gap_m)),
               "daq gap": int(np.sum(valid & ~out_m & ~out_d & ~gap_m & gap_d))}
    if not keep.any():
        raise DataError(f"{tracker.source}, {daq.source}, {motor.source}: no tracker frame falls inside both logs; "
                        "fix: give logs of the same run")
    tk = frames[keep]
    s_row = np.interp(tk, m_t, stroke)
    f_row = np.interp(tk, d_t, force)
    starts = cycle_starts(m_t, stroke)
    cyc = cycle_numbers(tk, starts)
    cyc = cyc - cyc.min() + 1
    data = Dataset(np.full(tk.size, sample, dtype=object), cyc.astype(np.int64), tk - tk[0], s_row, f_row,
                   bend.angle_deg[keep], {"out_of_plane_deg": bend.out_of_plane_deg[keep]})
    traces = {"motor_t": m_t, "motor_stroke": stroke, "daq_t": d_t, "daq_force": force,
              "tip_state": None if tip is None else tip.state, "base_state": None if base is None else base.state,
              "row_t": tk, "t0_s": t0}
    return Ingested(data, bend, {"motor": c_motor, "daq": c_daq}, flagged, absent, dropped,
                    {"tracker": int(np.sum(dtt > 1.5 * med)), "daq": n_gap_d, "motor": n_gap_m}, traces,
                    {"tracker": tracker.source, "daq": daq.source, "motor": motor.source},
                    {k: x.repeated for k, x in (("tracker", tracker), ("daq", daq), ("motor", motor))
                     if isinstance(x, Series) and x.repeated.size})


def ingest_files(tracker_path, daq_path, motor_path, bench: BenchMap, sample: str | None = None, *,
                 max_lag_s: float | None = None, angle_log: bool = False) -> Ingested:
    """Read the three logs named by the bench map's columns and :func:`ingest` them.

    ``sample`` defaults to the tracker file's name without its suffix. With ``angle_log`` the first file is
    a time-series log of the joint angle (the map's ``angle`` section), not an NDI export.
    """
    from pathlib import Path

    from camtube.model.ingest.ndi import load_ndi
    from camtube.model.ingest.series import load_series

    name = sample if sample is not None else Path(tracker_path).stem
    origin = "--sample" if sample is not None else f"the sample name from the file name {Path(tracker_path).name}:"
    if not name.strip() or name.lstrip().startswith("#") or any(c in name for c in "\r\n\x00"):
        why = ("is empty" if not name.strip() else "starts with '#', which makes every row of the CSV a comment"
               if name.lstrip().startswith("#") else "holds a line break or NUL, which splits the CSV's rows")
        raise DataError(f"{origin} {name!r} {why}; fix: give a plain name, e.g. --sample S1")
    tm = bench.tracker
    if angle_log:
        a = bench.angle
        log = load_series(tracker_path, a.time, a.time_unit, a.angle, role="angle")
    else:
        log = load_ndi(tracker_path, unit=tm.unit, rate_hz=tm.rate_hz or None)
    d = bench.daq
    daq = load_series(daq_path, d.time, d.time_unit, d.force, d.trigger, role="daq")
    m = bench.motor
    motor = load_series(motor_path, m.time, m.time_unit, m.stroke, m.trigger, role="motor")
    return ingest(log, daq, motor, bench, name, max_lag_s=max_lag_s)


def _check_magnitudes(motor: Series, stroke: np.ndarray, daq: Series, force: np.ndarray, bench: BenchMap) -> None:
    """Refuse a stroke or a force no tendon-driven tube joint shows: a map's scale or unit is wrong (a motor read
    with half a count per revolution stroked 2.6 m; a DAQ logged in mV read as V pulled 3.8 kN; a zero of 5 V left every
    force below zero). One line naming the file, the column, the values and the keys to check."""
    motor_keys = ("motor.stroke_unit, motor.counts_per_rev, motor.gear_ratio and motor.lead_mm_per_rev"
                  if bench.motor.stroke_unit == "counts" else "motor.stroke_unit and motor.lead_mm_per_rev")
    peak = float(np.max(stroke)) if stroke.size else 0.0
    if peak > MAX_STROKE_MM:
        raise DataError(f"{motor.source}: column {motor.column!r} gives a stroke of up to {peak:.4g} mm, more than the "
                        f"{MAX_STROKE_MM:g} mm any notched-tube joint's tendon travels; fix: check {motor_keys}")
    if 0.0 < float(np.ptp(motor.value)) and peak < MIN_STROKE_MM:
        raise DataError(f"{motor.source}: column {motor.column!r} moves, but gives a stroke of at most {peak:.3g} mm; "
                        f"fix: check {motor_keys}")
    scale = ("daq.force_unit and daq.N_per_V (a log in mV read as V is 1000x too large)"
             if bench.daq.force_unit == "V" else "daq.force_unit (N: the column holds newtons)")
    big = float(np.max(np.abs(force))) if force.size else 0.0
    if big > MAX_FORCE_N:
        raise DataError(f"{daq.source}: column {daq.column!r} gives forces up to {big:.4g} N, more than the "
                        f"{MAX_FORCE_N:g} N any notched-tube joint's tendon carries; fix: check {scale}")
    at_rest = daq.time_s <= daq.time_s[0] + max(bench.tracker.rest_s, 0.0)
    if at_rest.any() and force.size > 2:
        rest = float(np.median(force[at_rest]))
        span = float(np.percentile(force, 99) - np.percentile(force, 1))
        if span > 0 and abs(rest) > span:
            raise DataError(f"{daq.source}: column {daq.column!r} gives {rest:.4g} N at the rest before the first pull "
                            f"(the first {bench.tracker.rest_s:g} s), beyond the {span:.3g} N the force spans: its zero "
                            f"(daq.offset_V = {bench.daq.offset_V}) is not the load cell's reading at rest; fix: "
                            "--map daq.offset_V=rest (the median over that rest)")
        noise = rest_noise(force, [np.flatnonzero(at_rest)])   # (the cell's row-to-row noise there)
        if span > 0 and rest < -max(REST_PUSH_NOISE * noise, REST_PUSH_SHARE * span):
            # (offset_V 0.5 V too high: -0.96 N at rest, written without a word; a fit then gave 19.5 deg RMS)
            raise DataError(f"{daq.source}: column {daq.column!r} gives {rest:.4g} N at the rest before the first pull "
                            f"(the first {bench.tracker.rest_s:g} s): a slack tendon cannot push, so its zero "
                            f"(daq.offset_V = {bench.daq.offset_V}) is not the load cell's reading at rest; fix: "
                            "--map daq.offset_V=rest (the median over that rest)")
