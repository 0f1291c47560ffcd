"""G-code post-processor: one emitter for every :class:`~camtube.export.dialects.Dialect`.

The wrap to the rotary axis happens here and only here: ``A = degrees(y / r_o)``
with the same x, A = 0 at y = 0. Passes are cut at the angles of their
unwrapped contour, whose centre lies in [0, 360) deg, so A stays within
(-180, 540) deg however long the job: A never winds up, and a rotary stage
with cables or a limited range never needs an unwind (a rapid between cuts may
turn the long way round, at most one turn; the time estimate includes it).

:func:`gcode` builds the machine moves (coordinates rounded exactly as they are
printed), converts them back to the unrolled frame, runs the safety check on
them, and only then formats the text. Same job and dialect: byte-identical text.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from camtube import __version__
from camtube.export.dialects import LINUXCNC, Dialect
from camtube.plan.moves import CUT, FOCUS, Moves, estimate, job_moves
from camtube.plan.packed import no_gc
from camtube.plan.safety import check_moves


@dataclass(frozen=True, eq=False)
class MachineMoves:
    """The moves of a job in one dialect's machine axes, rounded as printed.

    Attributes
    ----------
    neutral : Moves
        The unrolled move list they come from.
    ax, ay, az : (m,) float
        Axis values (mm, or deg for a rotary second axis), rounded to ``dialect.decimals``.
    feed : (m,) float
        F of every cutting move (1/min in G93, else mm/min or deg/min), rounded; 0 elsewhere.
    """

    neutral: Moves
    ax: np.ndarray
    ay: np.ndarray
    az: np.ndarray
    feed: np.ndarray
    dialect: Dialect
    outer_radius_mm: float

    def unrolled(self) -> Moves:
        """The emitted moves back in the unrolled frame (what the safety check sees)."""
        y = np.radians(self.ay) * self.outer_radius_mm if self.dialect.rotary else self.ay
        n = self.neutral
        return Moves(self.ax, y, -self.az, n.kind, n.laser, n.pass_index, n.vertex, n.speed)


def machine_moves(job, dialect: Dialect = LINUXCNC, moves: Moves | None = None) -> MachineMoves:
    """Map the job's moves to ``dialect``'s axes and feeds (vectorised)."""
    mv = job_moves(job) if moves is None else moves
    ro = job.outer_radius_mm
    dec = dialect.decimals
    ax = np.round(mv.x, dec)
    ay = np.round(np.degrees(mv.y / ro) if dialect.rotary else mv.y, dec)
    az = np.round(-mv.z, dec) + 0.0  # + 0.0: no "-0.000000"
    # surface length of each move from the printed coordinates
    ys = np.radians(ay) * ro if dialect.rotary else ay
    dx = np.diff(np.concatenate(([0.0], ax)))
    dy = np.diff(np.concatenate(([0.0], ys)))
    dz = np.diff(np.concatenate(([0.0], az)))
    surf = np.hypot(dx, dy)
    cut = mv.kind == CUT
    feed = np.zeros(len(mv))
    with np.errstate(divide="ignore", invalid="ignore"):
        minutes = surf / (mv.speed * 60.0)
        if dialect.feed_mode == "inverse_time":
            feed[cut] = 1.0 / minutes[cut]
        else:
            # G94: F applies to the XYZ distance if the move has any, else to the rotary angle
            lin = np.hypot(dx, dz) if dialect.rotary else np.sqrt(dx * dx + dy * dy + dz * dz)
            rot = np.abs(np.diff(np.concatenate(([0.0], ay)))) if dialect.rotary else np.zeros(len(mv))
            per = np.where(lin > 0, lin, rot)
            feed[cut] = per[cut] / minutes[cut]
    feed = np.round(feed, dialect.feed_decimals)
    return MachineMoves(mv, ax, ay, az, feed, dialect, ro)


def _header(job, dialect: Dialect, mm: MachineMoves) -> list[str]:
    est = estimate(job, mm.neutral)
    pr = job.process
    c = dialect.comment_line
    ax, ay, az = dialect.axes
    wrap = (f"{ay} = degrees(y / r_o) deg, r_o = {job.outer_radius_mm:g} mm" if dialect.rotary
            else f"{ay} = y mm (unrolled sheet)")
    return [
        c(f"camtube {__version__} job {job.name}, dialect {dialect.name}: {dialect.description}"),
        c(f"frame: {ax} = x mm from the tip, {wrap}, {az} = -focus offset into the material mm"),
        c(f"process: {pr.power_w:g} W, {pr.frequency_khz:g} kHz, {pr.scan_speed_mm_s:g} mm/s on the outer surface, "
          f"{pr.drill_passes} drill cuts {pr.drill_offset_mm:g} mm apart, defocus {pr.defocus_mm:g} mm, "
          f"{job.repeats} repeats, ordering {job.ordering}"),
        c(f"{est.cuts} cuts, {est.passes} passes, cut length {est.cut_length_mm:.3f} mm, estimated "
          f"{est.total_s:.1f} s, lower bound {est.lower_bound_s:.1f} s, ratio {est.ratio:.4f}"),
    ]


def emit(job, mm: MachineMoves, memo: bool = True, progress: Callable[[int, int], None] | None = None) -> str:
    """Format checked machine moves as G-code text (no safety check: use :func:`gcode`).

    ``memo`` reuses the text of a path's cutting moves for later passes over
    the same path at the same speed (their rows are identical by
    construction); ``memo=False`` formats every row (tests compare both).
    """
    d = dialect = mm.dialect
    n = mm.neutral
    ax, ay, az = d.axes
    f = f"{{:.{d.decimals}f}}"
    ff = f"{{:.{d.feed_decimals}f}}"
    focus = f"G0 {az}{f}".format
    cut = f"G1 {ax}{f} {ay}{f} F{ff}".format
    X, Y, Z, F = mm.ax.tolist(), mm.ay.tolist(), mm.az.tolist(), mm.feed.tolist()
    kind = n.kind.tolist()
    rows = n.pass_rows().tolist()
    pk = job.packed
    geom, speed = pk.pass_geom.tolist(), pk.pass_speed.tolist()
    out = _header(job, dialect, mm)
    out.extend(d.preamble)
    # the pass comment holds no parentheses, so it needs no escaping in either comment style
    lead, tail = ("(", ")") if d.comment == "paren" else ("; ", "")
    head = (lead + "pass {}: cut {} {}, repeat {}, focus {} at {:g} mm, drill {} offset {:.4f} mm" + tail
            + "\nG0 " + ax + f + " " + ay + f + "{}\n{}\n{}\n" + d.laser_off).format
    passes = job.passes
    total = len(passes)
    # per-pass focus line ("" when the focus does not change)
    r0s = rows[:-1]
    focus_txt = ["\n" + focus(Z[r + 1]) if kind[r + 1] == FOCUS else "" for r in r0s]
    # gate and settings lines per (power, frequency), settings only where they change
    gates: dict[tuple[float, float], tuple[str, str]] = {}
    pre: list[str] = []
    prev = None
    for ps in passes:
        key = (ps.power_w, ps.frequency_khz)
        if key not in gates:
            fields = d.fields(*key)
            gates[key] = ("".join(x.format(**fields) + "\n" for x in d.settings), d.laser_on.format(**fields))
        pre.append((gates[key][0] if key != prev else "") + gates[key][1])
        prev = key
    blocks: dict[tuple[int, float], str] = {}

    def block(p: int) -> str:
        start = rows[p] + (2 if focus_txt[p] else 1)
        if memo:
            bkey = (geom[p], speed[p])
            blk = blocks.get(bkey)
            if blk is None:
                blk = blocks[bkey] = "\n".join([cut(X[i], Y[i], F[i]) for i in range(start, rows[p + 1])])
            return blk
        return "\n".join([cut(X[i], Y[i], F[i]) for i in range(start, rows[p + 1])])

    step = 4096
    for lo in range(0, total, step):
        hi = min(total, lo + step)
        out.extend([
            head(p, ps.cut_index, ps.kind, ps.repeat, ps.focus_level, ps.focus_offset_mm, ps.drill_index,
                 ps.offset_mm, X[rows[p]], Y[rows[p]], focus_txt[p], pre[p], block(p))
            for p, ps in zip(range(lo, hi), passes[lo:hi])])
        if progress is not None:
            progress(hi, total)
    out.extend(d.postamble)
    out.append("")
    return "\n".join(out)


def gcode(job, dialect: Dialect = LINUXCNC, progress: Callable[[int, int], None] | None = None) -> str:
    """Safety-checked G-code of ``job`` in ``dialect``.

    Raises
    ------
    SafetyError
        The emitted moves fail :func:`camtube.plan.safety.check_moves`; no text is returned.
    """
    mm = machine_moves(job, dialect)
    check_moves(job, mm.unrolled())
    with no_gc():
        return emit(job, mm, progress=progress)
