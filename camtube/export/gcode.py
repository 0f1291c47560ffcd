"""G-code post-processor: one streaming emitter for every :class:`~camtube.export.dialects.Dialect`.

The wrap to the rotary axis happens in :mod:`camtube.machine.kinematics` and only there:
``A = degrees(y / r_o)`` with the same x, A = 0 at y = 0. Passes are cut at the angles of their
unwrapped contour, whose centre lies in [0, 360) deg, so A stays within
(-180, 540) deg however long the job: A never winds up, and a rotary stage
with cables or a limited range never needs an unwind (a rapid between cuts may
turn the long way round, at most one turn; the time estimate includes it).

:func:`iter_gcode` yields the text chunk by chunk (:data:`~camtube.plan.moves.CHUNK_PASSES`
passes at a time): for each chunk it builds the machine moves (coordinates rounded
exactly as they are printed), converts them back to the unrolled frame, runs the
safety check on them, and only then formats them; memory stays bounded however
long the job. :func:`gcode` joins the chunks (small jobs, tests). Same job and
dialect: byte-identical text.

Rows by kind: RAPID ``G0 <x> <y>``; FOCUS ``G0 <z>``; CUT, LINK and LEAD ``G1 <x> <y> F..``.
The beam gate follows the rows' ``laser`` flags: ``laser_on`` before the first
laser-on row after laser-off rows (preceded by the settings lines where power or
frequency change), ``laser_off`` before a laser-off row after laser-on rows and at
the end of every pass, so a LEAD move (over-travel, lead-in) runs with the gate closed;
a chain of linked passes (the ``chained`` ordering) is one beam-on run: the gate stays
open from its first pass to its last, and a pass entered by its LINK starts with that
G1 move (no rapid).
"""
from __future__ import annotations

from typing import Iterable, Iterator, Sequence

import numpy as np

from camtube import __version__
from camtube.export.dialects import LINUXCNC, Dialect
from camtube.fmt import fixed, format_duration_s
from camtube.machine.kinematics import MachineMoves, machine_moves
from camtube.machine.motion_time import job_estimate, slow_job_warning
from camtube.plan.moves import FOCUS, LINK, RAPID, Moves, iter_moves, time_warning
from camtube.plan.packed import no_gc
from camtube.plan.safety import check_moves
from camtube.progress import NO_PROGRESS, Progress

#: Distinct (path, speed) blocks whose text is kept for reuse (bounds the memo's memory).
MEMO_MAX = 200_000
_REOPEN = "\x00"  # placeholder of a gate-on inside a pass (see _Emitter._rows)


def _header(job, dialect: Dialect, est) -> list[str]:
    pr = job.process
    c = dialect.comment_line
    ax, ay, az = dialect.axes
    wrap = (f"{ay} = degrees(y / r_o) deg, r_o = {fixed(job.outer_radius_mm)} mm" if dialect.rotary
            else f"{ay} = y mm (unrolled sheet)")
    lines = [
        c(f"camtube {__version__} job {job.name}, dialect {dialect.name}: {dialect.description}"),
        c(f"frame: {ax} = x mm from the tip, {wrap}, {az} = -focus offset into the material mm"),
        c(f"process: {fixed(pr.power_w)} W, {fixed(pr.frequency_khz)} kHz, {fixed(pr.scan_speed_mm_s)} mm/s on the "
          f"outer surface, {pr.drill_passes} drill cuts {fixed(pr.drill_offset_mm)} mm apart, defocus "
          f"{fixed(pr.defocus_mm)} mm, "
          f"{job.repeats} repeats, ordering {job.ordering}"),
        c(f"{est.cuts} cuts, {est.passes} passes, cut length {est.cut_length_mm:.3f} mm, estimated "
          f"{format_duration_s(est.total_s)}" + (f" on machine {est.machine}" if est.machine else "")
          + f", lower bound {format_duration_s(est.lower_bound_s)}, ratio {est.ratio:.4f}"),
    ]
    for warning in (time_warning(job, est), slow_job_warning(job, est, dialect.profile, short=True)):
        if warning:
            lines.append(c("WARNING: " + warning))
    return lines


class _Emitter:
    """Formats checked machine moves chunk after chunk; keeps the state that crosses chunks."""

    def __init__(self, job, dialect: Dialect, memo: bool) -> None:
        d = self.d = dialect
        self.job, self.memo = job, memo
        ax, ay, az = d.axes
        f = f"{{:.{d.decimals}f}}"
        ff = f"{{:.{d.feed_decimals}f}}"
        self.rapid = f"G0 {ax}{f} {ay}{f}".format
        self.focus = f"G0 {az}{f}".format
        self.feed = f"G1 {ax}{f} {ay}{f} F{ff}".format
        # the pass comment holds no parentheses, so it needs no escaping in either comment style
        lead, tail = ("(", ")") if d.comment == "paren" else ("; ", "")
        comment = (lead + "pass {}: cut {} {}, repeat {}, focus {} at {} mm, drill {} offset {:.4f} mm" + tail).format
        z_text: dict[float, str] = {}  # the focus depth as fixed(z) (never an exponent); two values per job

        def pass_comment(p, cut, kind, rep, foc, z, dri, off):
            t = z_text.get(z)
            if t is None:
                t = z_text[z] = fixed(z)
            return comment(p, cut, kind, rep, foc, t, dri, off)
        self.comment = pass_comment
        self.gates: dict[tuple[float, float, float], tuple[str, str]] = {}
        self.prev_key: tuple[float, float, float] | None = None
        self.blocks: dict[tuple[int, float], tuple[str, str, bool, bool]] = {}

    def _gate_on(self, key: tuple[float, float, float]) -> tuple[str, str]:
        """(settings lines where they change, the gate-on line).

        The settings (``M68`` on LinuxCNC) are not motion-synchronised: the controller stops to
        apply them, so they go before the pass's first feed move (before a lead-in, not between
        the lead-in and the edge it brings up to speed).
        """
        d = self.d
        g = self.gates.get(key)
        if g is None:
            fields = d.fields(*key, self.job.outer_radius_mm)
            g = self.gates[key] = ("".join(x.format(**fields) + "\n" for x in d.settings),
                                   d.laser_on.format(**fields))
        # power and frequency (and the dose, for a distance-gated laser) are written where they change
        same = self.prev_key is not None and (key == self.prev_key or (key[:2] == self.prev_key[:2]
                                                                       and not self.d.uses_speed))
        out = ("" if same else g[0]), g[1]
        self.prev_key = key
        return out

    def _rows(self, X, Y, Z, F, K, L, lo: int, hi: int, open_in: bool = False, open_out: bool = False
              ) -> tuple[str, str, bool, bool]:
        """Text of rows [lo, hi) of one pass: (before the first gate-on, after it, gate opened at all,
        gate opened again later).

        Starts with the gate closed and ends with it closed, except in a chain of linked passes:
        ``open_in`` (the pass is entered by a link: the gate is open and the path blended already)
        and ``open_out`` (the next pass is linked to this one: the beam-on run goes on). A later
        gate-on (after a lead move inside the pass) is the marker ``_REOPEN``, replaced by the
        pass's formatted ``laser_on`` in :meth:`chunk` (the text is shared by passes of any power).
        """
        d = self.d
        parts: list[str] = []
        before = None
        state = open_in
        blend_on, blend_off = d.blend_on, d.blend_off

        def run_ends(i: int) -> bool:  # row i is the last beam-on row of its beam-on run
            return (not open_out and i + 1 == hi) or (i + 1 < hi and not L[i + 1])

        for i in range(lo, hi):
            on = L[i]
            if on != state:
                if on and before is None:
                    before, parts = "".join(parts), []
                else:
                    parts.append((_REOPEN if on else d.laser_off) + "\n")
                state = on
                if on and blend_on is not None and not run_ends(i):
                    parts.append(blend_on + "\n")  # the beam-on run is one blended path ...
            if on and blend_off is not None and run_ends(i):
                parts.append(blend_off + "\n")  # ... that ends at rest, where the gate closes
            k = K[i]
            if k == RAPID:
                parts.append(self.rapid(X[i], Y[i]) + "\n")
            elif k == FOCUS:
                parts.append(self.focus(Z[i]) + "\n")
            else:
                parts.append(self.feed(X[i], Y[i], F[i]) + "\n")
        if state and not open_out:
            parts.append(d.laser_off)
            state = False
        text = "".join(parts)
        if before is None:
            return text.rstrip("\n"), "", False, False
        return before, text.rstrip("\n") if not state else text, True, _REOPEN in text

    def chunk(self, mm: MachineMoves) -> str:
        """G-code of the passes in ``mm`` (checked machine moves), ending with a newline."""
        n = mm.neutral
        if len(n) == 0:
            return ""
        pk = self.job.packed
        X, Y, Z, F = mm.ax.tolist(), mm.ay.tolist(), mm.az.tolist(), mm.feed.tolist()
        K, L = n.kind.tolist(), n.laser.tolist()
        rows = n.pass_rows().tolist()
        p0 = n.first_pass
        p1 = p0 + len(rows) - 1
        s = slice(p0, p1)
        cols = [pk.pass_cut[s], pk.pass_repeat[s], pk.pass_focus[s], pk.pass_z[s], pk.pass_drill[s],
                pk.pass_offset[s], pk.pass_geom[s], pk.pass_speed[s], pk.pass_power[s], pk.pass_freq[s]]
        # chains of linked passes (a pass whose first row is its LINK): entered with the gate open, left
        # with it open for the next pass; a chunk never ends inside a chain (plan.moves.iter_moves)
        link_in = [r0 < len(K) and K[r0] == LINK for r0 in rows[:-1]]
        link_out = link_in[1:] + [False]
        design = self.job.design
        comment, rapid, focus = self.comment, self.rapid, self.focus
        blocks, memo = self.blocks, self.memo
        out: list[str] = []
        for k, (cut, rep, foc, z, dri, off, geom, speed, pw, fq) in enumerate(zip(*(c.tolist() for c in cols))):
            r0, r1 = rows[k], rows[k + 1]
            text = [comment(p0 + k, cut, design[cut].kind, rep, foc, z, dri, off)]
            i = r0
            while i < r1 and K[i] in (RAPID, FOCUS) and not L[i]:  # the pass's leading rapid and focus rows
                text.append(rapid(X[i], Y[i]) if K[i] == RAPID else focus(Z[i]))
                i += 1
            chain = (bool(link_in[k]), bool(link_out[k]))
            if memo:
                # a linked pass's text starts with its link, whose feed depends on the path it comes from
                bkey = (geom, speed, int(pk.pass_geom[p0 + k - 1]) if chain[0] else -1, chain[1])
                blk = blocks.get(bkey)
                if blk is None:
                    blk = self._rows(X, Y, Z, F, K, L, i, r1, *chain)
                    if len(blocks) < MEMO_MAX:
                        blocks[bkey] = blk
            else:
                blk = self._rows(X, Y, Z, F, K, L, i, r1, *chain)
            before, after, opened, reopened = blk
            if opened:
                settings, gate_on = self._gate_on((pw, fq, speed))
                text.append(settings + before + gate_on)
                text.append(after.replace(_REOPEN, gate_on) if reopened else after)
            elif before:
                text.append(before)
            out.append("\n".join(text))
        return "\n".join(out) + "\n"


def _check_machine_moves(job, dialect: Dialect, mv: Moves, mm: MachineMoves) -> None:
    """The safety check of the moves as printed, plus the machine profile's own limits.

    Raises
    ------
    SafetyError
        A move leaves its cut (:func:`check_moves`); when only the printed moves do, the profile's
        ``decimals`` are named (the rounding moved the beam). The rotary axis leaves the profile's
        ``rotary_range_deg``.
    """
    from camtube.errors import SafetyError

    prof = dialect.profile
    where = (f"machine {prof.name}" + (f" ({prof.source})" if prof.source else "") if prof is not None
             else f"dialect {dialect.name}")
    if prof is not None and prof.rotary and prof.rotary_range_deg is not None and len(mm.ay):
        lo, hi = prof.rotary_range_deg
        eps = 0.5 * 10.0 ** -prof.decimals
        a = np.concatenate(([mm.start[1]], mm.ay))
        out = np.flatnonzero((a < lo - eps) | (a > hi + eps))
        if out.size:
            i = int(out[0])
            raise SafetyError(f"{job.name}: {where}: the job turns the rotary axis to A = {a[i]:.3f} deg, outside "
                              f"the stage's travel rotary_range_deg = [{lo:g}, {hi:g}] deg (camtube keeps A within "
                              "-180..540 deg); nothing was written; fix: set rotary_range_deg to the stage's real "
                              "travel, or use a machine whose rotary axis turns that far")
    try:
        check_moves(job, mm.unrolled())
    except SafetyError as exc:
        if prof is None:
            raise
        try:
            check_moves(job, mv)  # the moves before rounding: if they pass, the printed digits moved the beam
        except SafetyError:
            raise exc from None
        first = str(exc).splitlines()[0]
        raise SafetyError(f"{first}: {where}: coordinates printed with decimals = {prof.decimals} move the beam "
                          f"outside the cuts (by up to {0.5 * 10.0 ** -prof.decimals:g} mm or deg); fix: set "
                          "decimals: 6 in the machine profile") from None


def _chunks(job, moves) -> Iterable[Moves]:
    if moves is None:
        return iter_moves(job)
    return [moves] if isinstance(moves, Moves) else moves


def iter_gcode(job, dialect: Dialect = LINUXCNC, *, progress: Progress = NO_PROGRESS,
               moves: Moves | Sequence[Moves] | None = None, memo: bool = True) -> Iterator[str]:
    """Safety-checked G-code of ``job`` in ``dialect``, as consecutive text chunks.

    Parameters
    ----------
    job : Job
    dialect : Dialect
    progress : camtube.progress.Progress
        Reports one task, ``G-code <dialect>``, in passes.
    moves : Moves or sequence of consecutive Moves chunks, optional
        A move list to write instead of the job's own (a hand-edited one, e.g. with LEAD
        moves); it is checked and estimated like the job's. Each chunk holds whole passes
        (``Moves.rows`` at pass boundaries, ``Moves.pass_rows``).
    memo : bool
        Reuse the text of a path's moves for later passes over the same path at the
        same speed (identical rows by construction of :func:`~camtube.plan.moves.job_moves`);
        ``False`` formats every row. Always off for a given ``moves``.

    Raises
    ------
    SafetyError
        A chunk's emitted moves fail :func:`camtube.plan.safety.check_moves`; that chunk's
        text is never yielded (the file layer discards the partial file).
    """
    from camtube.machine.corners import strategy_moves

    if moves is None and dialect.profile is not None:
        moves = strategy_moves(job, dialect.profile)  # the profile's corner strategy (None: the job's moves)
    est = job_estimate(job, dialect, moves)
    yield "\n".join(_header(job, dialect, est) + list(dialect.preamble)) + "\n"
    em = _Emitter(job, dialect, memo and moves is None)
    with progress.task(f"G-code {dialect.name}", total=len(job.passes)) as task:
        for mv in _chunks(job, moves):
            mm = machine_moves(job, dialect, mv)
            _check_machine_moves(job, dialect, mv, mm)
            with no_gc():
                text = em.chunk(mm)
            rows = mv.pass_rows()
            task.advance(len(rows) - 1)
            yield text
    yield "\n".join(dialect.postamble) + "\n"


def gcode(job, dialect: Dialect = LINUXCNC, *, progress: Progress = NO_PROGRESS,
          moves: Moves | Sequence[Moves] | None = None, memo: bool = True) -> str:
    """Safety-checked G-code of ``job`` in ``dialect`` as one string (see :func:`iter_gcode`).

    Raises
    ------
    SafetyError
        The emitted moves fail :func:`camtube.plan.safety.check_moves`; no text is returned.
    """
    return "".join(iter_gcode(job, dialect, progress=progress, moves=moves, memo=memo))
