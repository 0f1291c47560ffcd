"""Machine profiles: what a laser machine can do and how it wants its G-code, as data.

A profile is a YAML file (``machines/NAME.yaml`` ships the defaults, any file
can be given) holding a ``machine:`` mapping, parsed once into a frozen
:class:`MachineProfile`. Unknown keys are errors with a "did you mean"; every
error names the file, the line, the key, the allowed values and the fix
(:class:`camtube.errors.PatternError`, so the CLI prints it and exits 2).

Keys (units in the comments of the shipped files; ``docs/motion.md`` has the table):

``description``, ``dialect`` (``linuxcnc`` | ``grbl``), ``suffix``, ``rotary``,
``axes`` (axial, circumferential, focus letters), ``limits.<LETTER>.max_velocity``
(mm/s or deg/s) and ``.max_acceleration`` (mm/s^2 or deg/s^2), ``blending``
(``exact_stop``, a path tolerance in mm, or ``controller``), ``corner_strategy``
(``overtravel`` | ``none`` | ``blend``), ``servo_period_s``, ``laser`` (``gate_output``,
``power_output``, ``frequency_output``, ``gating`` (``time`` | ``distance``),
``dose_output``, ``radius_output`` for LinuxCNC; ``spindle`` M3/M4 and
``s_per_watt`` for GRBL), ``rotary_range_deg``, ``wrap``, ``comment``
(``paren`` | ``semicolon``), ``decimals``, ``feed_decimals``, ``warn_time_factor``,
``ordering`` (the pass ordering a job for this machine is planned with when none is
asked for: ``interleaved``, ``sequential`` or ``chained``; default ``interleaved``).

``laser.gating`` says how the laser's pulses follow the motion. ``time``: the laser
fires at its set frequency whenever the gate is open, so the dose per millimetre
rises wherever the stage slows down (corners, curves). ``distance``: the pulse rate
follows the surface speed (position-synchronised output, as Aerotech's PSO does),
so the pulses per millimetre stay at their nominal value however the stage moves;
the program gives the pulses per millimetre on analog output ``dose_output`` (and
the tube's outer radius on ``radius_output`` for a rotary axis), and
:mod:`camtube.motion.linuxcnc` wires the HAL that scales the pulse rate.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from camtube.errors import Issue, PatternError
from camtube.fmt import one_line
from camtube.yamltext import closest, line_map, read_yaml_file

#: Folder of the shipped profiles (package data; ``machines/`` at the top of the repository links to it).
MACHINES_DIR = Path(__file__).resolve().parent / "profiles"
DEFAULT_MACHINE = "linuxcnc-rotary"
DIALECT_KINDS = ("linuxcnc", "grbl")
CORNER_STRATEGIES = ("overtravel", "none", "blend")
GATINGS = ("time", "distance")
COMMENT_STYLES = ("paren", "semicolon")


@dataclass(frozen=True)
class AxisLimits:
    """Limits of one machine axis.

    Attributes
    ----------
    max_velocity : float
        mm/s for a linear axis, deg/s for a rotary one.
    max_acceleration : float
        mm/s^2 or deg/s^2.
    """

    max_velocity: float
    max_acceleration: float


@dataclass(frozen=True)
class MachineProfile:
    """One laser machine, as data (see the module docstring for the YAML keys).

    Attributes
    ----------
    name : str
        Profile name (the file stem).
    description : str
    dialect : {"linuxcnc", "grbl"}
        G-code family the emitter writes.
    suffix : str
        File suffix of the G-code, with the dot.
    rotary : bool
        True: the circumferential axis is rotary, ``degrees(y / r_o)``.
    axes : tuple[str, str, str]
        Letters of the axial, circumferential and focus axes.
    limits : tuple[tuple[str, AxisLimits], ...]
        Per axis letter (look up with :meth:`axis`).
    blending : str | float
        ``"exact_stop"`` (G61), a path tolerance in mm (G64 P..), or
        ``"controller"`` (nothing written; the controller's own junction handling).
    corner_strategy : {"overtravel", "none", "blend"}
        ``overtravel``: every cut edge is run at the scan speed from a beam-off
        lead-in to a beam-off lead-out along its own line (uniform dose, see
        :mod:`camtube.machine.corners`); ``none``: edges run back to back;
        ``blend``: the beam-on moves of a pass are one path, blended within the
        tolerance ``blending`` (``G64 P``: LinuxCNC joins them with tangent arcs at
        the speed their curvature allows), and the machine stops exactly (``G61``)
        wherever the gate switches, so the gate never switches in a blend.
    servo_period_s : float
        Controller servo period (s): the motion-synchronised gate switches on this clock.
    gate_output, power_output, frequency_output : int | None
        LinuxCNC digital output of the gate (M62/M63 P..) and analog outputs of
        power (W) and frequency (kHz) (M68 E..); None where not used.
    spindle : str | None
        GRBL beam-on code (``M3`` or ``M4``); None for LinuxCNC.
    s_per_watt : float
        S value per watt for the spindle code.
    rotary_range_deg : tuple[float, float] | None
        Travel of the rotary axis (deg).
    wrap : str
        ``none``: the rotary axis is continuous, never re-zeroed.
    comment : {"paren", "semicolon"}
    decimals, feed_decimals : int
    gating : {"time", "distance"}
        How the pulses follow the motion (module docstring): ``distance`` keeps the pulses
        per millimetre uniform, ``time`` keeps the pulses per second.
    dose_output, radius_output : int | None
        LinuxCNC analog outputs (``M68 E..``) of the pulses per mm and of the outer radius (mm)
        the distance gating's HAL reads; None with time gating.
    warn_time_factor : float
        Warn before writing when the estimate exceeds the lower bound (cut length / scan
        speed) by more than this factor.
    ordering : {"interleaved", "sequential", "chained"}
        The pass ordering a job for this machine is planned with unless another is asked for
        (:mod:`camtube.plan.planner`; ``chained`` joins the drill passes of a cut into one beam-on
        path).
    source : str | None
        File the profile was read from.
    """

    name: str
    description: str
    dialect: str
    suffix: str
    rotary: bool
    axes: tuple[str, str, str]
    limits: tuple[tuple[str, AxisLimits], ...]
    blending: str | float = "exact_stop"
    corner_strategy: str = "none"
    servo_period_s: float = 0.001
    gate_output: int | None = None
    power_output: int | None = None
    frequency_output: int | None = None
    spindle: str | None = None
    s_per_watt: float = 0.0
    rotary_range_deg: tuple[float, float] | None = None
    wrap: str = "none"
    comment: str = "paren"
    decimals: int = 6
    feed_decimals: int = 3
    gating: str = "time"
    dose_output: int | None = None
    radius_output: int | None = None
    warn_time_factor: float = 3.0
    ordering: str = "interleaved"
    source: str | None = None

    def axis(self, letter: str) -> AxisLimits:
        """Limits of axis ``letter`` (``KeyError`` if the profile has none)."""
        for k, v in self.limits:
            if k == letter:
                return v
        raise KeyError(f"machine {self.name!r} has no limits for axis {letter!r}")

    @property
    def exact_stop(self) -> bool:
        return self.blending == "exact_stop"

    @property
    def path_tolerance_mm(self) -> float:
        """How far the beam may stray from a drawn curve (mm): the chords' ``TOL.path`` (1 um, all on the
        inside) plus, where a pass is blended (``corner_strategy: blend``), the blending tolerance (``G64 P``):
        2 um for ``linuxcnc-path``, a tenth of a 20 um femtosecond kerf."""
        from camtube.tol import TOL

        extra = float(self.blending) if self.corner_strategy == "blend" else 0.0
        return TOL.path + extra

    @property
    def feed_mode(self) -> str:
        """``inverse_time`` (G93: F = 1 / minutes of each move) for LinuxCNC, ``units_per_minute`` (G94) for GRBL."""
        return "inverse_time" if self.dialect == "linuxcnc" else "units_per_minute"

    @property
    def uniform_dose(self) -> bool:
        """True when the pulses per millimetre stay at their nominal value however the stage moves
        (distance gating), or every beam-on move runs at the scan speed (over-travel)."""
        return self.gating == "distance" or self.corner_strategy == "overtravel"

    def record(self) -> dict:
        """What a job file stores about the machine it was made for (plain data, fixed order)."""
        return {
            "name": self.name, "dialect": self.dialect, "rotary": self.rotary,
            "axes": {k: {"max_velocity": float(v.max_velocity), "max_acceleration": float(v.max_acceleration),
                         "unit": "deg" if (self.rotary and k == self.axes[1]) else "mm"}
                     for k, v in self.limits},
            "blending": self.blending if isinstance(self.blending, str) else float(self.blending),
            "corner_strategy": self.corner_strategy, "servo_period_s": float(self.servo_period_s),
            "gating": self.gating,
        }


# ---------------------------------------------------------------- validation
#: Suffixes of the other files a build writes beside the G-code (NAME.job.json, ...): not a G-code suffix.
OWN_SUFFIXES = (".design.dxf", ".toolpath.dxf", ".job.json", ".design.step", ".design.stl", ".ascut.stl",
                ".verify.txt", ".verify.json", ".tube.png", ".unrolled.png")

_LIMIT_KEYS = ("max_velocity", "max_acceleration")
_LASER_KEYS = ("gate_output", "power_output", "frequency_output", "spindle", "s_per_watt", "gating", "dose_output",
               "radius_output")
_KEYS = ("description", "dialect", "suffix", "rotary", "axes", "limits", "blending", "corner_strategy",
         "servo_period_s", "laser", "rotary_range_deg", "wrap", "comment", "decimals", "feed_decimals",
         "warn_time_factor", "ordering")
_REQUIRED = ("dialect", "axes", "limits")


#: Ranges of the profile's numbers (fuzz report E3): what real stages, controllers and G-code readers do, so
#: that no value writes a doubtful program or a meaningless estimate. ``(lo, hi)``, both included.
#: Velocities: 0.01 mm/s (or deg/s) to 100000 (a 16,000 rpm spindle); accelerations: 0.1 to 10^7 mm/s^2 or
#: deg/s^2 (10 g is 98,000 mm/s^2); 1e-300 gave a time estimate of 150 digits.
VELOCITY_RANGE = (0.01, 100_000.0)
ACCELERATION_RANGE = (0.1, 10_000_000.0)
#: The path tolerance of ``G64 P`` (mm): 1 nm (the 6-decimal coordinates' resolution) to 10 um (a femtosecond
#: kerf: a larger tolerance lets the beam stray from the drawn path by more than the width it cuts).
BLENDING_RANGE_MM = (0.000001, 0.01)
#: Digits after the point of coordinates and feeds: 9 is 1 pm, far below any stage's resolution, and still
#: exact in double precision for a 2000 mm coordinate (decimals: 50 wrote 50-digit coordinates).
MAX_DECIMALS = 9
#: Servo period (s): 1 us to 10 ms (LinuxCNC's usual 1 ms, 25 us for a fast gate).
SERVO_PERIOD_RANGE_S = (0.000001, 0.01)
#: GRBL S per watt: S1000 = 1000 W to S1000 = 10 mW (laser power = S / s_per_watt).
S_PER_WATT_RANGE = (1.0, 100_000.0)
#: LinuxCNC's motion module has at most 64 digital and 64 analog I/O (num_dio, num_aio).
MAX_OUTPUT = 63
#: warn_time_factor: 1 (warn whenever the estimate exceeds the lower bound) to 1000.
WARN_FACTOR_RANGE = (1.0, 1000.0)
#: The rotary axis' travel (deg): 100 turns either way at most (a continuous axis: leave rotary_range_deg out).
ROTARY_RANGE_LIMIT_DEG = 36000.0


#: Axis letters of G-code that turn (degrees): A, B, C; the others move (mm).
ANGULAR_AXES = "ABC"


def _check_axis_roles(ck, axes: tuple[str, str, str], rotary: bool, dialect: str) -> None:
    """The letters fit their roles: the axial and focus axes move in mm, so neither is angular (axes [X, Z, A] drove
    the focus to 168 mm and the tube's axis to the focus, exit 0); the circumferential axis is angular on a rotary
    stage under LinuxCNC (whose A, B, C are degrees and X..W millimetres) and linear without one (rotary: false sent
    millimetres of the unrolled surface to A)."""
    axial, circ, focus = axes
    for role, letter in (("axial", axial), ("focus", focus)):
        if letter in ANGULAR_AXES:
            ck.add("axes", f"the {role} axis {letter} turns (A, B and C are rotary axes in G-code), but it must move "
                   "in mm", list(axes), "axes: [axial, circumferential, focus], axial and focus linear (X Y Z U V W)",
                   "e.g. axes: [X, A, Z] on a rotary stage, [X, Y, Z] without one")
            return
    if rotary and dialect == "linuxcnc" and circ not in ANGULAR_AXES:
        ck.add("axes", f"rotary: true, but the circumferential axis {circ} is a linear axis under LinuxCNC (its "
               "moves are in mm, the stage's in degrees)", list(axes), "A, B or C for the rotary stage",
               f"e.g. axes: [{axial}, A, {focus}], or rotary: false if {circ} carries the unrolled surface in mm")
    elif not rotary and circ in ANGULAR_AXES:
        ck.add("axes", f"rotary: false (the second axis carries the unrolled surface in mm), but {circ} is a rotary "
               "axis (degrees)", list(axes), "a linear axis (X Y Z U V W) without a rotary stage",
               f"set rotary: true if {circ} turns the tube, or use a linear letter, e.g. axes: [{axial}, Y, {focus}]")


def _hint(word: str, options) -> str:
    m = closest(word, options)
    return f"did you mean '{m}'?" if m else f"remove it (known: {', '.join(options)})"


def _num(x: float) -> str:
    """A bound for a message: plain digits (0.000001, 10000000), as a profile would give it."""
    from camtube.fmt import fixed

    return fixed(x)


class _Checker:
    def __init__(self, file: str | None, lines: dict[str, int]):
        self.file, self.lines, self.issues = file, lines, []

    def add(self, key, message, value=None, allowed="", fix=""):
        full = f"machine.{key}" if key else "machine"
        self.issues.append(Issue(full, message, value, allowed, fix, self.file,
                                 self.lines.get(full, self.lines.get("machine"))))

    def unknown(self, mapping: dict, allowed, prefix: str) -> None:
        for k in mapping:
            if k not in allowed:
                self.add(f"{prefix}{k}", "unknown key", None, ", ".join(allowed), _hint(k, allowed))

    def number(self, v, key, lo=0.0, strict=True, integer=False, hi=math.inf, unit=""):
        ok = isinstance(v, (int, float)) and not isinstance(v, bool)
        try:
            ok = ok and math.isfinite(v)
        except OverflowError:  # an integer of hundreds of digits
            ok, v = False, f"a number of {len(str(abs(v)))} digits"
        if ok and integer and float(v) != int(v):
            ok = False
        if ok and (v <= lo if strict else v < lo):
            ok = False
        if ok and v > hi:
            ok = False
        if not ok:
            what = "a whole number" if integer else "a finite number"
            rng = f"{what} {'>' if strict else '>='} {_num(lo)}" + (f" and <= {_num(hi)}" if hi < math.inf else "")
            rng += f" {unit}" if unit else ""
            if v is None:   # (a key left out read "must be a finite number ...", never that it was missing)
                self.add(key, "is missing", None, rng, f"add {key.split('.')[-1]}: <value> (your stage's figure)")
            else:
                self.add(key, f"must be {rng}", v, rng, f"set {key} to {rng}")
            return None
        return int(v) if integer else float(v)

    def choice(self, v, key, options):
        if v not in options:
            self.add(key, "not an allowed value", v, " | ".join(map(str, options)), _hint(v, options))
            return None
        return v


def build_profile(raw: Any, name: str, file: str | None = None, lines: dict[str, int] | None = None
                  ) -> MachineProfile:
    """Validate the raw YAML data of a profile file and build it.

    Raises
    ------
    PatternError
        Every problem found, each naming the file, line, key, allowed values and fix.
    """
    ck = _Checker(file, lines or {})
    if not isinstance(raw, dict) or set(raw) != {"machine"} or not isinstance(raw.get("machine"), dict):
        ck.add("", "a machine profile is one mapping under the top-level key 'machine:'", None,
               "machine: {dialect: ..., axes: [...], limits: {...}}", "start the file with 'machine:'")
        raise PatternError(ck.issues)
    m = raw["machine"]
    ck.unknown(m, _KEYS, "")
    for k in _REQUIRED:
        if k not in m:
            ck.add(k, "required key missing", None, "", f"add machine.{k}")
    if ck.issues:
        raise PatternError(ck.issues)
    dialect = ck.choice(m["dialect"], "dialect", DIALECT_KINDS)
    rotary = m.get("rotary", dialect == "linuxcnc")
    if not isinstance(rotary, bool):
        ck.add("rotary", "must be true or false", rotary, "true | false", "write rotary: true or rotary: false")
    axes = m["axes"]
    if not (isinstance(axes, list) and len(axes) == 3 and all(isinstance(a, str) and len(a) == 1
                                                              and a.upper() in "XYZABCUVW" for a in axes)
            and len({a.upper() for a in axes}) == 3):   # (x and X are one axis: it was "limits.A ... X, X, Z")
        ck.add("axes", "must list three different axis letters: axial, circumferential, focus", axes,
               "three of X Y Z A B C U V W", "e.g. axes: [X, A, Z]")
        axes = ["X", "A", "Z"]
        axes_named = False   # (the limits' letters are then not checked against a guess)
    else:
        axes_named = True
    axes = tuple(a.upper() for a in axes)
    if axes_named:
        _check_axis_roles(ck, axes, rotary if isinstance(rotary, bool) else True, dialect)
    limits = []
    lim = m["limits"]
    if not isinstance(lim, dict):
        ck.add("limits", "must map each axis letter to max_velocity and max_acceleration", lim, "",
               "e.g. limits: {X: {max_velocity: 50, max_acceleration: 500}}")
        lim = {}
    for letter in axes if axes_named else ():
        if letter not in lim:
            ck.add(f"limits.{letter}", "no limits for this axis", None, "max_velocity > 0, max_acceleration > 0",
                   f"add limits.{letter}: {{max_velocity: .., max_acceleration: ..}}")
    for letter, v in lim.items():
        key = f"limits.{letter}"
        if letter not in axes:
            if axes_named:
                ck.add(key, "not one of the profile's axes", letter, ", ".join(axes), _hint(letter, axes))
            continue
        if not isinstance(v, dict):
            ck.add(key, "must be a mapping", v, "max_velocity, max_acceleration", "e.g. {max_velocity: 50, ...}")
            continue
        ck.unknown(v, _LIMIT_KEYS, key + ".")
        unit = "deg" if (letter == axes[1] and rotary is True) else "mm"
        vals = [ck.number(v.get(k), f"{key}.{k}", lo, strict=False, hi=hi, unit=unit + per)
                for k, (lo, hi), per in zip(_LIMIT_KEYS, (VELOCITY_RANGE, ACCELERATION_RANGE), ("/s", "/s^2"))]
        if None not in vals:
            limits.append((letter, AxisLimits(*vals)))
    blending = m.get("blending", "exact_stop")
    lo_b, hi_b = BLENDING_RANGE_MM
    if not (blending in ("exact_stop", "controller")
            or (isinstance(blending, (int, float)) and not isinstance(blending, bool) and math.isfinite(blending)
                and lo_b <= blending <= hi_b)):
        ck.add("blending", "not an allowed value", blending,
               f"exact_stop | controller | a path tolerance >= {_num(lo_b)} and <= {_num(hi_b)} mm",
               "write blending: exact_stop, or a path tolerance such as 0.001")
    elif not isinstance(blending, str):
        blending = float(blending)
    if dialect == "grbl" and blending not in ("controller", "exact_stop"):
        ck.add("blending", "GRBL has no path tolerance (G64)", blending, "controller | exact_stop",
               "write blending: controller")
    corner = ck.choice(m.get("corner_strategy", "none"), "corner_strategy", CORNER_STRATEGIES)
    if dialect == "linuxcnc" and blending == "controller" and corner == "none":
        # LinuxCNC starts in G64 without a tolerance: it rounds each corner as far as speed asks, here with the beam
        # on (the planner stops at each corner as under G61, and the G61 line was left out, exit 0)
        ck.add("blending", "controller on LinuxCNC leaves its start-up mode (G64, corners blended without a "
               "tolerance), and with corner_strategy: none the beam stays on through each corner: it would round them",
               blending, "exact_stop | a path tolerance (mm) with corner_strategy none on LinuxCNC",
               "write blending: exact_stop (G61), or a path tolerance such as 0.001")
    if corner == "overtravel" and dialect != "linuxcnc":
        ck.add("corner_strategy", "overtravel needs motion-synchronised gating (dialect linuxcnc)", corner,
               "none for grbl", "write corner_strategy: none")
    if corner == "blend" and (dialect != "linuxcnc" or isinstance(blending, str) or rotary):
        ck.add("corner_strategy", "blend needs a LinuxCNC profile with a path tolerance (blending: 0.001) on linear "
               "axes (LinuxCNC blends moves with rotary motion parabolically, at half the acceleration)", corner,
               "none | overtravel", "write corner_strategy: none, or drive the rotary axis in surface mm (Y)")
    servo = ck.number(m.get("servo_period_s", 0.001), "servo_period_s", SERVO_PERIOD_RANGE_S[0], strict=False,
                      hi=SERVO_PERIOD_RANGE_S[1], unit="s")
    laser = m.get("laser", {}) or {}
    if not isinstance(laser, dict):
        ck.add("laser", "must be a mapping", laser, ", ".join(_LASER_KEYS), "e.g. laser: {gate_output: 0}")
        laser = {}
    ck.unknown(laser, _LASER_KEYS, "laser.")
    outs = {}
    for k in ("gate_output", "power_output", "frequency_output", "dose_output", "radius_output"):
        if k in laser:
            outs[k] = ck.number(laser[k], f"laser.{k}", 0, strict=False, integer=True, hi=MAX_OUTPUT)
    spindle, spw = laser.get("spindle"), 0.0
    if dialect == "linuxcnc":
        if "gate_output" not in laser:
            ck.add("laser.gate_output", "is missing: LinuxCNC gates the beam with a digital output", None,
                   f"a digital output 0..{MAX_OUTPUT}", "add laser.gate_output: 0")
        if spindle is not None or "s_per_watt" in laser:
            ck.add("laser.spindle", "LinuxCNC profiles gate the beam with outputs, not a spindle", spindle,
                   "gate_output/power_output/frequency_output", "remove laser.spindle and laser.s_per_watt")
    elif dialect == "grbl":
        if outs:
            ck.add("laser." + next(iter(outs)), "GRBL has no motion-synchronised outputs", None, "spindle, s_per_watt",
                   "use laser.spindle: M4 and laser.s_per_watt")
        spindle = ck.choice(spindle if spindle is not None else "M4", "laser.spindle", ("M3", "M4"))
        spw = ck.number(laser.get("s_per_watt"), "laser.s_per_watt", S_PER_WATT_RANGE[0], strict=False,
                        hi=S_PER_WATT_RANGE[1], unit="S per W") or 0.0
    gating = ck.choice(laser.get("gating", "time"), "laser.gating", GATINGS)
    if gating == "distance":
        if dialect != "linuxcnc":
            ck.add("laser.gating", "distance gating needs LinuxCNC's HAL (dialect linuxcnc)", gating, "time for grbl",
                   "write laser.gating: time")
        elif "dose_output" not in laser:
            ck.add("laser.dose_output", "distance gating reads the pulses per mm from an analog output", None, "0..3",
                   "add laser.dose_output: 2")
        elif rotary and "radius_output" not in laser:
            ck.add("laser.radius_output", "distance gating on a rotary axis reads the outer radius from an analog "
                   "output", None, "0..3", "add laser.radius_output: 3")
    elif "dose_output" in laser or "radius_output" in laser:
        ck.add("laser.dose_output", "only distance gating uses dose_output and radius_output", None,
               "laser.gating: distance", "add laser.gating: distance, or remove them")
    seen: dict = {}  # M68 E<n>: one analog output carries one signal (a second would overwrite the first)
    for k in ("power_output", "frequency_output", "dose_output", "radius_output"):
        v = outs.get(k)
        if v is None:
            continue
        if v in seen:
            ck.add(f"laser.{k}", f"is the same analog output as laser.{seen[v]} (M68 E{v} would carry both "
                   "values, each overwriting the other)", v, "a different analog output for each signal",
                   f"give laser.{k} an output of its own")
        else:
            seen[v] = k
    warn_factor = ck.number(m.get("warn_time_factor", 3.0), "warn_time_factor", WARN_FACTOR_RANGE[0], strict=False,
                            hi=WARN_FACTOR_RANGE[1])
    from camtube.plan.planner import DEFAULT_ORDERING, ORDERINGS

    ordering = ck.choice(m.get("ordering", DEFAULT_ORDERING), "ordering", ORDERINGS)
    rng = m.get("rotary_range_deg")
    if rng is not None:
        lim_deg = ROTARY_RANGE_LIMIT_DEG
        if not (isinstance(rng, list) and len(rng) == 2
                and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in rng)
                and all(-lim_deg <= v <= lim_deg for v in rng) and rng[0] < rng[1]):
            ck.add("rotary_range_deg", f"must be [min, max] in deg with min < max, each within +-{_num(lim_deg)}", rng,
                   f"[min, max] deg within -{_num(lim_deg)}..{_num(lim_deg)} (100 turns)",
                   "e.g. rotary_range_deg: [-360, 720]; leave the key out for a continuous axis")
            rng = None
        else:
            rng = (float(rng[0]), float(rng[1]))
    wrap = ck.choice(m.get("wrap", "none"), "wrap", ("none",))
    comment = ck.choice(m.get("comment", "paren"), "comment", COMMENT_STYLES)
    dec = ck.number(m.get("decimals", 6), "decimals", 0, strict=False, integer=True, hi=MAX_DECIMALS)
    fdec = ck.number(m.get("feed_decimals", 3), "feed_decimals", 0, strict=False, integer=True, hi=MAX_DECIMALS)
    suffix = m.get("suffix", ".ngc" if dialect == "linuxcnc" else ".nc")
    if not (isinstance(suffix, str) and suffix.startswith(".") and suffix.strip(".")
            and not any(c in suffix for c in "/\\\0")):
        ck.add("suffix", "must be a file suffix starting with a dot (no folder)", suffix, ".ngc, .nc, ...",
               "e.g. suffix: .ngc")
    elif suffix.lower() in OWN_SUFFIXES:
        ck.add("suffix", "is the suffix of another file camtube writes beside the G-code (one would "
               "overwrite the other)", suffix, "not one of " + ", ".join(OWN_SUFFIXES), "e.g. suffix: .ngc")
    desc = m.get("description", "")
    if not isinstance(desc, str):
        ck.add("description", "must be text", desc, "text", "quote it")
    elif one_line(desc) != desc:
        ck.add("description", "holds a line break or another control character (it is written into the G-code's "
               "header)", desc, "text on one line",
               "write the description on one line (a YAML '>' block folds its lines into one)")
    if ck.issues:
        raise PatternError(ck.issues)
    return MachineProfile(
        name=name, description=desc, dialect=dialect, suffix=suffix, rotary=rotary, axes=axes,
        limits=tuple(limits), blending=blending, corner_strategy=corner, servo_period_s=servo,
        gate_output=outs.get("gate_output"), power_output=outs.get("power_output"),
        frequency_output=outs.get("frequency_output"), spindle=spindle if dialect == "grbl" else None,
        s_per_watt=spw, rotary_range_deg=rng, wrap=wrap, comment=comment, decimals=dec, feed_decimals=fdec,
        gating=gating, dose_output=outs.get("dose_output"), radius_output=outs.get("radius_output"),
        warn_time_factor=warn_factor if warn_factor is not None else 3.0, ordering=ordering, source=file)


def read_profile(path: str | os.PathLike) -> MachineProfile:
    """Read and validate one profile file (raises :class:`PatternError`)."""
    file = str(path)
    raw, text = read_yaml_file(path, "machine profile", "check the path, or give a name from `camtube machines`")
    return build_profile(raw, Path(path).stem, file, line_map(text))


def profile_names() -> tuple[str, ...]:
    """Names of the shipped profiles (sorted)."""
    if not MACHINES_DIR.is_dir():
        return ()
    return tuple(sorted(p.stem for p in MACHINES_DIR.glob("*.yaml")))


def load_profile(name_or_path: str | os.PathLike | None = None) -> MachineProfile:
    """A shipped profile by name (``linuxcnc-rotary``), or a profile file by path; None: the default.

    Raises
    ------
    PatternError
        Unknown name (with a "did you mean"), unreadable file or invalid profile.
    """
    if name_or_path is None:
        name_or_path = DEFAULT_MACHINE
    s = os.fspath(name_or_path)
    if os.sep in s or "/" in s or s.endswith((".yaml", ".yml")) or Path(s).is_file():
        return read_profile(s)
    path = MACHINES_DIR / f"{s}.yaml"
    if not path.is_file():
        names = profile_names()
        raise PatternError([Issue("--machine", "no such machine profile", s, ", ".join(names) or "a YAML file",
                                  _hint(s, names) if names else "give the path of a profile YAML")])
    return read_profile(path)


def default_profile(dialect: str) -> MachineProfile:
    """The shipped profile whose G-code family is ``dialect`` (``linuxcnc`` -> the default)."""
    return load_profile(DEFAULT_MACHINE if dialect == "linuxcnc" else "grbl-flat")
