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

import numpy as np

from camtube.machine.profile import MachineProfile
from camtube.plan.moves import CUT, LEAD, Moves, job_moves


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
        F of every feed move (CUT, LEAD; 1/min in G93, else mm/min or deg/min), rounded; 0 elsewhere.
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
    feedrow = (mv.kind == CUT) | (mv.kind == LEAD)
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
