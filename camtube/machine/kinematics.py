"""Kinematics: the job's unrolled moves in a machine's axes, rounded exactly as they are printed.

The wrap to the rotary axis happens here and only here: ``A = degrees(y / r_o)`` with the
same x, A = 0 at y = 0; ``Z = -focus offset``. Feeds follow the machine's feed mode: in
G93 (inverse time) ``F = 1 / minutes`` of each feed move, from its surface length on the
printed coordinates; in G94 mm/min of the XYZ distance (deg/min for a pure rotary move).
The G-code writer prints these values, the motion-time estimate (:mod:`camtube.machine.motion_time`)
times them, and the safety check reads them back (:meth:`MachineMoves.unrolled`).
"""
from __future__ import annotations

from dataclasses import dataclass

import math

import numpy as np

from camtube.machine.profile import MachineProfile
from camtube.plan.moves import CUT, LEAD, LINK, Moves, job_moves


@dataclass(frozen=True, eq=False)
class MachineMoves:
    """The moves of a job (or of a chunk of it) in one machine's axes, rounded as printed.

    Attributes
    ----------
    neutral : Moves
        The unrolled move list they come from.
    ax, ay, az : (m,) float
        Axis values (mm, or deg for a rotary second axis), rounded to ``profile.decimals``.
    feed : (m,) float
        F of every feed move (CUT, LINK, LEAD; 1/min in G93, else mm/min or deg/min), rounded; 0 elsewhere.
    profile : MachineProfile
        The machine (axes, rotary or flat, decimals, feed mode).
    outer_radius_mm : float
    start : tuple[float, float, float]
        Axis values before the first move (the rounded start of ``neutral``).
    """

    neutral: Moves
    ax: np.ndarray
    ay: np.ndarray
    az: np.ndarray
    feed: np.ndarray
    profile: MachineProfile
    outer_radius_mm: float
    start: tuple[float, float, float] = (0.0, 0.0, 0.0)

    def _unroll(self, ay):
        return np.radians(ay) * self.outer_radius_mm if self.profile.rotary else ay

    def unrolled(self) -> Moves:
        """The emitted moves back in the unrolled frame (what the safety check sees)."""
        n = self.neutral
        sx, sa, sz = self.start
        start = (sx, float(self._unroll(np.float64(sa))), -sz + 0.0)
        return Moves(self.ax, self._unroll(self.ay), -self.az, n.kind, n.laser, n.pass_index, n.vertex, n.speed,
                     start)


def machine_moves(job, machine, moves: Moves | None = None) -> MachineMoves:
    """Map moves (default: all of the job's) to a machine's axes and feeds (vectorised).

    Parameters
    ----------
    job : camtube.plan.Job
    machine : MachineProfile, or anything with a ``profile`` (a G-code dialect)
    moves : Moves, optional
        The move list (a chunk) to map; default: all of the job's.
    """
    dialect = getattr(machine, "profile", machine)  # the profile: axes, rotary, decimals, feed mode
    mv = job_moves(job) if moves is None else moves
    ro = job.outer_radius_mm
    dec = dialect.decimals
    sx, sy, sz = mv.start
    rot = (lambda y: np.degrees(y / ro)) if dialect.rotary else (lambda y: y)  # noqa: E731
    ax = np.round(mv.x, dec)
    ay = np.round(rot(mv.y), dec)
    az = np.round(-mv.z, dec) + 0.0  # + 0.0: no "-0.000000"
    s_ax, s_ay, s_az = (float(np.round(np.float64(v), dec)) for v in (sx, rot(np.float64(sy)), -sz))
    s_az += 0.0
    # surface length of each move from the printed coordinates
    ys = np.radians(ay) * ro if dialect.rotary else ay
    s_ys = float(np.radians(s_ay) * ro) if dialect.rotary else s_ay
    dx = np.diff(np.concatenate(([s_ax], ax)))
    dy = np.diff(np.concatenate(([s_ys], ys)))
    dz = np.diff(np.concatenate(([s_az], az)))
    surf = np.hypot(dx, dy)
    feedrow = (mv.kind == CUT) | (mv.kind == LEAD) | (mv.kind == LINK)
    feed = np.zeros(len(mv))
    with np.errstate(divide="ignore", invalid="ignore"):
        minutes = surf / (mv.speed * 60.0)
        if dialect.feed_mode == "inverse_time":
            feed[feedrow] = 1.0 / minutes[feedrow]
        else:
            # G94: F applies to the XYZ distance if the move has any, else to the rotary angle
            lin = np.hypot(dx, dz) if dialect.rotary else np.sqrt(dx * dx + dy * dy + dz * dz)
            rota = np.abs(np.diff(np.concatenate(([s_ay], ay)))) if dialect.rotary else np.zeros(len(mv))
            per = np.where(lin > 0, lin, rota)
            feed[feedrow] = per[feedrow] / minutes[feedrow]
    feed = np.round(feed, dialect.feed_decimals)
    return MachineMoves(mv, ax, ay, az, feed, dialect, ro, (s_ax, s_ay, s_az))


#: Largest rounding error of a printed feed, relative to the feed (the dose follows the speed).
FEED_ROUNDING = 0.01


def check_feeds(job, machine) -> None:
    """Refuse a job whose feeds the machine's G-code cannot carry (before anything is written).

    The smallest feed of a job is that of its longest cut move: in G93 (inverse time)
    ``F = 60 v / L`` per minute, in G94 ``F = 60 v`` mm/min. Printed with
    ``profile.feed_decimals`` it is off by up to half a unit of the last decimal; when that is
    more than :data:`FEED_ROUNDING` of the feed (a feed that rounds to zero is the extreme), the
    machine would run the job at another speed than planned, and the estimate could fall below
    the lower bound: the job is meaningless.

    Raises
    ------
    PatternError
        One issue naming ``process.scan_speed_mm_s``, the feed, and the slowest speed that works.
    """
    from camtube.errors import Issue, PatternError

    profile = getattr(machine, "profile", machine)
    pk = job.packed
    if pk.n_pass == 0:
        return
    v = float(np.min(pk.pass_speed))
    seg = np.hypot(*pk.edge_mm.T)
    L = float(seg.max()) if len(seg) else 0.0
    if not L > 0:
        return
    half = 0.5 * 10.0 ** -profile.feed_decimals
    inverse = profile.feed_mode == "inverse_time"
    f = 60.0 * v / L if inverse else 60.0 * v
    if half <= FEED_ROUNDING * f:
        return
    f_min = half / FEED_ROUNDING
    v_min = f_min * L / 60.0 if inverse else f_min / 60.0
    unit = "/min (G93, inverse time)" if inverse else "mm/min (G94)"
    printed = f"F{round(f, profile.feed_decimals):.{profile.feed_decimals}f}"
    raise PatternError([Issue(
        "process.scan_speed_mm_s",
        f"too slow for machine {profile.name}: the longest cut move ({L:.4g} mm) would get F = {f:.3g} {unit}, "
        f"written {printed} with {profile.feed_decimals} decimals (off by more than {100 * FEED_ROUNDING:g} %); "
        "the job would be meaningless", f"{v:g} mm/s", f">= {v_min:.3g} mm/s on this machine",
        f"set the machine profile's feed_decimals to {_decimals_needed(f, FEED_ROUNDING)} or more (the G-code then "
        f"carries the feed), or process.scan_speed_mm_s to at least {v_min:.3g}")])


def _decimals_needed(feed: float, share: float) -> int:
    """Fewest decimals with which ``feed`` is written within ``share`` of itself (half a unit of the last one)."""
    d = 0
    while 0.5 * 10.0 ** -d > share * feed and d < 12:
        d += 1
    return d


def check_speeds(job, machine) -> None:
    """Refuse a job whose cut moves the machine's axes cannot run at the scan speed, where its laser fires in time
    (before anything is written).

    A cut move along ``(dx, dy)`` (mm on the outer surface) at ``v`` mm/s needs ``v |dx| / L`` mm/s of the axial
    axis and ``v |dy| / L`` of the circumferential one (in deg/s on a rotary axis: ``/ r_o x 180 / pi``); a LinuxCNC
    profile's path speed is capped too, by its fastest linear axis (``[TRAJ] MAX_LINEAR_VELOCITY``). Where a move
    needs more, the controller runs it slower than planned. With the laser gated in time (a constant pulse rate)
    the pulses per mm then rise by the same factor, a dose the process was not tuned for: refused. A profile gated
    by distance keeps the pulses per mm whatever the speed (only the time grows): allowed.

    Raises
    ------
    PatternError
        One issue naming ``process.scan_speed_mm_s``, the axis, what the move needs and the fastest speed that works.
    """
    from camtube.errors import Issue, PatternError

    profile = getattr(machine, "profile", machine)
    pk = job.packed
    if pk.n_pass == 0 or getattr(profile, "gating", "time") == "distance":
        return
    n_geom = len(pk.geom_offset) - 1
    speed = np.zeros(n_geom)
    np.maximum.at(speed, np.asarray(pk.pass_geom), np.asarray(pk.pass_speed, float))
    d = np.abs(pk.edge_mm)
    seg = np.hypot(d[:, 0], d[:, 1])
    v = np.repeat(speed, pk.geom_size)
    cut = (seg > 0) & (v > 0)
    if not cut.any():
        return
    d, seg, v = d[cut], seg[cut], v[cut]
    ax, ay = profile.axes[0], profile.axes[1]
    deg_per_mm = 180.0 / (math.pi * job.outer_radius_mm) if profile.rotary else 1.0
    unit_y = "deg/s" if profile.rotary else "mm/s"
    needs = [(ax, v * d[:, 0] / seg, profile.axis(ax).max_velocity, "mm/s"),
             (ay, v * d[:, 1] / seg * deg_per_mm, profile.axis(ay).max_velocity, unit_y)]
    if profile.dialect == "linuxcnc":
        linear = [c for c in profile.axes[:2] if c in "XYZUVW"]
        path = v * (d[:, 0] / seg if profile.rotary else 1.0)
        needs.append(("path", path, max(profile.axis(c).max_velocity for c in linear), "mm/s"))
    worst = max(needs, key=lambda n: float(np.max(n[1] / n[2])))
    letter, need, limit, unit = worst
    k = int(np.argmax(need / limit))
    ratio = float(need[k] / limit)
    if ratio <= 1.0 + 1e-9:
        return
    what = ("the path speed (LinuxCNC's [TRAJ] MAX_LINEAR_VELOCITY, its fastest linear axis)" if letter == "path"
            else f"axis {letter}")
    v_max = float(v[k]) / ratio
    raise PatternError([Issue(
        "process.scan_speed_mm_s",
        f"too fast for machine {profile.name}: a cut move at {float(v[k]):g} mm/s needs {float(need[k]):.4g} {unit} "
        f"of {what}, whose limit is {limit:g} {unit}; the controller would cut slower, and with its laser gated in "
        f"time the pulses per mm would rise {ratio:.3g}x", f"{float(v[k]):g} mm/s", f"<= {v_max:.4g} mm/s on this machine",
        f"set process.scan_speed_mm_s to at most {v_max:.4g}, or use a machine whose laser is gated by distance "
        "(see `camtube machines`)")])


#: Process key (and what else sets it) of each value a dialect's laser lines write.
_LASER_FIELDS = {
    "power_w": ("process.power_w", "the laser power (W)"),
    "spindle": ("process.power_w", "the spindle value S = power x machine.laser.s_per_watt"),
    "frequency_khz": ("process.frequency_khz", "the pulse rate (kHz)"),
    "pulses_per_mm": ("process.frequency_khz", "the dose 1000 x frequency / scan speed (pulses per mm)"),
    "outer_radius_mm": ("tube.outer_radius", "the outer radius (mm)"),
}


def check_laser_values(job, machine) -> None:
    """Refuse a job whose laser lines (``M68 E.. Q..``, ``M4 S..``) would write a positive value as zero.

    Each value is printed with its line's fixed format (``Q{power_w:.3f}``, ``S{spindle:.0f}``); one that prints
    as 0 (a GRBL ``S0``: no beam; ``Q0.000``: no pulses) makes the job meaningless, as a feed that rounds to zero
    does (:func:`check_feeds`).

    Raises
    ------
    PatternError
        One issue naming the process key, the line as it would be written, and the smallest value that works.
    """
    import string

    from camtube.errors import Issue, PatternError
    from camtube.fmt import fixed

    dialect = machine
    templates = tuple(getattr(dialect, "settings", ())) + ((dialect.laser_on,) if hasattr(dialect, "laser_on") else ())
    specs = [(name, spec, t) for t in templates for _, name, spec, _ in string.Formatter().parse(t)
             if name in _LASER_FIELDS]
    pk = job.packed
    if not specs or pk.n_pass == 0:
        return
    keys = sorted({(float(p), float(f), float(v)) for p, f, v in zip(pk.pass_power.tolist(), pk.pass_freq.tolist(),
                                                                      pk.pass_speed.tolist())})
    for key in keys:
        fields = dialect.fields(*key, job.outer_radius_mm)
        for name, spec, template in specs:
            value = fields[name]
            if value > 0 and float(format(value, spec)) == 0.0:
                what, words = _LASER_FIELDS[name]
                line = template.format(**fields)
                profile = getattr(dialect, "profile", None)
                where = f" for machine {profile.name}" if profile is not None else ""
                dec = int(spec.rstrip("f").lstrip(".") or 0)
                raise PatternError([Issue(
                    what, f"{words} is {value:.3g}, written '{line}'{where}: zero, so the job would be meaningless",
                    None, f">= {fixed(0.5 * 10.0 ** -dec)} (written with {dec} decimals)",
                    f"raise {what}" + (" or machine.laser.s_per_watt" if name == "spindle" else ""))])
