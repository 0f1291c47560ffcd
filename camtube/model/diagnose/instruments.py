"""The instruments before the physics: artefacts set aside, the logger's rates, the lag between channels.

``check_instruments(data, lag_ms=None) -> Instruments``

A diagnosis of the joint must not be a diagnosis of the sensors. Before any physics is fitted:

* **Spikes** (interference in the tracker or the load cell): a row outside the range of its two neighbours
  either side (same sample) by more than :data:`SPIKE_Z` noise scales; the scale is the median absolute
  row-to-row change (x 1.4826 / sqrt 2, robust to the spikes themselves). Turning points and kinks of the
  motion stay within their neighbours' range, so only isolated jumps qualify.
* **Bursts** (interference lasting several samples; a tracker that writes zeros while it has lost the sensor): a
  run of 2 to :data:`BURST_S` seconds of rows (at most :data:`BURST_ROWS`) that all lie on one side of the range
  of the two rows either side of the run, by more than :data:`SPIKE_Z` noise scales. A reversal of the motion
  puts the run's first and last rows within a row's change of the rows beside them, so it does not qualify.
  Interference lasting longer, up to :data:`LONG_BURST_S`, displaces the angle through a ramp, where the range
  test does not see it: a jump (a row-to-row change off the changes either side of it, by more than
  :data:`SPIKE_Z` noise scales, read on the rows not yet set aside) and the next jump, back by the same amount,
  set aside the rows between.
* **A frozen tracker**: :data:`FROZEN_REPEATS` or more rows in a row repeating the angle before them exactly while
  the stroke moves (more than :data:`FROZEN_STROKE` of the sample's stroke range across the run): the tracker
  held its last value; the repeats are set aside, the first value kept unless the angle jumped to it (a tracker
  that writes 0 while it has lost the sensor). A run the angle jumped to *and* jumped away from is set aside
  whole while the stroke rests too: a tracker writing 0 through a dwell at the top, where the joint stands bent
  (longer than a burst: 13 rows of 0 at 32 deg in one file of ``bench-heldout16`` doubled its RMSE).
* **A load cell at the end of its range**: the force repeating its sample's largest reading exactly, in a run of
  :data:`FROZEN_REPEATS` or more rows across which the stroke moves (by more than :data:`FROZEN_STROKE` of its
  range): the cell (or its amplifier) saturated, and the force it read is no longer the tension. Every row at that
  reading is set aside and the level is stated. A force quantised by the logger repeats its top value only where
  the stroke rests (a dwell), so it does not qualify.
* **The force ahead of the stroke**: a row where the stroke starts to move only after it (its step into the row at
  most :data:`AHEAD_STEP` of its step out) while the force has already changed the way that motion takes it (by
  more than :data:`SPIKE_Z` noise scales of the force at rest); or the first row at rest after a motion whose force
  jumps only into the next row, against the motion that ended. The drive moved by less than the stroke resolves,
  and something that switches at once (a guide's Coulomb friction) moved the tension: the row's stamp has no state a
  model can use, so it is set aside (:func:`_force_ahead`).
* **Repeated time stamps**: a row whose stamp equals the previous row's (the logger wrote one instant
  twice) is set aside. Rows whose stamp goes backwards, and rows with a missing value, are dropped when
  the file is read (:func:`camtube.model.data.read_measurements`), and counted there.
* **Rate changes**: the sampling interval's median over blocks of 200 rows; a block more than 20 % off the
  sample's median is reported (the rate is stated, nothing is set aside).
* **Lag of the angle channel** against the force (both see the same tendon tension; the drive, the tendon's
  slack, toe and creep sit upstream of both, so they do not shift one against the other). For a trial lag
  ``tau`` (whole rows: interpolating between rows averages the noise and favours half-row shifts) the
  angle is regressed, per sample, on the force ``tau`` earlier (smoothed by a centred running mean; the same
  angles for every trial, so an angle the check missed weighs on every shift alike):
  a cubic, a step and a hysteresis proportional to the force that flip with the direction of motion
  (friction in the joint, at the guide), the force times the guide's sliding state ``tanh(v / v_slip)`` to
  second order for two slip speeds and what it keeps at rest (a capstan whose friction develops with the
  tendon's speed changes the hysteresis smoothly at every start and stop, which a delay mimics: 40-85 ms false
  lags on the bench's friction files without these), and the force minus its low-passed copies with time constants of
  2, 8 and 32 s (a slow relaxation of the joint's backbone makes the angle follow the force's history: not
  a delay). The step also absorbs what a delay does at constant speed, so the lag is resolved by the parts
  of the record where the speed changes (ramps that start and stop smoothly, reversals, dwells); on a
  constant-speed triangle it is usually not resolved and not corrected. The lag minimising the residual
  is refined by a parabola through the best three shifts. A shift is of time, not of rows: a row whose trial
  shifts reach across rows set aside (a load cell at its limit sets aside a chunk of every cycle) is left out, the
  same rows for every shift; once corrected, a row whose angle a lag later was set aside is set aside too. Its
  standard error is the spread of the same estimate over blocks of cycles (``sd / sqrt(blocks)``, each block
  scanned 3 rows either side of the whole's lag); where half the blocks or more have their minimum at the edge of
  that window, they do not agree on a delay and it is not resolved. It is a property of the instruments: it is
  corrected (the angle read ``lag`` later) when it exceeds three standard errors and a quarter of the sampling
  interval, is a minimum inside the range tried (+-250 ms) and lowers the regression's residual RMS by
  :data:`MIN_FALL` (1 %), or when the user gives ``--lag-ms``, and it is never offered as an effect of the joint.
  Each sample's lag is also read on its own rows (two tubes logged in two sessions, each tracker's clock aligned on
  its own); where the samples differ by far more than their errors (:func:`estimate_lags`), each is corrected by
  its own (``--lag-ms S1=76,S2=0``). Where a load cell read its limit, those rows are set aside with the top of
  every stroke, the reversal and dwell where a delay shows most; the lag is then read again against the motor's
  stroke (logged with the force, whole on every row) over the rows kept and the limit's rows, and that reading is
  taken where it lowers its regression's residual by :data:`STROKE_LAG_FALL` and by more than the force's does
  (:func:`lag_at_limit`).
"""
from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field, replace
from typing import Mapping, Sequence

import numpy as np
import scipy.linalg

from camtube.errors import DataError
from camtube.model.core.params import DEFAULT_E_T_GPA
from camtube.model.core.threads import one_blas_thread
from camtube.model.data.dataset import SPEED_COLUMN, Dataset, Rests, at_bottom, rest_noise, rests_of

#: A row this many robust scales from its running median is a spike.
SPIKE_Z = 8.0
#: Neighbours either side whose range a row is compared with.
NEIGHBOURS = 2
#: A stroke spike lies beyond its neighbours' range by this share of the sample's stroke span too (:func:`stroke_spikes`).
STROKE_SPIKE_SPAN = 0.05
#: The longest burst (rows displaced together) set aside, in seconds of the sample's median interval ...
BURST_S = 0.5
#: ... and in rows.
BURST_ROWS = 50
#: The longest interference set aside as displaced together (s) when it is longer than a burst (:data:`BURST_S`):
#: a jump and a jump back by the same amount, within this time ...
LONG_BURST_S = 3.0
#: ... the jump back equal to the jump within this share of it ...
STEP_MATCH = 0.25
#: ... each jump read against the medians of this many row-to-row changes either side.
STEP_SIDE = 3
#: ... and besides that share, by this many noise scales (each size is read from one row's change: two noisy rows)
STEP_NOISE = 4.0
#: ... and with jumps between them only when those are smaller than this share of the first (see :func:`_paired_jumps`)
SMALLER_INSIDE = 0.5
#: Repeats of the angle before them, in a row, that make a frozen tracker ...
FROZEN_REPEATS = 4
#: ... while the stroke moves by this share of the sample's stroke range across them.
FROZEN_STROKE = 0.01
#: A row where the motion starts (the stroke's step into it at most this share of its step out) whose force has
#: already moved with that motion, by more than :data:`SPIKE_Z` noise scales at rest, is a row the load cell read
#: after the drive moved (see :func:`_force_ahead`) ...
AHEAD_STEP = 0.1
#: ... and the first row at rest after a motion whose force jumps only into the next row (by this many times its
#: changes either side) is one where the stroke's log had stopped before the carriage did.
AHEAD_OUT = 2.0
#: The largest ``--lag-ms`` taken (ms): a tracker's delay is tens of milliseconds; more is clocks not aligned.
MAX_GIVEN_LAG_MS = 2000.0
#: A lag is corrected only when it lowers the residual RMS of the lag regression by this fraction. (2 % while the
#: regression shifted the angle, whose noise then differed from shift to shift; with the same angles at every shift
#: a lag of one row at 40 Hz lowers it by 1.1-2.0 %, and no file of 41 with a guide's friction and no lag by more
#: than 0.7 %, over the bench batches to bench-heldout25)
MIN_FALL = 0.01
#: A lag the regression resolves but barely improves with (below :data:`MIN_FALL`) is corrected when it lowers the
#: current model's RMSE by this fraction (:func:`confirm_lag`) ...
MODEL_LAG_FALL = 0.05
#: ... and that model is within this many times the angle's white noise and the misfit the estimated lag itself
#: leaves (:func:`lag_misfit_deg`), taken together, without it (a model that misfits more than that would take a
#: shift of the angle for any missing effect with a history).
MODEL_LAG_MAX_RATIO = 3.0
#: Window (s) of the filter that reads the angle's rate for :func:`lag_misfit_deg`: several rows at 25-100 Hz, short
#: against a ramp.
LAG_RATE_WINDOW_S = 0.25
#: A sample logged more slowly than this (Hz) gets a line that asks whether its time stamps are in ms (a bench logs at
#: 25-100 Hz; time in ms read as s is 0.025-0.1 Hz).
SLOW_RATE_HZ = 1.0
#: A sampling interval this far off the sample's median is a rate change.
RATE_CHANGE = 0.2


@dataclass(frozen=True, eq=False)
class Lag:
    """Lag of the angle channel behind the force channel.

    Attributes
    ----------
    lag_ms, se_ms : float
        Estimate and its standard error (ms); positive: the angle is late.
    given : bool
        The user gave the lag (``--lag-ms``): no estimate.
    applied_ms : float
        The lag corrected (0 when none was).
    fall : float
        Relative fall of the residual RMS of the lag regression from no lag to the estimate.
    model_rmse_deg : tuple
        ``(without, with)``: the current model's RMSE without the lag and with the lag applied, when the model
        confirmed a lag the regression resolved but did not lower enough (:func:`confirm_lag`); else empty.
    per_sample : tuple
        ``(sample, lag_ms, se_ms, fall, applied_ms)`` for each sample when the samples' lags differ
        (:func:`estimate_lags`: two tubes logged in two sessions, each with its own alignment of the tracker's
        clock), each corrected on its own; empty when one lag serves every sample (``lag_ms``, ``applied_ms``).
        With them, ``model_rmse_deg`` is ``((sample, without, with), ...)`` for the samples whose lag the current
        model confirmed (:func:`confirm_lag`).
    own : tuple
        ``(sample, lag_ms, se_ms, fall)``: each sample's lag estimated on its own rows (several samples, each
        resolved; else empty).
    against : str
        The channel the angle was read against: ``"force"``, or ``"stroke"`` where a load cell at its limit set aside
        the top of every stroke (:func:`lag_at_limit`).
    """

    lag_ms: float
    se_ms: float
    given: bool = False
    applied_ms: float = 0.0
    fall: float = 0.0
    model_rmse_deg: tuple = ()
    per_sample: tuple = ()
    own: tuple = ()
    against: str = "force"

    def applied_for(self, sample: str) -> float:
        """The lag corrected in ``sample`` (ms): its own where the samples' lags differ, else :attr:`applied_ms`."""
        for smp, _, _, _, applied in self.per_sample:
            if smp == sample:
                return applied
        return self.applied_ms

    @property
    def corrected(self) -> bool:
        """A lag was corrected in some sample."""
        return bool(self.applied_ms) or any(p[4] for p in self.per_sample)

    def as_option(self) -> str:
        """The correction as ``--lag-ms`` takes it: ``20`` for every sample, ``S1=76,S2=0`` one per sample."""
        if self.per_sample:
            return ",".join(f"{smp}={applied:.6g}" for smp, _, _, _, applied in self.per_sample)
        return f"{self.applied_ms:.6g}"


#: The load cell's zero, read at the rests: a drift is corrected when it exceeds this many standard errors ...
ZERO_Z = 5.0
#: ... the rests scatter about its line by at most this share of it (a zero drifts smoothly; a tendon held taut at
#: some rests and not at others does not) ...
ZERO_SMOOTH = 0.25
#: ... and no step from one rest to the next (each the median of it and its neighbours) exceeds this share of it: a
#: zero drifts a little each cycle (at most 0.22 of the whole drift in one step on the bench batches), while a
#: carriage its rail holds at some rests puts the tendon's held tension at rest in one step (0.63-1.05 of it)
ZERO_JUMP = 0.4
#: ... and the first rests read within this share of it (plus two scatters) of zero: the cell was zeroed before the
#: test, so a force that stays at rest is a taut tendon (or an offset the model's force_zero takes), not a drift.
ZERO_START = 0.25
#: Fewest rests (runs of rows at the bottom of the stroke) a sample needs for its zero to be read.
MIN_RESTS = 6
#: The rests read below zero when their median is below zero by this many of the cell's row-to-row noise at rest: no
#: tension (a tendon cannot push), so the cell's own zero (:attr:`Zero.below_zero`).
BELOW_ZERO_NOISE = 5.0
#: A force above zero at the rests is the cell's zero, not a tendon held taut, where the joint there is nearly straight:
#: bent by less than this share of what that force bends it by as tension (its angle against the force on the pulls;
#: a tendon a carriage holds taut at rest bends it by 1.0-2.0x that on the bench's lost-motion files: the unloading
#: branch's hysteresis; a backbone's relaxation or a tracker's drift bend it by 0.02-0.15x beside a cell 0.35-1.4 N
#: high on bench-heldout41) ...
STRAIGHT_SHARE = 0.25
#: ... and that bend is this many times the tracker's noise at rest (else the two cannot be told apart).
STRAIGHT_NOISE = 10.0
#: Fewest rows before the first pull (from the sample's first row, the stroke at the bottom of its span) for the cell's
#: reading there to be read (:attr:`Zero.offset_at_start`; a record that starts with the motor's ramp has two to four
#: rows before the stroke leaves the bottom 0.1 % of its span on the bench batches).
MIN_FIRST_ROWS = 2
#: The rests' line, taken back to the rows before the first pull, reads above the reading there by this many of the
#: cell's row-to-row noise (and two of the rests' scatters): a tension held at rest (a carriage its rail holds) beside a
#: cell not zeroed (:attr:`Zero.held_beside_offset`).
HELD_ABOVE_NOISE = 5.0


@dataclass(frozen=True, eq=False)
class Zero:
    """The load cell's reading at the rests (motor at the bottom of its stroke, tendon slack), one sample.

    Attributes
    ----------
    n_rests : int
    start_N, end_N : float
        The median reading of the first and of the last three rests.
    change_N, se_N : float
        The change of the line through the rests' readings over the sample's record, and its standard error.
    scatter_N : float
        The rests' scatter about that line.
    jump_N : float
        The largest step from one rest's reading to the next (each the median of it and its neighbours).
    rest_deg, implied_deg, angle_noise_deg : float
        The joint's angle at the rests; the bend the rests' reading gives as tension (the angle's slope against the
        force on the pulls times that reading); the tracker's row-to-row noise at rest.
    slope_deg_per_N : float
        That slope (0 where the pulls do not give it).
    first_rows : int
        Rows before the first pull (the stroke at the bottom of its span from the sample's first row); 0 where there
        are fewer than :data:`MIN_FIRST_ROWS` (then ``first_N`` and ``first_deg`` are nan).
    first_N, first_deg : float
        The median force and angle there: the joint never loaded yet.
    rests_at_first_N : float
        The line through the rests' readings (``change_N``'s) at the time of those rows: where the zero drifts, what
        the rests read there.
    first_cycle : int
        The cycle the sample's rows begin with: past 1 (a ``--cycles`` selection, a log that starts late), the joint
        was loaded before those rows, and the words say so.
    row_noise_N : float
        The load cell's noise from row to row at rest.
    applied : bool
        Corrected: the force re-zeroed at every rest (:func:`rezero_force`).
    rests : Rests or None
        The readings it was read from (kept for :func:`rezero_force`).
    """

    n_rests: int
    start_N: float
    end_N: float
    change_N: float
    se_N: float
    scatter_N: float
    row_noise_N: float
    jump_N: float = 0.0
    applied: bool = False
    rests: Rests | None = None
    rest_deg: float = 0.0
    implied_deg: float = 0.0
    angle_noise_deg: float = 0.0
    slope_deg_per_N: float = 0.0
    first_rows: int = 0
    first_N: float = math.nan
    first_deg: float = math.nan
    rests_at_first_N: float = math.nan
    first_cycle: int = 1
    wander_N: float = 0.0
    local_N: float = 0.0

    @property
    def drifts(self) -> bool:
        """A drift resolved beyond :data:`ZERO_Z` standard errors and the cell's row noise."""
        return abs(self.change_N) > ZERO_Z * self.se_N and abs(self.change_N) > self.row_noise_N

    @property
    def smooth(self) -> bool:
        return self.scatter_N <= ZERO_SMOOTH * abs(self.change_N) and self.jump_N <= ZERO_JUMP * abs(self.change_N)

    @property
    def zeroed(self) -> bool:
        return abs(self.start_N) <= ZERO_START * abs(self.change_N) + 2.0 * self.scatter_N

    @property
    def level_N(self) -> float:
        """The rests' median reading (0 without rests)."""
        return float(np.median(self.rests.force_N)) if self.rests is not None and self.rests.force_N.size else 0.0

    @property
    def wanders(self) -> bool:
        """The zero moves away and back: the rests (each the median of it and its neighbours) leave the line through
        them by more than :data:`ZERO_Z` of their rest-to-rest noise (``local_N``, from second differences, which a
        smooth drift leaves out) and the cell's row noise, with no step from one rest to the next above
        :data:`ZERO_JUMP` of that excursion. (A zero 0.11 N up and back to zero over the record has no line to speak
        of: it was read as steady, and 4.4x the floor was left; an independent bench simulator.)"""
        return (self.wander_N > ZERO_Z * self.local_N and self.wander_N > self.row_noise_N
                and self.jump_N <= ZERO_JUMP * self.wander_N)

    @property
    def drift_corrected(self) -> bool:
        """A drift of a cell zeroed before the test, smooth (along a line, or away and back): corrected
        (:func:`rezero_force`)."""
        return (self.drifts and self.smooth and self.zeroed) or (
            self.wanders and abs(self.start_N) <= ZERO_START * self.wander_N + 2.0 * self.local_N)

    @property
    def rezeroes(self) -> bool:
        """The cell's zero is taken off (:func:`rezero_force`): read before the first pull (:attr:`offset_at_start`),
        or at the rests: a drift corrected, rests below zero, or a nearly straight joint at rests that read above
        zero."""
        return self.offset_at_start or self.drift_corrected or self.below_zero or self.unloaded_offset

    @property
    def first_implied_deg(self) -> float:
        """The bend the reading before the first pull gives as tension (the pulls' slope times it; 0 below zero)."""
        return self.slope_deg_per_N * max(self.first_N, 0.0) if self.first_rows else 0.0

    @property
    def offset_at_start(self) -> bool:
        """Before the first pull the cell reads off zero where no tension can be: below zero beyond
        :data:`BELOW_ZERO_NOISE` x its noise (a tendon cannot push), or above it with the joint straight there (bent by
        less than :data:`STRAIGHT_SHARE` of what that reading bends it by as tension, which is :data:`STRAIGHT_NOISE` x
        the angle's standard error there, the tracker's noise over the square root of the rows: a preload bends it;
        bench-heldout44's creep file, a cell 0.21 N high, bends it by 2.0 deg, 10x the tracker's noise in a row but
        16x that standard error over its 4 rows). The joint has never been loaded there, so neither a backbone's
        relaxation or set nor a carriage its rail holds can be what the rests show instead: the reading is the
        cell's zero (not zeroed before the test), also where the joint rests bent later."""
        if self.first_rows < MIN_FIRST_ROWS:
            return False
        noise = BELOW_ZERO_NOISE * self.row_noise_N
        if self.first_N < -noise:
            return True
        se_deg = self.angle_noise_deg / math.sqrt(self.first_rows)
        return (self.first_N > noise and self.first_implied_deg > STRAIGHT_NOISE * se_deg
                and abs(self.first_deg) < STRAIGHT_SHARE * self.first_implied_deg)

    @property
    def held_beside_offset(self) -> bool:
        """:attr:`offset_at_start`, and the rests read above that zero by more than :data:`HELD_ABOVE_NOISE` x the
        cell's noise plus two of their scatters about their line, that line taken back to the rows before the first
        pull (a zero drifting from the offset reads the offset there: a cell drifting 2 N/h from 0.08 N high read
        0.017 N above it at its first three rests already): a tension held at rest (a carriage its rail holds: lost
        motion in the drive) beside the cell's offset. The offset read before the first pull is taken off throughout
        and the held tension stays (the rests are not the zero)."""
        return (self.offset_at_start and self.rests_at_first_N - self.first_N
                > HELD_ABOVE_NOISE * self.row_noise_N + 2.0 * self.scatter_N)

    @property
    def below_zero(self) -> bool:
        """The rests read below zero beyond the cell's noise (:data:`BELOW_ZERO_NOISE`): a tendon cannot push, so no
        tension reads so; the cell was not zeroed (or its zero drifted down), and the rests measure its zero."""
        return self.level_N < -BELOW_ZERO_NOISE * self.row_noise_N

    @property
    def unloaded_offset(self) -> bool:
        """The rests read above zero (beyond :data:`BELOW_ZERO_NOISE` x the cell's noise) while the joint there is
        nearly straight: bent by less than :data:`STRAIGHT_SHARE` of what that reading bends it by as tension (which
        is :data:`STRAIGHT_NOISE` x the tracker's noise). No tension holds it: the reading is the cell's zero (not
        zeroed before the test; drifting or not). A tendon a carriage holds taut at rest bends the joint as its
        tension does: its reading stays. Beside a cell not zeroed, a held tension under a quarter of the reading is
        taken for the zero too (the limit: the reading at rest cannot be split between them)."""
        return (self.level_N > BELOW_ZERO_NOISE * self.row_noise_N
                and self.implied_deg > STRAIGHT_NOISE * self.angle_noise_deg
                and self.rest_deg < STRAIGHT_SHARE * self.implied_deg)

    @property
    def held(self) -> bool:
        """The force stays well above the cell's noise at rest, steadily: a taut tendon (or an offset)."""
        return abs(self.start_N) > 5.0 * self.row_noise_N and not self.drifts


def _rest_medians(z: np.ndarray) -> np.ndarray:
    """Each rest's reading as the median of it and its neighbours' (one odd rest does not move the zero)."""
    return np.array([float(np.median(z[max(i - 1, 0):i + 2])) for i in range(z.size)])


def read_zero(data: Dataset) -> dict:
    """``{sample: Zero}``: the load cell's reading at each sample's rests (samples with too few rests left out)."""
    out = {}
    for smp, sl in data.sample_slices():
        rests = rests_of(data, sl)
        if len(rests.runs) < MIN_RESTS:
            continue
        z, t = rests.force_N, rests.time_s
        dt = t - t.mean()
        sxx = float(dt @ dt)
        if sxx <= 0.0:
            continue
        b = float(dt @ (z - z.mean())) / sxx
        resid = z - z.mean() - b * dt
        scatter = float(np.sqrt(resid @ resid / max(z.size - 2, 1)))
        span = float(t[-1] - t[0])
        jump = float(np.max(np.abs(np.diff(_rest_medians(z))))) if z.size > 1 else 0.0
        first = _before_first_pull(data, sl)
        if first:
            first["rests_at_first_N"] = float(z.mean() + b * (first.pop("first_time_s") - t.mean()))
        # away from the line and back: the rests' medians about it, and their noise from rest to rest
        wander = float(np.max(np.abs(_rest_medians(z) - z.mean() - b * dt))) if z.size > 2 else 0.0
        d2 = z[2:] - 2.0 * z[1:-1] + z[:-2]
        local = float(1.4826 * np.median(np.abs(d2 - np.median(d2))) / math.sqrt(6.0)) if d2.size else 0.0
        out[smp] = Zero(z.size, float(np.median(z[:3])), float(np.median(z[-3:])), b * span,
                        scatter / math.sqrt(sxx) * span, scatter, rests.row_noise_N, jump, rests=rests,
                        **_bend_at_rest(data, sl, rests), **first, wander_N=wander, local_N=local)
    return out


def _before_first_pull(data: Dataset, sl: slice) -> dict:
    """``first_rows``, ``first_N``, ``first_deg``, ``first_time_s`` of one sample: the rows from its first while the
    stroke stays at the bottom of its span (:func:`~camtube.model.data.dataset.at_bottom`, as a rest's), and the
    median force, angle and time there (none: an empty dict)."""
    s = np.asarray(data.stroke_mm[sl], float)
    if s.size < 2:
        return {}
    moved = np.flatnonzero(~at_bottom(s))
    k = int(moved[0]) if moved.size else 0
    if k < MIN_FIRST_ROWS:
        return {}
    return {"first_rows": k, "first_N": float(np.median(data.force_N[sl][:k])),
            "first_deg": float(np.median(data.angle_deg[sl][:k])), "first_time_s": float(np.median(data.time_s[sl][:k])),
            "first_cycle": int(data.cycle[sl][0])}


def _bend_at_rest(data: Dataset, sl: slice, rests: Rests) -> dict:
    """``rest_deg`` (the joint's median angle at the rests), ``implied_deg`` (the bend the rests' median reading gives
    as tension: the slope of the angle against the force on the pulls, between 20 and 80 % of the force's rise above
    that reading, times the reading) and ``angle_noise_deg`` (the tracker's row-to-row noise at rest) of one sample."""
    angle = np.asarray(data.angle_deg, float)
    a, f = angle[sl], np.asarray(data.force_N[sl], float)
    level = float(np.median(rests.force_N))
    top = float(np.percentile(f, 99))
    pull = (np.asarray(data.direction[sl]) > 0) & (f > level + 0.2 * (top - level)) & (f < level + 0.8 * (top - level))
    slope = 0.0
    if pull.sum() >= 20 and top > level:
        slope = max(float(np.polyfit(f[pull], a[pull], 1)[0]), 0.0)
    return {"rest_deg": float(np.median(angle[np.concatenate(rests.runs)])), "implied_deg": slope * max(level, 0.0),
            "angle_noise_deg": rest_noise(angle, rests.runs), "slope_deg_per_N": slope}


def rezero_force(data: Dataset, zeros: dict) -> tuple[Dataset, dict]:
    """``data`` with the load cell's zero taken off in the samples where :attr:`Zero.rezeroes`, and ``zeros`` with
    ``applied`` set: re-zeroed at every rest where the rests are the zero (a zero that drifts smoothly from a cell
    zeroed before the test; rests below zero; rests above zero with the joint nearly straight; a cell that read off
    zero before the first pull, as the rests do), the zero between two rests interpolated in time (each rest's reading
    the median of it and its neighbours'), held before the first and after the last; the reading before the first
    pull taken off throughout where the rests hold a tension above it (:attr:`Zero.held_beside_offset`)."""
    force = data.force_N.copy()
    out = dict(zeros)
    for smp, sl in data.sample_slices():
        zr = zeros.get(smp)
        if zr is None or not zr.rezeroes:
            continue
        if zr.held_beside_offset:   # the zero read before the first pull; the rests hold a tension above it
            force[sl] = data.force_N[sl] - zr.first_N
        else:
            force[sl] = data.force_N[sl] - np.interp(data.time_s[sl], zr.rests.time_s, _rest_medians(zr.rests.force_N))
        out[smp] = replace(zr, applied=True)
    if not any(z.applied for z in out.values()):
        return data, out
    return data.with_force(force), out


def zero_lines(zeros: dict, enabled: bool, option: str = "--no-rezero to keep it") -> list[str]:
    """The load cell's zero at the rests, one sentence per finding (``option``: how the user turns the correction
    off, or asked for it)."""
    if not zeros:
        return []
    out = []
    fixed = {s: z for s, z in zeros.items() if z.applied}
    for smp, z in fixed.items():
        if z.offset_at_start:
            why = (f"below zero by more than {BELOW_ZERO_NOISE:g}x its noise ({z.row_noise_N:.2g} N): a tendon cannot "
                   "push" if z.first_N < 0.0 else
                   f"with the joint straight ({z.first_deg:.2g} deg; that force bends it by {z.first_implied_deg:.2g} "
                   "deg on the pulls): no tension holds it")
            start = (f"load cell zero: before {smp}'s first pull (motor at zero, the joint never loaded) the force "
                     if z.first_cycle <= 1 else
                     f"load cell zero: before {smp}'s first pull in these rows (they begin with cycle {z.first_cycle}: "
                     "the joint was loaded in the cycles before; motor at zero) the force ")
            start += f"reads {z.first_N:.3g} N, {why}, so that is the cell's zero (not zeroed before the test); "
            if z.held_beside_offset:
                out.append(start + f"taken off throughout. At the rests it reads {z.start_N:.3g} N at the start and "
                           f"{z.end_N:.3g} N at the end, {z.rests_at_first_N - z.first_N:.3g} N above that zero: a "
                           f"tension held at rest (a carriage its rail holds: lost motion in the drive), kept ({option})")
            else:
                out.append(start + f"the rests' line reads {z.rests_at_first_N:.3g} N there ({z.start_N:.3g} N at the "
                           f"first rests, {z.end_N:.3g} N at the last): corrected, the force re-zeroed at every rest "
                           f"({option})")
            continue
        if z.unloaded_offset and not z.drift_corrected and not z.below_zero:
            out.append(f"load cell zero: at {smp}'s rests (motor at zero) the force reads {z.start_N:.3g} N at the "
                       f"start and {z.end_N:.3g} N at the end while the joint there is nearly straight "
                       f"({z.rest_deg:.2g} deg; that force bends it by {z.implied_deg:.2g} deg on the pulls): no tension "
                       f"holds it, so that is the cell's zero (not zeroed before the test); corrected, the force "
                       f"re-zeroed at every rest ({option})")
            continue
        if not z.drift_corrected:   # re-zeroed for reading below zero at the rests
            out.append(f"load cell zero: at {smp}'s rests (motor at zero, tendon slack) the force reads "
                       f"{z.start_N:.3g} N at the start and {z.end_N:.3g} N at the end, below zero by more than "
                       f"{BELOW_ZERO_NOISE:g}x its noise ({z.row_noise_N:.2g} N): a tendon cannot push, so that is "
                       f"the cell's zero (not zeroed before the test, or drifting); corrected, the force re-zeroed "
                       f"at every rest ({option})")
            continue
        if not (z.drifts and z.smooth and z.zeroed):   # away and back
            out.append(f"load cell zero: at {smp}'s rests (motor at zero, tendon slack) the force moves away and back "
                       f"({z.start_N:.3g} N at the start, {z.end_N:.3g} N at the end, up to {z.wander_N:.3g} N off that "
                       f"line, smoothly from rest to rest: {z.wander_N / max(z.local_N, 1e-300):.0f}x their noise): the "
                       "load cell's zero wanders (an instrument's, not the tendon's); corrected, the force re-zeroed at "
                       f"every rest ({option})")
            continue
        out.append(f"load cell zero: at {smp}'s rests (motor at zero, tendon slack) the force moves from "
                   f"{z.start_N:.3g} to {z.end_N:.3g} N, a drift of {z.change_N:+.3g} N over the record "
                   f"({abs(z.change_N) / max(z.se_N, 1e-300):.0f} standard errors): the load cell's zero drifts (an "
                   "instrument's, not the tendon's: creep lengthens the tendon and leaves the force at rest at zero); "
                   f"corrected, the force re-zeroed at every rest ({option})")
    for smp, z in zeros.items():
        if z.applied:
            continue
        if z.drifts and not enabled:
            out.append(f"load cell zero: at {smp}'s rests the force moves from {z.start_N:.3g} to {z.end_N:.3g} N "
                       f"({z.change_N:+.3g} N): not corrected (--no-rezero)")
        elif z.drifts and not z.smooth:
            out.append(f"load cell zero: at {smp}'s rests (motor at zero) the force changes from rest to rest "
                       f"({z.scatter_N:.3g} N about its trend of {z.change_N:+.3g} N, up to {z.jump_N:.3g} N from one "
                       "rest to the next): not a drifting zero; a "
                       "tendon held taut at some rests (a carriage its rail holds within the nut's gap: lost motion "
                       "in the drive) would do it; not corrected")
        elif z.drifts:
            out.append(f"load cell zero: at {smp}'s rests (motor at zero) the force reads {z.start_N:.3g} N at the "
                       f"start and {z.end_N:.3g} N at the end: not corrected, the cell does not read zero at the "
                       "first rests (a tendon held taut at rest, a preload, or a cell not zeroed); re-zero it with "
                       "the tendon unloaded before and after the test to tell")
        elif z.held:
            out.append(f"load cell at rest: {smp}'s force stays at {z.start_N:.3g} N at every rest with the motor at "
                       "zero: the tendon is held taut at rest (a carriage its rail holds within the nut's gap: lost "
                       "motion in the drive; a preload), or the cell is not zeroed; a displacement gauge on the "
                       "carriage, or a reading with the tendon unhooked, tells")
    if not out:
        out.append("load cell zero: steady at the rests (" + ", ".join(
            f"{smp} {z.start_N:.2g} to {z.end_N:.2g} N" for smp, z in zeros.items()) + "): none to correct")
    return out


@dataclass(frozen=True, eq=False)
class Instruments:
    """What the instruments did (:func:`check_instruments`).

    Attributes
    ----------
    data : Dataset
        The rows kept, the angle corrected for the lag.
    raw : Dataset
        The rows as read.
    aside : dict[str, (k,) int]
        Rows of ``raw`` set aside, by reason (``"angle spike"``, ``"force spike"``, ``"repeated time stamp"``; and
        where found ``"angle burst row"``, ``"force burst row"``, ``"frozen angle row"``, ``"load cell limit
        row"``, ``"force ahead of the stroke row"``).
    kept : (n_raw,) bool
        Rows of ``raw`` kept in ``data``.
    rates_hz : dict[str, float]
        Each sample's median sampling rate.
    rate_changes : tuple[str, ...]
        Sentences on blocks sampled at another rate.
    lag : Lag
    dropped : str
        The reader's line on rows dropped (missing values, backward stamps), or ``""``.
    n_dropped : int
    zeros : dict
        Each sample's load-cell zero read at the rests (:func:`read_zero`).
    rezero : bool
    limits : dict[str, (float, int)]
        Each sample whose load cell read the end of its range: ``(reading N, rows)`` (:func:`_saturated`).
    """

    data: Dataset
    raw: Dataset
    aside: dict
    kept: np.ndarray
    rates_hz: dict
    rate_changes: tuple
    lag: Lag
    dropped: str = ""
    n_dropped: int = 0
    zeros: dict = field(default_factory=dict)
    rezero: bool = True
    limits: dict = field(default_factory=dict)

    @property
    def rezeroed(self) -> bool:
        """The force was re-zeroed at the rests in some sample."""
        return any(z.applied for z in self.zeros.values())

    @property
    def n_aside(self) -> int:
        return int((~self.kept).sum())

    def lines(self) -> list[str]:
        """The instruments' findings, one sentence each."""
        out = []
        if self.dropped:
            out.append(self.dropped)
        parts = [f"{len(v)} {k}{'s' if len(v) != 1 else ''}" for k, v in self.aside.items() if len(v)]
        n_raw = len(self.raw)
        if parts:
            out.append(f"set aside before fitting: {self.n_aside} of {n_raw} rows ({', '.join(parts)})")
        else:
            out.append(f"set aside before fitting: none of {n_raw} rows (no spikes, no repeated time stamps)")
        if self.limits:
            out.append("load cell at the end of its range: " + ", ".join(
                f"{smp} reads {v:.4g} N in {k} rows while the stroke goes on" for smp, (v, k) in self.limits.items())
                + ": those rows are set aside (the force there is not the tension); a cell of larger range, or a "
                  "smaller stroke, measures them")
        ahead = self.aside.get("force ahead of the stroke row", ())
        if len(ahead):
            out.append(f"force ahead of the stroke: in {len(ahead)} row(s) the load cell and the stroke disagree on "
                       "when the drive started or stopped (the tension jumped a row before the stroke moved, or a row "
                       "after it stopped: the drive moved by less than the stroke resolves, and something that "
                       "switches at once with the motion, such as a guide's Coulomb friction, moved the tension); no "
                       "model of the rows' stamps fits them, so they are set aside; a stroke logged at a finer "
                       "resolution, or at the load cell's instant, measures them")
        out.append("sampling: " + ", ".join(f"{s} {r:.4g} Hz" for s, r in self.rates_hz.items()))
        slow = slow_sampling_line(self.rates_hz)
        if slow:
            out.append(slow)
        out.extend(self.rate_changes)
        out.extend(zero_lines(self.zeros, self.rezero))
        lg = self.lag
        ref = "the load cell" if lg.against == "force" else "the motor's stroke"
        if lg.against == "stroke":
            out.append("angle lag read against the motor's stroke: the load cell's limit set aside the top of every "
                       f"stroke, where a delay shows most, and the stroke's reading lowers its regression's residual "
                       f"by {100 * lg.fall:.1f} % (at least {100 * STROKE_LAG_FALL:g} %, and more than the force's)")
        if lg.per_sample:
            out.append(_per_sample_lag_line(lg, self.rates_hz))
        elif lg.given:
            out.append(f"angle lag: {lg.lag_ms:.4g} ms as given (--lag-ms); the angle is read {lg.applied_ms:.4g} ms "
                       "later (whole rows)")
        elif lg.applied_ms and lg.model_rmse_deg:
            out.append(f"angle lag: the tracker lags {ref} by {lg.lag_ms:.3g} +- {lg.se_ms:.2g} ms "
                       f"(an instrument property, not the joint's); the lag regression alone barely improves with "
                       f"it ({100 * lg.fall:.1f} % < {100 * MIN_FALL:g} %), the current model's RMSE falls from "
                       f"{lg.model_rmse_deg[0]:.3f} to {lg.model_rmse_deg[1]:.3f} deg with it: corrected, the "
                       f"angle is read {lg.applied_ms:.3g} ms later (whole rows; --lag-ms 0 to keep it)")
        elif lg.applied_ms:
            out.append(f"angle lag: the tracker lags {ref} by {lg.lag_ms:.3g} +- {lg.se_ms:.2g} ms "
                       f"(an instrument property, not the joint's); corrected: the angle is read {lg.applied_ms:.3g}"
                       " ms later (whole rows; --lag-ms 0 to keep it)")
        else:
            out.append(f"angle lag: {lg.lag_ms:.2g} +- {lg.se_ms:.2g} ms against {ref}: none to correct"
                       if math.isfinite(lg.se_ms) else "angle lag: not resolved by these data (no minimum within "
                       "+-250 ms, or half the blocks of cycles with their minimum more than 3 rows from the "
                       "whole's): none corrected; give --lag-ms if it is known")
        return out


def _per_sample_lag_line(lg: Lag, rates_hz: Mapping[str, float]) -> str:
    """The findings' line on a lag that differs between the samples (each corrected on its own; a sample whose own
    lag is unresolved, :func:`_resolved` at its rate ``rates_hz``, only by the lag another sample shows)."""
    if lg.given:
        return ("angle lag, per sample as given (--lag-ms): "
                + ", ".join(f"{smp} read {applied:.4g} ms later" for smp, _, _, _, applied in lg.per_sample)
                + " (whole rows)")
    by_model = {smp: (a, b) for smp, a, b in lg.model_rmse_deg}

    def anothers(smp: str, ms: float, applied: float, row_ms: float) -> bool:
        """The lag corrected in ``smp`` is another sample's, beyond the rows its own estimate was tried at (its
        whole rows and one either side, :func:`_model_lag`)."""
        return row_ms > 0.0 and abs(applied / row_ms - round(ms / row_ms)) > 1.0 + 1e-9 and any(
            abs(a - applied) <= 0.5 * row_ms for o, _, _, _, a in lg.per_sample if o != smp)

    def how(smp: str, ms: float, se: float, applied: float) -> str:
        if not applied:
            return ", none to correct"
        row_ms = 1e3 / rates_hz[smp] if rates_hz.get(smp) else 0.0
        if not _resolved(ms, se, row_ms):
            what = ", unresolved, corrected by the lag another sample shows"
        elif anothers(smp, ms, applied, row_ms):
            what = ", corrected by the lag another sample shows, which the model fits better than its own"
        else:
            what = ", corrected"
        return what + f": read {applied:.3g} ms later"

    each = "; ".join(f"{smp} {ms:.3g} +- {se:.2g} ms" + how(smp, ms, se, applied)
                     + (f" (the current model's RMSE in {smp} falls from {by_model[smp][0]:.3f} to "
                        f"{by_model[smp][1]:.3f} deg with it)" if smp in by_model else "")
                     for smp, ms, se, _, applied in lg.per_sample)
    return (f"angle lag: differs between the samples ({each}; one lag over all of them reads {lg.lag_ms:.2g} ms): an "
            "instrument property, not the joint's (each sample's tracker clock aligned to the load cell's on its "
            f"own); --lag-ms {lg.as_option()} gives the same, --lag-ms 0 keeps the angle as logged")


def _noise_scale(v: np.ndarray, limit: np.ndarray | None = None) -> float:
    """The white-noise scale of ``v`` from its row-to-row changes: ``1.4826 MAD(diff v) / sqrt(2)`` (robust to
    spikes and to the motion's steady changes); ``limit`` (bool, as ``v``), rows of a load cell at its limit, whose
    changes are left out: they are exactly 0 (a cell at its limit in half the rows read a scale near 0, and 809 rows of
    noise were set aside as spikes in one file of bench-heldout44)."""
    d = np.diff(v)
    if limit is not None and limit.any():
        d = d[~(limit[1:] | limit[:-1])]
    return _change_scale(d) if d.size else 0.0


def _change_scale(d: np.ndarray) -> float:
    """The white-noise scale of a signal from its row-to-row changes ``d``: ``1.4826 median |d| / sqrt(2)``."""
    return 1.4826 * float(np.median(np.abs(d))) / math.sqrt(2.0)


def _spikes(x: np.ndarray, slices: list, limit: np.ndarray | None = None) -> np.ndarray:
    """Rows of ``x`` (n,) outside the range of their neighbours (:data:`NEIGHBOURS` rows either side, same
    sample) by more than :data:`SPIKE_Z` noise scales (:func:`_noise_scale`; ``limit`` (n,) bool: a load cell's rows
    at its limit, left out of the scale). A turning point or a kink of the motion stays within its neighbours' range
    (within a row's change), so only isolated jumps qualify."""
    return _rows_beyond(x, slices, lambda v, sl: SPIKE_Z * _noise_scale(v, None if limit is None else limit[sl]))


def stroke_spikes(stroke: np.ndarray, slices: list) -> np.ndarray:
    """Rows whose stroke lies outside the range of their neighbours (:data:`NEIGHBOURS` rows either side, same sample)
    by more than :data:`SPIKE_Z` typical steps of the motion and :data:`STROKE_SPIKE_SPAN` of the sample's span: a
    motor's log glitching for one row (a value of 50 mm in a 2 mm stroke). The motor's own steps are smooth, its
    turning points within a step of their neighbours; its rests repeat a value, so the typical step is read on the
    rows that move (the angle's and force's noise scale would be 0 where the stroke dwells half the time)."""
    def beyond(v: np.ndarray, sl: slice) -> float:
        d = np.abs(np.diff(v))
        d = d[np.isfinite(d) & (d > 0)]
        if d.size < 10:
            return 0.0
        lo, hi = np.percentile(v, [0.5, 99.5])
        return max(SPIKE_Z * float(np.median(d)), STROKE_SPIKE_SPAN * float(hi - lo))

    return _rows_beyond(stroke, slices, beyond)


def _rows_beyond(x: np.ndarray, slices: list, beyond_of) -> np.ndarray:
    """(n,) bool: per sample of at least ``10 x`` :data:`NEIGHBOURS` rows, the rows of ``x`` beyond their neighbours'
    range by ``beyond_of(the sample's values, its slice)`` (a sample whose threshold is not > 0: none)."""
    out = np.zeros(x.size, bool)
    for _, sl in slices:
        v = x[sl]
        if v.size < 10 * NEIGHBOURS:
            continue
        beyond = beyond_of(v, sl)
        if beyond > 0.0:
            out[sl] = _beyond_neighbours(v, beyond)
    return out


def _beyond_neighbours(v: np.ndarray, beyond: float) -> np.ndarray:
    """(n,) bool: rows of ``v`` above the largest or below the smallest of their :data:`NEIGHBOURS` rows either side
    by more than ``beyond`` (the ends read against the first and last row)."""
    h = NEIGHBOURS
    pad = np.concatenate((np.full(h, v[0]), v, np.full(h, v[-1])))
    win = np.delete(np.lib.stride_tricks.sliding_window_view(pad, 2 * h + 1), h, axis=1)
    return (v > win.max(axis=1) + beyond) | (v < win.min(axis=1) - beyond)


def _bursts(x: np.ndarray, steps_s: Sequence[float], slices: list, single: np.ndarray,
            across: np.ndarray | None = None, limit: np.ndarray | None = None) -> np.ndarray:
    """Rows of ``x`` (n,) in runs of 2 or more rows that all lie outside the range of the run's neighbours
    (:data:`NEIGHBOURS` rows either side, same sample) on the same side, by more than :data:`SPIKE_Z` noise scales;
    runs up to :data:`BURST_S` seconds (at most :data:`BURST_ROWS` rows). ``steps_s``: each sample's median positive
    time step (:meth:`Dataset.median_steps_s`, in the order of ``slices``). ``single`` (n,) bool: the spikes of one
    row, which are not neighbours (a burst beside a spike is still found). ``across`` (n,) bool, optional: rows
    displaced for longer (:func:`_long_bursts`), read as the line between the rows either side of each run of them,
    so that they are not the neighbours of the real rows beside them. ``limit`` (n,) bool, optional: a load cell's
    rows at its limit, left out of the noise scale (:func:`_noise_scale`)."""
    out = np.zeros(x.size, bool)
    h = NEIGHBOURS
    for (_, sl), step in zip(slices, steps_s):
        v = x[sl]
        n = v.size
        if n < 10 * h:
            continue
        scale = _noise_scale(v, None if limit is None else limit[sl])
        if scale <= 0.0 or not step > 0.0:
            continue
        longest = int(min(BURST_ROWS, max(2, math.floor(BURST_S / step))))
        # a single spike beside a run stands for its neighbour: the value across it (its own neighbour's)
        w = v.copy()
        if across is not None and across[sl].any() and (~across[sl]).sum() >= 2:
            real = np.flatnonzero(~across[sl])
            w = np.interp(np.arange(n), real, v[real])
        for i in np.flatnonzero(single[sl]):
            w[i] = w[i - 1] if i > 0 else w[min(i + 1, n - 1)]
        lo_run = w.copy()
        hi_run = w.copy()
        # the shortest runs first; a run found is replaced by the line across it, so that it does not stand beside
        # the real rows between it and another artefact as their neighbour
        for length in range(2, longest + 1):
            m = n - length + 1
            if m <= 0:
                break
            lo_run = np.minimum(lo_run[:m], w[length - 1:])
            hi_run = np.maximum(hi_run[:m], w[length - 1:])
            pad = np.concatenate((np.full(h, w[0]), w, np.full(h + 1, w[-1])))
            i = np.arange(m)
            nb = np.stack((pad[i], pad[i + 1], pad[i + h + length], pad[i + h + length + 1]))
            hit = (lo_run > nb.max(axis=0) + SPIKE_Z * scale) | (hi_run < nb.min(axis=0) - SPIKE_Z * scale)
            starts = np.flatnonzero(hit)
            for start in starts:
                out[sl.start + start:sl.start + start + length] = True
                a, b = (w[start - 1] if start else w[start + length]), (w[start + length] if start + length < n
                                                                       else w[start - 1])
                w[start:start + length] = np.linspace(a, b, length + 2)[1:-1]
            if starts.size:
                win = np.lib.stride_tricks.sliding_window_view(w, length)
                lo_run, hi_run = win.min(axis=1), win.max(axis=1)
    return out


def _steps(w: np.ndarray, scale: float, span: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Rows where ``w`` (m,) jumps: ``(rows, size)``, row ``k`` the first after a change ``w[k] - w[k - 1]`` that is
    off the changes before it *and* those after it (the medians of :data:`STEP_SIDE` either side) by more than
    :data:`SPIKE_Z` noise scales, on the same side of both. A kink of the motion (a ramp that starts or stops) keeps
    its change beside those of one side, so it is not a jump. ``span`` (m - 1,) int, optional: how many of the
    sample's median time steps each change spans (1 where no row is missing); a change across rows that are not in
    the record (a dropout) is read against the motion's change per step times its span, so a ramp's progress across
    the gap is not a jump (a 0.1 s dropout inside a 0.9 s burst read -2.2 deg and left the burst unpaired)."""
    return _jumps(_off_the_sides(w, span), scale)


def _jumps(sides: tuple[np.ndarray, np.ndarray] | None, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_steps` from the changes ``sides`` (:func:`_off_the_sides`; None: too short, no jump)."""
    if sides is None:
        return np.zeros(0, int), np.zeros(0)
    a, b = sides
    hit = (np.abs(a) > SPIKE_Z * scale) & (np.abs(b) > SPIKE_Z * scale) & (np.sign(a) == np.sign(b))
    k = np.flatnonzero(hit)
    return k + 1, 0.5 * (a[k] + b[k])


def _off_the_sides(w: np.ndarray, span: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray] | None:
    """``(a, b)`` (m - 1,) each change of ``w`` (m,) less the motion's change per step before it and after it (the
    medians of :data:`STEP_SIDE` changes either side, times the steps it spans): what :func:`_steps` reads a jump
    from; None when ``w`` is too short."""
    d = np.diff(w)
    h = STEP_SIDE
    if d.size < 2 * h + 1:
        return None
    g = np.ones(d.size) if span is None else np.asarray(span, float)
    r = d / g                          # the change per step
    win = np.lib.stride_tricks.sliding_window_view(r, h)
    before = np.full(d.size, np.nan)
    after = np.full(d.size, np.nan)
    before[h:] = np.median(win[:-1], axis=1)
    after[:-h] = np.median(win[1:], axis=1)
    # across a gap the rate is multiplied by its span, and a median of three noisy changes by ten was off by 1.5 deg:
    # there the rate is the mean over as many changes either side as the gap spans (the line through them)
    cg = np.concatenate(([0.0], np.cumsum(g)))
    for k in np.flatnonzero(g > 1.0):
        m = max(h, int(g[k]))
        if k >= m:
            before[k] = (w[k] - w[k - m]) / (cg[k] - cg[k - m])
        if k + m + 1 <= d.size:
            after[k] = (w[k + m + 1] - w[k + 1]) / (cg[k + m + 1] - cg[k + 1])
    return d - g * before, d - g * after


#: Jumps of the force of one sign that give the angle's typical jump in their rows (:func:`_beyond_own`); with
#: fewer, an angle's jump in a force's row is the joint's own, whatever its size.
OWN_JUMPS_MIN = 5


def _beyond_own(sides: tuple[np.ndarray, np.ndarray], rows: np.ndarray, size: np.ndarray, own: np.ndarray,
                own_size: np.ndarray, scale: float) -> tuple[np.ndarray, np.ndarray]:
    """The angle's jumps ``(rows, size)`` (:func:`_jumps` of its changes ``sides``, :func:`_off_the_sides`) that are
    not the joint's own: a jump in a row
    where the force jumps too (``own``, ``own_size``: the force's jumps) is the joint's (a guide's Coulomb friction
    switched the tension), as far as it is the angle's typical change in the rows where the force jumps the same way
    (the median over them, at least :data:`OWN_JUMPS_MIN`: the guide switches at every reversal alike); what is
    beyond that by :data:`SPIKE_Z` noise scales is the edge of a displacement that began or ended in that row, kept
    with that size. ``bench-heldout51``'s sharp guide: 6 deg of interference began in the row the release switched
    the guide (the joint's own 1-2 deg), the angle's 6.9 deg jump was taken for the joint's, its jump back at the
    rest was left unpaired, and 185 rows 6 deg off were kept (the partial chain at 1.6x the floor, nothing
    recommended)."""
    same = np.isin(rows, own)
    if not same.any():
        return rows, size
    keep = ~same
    size = size.copy()
    a, b = sides
    at = {int(r): float(z) for r, z in zip(own, own_size)}
    for direction in (1.0, -1.0):
        group = own[np.sign(own_size) == direction]
        if group.size < OWN_JUMPS_MIN:
            continue
        typical = float(np.median(0.5 * (a[group - 1] + b[group - 1])))
        for i in np.flatnonzero(same):
            if np.sign(at[int(rows[i])]) != direction:
                continue
            excess = size[i] - typical
            if abs(excess) > SPIKE_Z * scale:
                keep[i] = True
                size[i] = excess
    return rows[keep], size[keep]


def _spans(t: np.ndarray, step: float) -> np.ndarray:
    """(m - 1,) how many median time steps ``step`` each change of the times ``t`` (m,) spans: 1 for a row's
    own step (the stamps' jitter and a repeated stamp included), the whole count where rows are missing."""
    return np.maximum(1.0, np.round(np.diff(t) / step))


def _long_bursts(x: np.ndarray, steps_s: Sequence[float], slices: list, known: np.ndarray,
                 t: np.ndarray | None = None, force: np.ndarray | None = None, stroke: np.ndarray | None = None,
                 limit: np.ndarray | None = None) -> np.ndarray:
    """Rows of ``x`` (n,) displaced together for longer than a burst, up to :data:`LONG_BURST_S`: a jump
    (:func:`_steps`) and, within that time, the next jump, back by the same amount (within
    :data:`STEP_MATCH` of it). ``known`` (n,) bool: rows already set aside, left out (the change across them is one
    change, read over the rows it spans). ``t`` (n,), optional: the rows' times, so that a change across missing rows
    is read over the time it spans (:func:`_steps`). Interference that lasts a second displaces the angle through a
    ramp, so the range test of :func:`_bursts` does not see it; the jumps into it and out of it stand out at any speed
    of the motion.
    ``force`` (n,), optional: a jump of the angle in the row of a jump of the force is the joint's own (the
    tension switched: a guide's Coulomb friction at a reversal moves the joint 3 deg within a row), so it is neither
    an edge of a displacement nor a jump between two (``bench-heldout25``: a 4.9 deg burst with the joint's 3.3 deg
    jump inside it kept 10 rows). ``stroke`` and ``limit`` (n,), optional: where the load cell reads the end of its
    range (``limit``) it cannot show the switch, so a jump of the angle within :data:`STEP_SIDE` rows after the
    stroke stops or starts may be the joint's own there: the displacements are read with those jumps and without
    them (``bench-sharp``: the guide let go as the stroke reached the top, the joint rose 2.7 deg with the cell at
    its limit, inside a 5.2 deg burst, and 96 rows were kept). With the force read, a single jump at rest at a
    sample's end or start is interference the record ends or begins in (:func:`_open_ends`)."""
    out = np.zeros(x.size, bool)
    for (_, sl), step in zip(slices, steps_s):
        v = x[sl]
        n = v.size
        if n < 10 * NEIGHBOURS or not step > 0.0:
            continue
        scale = _noise_scale(v)
        if scale <= 0.0:
            continue
        good = ~known[sl]
        if good.sum() < 10 * NEIGHBOURS:
            continue
        # the rows kept, each change read over the time (or the rows) it spans: a jump beside a row set aside stays
        # one jump (the line across a repeated stamp just before a burst's 7.9 deg jump split it into 4.1 and 2.6,
        # neither the size of the jump back, and 146 rows 8 deg off were kept in bench-heldout26)
        idx = np.flatnonzero(good)
        w = v[idx]
        span = np.diff(idx).astype(float) if t is None else np.maximum(_spans(t[sl][idx], step), np.diff(idx))
        sides = _off_the_sides(w, span)
        rows, size = _jumps(sides, scale)
        steady = False   # (the force's own jumps read: an angle's jump that is not in a row of one)
        if force is not None and rows.size:
            f = force[sl][idx]
            fscale = _noise_scale(f, None if limit is None else limit[sl][idx])
            if np.isfinite(f).all() and fscale > 0.0:
                steady = True
                own, own_size = _steps(f, fscale, span)   # (across a dropout, read over the time it spans)
                if own.size:
                    # in the same row only: interference that ends a row from the joint's own jump is still an edge
                    # (a burst's end beside a carriage let go at the rest, in bench-heldout21); and one that begins
                    # in that row is the angle's jump beyond the joint's own there
                    rows, size = _beyond_own(sides, rows, size, own, own_size, scale)
        rows = idx[rows]   # (the sample's own rows again: the longest displacement is counted in them)
        longest, noise = int(LONG_BURST_S / step), STEP_NOISE * scale
        pairs = _paired_jumps(rows, size, longest, noise)
        if stroke is not None and limit is not None and limit[sl].any() and rows.size:
            moving = np.concatenate(([False], np.diff(stroke[sl]) != 0.0))
            switch = np.flatnonzero(np.concatenate(([False], moving[1:] != moving[:-1])))
            # the switches at or before each jump, within STEP_SIDE rows of it, where the cell reads its limit: the
            # displacements read without those jumps too (a burst that begins as the stroke starts, the cell at its
            # limit and no guide to switch, is still paired with them)
            near = np.searchsorted(switch, rows, side="right") - 1
            # (at the limit, or just off it: the row before read the limit, so the force's change into the row is
            # not the tension's; bench-heldout36's sharp guide switched 3 deg in the row the cell left its limit,
            # inside a 4.5 deg burst, and 18 rows were kept)
            lim = limit[sl]
            own = (near >= 0) & (rows - switch[np.maximum(near, 0)] <= STEP_SIDE) \
                & (lim[rows] | lim[np.maximum(rows - 1, 0)])
            if own.any():
                pairs += _paired_jumps(rows[~own], size[~own], longest, noise)
        if steady and stroke is not None and rows.size:
            pairs += _open_ends(rows, stroke[sl], longest, pairs)
        for r0, r1 in pairs:
            out[sl.start + r0:sl.start + r1] = True
    return out & ~known


#: The stroke "rests" around a jump at a record's end (or start) while it moves by at most this share of its span: the
#: slow last steps of a ramp coming to rest (``bench-heldout44``'s slack file: 3.3 deg of interference for the last
#: 1.2 s of a sample, begun as the stroke's last 0.007 mm of 2 mm came in, was kept: 1.23x the true floor). The joint
#: cannot follow such a step by degrees.
OPEN_END_STROKE = 0.01


def _open_ends(rows: np.ndarray, stroke: np.ndarray, longest: int, pairs: list) -> list:
    """Interference the record ends in (or begins in), in one sample: ``[(first row, stop row)]``. A last jump
    (:func:`_steps`, ``rows``) within ``longest`` rows of the sample's end, or a first one within them of its start,
    that is not inside a displacement of ``pairs``, while the ``stroke`` (the sample's) rests from :data:`STEP_SIDE`
    rows before the jump to the end (from the start to as many rows after it; moving by at most
    :data:`OPEN_END_STROKE` of its span), the force not jumping in its row (the
    caller leaves such jumps out). A joint at rest under a steady tension does not move by itself; a single jump
    elsewhere (a carriage that slips: the tension moves too) is left, as is one while the stroke moves
    (``bench-heldout27``: 6.7 deg for the last 68 rows of a sample, at the rest, kept: 0.2 deg RMS over the
    sample)."""
    out = []
    n = stroke.size

    def free(r: int) -> bool:
        return not any(r0 <= r <= r1 for r0, r1 in pairs)

    last, first = int(rows[-1]), int(rows[0])
    still = OPEN_END_STROKE * float(np.ptp(stroke))
    if n - last <= longest and free(last) and float(np.ptp(stroke[max(last - STEP_SIDE, 0):])) <= still:
        out.append((last, n))
    if 0 < first <= longest and free(first) and float(np.ptp(stroke[:first + STEP_SIDE])) <= still:
        out.append((0, first))
    return out


def _paired_jumps(rows: np.ndarray, size: np.ndarray, longest: int, noise: float = 0.0) -> list:
    """``(first row, stop row)`` of each displacement the jumps ``(rows, size)`` (:func:`_steps`) enclose: a jump
    and a jump back of the same size (within :data:`STEP_MATCH` of it, plus ``noise``: each size is read from one
    row's change, so two noisy rows; a 4.5 deg burst at 100 Hz read +4.1 in and -5.2 out) at most ``longest`` rows
    later. Taken in turn:

    1. each jump and the next one (one burst);
    2. then, among the jumps not yet paired, again each and the next one: two bursts, one inside the other (the
       inner pair taken first, the outer's jumps become neighbours);
    3. then four jumps in a row within ``longest`` of which the first and third, and the second and fourth,
       match: two bursts that overlap (the second began before the first ended). The jumps add: 8 deg, then
       4 more, then 8 back and 4 back in one file of ``bench-heldout17``; pairing each jump with the next missed
       both, and 2.2 s of the record stayed 4-12 deg off;
    4. then a jump and the next one that matches it, with only smaller jumps between (less than
       :data:`SMALLER_INSIDE` of its size: the joint's own quick motion, a tracker that held its last value and
       caught up, read inside the displacement). ``bench-heldout24``'s friction file: 5.1 deg in, a 1.6 deg catch-up,
       5.2 deg back 1.7 s later; 8.2 in, 1.4, 7.3 back; 148 rows 5-8 deg off were kept;
    5. then a jump not yet paired and a later one, within twice ``longest``, where the sum of every jump from the
       first to the second comes back to zero (within :data:`STEP_MATCH` of the largest displacement on the way,
       plus ``noise``): two bursts that overlap, whose inner jumps (the second's jump in, the first's jump back)
       were paired with each other in 1., or not at all. The interference adds, so the displacement ends where the
       sum does. ``bench-heldout44``'s control: -5.2 deg for 1.8 s, -4.8 more from 1.3 s in, +5.3 and +4.8 back,
       the last 3.1 s after the first, 67 rows 5 deg off kept beside a cell at its limit ("unexplained" at 1.26x the
       floor); ``bench-heldout46``'s lag file: -4.4, -7.1, +4.9 (paired with the -7.1 in 1.), +7.4: 30 rows 7.5 deg
       off kept.
    """
    def match(i: int, j: int) -> bool:
        return (rows[j] - rows[i] <= longest and np.sign(size[j]) == -np.sign(size[i])
                and abs(size[i] + size[j]) <= STEP_MATCH * abs(size[i]) + noise)

    out = []
    free = list(range(rows.size))
    for _ in range(2):   # 1. neighbours; 2. neighbours once the inner pairs are gone
        left, i = [], 0
        while i < len(free):
            if i + 1 < len(free) and match(free[i], free[i + 1]):
                out.append((rows[free[i]], rows[free[i + 1]]))
                i += 2
            else:
                left.append(free[i])
                i += 1
        free = left
    i, left = 0, []
    while i < len(free):  # 3. overlapping: (a, b, -a, -b)
        if i + 3 < len(free):
            p, q, r, t = free[i:i + 4]
            if rows[t] - rows[p] <= longest and match(p, r) and match(q, t):
                out.append((rows[p], rows[t]))
                i += 4
                continue
        left.append(free[i])
        i += 1
    free = left
    i = 0
    while i < len(free):  # 4. a jump and the jump back with smaller ones between (inside the displacement)
        back = None
        for j in range(i + 1, len(free)):
            if rows[free[j]] - rows[free[i]] > longest:
                break
            if match(free[i], free[j]):
                back = j
                break
            if abs(size[free[j]]) >= SMALLER_INSIDE * abs(size[free[i]]):
                break   # a jump as large as the first one between: not one displacement
        if back is None:
            i += 1
        else:
            out.append((rows[free[i]], rows[free[back]]))
            i = back + 1
    # 5. overlapping bursts read by the sum of their jumps (the jumps inside a displacement taken are not free)
    taken = np.zeros(rows.size, bool)
    for r0, r1 in out:
        taken |= (rows >= r0) & (rows <= r1)
    i = 0
    while i < rows.size:
        if taken[i]:
            i += 1
            continue
        total, peak, end = 0.0, 0.0, None
        for j in range(i, rows.size):
            if rows[j] - rows[i] > 2 * longest:
                break
            total += size[j]
            peak = max(peak, abs(total))
            if j > i and not taken[j] and np.sign(size[j]) == -np.sign(size[i]) \
                    and abs(total) <= STEP_MATCH * peak + noise:
                end = j
                break
        if end is None:
            i += 1
        else:
            out.append((rows[i], rows[end]))
            taken[i:end + 1] = True
            i = end + 1
    return out


def _true_runs(mask: np.ndarray) -> zip:
    """``(start, stop)`` of each run of True in ``mask`` (1-D bool), stop exclusive."""
    edges = np.diff(np.concatenate(([0], mask.astype(np.int8), [0])))
    return zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1))


def _frozen(angle: np.ndarray, stroke: np.ndarray, slices: list) -> np.ndarray:
    """Rows repeating the angle before them exactly, in runs of :data:`FROZEN_REPEATS` or more, across which the
    stroke moves by more than :data:`FROZEN_STROKE` of the sample's stroke range (a tracker holding its last
    value); the run's first value is kept, unless the angle jumped to it (more than :data:`SPIKE_Z` noise scales
    from the row before: a tracker that writes a fixed value, such as 0, while it has lost the sensor). A run the
    angle jumped to and away from (by as much) is such a fixed value wherever the stroke is (a dwell: the joint
    stands bent while the tracker writes 0), so it is set aside whole; a quantised reading repeating at rest moves
    by a step, not a jump, and stays."""
    out = np.zeros(angle.size, bool)
    for _, sl in slices:
        a, s = angle[sl], stroke[sl]
        if a.size < 3:
            continue
        span = float(np.ptp(s))
        scale = _noise_scale(a)
        rep = np.concatenate(([False], a[1:] == a[:-1]))
        for b, e in _true_runs(rep):
            if e - b < FROZEN_REPEATS:
                continue
            jumped = b >= 2 and abs(float(a[b - 1]) - float(a[b - 2])) > SPIKE_Z * scale
            left = e < a.size and abs(float(a[e]) - float(a[e - 1])) > SPIKE_Z * scale
            if abs(float(s[e - 1]) - float(s[b - 1])) > FROZEN_STROKE * span or (jumped and left):
                out[sl.start + b - int(jumped):sl.start + e] = True
    return out


def _saturated(force: np.ndarray, stroke: np.ndarray, slices: list) -> tuple[np.ndarray, dict]:
    """Rows of a load cell at the end of its range: ``(mask (n,), {sample: (reading N, rows)})``. In each sample,
    every row at the sample's largest force reading, when that reading repeats exactly in a run of
    :data:`FROZEN_REPEATS` or more rows across which the stroke moves by more than :data:`FROZEN_STROKE` of its
    range within the run (the tension rose on, and fell back, while the cell read its limit)."""
    out = np.zeros(force.size, bool)
    levels = {}
    for smp, sl in slices:
        f, s = force[sl], stroke[sl]
        if f.size < 3 or not np.isfinite(f).all():
            continue
        top = float(f.max())
        # a force that never rises (all 0) has no limit to reach; one at its limit in most rows does (a cell too small
        # and not zeroed: bench-heldout42's slack file read its limit in 15,821 of 29,900 rows, the median, and none was
        # set aside)
        if not top > float(f.min()):
            continue
        at = f == top
        span = float(np.ptp(s))
        if any(e - b >= FROZEN_REPEATS and float(np.ptp(s[b:e])) > FROZEN_STROKE * span for b, e in _true_runs(at)):
            out[sl] = at
            levels[str(smp)] = (top, int(at.sum()))
    return out, levels


def _force_ahead(force: np.ndarray, stroke: np.ndarray, t: np.ndarray, slices: list, known: np.ndarray,
                 limit: np.ndarray | None = None) -> np.ndarray:
    """Rows where the load cell and the stroke disagree on when the motion started or stopped.

    Two kinds of row qualify, read against the force's noise scale at rest:

    * **ahead**: the stroke starts to move only after the row (its step into it at most :data:`AHEAD_STEP` of its
      step out, which is not zero) while the force changed into it by more than :data:`SPIKE_Z` noise scales, the
      way that motion takes it (up when pulling, down when releasing): the drive started within the row, by less
      than the stroke resolves (the whole jump, or part of it: a row read halfway through the switch);
    * **behind**: the first row at rest after a motion (no step into it, a step into the row before) while the force
      jumps only into the next row (by more than :data:`SPIKE_Z` noise scales and :data:`AHEAD_OUT` times its
      changes into the row and out of the next: a step, not a ramp), against the direction of the motion that
      ended (a guide releasing): the carriage still moved at the row's instant though the motor's log had stopped.

    Something that switches at once with the motion (a guide's Coulomb friction) does this at reversals: the row
    reads one state of the guide with the stroke in the other, and no law of the rows' stamps fits it (the joint's
    tension misses by the guide's whole ratio: 13 deg in rows of ``bench-heldout25``), nor does a delay (a false
    lag of 25 ms there). A smooth start or stop moves the force with the stroke, so it does not qualify, nor does a
    row beside a gap in the record (every change read is one row's step of time: across 0.1 s of missing rows the
    stroke's step looks like a start). ``t`` (n,): the rows' times. ``known``: rows already set aside (skipped as
    the row itself; a neighbour set aside still counts as read: a load cell at its limit before the release).

    ``limit`` (n,) bool, optional: rows of a load cell at the end of its range (:func:`_saturated`). Where the row
    before reads the limit, the force's change into the row is not the tension's (that was above the range), so a
    row **ahead** is one that leaves the limit the way the motion after it takes the force, whatever the size of that
    change: a cell that read its limit through a dwell falls below it only once the tension falls, and the tension
    falls at the release (``bench-heldout36``'s sharp guide: the last row of each dwell read 3.206 N against the limit
    of 3.219 N, the joint 3 deg up as the guide switched, the stroke still at the top; the model's loading branch
    missed it by 20 deg, 13 rows held 60 % of what the partial chain left)."""
    out = np.zeros(force.size, bool)
    for _, sl in slices:
        f, s = force[sl], stroke[sl]
        if f.size < 10 or not (np.isfinite(f).all() and np.isfinite(s).all()):
            continue
        step = np.diff(s)
        df = np.diff(f)
        dt = np.diff(t[sl])
        h = float(np.median(dt))
        even = np.abs(dt - h) < 0.5 * h          # a change over one row's step of time
        # the force's noise from its changes at rest, exact repeats left out (a cell at its limit through a dwell
        # repeats its reading for thousands of rows: with them the scale is 0 and any wiggle a jump)
        rest = (step[1:] == 0.0) & (step[:-1] == 0.0) & (df[1:] != 0.0)
        if rest.sum() < 20:   # no rests to read the force's noise from
            continue
        scale = _change_scale(df[1:][rest])
        if scale <= 0.0:
            continue
        # row k = 1 .. n-2 of the sample: step and force change into it (index k-1) and out of it (index k)
        s_in, s_out, f_in, f_out = step[:-1], step[1:], df[:-1], df[1:]
        # (the force may reach the new state over two rows: a row read halfway through the switch is ahead too)
        start = (s_out != 0.0) & (np.abs(s_in) <= AHEAD_STEP * np.abs(s_out))
        # a change into the row the size of a jump, or any change off the cell's limit (the row before read it)
        moved = np.abs(f_in) > SPIKE_Z * scale
        if limit is not None:
            moved |= limit[sl][:-2] & ~limit[sl][1:-1]
        ahead = start & moved & (np.sign(f_in) == np.sign(s_out)) & even[:-1] & even[1:]
        # behind: row k at rest after a step into row k-1, the jump into row k+1 (f_out) against that step
        s_before = np.concatenate(([0.0], step[:-2]))
        f_next = np.concatenate((df[2:], [0.0]))
        jump_out = (np.abs(f_out) > SPIKE_Z * scale) & (np.abs(f_out) > AHEAD_OUT * np.abs(f_in)) \
            & (np.abs(f_out) > AHEAD_OUT * np.abs(f_next))
        even_before = np.concatenate(([False], even[:-2]))
        even_next = np.concatenate((even[2:], [False]))
        behind = (s_in == 0.0) & (s_before != 0.0) & jump_out & (np.sign(f_out) == -np.sign(s_before)) \
            & even_before & even[:-1] & even[1:] & even_next
        out[sl.start + 1:sl.stop - 1] = ahead | behind
    return out & ~known


def slow_sampling_line(rates_hz: Mapping[str, float]) -> str:
    """``"sampling: S1 a row every 25 s, slower than 1 Hz; ..."`` for the samples of ``rates_hz`` (Hz) slower than
    :data:`SLOW_RATE_HZ` (a time column in ms read as s), or ""."""
    slow = {smp: r for smp, r in rates_hz.items() if 0.0 < r < SLOW_RATE_HZ}
    if not slow:
        return ""
    return ("sampling: " + ", ".join(f"{smp} a row every {1.0 / r:.3g} s" for smp, r in slow.items())
            + f", slower than {SLOW_RATE_HZ:g} Hz; if the time column is in ms, give it in s (time_s, divided by 1000): "
              "the model's time constants (creep, relaxation, a lag) are read in s")


def sampling_rates(data: Dataset) -> tuple[dict, tuple]:
    """Each sample's rate (Hz, from its median time step), and notes on a rate that changes along a sample."""
    rates, notes = {}, []
    for s, sl in data.sample_slices():
        dt = np.diff(data.time_s[sl])
        dt = dt[dt > 0]
        if not dt.size:
            continue
        med = float(np.median(dt))
        rates[s] = 1.0 / med
        nb = dt.size // 200
        if nb >= 2:
            blk = np.median(dt[: nb * 200].reshape(nb, 200), axis=1)
            off = np.flatnonzero(np.abs(blk / med - 1.0) > RATE_CHANGE)
            if off.size:
                t0 = float(data.time_s[sl][off[0] * 200])
                notes.append(f"sampling rate of sample {s} changes: {1.0 / blk[off[0]]:.4g} Hz from t = {t0:.4g} s "
                             f"({off.size} of {nb} blocks of 200 rows off the median {1.0 / med:.4g} Hz)")
    return rates, tuple(notes)


#: Time constants (s) of the low-passed force regressors that absorb a slow relaxation of the joint.
RELAX_TAUS_S = (2.0, 8.0, 32.0)
#: Widths (fractions of the force's range) of the play operators that absorb friction in the joint (it holds
#: the angle while the force reverses, which a delay would otherwise be fitted to).
STICK_WIDTHS = (0.01, 0.03)
#: Slip speeds of the guide-friction regressors, as fractions of the median stroke speed while moving.
SLIP_FRACTIONS = (0.05, 0.2)
#: Width (s) of the centred running mean of the force in the lag regression (short against the motion: a
#: wide one flattens the force's turning points, which a shift of the angle then mimics).
SMOOTH_S = 0.1


def _play(x: np.ndarray, width: float) -> np.ndarray:
    """Play (backlash) operator of ``x`` (n,) with full width ``width``: the output follows ``x`` only once
    ``x`` has moved ``width`` from where it last pushed it."""
    out = np.empty_like(x)
    y = float(x[0])
    h = 0.5 * width
    for i, v in enumerate(x.tolist()):
        if v > y + h:
            y = v - h
        elif v < y - h:
            y = v + h
        out[i] = y
    return out


def _lag_design(data: Dataset, of: str = "force") -> list:
    """Per sample: ``(slice, basis)`` with the force regressors of :func:`_lag_sse`: a cubic of the force per
    direction of motion, and the force low-passed with :data:`RELAX_TAUS_S` (a relaxation of the joint
    makes the angle follow the force's history, not a delay). ``of="stroke"``: the same regressors of the stroke
    (:func:`lag_at_limit`)."""
    from scipy.signal import lfilter

    out = []
    direction = data.direction
    signal = data.stroke_mm if of == "stroke" else data.force_N
    for (_, sl), step in zip(data.sample_slices(), data.median_steps_s()):
        f = np.asarray(signal[sl], float)
        dt = step if f.size > 1 else 1.0
        k = 2 * int(SMOOTH_S / max(dt, 1e-9) / 2) + 1
        if 1 < k < f.size:  # a centred running mean: less force noise in the regressors, no shift in time
            f = np.convolve(np.pad(f, k // 2, mode="edge"), np.ones(k) / k, "valid")
        x = (f - f.mean()) / (f.std() or 1.0)
        # a cubic of the force, a step (friction in the joint) and a hysteresis proportional to the force
        # (friction at the guide: the cell reads a tension that differs from the joint's by a ratio) that flip
        # with the direction of motion
        dirn = direction[sl].astype(float)
        cols = [np.ones_like(x), x, x * x, x ** 3, dirn * x, dirn]
        # friction at a guide that develops with the tendon's speed (capstan, regularised): the force times the
        # sliding state tanh(v / v_slip) for slip speeds a fraction of the typical speed (a delay mimics that
        # smooth change of the hysteresis at every start and stop otherwise)
        v = data.stroke_speed_mm_s[sl]
        vmed = float(np.median(np.abs(v[v != 0.0]))) if np.any(v != 0.0) else 0.0
        if vmed > 0.0:
            for k in SLIP_FRACTIONS:
                slide = np.tanh(v / (k * vmed))
                cols += [slide, x * slide, slide * slide, x * slide * slide]   # F exp(-mu s) to second order
            rest = (v == 0.0).astype(float)
            cols += [rest, x * rest]                       # what the guide keeps while the drive rests
        for w in STICK_WIDTHS:  # friction that holds the joint while the force reverses: a play of the force
            cols.append(_play(x, w * float(np.ptp(x))) - x)
        for tau in RELAX_TAUS_S:
            a = math.exp(-dt / tau)
            lp = lfilter([1.0 - a], [1.0, -a], x, zi=[a * x[0]])[0]
            cols.append(x - lp)
        out.append((sl, np.stack(cols, axis=1)))
    return out


@np.errstate(over="ignore", invalid="ignore")  # an absurd value (angle 1e300) overflows: inf, and no warning
def _lag_sse(data: Dataset, design: list, shift: int, rows: np.ndarray) -> float:
    """Residual sum of squares of the angle regressed on the force regressors (:func:`_lag_design`) ``shift`` rows
    earlier, over the angles of ``rows`` (index array).

    The angles are the same for every shift, the regressors move: with the rows thinned (every k-th), shifting the
    angle instead changes which angles are read, and one the instruments' check missed (a burst's remnant, 6 deg) is
    left out by every shift but a k-th of them: a false lag of 25 ms (``bench-heldout25``)."""
    sse = 0.0
    for sl, basis in design:
        idx = rows[(rows >= sl.start + max(0, shift)) & (rows < sl.stop + min(0, shift))]
        if idx.size < 40:
            continue
        a = data.angle_deg[idx]
        x = basis[idx - shift - sl.start]
        r = a - x @ _least_squares(x, a)
        sse += float(r @ r)
    return sse


#: The normal equations solve a lag's regression (:func:`_least_squares`) where the columns, scaled to unit length,
#: are this far from dependent (the Cholesky factor's smallest diagonal over its largest; the square root of the
#: reciprocal of the Gram matrix's condition number: 1e-6 keeps that number below 1e12, and the residual to about
#: 1e-4 of the noise); else the SVD's least squares.
GRAM_RCOND = 1e-6


def _least_squares(x: np.ndarray, a: np.ndarray) -> np.ndarray:
    """The coefficients minimising ``|a - x c|``: by the normal equations (Cholesky) with the columns scaled to unit
    length, where they are well conditioned (:data:`GRAM_RCOND`); else (a column of zeros: no rest in a sample) by
    the SVD's least squares, the minimum-norm solution.

    speed: a lag's scan solves some 400 regressions of 6,000-12,000 rows and 21 columns; the SVD took 1.4 ms each
    on one core, the normal equations 0.3 ms, with residual sums of squares equal to 1e-14 (relative)."""
    norm = np.sqrt(np.einsum("ij,ij->j", x, x))
    if np.all(norm > 0.0) and np.all(np.isfinite(norm)):
        xs = x / norm
        gram = xs.T @ xs
        try:
            chol = scipy.linalg.cholesky(gram, lower=True, check_finite=False)
        except np.linalg.LinAlgError:
            chol = None
        if chol is not None:
            d = np.abs(np.diag(chol))
            if d.min() > GRAM_RCOND * d.max():
                return scipy.linalg.cho_solve((chol, True), xs.T @ a, check_finite=False) / norm
    return np.linalg.lstsq(x, a, rcond=None)[0]


@np.errstate(over="ignore", invalid="ignore")  # an absurd value (angle 1e300) overflows: inf, and no warning
def _lag_scan(data: Dataset, design: list, rows: np.ndarray, lo: int, hi: int) -> tuple[float, bool, float]:
    """``(lag in rows, interior minimum?, relative fall of the residual RMS from no shift to the best)``."""
    shifts = np.arange(lo, hi + 1)
    sse = np.array([_lag_sse(data, design, int(k), rows) for k in shifts])
    k = int(np.argmin(sse))
    zero = sse[shifts == 0][0] if (shifts == 0).any() else sse[k]
    fall = 1.0 - math.sqrt(sse[k] / zero) if zero > 0 else 0.0
    if 0 < k < sse.size - 1:
        y0, y1, y2 = sse[k - 1], sse[k], sse[k + 1]
        den = y0 - 2 * y1 + y2
        return float(shifts[k] + (0.5 * (y0 - y2) / den if den > 0 else 0.0)), True, fall
    return float(shifts[k]), False, fall


def estimate_lag(data: Dataset, max_rows: int = 12000, blocks: int = 6, max_lag_ms: float = 250.0,
                 of: str = "force") -> Lag:
    """Lag of the angle behind the force (ms) with its standard error (see the module docstring).

    Parameters
    ----------
    data : Dataset
        Rows free of artefacts.
    max_rows : int
        Rows used (evenly thinned in time).
    blocks : int
        Blocks of cycles per sample for the standard error.
    max_lag_ms : float
        Largest lag tried either way.
    of : str
        The channel the angle is read against: ``"force"`` or ``"stroke"`` (:func:`lag_at_limit`).
    """
    n = len(data)
    dt = float(np.median(np.diff(data.time_s))) if n > 1 else 1.0
    dt = dt if dt > 0 else 1.0
    max_shift = max(3, int(round(max_lag_ms * 1e-3 / dt)))
    step = max(1, n // max_rows)
    rows = np.arange(0, n, step)
    # rows whose every trial shift is that many rows of time later: none across rows set aside (a spike, a burst, a
    # load cell at its limit), the same rows for every shift (a sum of squares over fewer rows is smaller)
    t = data.time_s
    for (_, sl), h in zip(data.sample_slices(), data.median_steps_s(positive=True)):
        r = rows[(rows - max_shift >= sl.start) & (rows + max_shift < sl.stop)]
        gap = np.abs(t[r + max_shift] - t[r - max_shift] - 2 * max_shift * h) >= 0.5 * h
        rows = np.setdiff1d(rows, r[gap], assume_unique=True)
    design = _lag_design(data, of)
    est, interior, fall = _lag_scan(data, design, rows, -max_shift, max_shift)
    near = int(round(est))
    per = []
    outside = 0
    cyc = data.cycle
    for _, sl in data.sample_slices():
        c = cyc[sl]
        edges = np.linspace(c.min(), c.max() + 1, blocks + 1)
        for lo, hi in zip(edges[:-1], edges[1:]):
            r = rows[(rows >= sl.start) & (rows < sl.stop)]
            r = r[(cyc[r] >= lo) & (cyc[r] < hi)]
            if r.size >= 100:
                lag_b, inside, _ = _lag_scan(data, design, r, near - 3, near + 3)
                per.append(lag_b)
                outside += not inside
    se = float(np.std(per, ddof=1) / math.sqrt(len(per))) if len(per) > 1 else float("inf")
    # no minimum inside the range tried: not a delay the data resolve. Nor where half the blocks or more have their
    # minimum outside the 3 rows either side of the whole's: they do not agree on a delay (each block at the window's
    # edge, all alike, read a standard error of 0: 58 +- 0 ms on a relaxing backbone, bench-heldout26; one noisy block
    # of twelve at the edge, at 25-40 Hz, leaves a delay that the others agree on, bench-heldout16 and 22)
    if not interior or 2 * outside >= len(per):
        se = float("inf")
    return Lag(est * dt * 1e3, se * dt * 1e3, fall=fall, against=of)


#: The samples' lags differ (each is then corrected on its own) when two of them are further apart than this many
#: standard errors of their difference (the blocks' spread understates a bias the regression leaves, and it differs
#: from sample to sample: a backbone relaxing on three time scales, and no lag, read 18 +- 2.6 ms beside -4.9 +- 1.5
#: in one file, 33 +- 6.9 beside -0.5 +- 1.5 in another, 7.7 and 4.8 standard errors apart; a tracker 76 ms late
#: beside one on time read 71 +- 2.8 and -15 +- 2.8, 22 apart: bench-heldout27) ...
LAG_SPLIT_Z = 10.0
#: ... and than this many rows: a difference the whole rows of a correction barely show is no difference. (And one
#: sample's own lag at least must be corrected, :func:`check_instruments`: a split that corrects nothing says nothing.)
LAG_SPLIT_ROWS = 1.0
#: Closer than :data:`LAG_SPLIT_Z`, but more than this many standard errors apart (and that many rows), the current
#: model decides (:func:`confirm_lag`): a sample's own lag is corrected where the model fitted to that sample's rows
#: confirms it.
LAG_SPLIT_MODEL_Z = 4.0


def estimate_lags(data: Dataset, of: str = "force") -> Lag:
    """The angle's lag (:func:`estimate_lag`) over every sample, and per sample where the samples differ.

    Two tubes are often logged in two sessions, each with its own alignment of the tracker's clock to the load
    cell's, so their lags need not agree: one lag over both reads neither (76 ms in one sample beside none in the
    other read as 8 ms, ``bench-heldout27``). Each sample's lag is estimated on its own rows; when every one is
    resolved and two differ by more than :data:`LAG_SPLIT_Z` standard errors of their difference and
    :data:`LAG_SPLIT_ROWS` rows, the result holds each (:attr:`Lag.per_sample`, none applied yet). ``of``: the
    channel read against (:func:`estimate_lag`)."""
    pooled = estimate_lag(data, of=of)
    samples = list(data.samples)
    if len(samples) < 2:
        return pooled
    sample = np.asarray(data.sample)
    own = {}
    for smp in samples:
        sub = data.take(sample == smp)
        if len(sub) < 200:
            return pooled
        own[smp] = (estimate_lag(sub, of=of), float(np.median(np.diff(sub.time_s))) * 1e3)
    if not all(math.isfinite(lg.se_ms) for lg, _ in own.values()):
        return pooled
    pooled = replace(pooled, own=tuple((smp, lg.lag_ms, lg.se_ms, lg.fall) for smp, (lg, _) in own.items()))
    if not _lags_differ([(lg.lag_ms, lg.se_ms, row_ms) for lg, row_ms in own.values()], LAG_SPLIT_Z):
        return pooled
    return replace(pooled, per_sample=tuple((smp, lg.lag_ms, lg.se_ms, lg.fall, 0.0) for smp, (lg, _) in own.items()))


#: The lag read against the stroke (:func:`lag_at_limit`) is taken where it lowers its regression's residual RMS by
#: this share (and by more than the force's reading does): 7.0 % on ``bench-heldout39``'s lag file (both trackers
#: 35 ms late, both load cells at their limit in 9,000 rows; the force's 2.1 %), 4.4-6.4 % for 35 ms beside a relaxing
#: backbone in the tests. Where nothing is late it lowered its residual by 1.5 % at most on the 44 such files of
#: ``bench-sharp`` and ``bench-heldout17`` .. ``22`` whose load cells reach their limit (0.0 % on most); a carriage held
#: within 0.1 mm of backlash, 2.6 % (the force's reading must show the delay too).
STROKE_LAG_FALL = 0.03


def _with_speed(clean: Dataset, data: Dataset, kept: np.ndarray, rep: np.ndarray) -> Dataset:
    """``clean`` (the rows ``kept`` of ``data``) with the drive's speed read on every row of ``data`` whose stamp is
    sound, when rows were set aside (see :func:`check_instruments`)."""
    if (~kept & ~rep).any() and SPEED_COLUMN not in data.extra:
        sound = np.flatnonzero(~rep)
        return clean.with_speed_of(data.take(sound), np.searchsorted(sound, np.flatnonzero(kept)))
    return clean


def lag_at_limit(lag: Lag, data: Dataset, kept: np.ndarray, limit: np.ndarray, rep: np.ndarray) -> Lag:
    """``lag`` (read against the force on the rows ``kept`` of ``data``), or the lag read against the stroke where a
    load cell at its limit set rows aside (``limit``, (n,) bool).

    Those rows are the top of every stroke: the reversal and the dwell, where a delay shows most (the ramps show it
    barely: at constant speed the regressors' step absorbs it). Read over what is left, a delay is biased
    (``bench-heldout39``'s lag file, both trackers 35 ms late: 26.5 +- 1.7 ms; with cells of larger range 34.9 +- 1.3).
    The motor's stroke is logged whole on those rows, so the angle is regressed on the same terms of the stroke over
    the rows kept and the limit's rows (33.0 +- 0.9 ms there). The drive's lost motion, the tendon's slack, toe and
    creep sit between the stroke and the angle, so that reading alone could take one of them for a delay (a carriage
    held within 0.1 mm of backlash read -23 +- 0.8 ms against the stroke, 0.7 +- 0.7 against the force): it only
    measures a delay the force shows too. It is taken where the force's reading is beyond three standard errors, the
    stroke's is of the same sign and lowers its regression's residual by :data:`STROKE_LAG_FALL` and by more than
    ``lag`` lowers the force's; else ``lag`` stands. ``rep``: rows with a repeated stamp (never read)."""
    if not limit.any() or lag.given or not abs(lag.lag_ms) > 3.0 * lag.se_ms:
        return lag
    rows = (kept | limit) & ~rep
    with one_blas_thread():
        by_stroke = estimate_lags(_with_speed(data.take(rows), data, rows, rep), of="stroke")
    if (by_stroke.fall >= STROKE_LAG_FALL and by_stroke.fall > lag.fall and math.isfinite(by_stroke.se_ms)
            and by_stroke.lag_ms * lag.lag_ms > 0.0):
        return by_stroke
    return lag


def _lags_differ(own: Sequence[tuple[float, float, float]], z: float) -> bool:
    """Two of ``own`` (``(lag_ms, se_ms, row_ms)`` each) further apart than ``z`` standard errors of their difference
    and :data:`LAG_SPLIT_ROWS` rows."""
    return any(abs(a - b) > z * math.hypot(sa, sb) and abs(a - b) > LAG_SPLIT_ROWS * max(ha, hb)
               for (a, sa, ha), (b, sb, hb) in itertools.combinations(own, 2))


def _resolved(lag_ms: float, se_ms: float, row_ms: float) -> bool:
    """A lag the data resolve: beyond three standard errors and a quarter of a row."""
    return abs(lag_ms) > 3.0 * se_ms and abs(lag_ms) > 0.25 * row_ms


def shift_angle(data: Dataset, lag_ms: float | Mapping[str, float]) -> tuple[Dataset, np.ndarray, float, np.ndarray]:
    """``data`` with the angle read ``lag_ms`` later, by whole rows of each sample (interpolating between rows
    would average the tracker's noise and hide it from the noise floor); a row whose later angle is past the
    record, or not that many rows of time later (across rows set aside), is dropped. ``lag_ms`` is one lag for
    every sample or ``{sample: lag_ms}`` (a sample not named: none).

    Returns
    -------
    data : Dataset
    kept : (n,) bool
        Rows of the input kept.
    applied_ms : float or dict
        The shift applied: whole rows times the median sampling interval (within half a row of ``lag_ms``); the
        mean over the samples, or ``{sample: shift}`` when ``lag_ms`` is given per sample.
    past_end : (n,) bool
        Rows dropped because their later angle is past the record (the others dropped: across a gap).
    """
    each = isinstance(lag_ms, Mapping)
    if not each and lag_ms == 0.0:
        return data, np.ones(len(data), bool), 0.0, np.zeros(len(data), bool)
    ang = data.angle_deg.copy()
    keep = np.ones(len(data), bool)
    past_end = np.zeros(len(data), bool)
    applied = {}
    for smp, sl in data.sample_slices():
        t = data.time_s[sl]
        dt = float(np.median(np.diff(t))) if t.size > 1 else 0.0
        ms = float(lag_ms.get(smp, 0.0)) if each else lag_ms
        k = int(round(ms * 1e-3 / dt)) if dt > 0 else 0
        applied[smp] = k * dt * 1e3
        if k == 0:
            continue
        idx = np.arange(sl.start, sl.stop)
        src = np.clip(idx + k, sl.start, sl.stop - 1)
        ang[idx] = data.angle_deg[src]
        past_end[idx] = (idx + k < sl.start) | (idx + k >= sl.stop)
        # the angle k rows later must be k rows of time later: not past the record, nor across rows set aside
        keep[idx] = ~past_end[idx] & (np.abs(data.time_s[src] - t - k * dt) < 0.5 * dt)
    out = applied if each else float(np.mean(list(applied.values())))
    return data.with_angle(ang).take(keep), keep, out, past_end

def _artefacts(data: Dataset, slices: list) -> tuple[dict, np.ndarray, np.ndarray, dict]:
    """The instruments' artefacts of ``data`` (rows as read): ``(aside {why: rows}, kept (n,) bool, rows whose stamp
    repeats or whose stroke spikes (n,) bool: read nowhere, the drive's speed and history included, the load cells' limits {sample: (reading N, rows)})``; see :func:`check_instruments`."""
    aside: dict[str, np.ndarray] = {}
    rep = np.zeros(len(data), bool)
    for _, sl in slices:
        t = data.time_s[sl]
        rep[sl.start + 1:sl.stop] = np.diff(t) <= 0.0
    aside["repeated time stamp"] = np.flatnonzero(rep)
    # a stroke that jumps for one row: its row set aside whole (its force and angle are read at a stroke it never had),
    # and left out of the others' tests as a repeated stamp is
    ss = stroke_spikes(data.stroke_mm, slices) & ~rep
    rep_or_ss = rep | ss
    sa = _spikes(data.angle_deg, slices) & ~rep_or_ss
    sat, limits = _saturated(data.force_N, data.stroke_mm, slices)
    sat &= ~rep_or_ss
    sf = _spikes(data.force_N, slices, limit=sat) & ~rep_or_ss & ~sa & ~sat
    steps = data.median_steps_s(positive=True)
    ba = _bursts(data.angle_deg, steps, slices, sa) & ~rep_or_ss & ~sa & ~sf
    bf = _bursts(data.force_N, steps, slices, sf, limit=sat) & ~rep_or_ss & ~sa & ~sf & ~ba
    frozen = _frozen(data.angle_deg, data.stroke_mm, slices)
    fz = frozen & ~rep_or_ss & ~sa & ~sf & ~ba & ~bf & ~sat
    ahead = _force_ahead(data.force_N, data.stroke_mm, data.time_s, slices, rep_or_ss | sf | bf | sat, sat)
    # (read across the angle's own artefacts only: where the force was set aside the angle is still read; a tracker
    # that wrote a fixed value, such as 0, is one of them though the burst test took it first: 9 rows of 0 just
    # before a burst of 8 deg for 0.9 s split its jump in two, -16 and +6, and its 94 rows were kept
    # (bench-heldout35's tracker drift: twice the floor, the misfit read as following the angle))
    lb = _long_bursts(data.angle_deg, steps, slices, rep_or_ss | sa | fz | (ba & frozen), data.time_s, data.force_N,
                      data.stroke_mm, sat) & ~(sf | bf | sat)
    if lb.any():
        # the short bursts read again across the long ones: rows displaced for a second beside a run of real rows
        # made it look displaced (5 rows after a 2 s burst, where the carriage slipped, in one file of 244)
        ba = (_bursts(data.angle_deg, steps, slices, sa, across=lb) & ~rep_or_ss & ~sa & ~sf & ~lb) | lb
        # (a fixed value the first reading took as a burst, beside a long one, is still a frozen tracker's)
        fz = frozen & ~rep_or_ss & ~sa & ~sf & ~ba & ~bf & ~sat
    ba &= ~sat
    bf &= ~sat
    ahead &= ~(sa | ba | fz)
    if ss.any():
        aside["stroke spike"] = np.flatnonzero(ss)
    aside["angle spike"] = np.flatnonzero(sa)
    aside["force spike"] = np.flatnonzero(sf)
    for why, rows in (("angle burst row", ba), ("force burst row", bf), ("frozen angle row", fz),
                      ("load cell limit row", sat), ("force ahead of the stroke row", ahead)):
        if rows.any():   # (the findings name only the kinds found)
            aside[why] = np.flatnonzero(rows)
    kept = ~(rep_or_ss | sa | sf | fz | ba | bf | sat | ahead)
    return aside, kept, rep_or_ss, limits


def check_instruments(data: Dataset, lag_ms: float | Mapping[str, float] | None = None, dropped: str = "",
                      n_dropped: int = 0, rezero: bool = True) -> Instruments:
    """Find the instruments' artefacts, set them aside, estimate (or apply) the angle's lag.

    Parameters
    ----------
    data : Dataset
        The rows as read (``n`` rows).
    lag_ms : float or dict, optional
        The angle channel's lag (ms) to correct, one for every sample or ``{sample: lag_ms}`` (a sample not named:
        none); ``None``: estimate it (per sample where the samples differ, :func:`estimate_lags`) and correct it
        where it is resolved.
    dropped, n_dropped : str, int
        The reader's line on dropped rows and their count (stated in the findings).
    rezero : bool
        Re-zero the force at the rests where the load cell's zero drifts (:func:`rezero_force`); False: read it only.

    Returns
    -------
    Instruments
    """
    given = {} if lag_ms is None else dict(lag_ms) if isinstance(lag_ms, Mapping) else {"": lag_ms}
    for smp, ms in given.items():
        what = f"--lag-ms {smp}={ms:g}" if smp else f"--lag-ms {ms:g}"
        if not math.isfinite(ms):
            raise DataError(f"{what}: the angle channel's lag must be a finite number of ms; fix: give e.g. "
                            "--lag-ms 20, or 0 for none")
        if abs(ms) > MAX_GIVEN_LAG_MS:
            raise DataError(f"{what}: a lag of more than {MAX_GIVEN_LAG_MS:g} ms between the tracker and the "
                            "load cell is not an instrument's delay but clocks that were not aligned; fix: give the "
                            "tracker's delay in ms (e.g. --lag-ms 20, 0 for none), and align the logs' clocks first "
                            "(camtube model ingest)")
    unknown = sorted(smp for smp in given if smp and smp not in set(data.samples))
    if unknown:
        raise DataError(f"--lag-ms {unknown[0]}=...: no sample {unknown[0]!r} in the data (samples: "
                        f"{', '.join(map(str, data.samples))}); fix: name a sample of the file, or give one lag for all")
    slices = data.sample_slices()
    aside, kept, rep, limits = _artefacts(data, slices)
    # the drive's speed at each row kept is read on every row whose stamp is sound: a load cell at its limit sets
    # aside the top of each stroke, and the speed read across that gap (the end of the pull, the dwell and the start
    # of the release in one step) took the guide's friction out of 9,000 rows (bench-heldout19)
    clean = _with_speed(data.take(kept), data, kept, rep)
    rates, notes = sampling_rates(clean)
    zeros = read_zero(clean)
    if rezero:
        clean, zeros = rezero_force(clean, zeros)
    if isinstance(lag_ms, Mapping):   # one per sample, as given (whole rows below)
        per = tuple((smp, float(lag_ms.get(smp, 0.0)), 0.0, 0.0, float(lag_ms.get(smp, 0.0))) for smp in data.samples)
        lag = Lag(0.0, 0.0, given=True, per_sample=per)
    elif lag_ms is not None:
        lag = Lag(float(lag_ms), 0.0, given=True, applied_ms=float(lag_ms))  # whole rows below
    else:
        with one_blas_thread():   # speed: the lag scan's regressions are tall and thin (camtube.model.core.threads)
            lag = estimate_lags(clean)
        if limits:   # a load cell at its limit set aside the top of every stroke: the stroke may read the lag better
            sat = np.zeros(len(data), bool)
            sat[aside.get("load cell limit row", [])] = True
            lag = lag_at_limit(lag, data, kept, sat, rep)

        def resolved(ms: float, se: float, fall: float, smp: str | None = None) -> bool:
            hz = rates.get(smp) if smp is not None else None
            hz = hz or (np.median(list(rates.values())) if rates else 1.0)
            return _resolved(ms, se, 1e3 / max(hz, 1e-9)) and fall >= MIN_FALL

        if lag.per_sample:
            lag = replace(lag, per_sample=tuple((smp, ms, se, fall, ms if resolved(ms, se, fall, smp) else 0.0)
                                                for smp, ms, se, fall, _ in lag.per_sample))
            if not lag.corrected:   # the samples differ, but neither's own lag is resolved: one lag over both
                lag = replace(lag, per_sample=())
        if not lag.per_sample and resolved(lag.lag_ms, lag.se_ms, lag.fall):
            lag = replace(lag, applied_ms=lag.lag_ms)
    if lag.per_sample:
        shifted, k2, applied, ends = shift_angle(clean, {p[0]: p[4] for p in lag.per_sample})
        lag = replace(lag, per_sample=tuple(p[:4] + (applied.get(p[0], 0.0),) for p in lag.per_sample))
    else:
        shifted, k2, applied, ends = shift_angle(clean, lag.applied_ms)
        if lag.applied_ms:
            lag = replace(lag, applied_ms=applied)
    idx = np.flatnonzero(kept)
    kept[idx[~k2]] = False
    # a row whose angle a lag later is past the record's end, or across rows set aside (no reading there)
    if ends.any():
        aside["end of record after the lag shift"] = idx[ends]
    if (~k2 & ~ends).any():
        aside["row before a gap after the lag shift"] = idx[~k2 & ~ends]
    shifted = _on_history(shifted, data, kept, aside, rep, zeros if rezero else {})
    return Instruments(shifted, data, aside, kept, rates, notes, lag, dropped, n_dropped, zeros, rezero, limits)


#: Rows set aside for what the angle read alone: their stroke, force and time are sound, and the drive's history runs
#: through them (:func:`_on_history`).
ANGLE_ONLY = ("angle spike", "angle burst row", "frozen angle row")


def _on_history(rows: Dataset, data: Dataset, kept: np.ndarray, aside: dict, rep: np.ndarray, zeros: dict) -> Dataset:
    """``rows`` (the rows ``kept`` of ``data``) taken from the record of the drive's history: every row of ``data`` but
    those whose stamp repeats or whose force was set aside, the force re-zeroed as ``rows``' was (``zeros``), so that a
    law computed on the whole record (:meth:`Dataset.rows_of_record`: a carriage its rail holds) runs through the rows
    set aside for the angle alone. An interference burst of 2 s over the end of an unloading hid the row where the
    force fell to the rail's hold: the carriage's law, read across the gap, let it go at once, and the rest after it
    read 8 deg off (``bench-heldout49``'s lost motion: nothing recommended, at 16x the floor)."""
    history = kept.copy()
    for why in ANGLE_ONLY:
        history[aside.get(why, np.zeros(0, int))] = True
    history &= ~rep
    at = np.flatnonzero(history)
    taken = data.take(at)
    record = Dataset(taken.sample, taken.cycle, taken.time_s, taken.stroke_mm, taken.force_N, taken.angle_deg,
                     taken.extra)   # (a record of its own: its rows_of_record is itself)
    if zeros:
        record, _ = rezero_force(record, zeros)
    out = Dataset(rows.sample, rows.cycle, rows.time_s, rows.stroke_mm, rows.force_N, rows.angle_deg, rows.extra)
    object.__setattr__(out, "taken_from", (record, np.searchsorted(at, np.flatnonzero(kept))))
    return out


@np.errstate(over="ignore", invalid="ignore")  # an absurd value (angle 1e300) overflows: inf, and no warning
def with_aside(ins: Instruments, predicted_deg: np.ndarray, floor_deg: float) -> tuple[float, float, int]:
    """Errors over the rows kept *and* the rows set aside (spikes, repeated stamps).

    The model's prediction at a row set aside is interpolated in time from the rows kept around it (the
    model is smooth in time), at the instant the angle was seen (``t - lag``).

    Parameters
    ----------
    ins : Instruments
    predicted_deg : (n,) float
        A model's prediction on ``ins.data`` (the rows kept).
    floor_deg : float
        The noise floor estimated on the rows kept.

    Returns
    -------
    rmse_deg : float
        RMSE over the rows kept and set aside.
    allowed_deg : float
        What the data allow over the same rows: the floor on the rows kept, the artefacts' own size on the rows
        set aside (a perfect model misses a spike by the spike).
    n_aside : int
        Rows set aside that were counted (those inside a sample's record).
    """
    clean = ins.data
    resid = clean.angle_deg - predicted_deg
    sse, n = float(resid @ resid), resid.size
    extra = 0.0
    aside = np.flatnonzero(~ins.kept)
    raw = ins.raw
    counted = 0
    for smp, sl in clean.sample_slices():
        a = aside[raw.sample[aside] == smp]
        if not a.size:
            continue
        t = raw.time_s[a] - ins.lag.applied_for(smp) * 1e-3
        inside = (t >= clean.time_s[sl][0]) & (t <= clean.time_s[sl][-1])
        r = raw.angle_deg[a][inside] - np.interp(t[inside], clean.time_s[sl], predicted_deg[sl])
        extra += float(r @ r)
        counted += int(inside.sum())
    rmse = math.sqrt((sse + extra) / max(n + counted, 1))
    allowed = math.sqrt((n * floor_deg ** 2 + extra) / max(n + counted, 1))
    return rmse, allowed, counted


def lag_misfit_deg(data: Dataset, lag_ms: float) -> float:
    """The misfit (deg, RMS) a lag of ``lag_ms`` leaves in a model that has none: the angle's RMS rate times the lag,
    the largest over the samples. The rate is the measured angle's first derivative through a quadratic
    Savitzky-Golay filter over :data:`LAG_RATE_WINDOW_S` (at least 5 rows), so the tracker's noise does not count."""
    from scipy.signal import savgol_filter

    out = 0.0
    for (_, sl), h in zip(data.sample_slices(), data.median_steps_s(positive=True)):
        a = np.asarray(data.angle_deg[sl], float)
        if h <= 0.0 or a.size < 5:
            continue
        w = min(max(5, 2 * int(LAG_RATE_WINDOW_S / h / 2) + 1), a.size - (1 - a.size % 2))
        rate = savgol_filter(a, w, 2, deriv=1, delta=h)
        out = max(out, float(np.sqrt(np.mean(rate * rate))) * abs(lag_ms) / 1e3)
    return out


def _model_lag(model, data: Dataset, fixed: dict, fit_names, lag_ms: float, dt_ms: float) -> tuple | None:
    """``(RMSE without, RMSE with, lag applied ms)`` when the current model fitted to ``data`` confirms the lag
    ``lag_ms`` (see :func:`confirm_lag`), else None."""
    from camtube.model.core.fit import FitError, fit
    from camtube.model.core.noise import white_noise_sd

    try:
        r0 = fit(model, data, list(fit_names), fixed)
        noise = min(white_noise_sd(r0.residuals[sl]) for _, sl in data.sample_slices())
        own = lag_misfit_deg(data, lag_ms)
        if not (noise > 0.0 and r0.rmse <= MODEL_LAG_MAX_RATIO * math.hypot(noise, own)):
            return None
        k0 = int(round(lag_ms / dt_ms))
        sign = 1 if lag_ms > 0 else -1
        best = (r0.rmse, 0.0)
        for k in sorted({k0 - sign, k0, k0 + sign}):
            if k == 0 or (k > 0) != (lag_ms > 0):
                continue
            shifted = shift_angle(data, k * dt_ms)[0]
            rk = fit(model, shifted, list(fit_names), fixed).rmse
            if rk < best[0]:
                best = (rk, k * dt_ms)
    except FitError:
        return None
    if not best[1] or best[0] > (1.0 - MODEL_LAG_FALL) * r0.rmse:
        return None
    return r0.rmse, best[0], best[1]


def _confirm_per_sample(ins: Instruments, model, fixed: dict, fit_names) -> Instruments | None:
    """The instruments' check with each sample's own lag that the current model confirms on that sample's rows
    corrected (:func:`confirm_lag`), where the samples' own lags differ by more than :data:`LAG_SPLIT_MODEL_Z`
    standard errors, or where the regression split them (:func:`estimate_lags`) and left a sample uncorrected (its
    lag resolved but lowering the regression's residual by less than :data:`MIN_FALL`); in a sample whose own lag is
    unresolved, a lag corrected in another sample, where the model confirms it there too; None when nothing more is
    corrected."""
    lg = ins.lag
    rows_ms = {smp: 1e3 / hz for smp, hz in ins.rates_hz.items() if hz > 0}
    if len(lg.own) < 2 or not all(smp in rows_ms for smp, *_ in lg.own) or not (lg.per_sample or
                                                                               _own_lags_differ(ins)):
        return None
    sample = np.asarray(ins.data.sample)
    # the regression's own corrections stand (a split: each resolved and lowering its residual by MIN_FALL)
    split = {smp: applied for smp, _, _, _, applied in lg.per_sample if applied}
    confirmed, rmse = dict(split), []
    unresolved = [smp for smp, ms, se, _ in lg.own if not _resolved(ms, se, rows_ms[smp])]
    for smp, ms, se, _ in lg.own:
        got = None if smp in unresolved or smp in split else _model_lag(
            model, ins.data.take(sample == smp), fixed, fit_names, ms, rows_ms[smp])
        if got is not None:
            confirmed[smp] = got[2]
            rmse.append((smp, got[0], got[1]))
    if not confirmed:
        return None
    # a sample whose own lag the model confirmed is tested with the lags confirmed in the others too, and reads the
    # one the model fits best: its own regression may see too little of the lag (bench-heldout51: one tracker 57 ms
    # late, S2's cell at its limit in 45 % of its rows; S2 read 28.8 +- 4.6 ms beside S1's 55.8 +- 0.8, and 40 ms,
    # the last of the rows tried around its own, was corrected there). A sample whose tracker lags differently keeps
    # its own: the others' lag fits it worse
    for smp in [smp for smp in confirmed if smp not in split]:
        others = sorted(set(ms for o, ms in confirmed.items() if o != smp) - {confirmed[smp]})
        if not others:
            continue
        sub = ins.data.take(sample == smp)
        mine = next(r for r in rmse if r[0] == smp)
        tries = [g for g in (_model_lag(model, sub, fixed, fit_names, ms, rows_ms[smp]) for ms in others)
                 if g is not None]
        got = min(tries, key=lambda g: g[1], default=None)
        if got is not None and got[1] < mine[2]:
            confirmed[smp] = got[2]
            rmse[rmse.index(mine)] = (smp, got[0], got[1])
    # a sample whose own estimate is unresolved is no evidence against a lag another sample confirms: one tracker
    # often serves both tubes, and a sample's regression may see too little of the lag (a load cell at its limit sets
    # aside the top of every cycle: bench-heldout33's S2 read -12.1 +- 4.9 ms beside S1's 46.6 +- 7.4, both 51 ms
    # late). The lags confirmed elsewhere are tested on its rows against the model, as its own would be
    for smp in unresolved:
        sub = ins.data.take(sample == smp)
        tries = [_model_lag(model, sub, fixed, fit_names, ms, rows_ms[smp]) for ms in sorted(set(confirmed.values()))]
        got = min((g for g in tries if g is not None), key=lambda g: g[1], default=None)
        if got is not None:
            confirmed[smp] = got[2]
            rmse.append((smp, got[0], got[1]))
    if confirmed == split:
        return None
    new = check_instruments(ins.raw, lag_ms={smp: confirmed.get(smp, 0.0) for smp, *_ in lg.own},
                            dropped=ins.dropped, n_dropped=ins.n_dropped, rezero=ins.rezero)
    per = tuple((smp, ms, se, fall, new.lag.applied_for(smp)) for smp, ms, se, fall in lg.own)
    return replace(new, lag=Lag(lg.lag_ms, lg.se_ms, False, 0.0, lg.fall, tuple(rmse), per_sample=per, own=lg.own,
                                against=lg.against))


def _own_lags_differ(ins: Instruments) -> bool:
    """The samples' own lags (:attr:`Lag.own`) differ by more than :data:`LAG_SPLIT_MODEL_Z` standard errors and a row."""
    rows_ms = {smp: 1e3 / hz for smp, hz in ins.rates_hz.items() if hz > 0}
    own = ins.lag.own
    return (len(own) >= 2 and all(smp in rows_ms for smp, *_ in own)
            and _lags_differ([(ms, se, rows_ms[smp]) for smp, ms, se, _ in own], LAG_SPLIT_MODEL_Z))


def confirm_lag(ins: Instruments, model, fixed: dict, fit_names=("E_t",)) -> Instruments:
    """The instruments' check with a lag the regression resolved but did not correct tested against the current
    model.

    At a low logging rate a lag of one or two rows lowers the lag regression's residual by less than
    :data:`MIN_FALL` (its force terms absorb part of a delay at constant speed), so it is left uncorrected. When
    the estimate is resolved (beyond three standard errors and a quarter of the sampling interval) and the current
    model fits within :data:`MODEL_LAG_MAX_RATIO` x the angle's white noise and the misfit the estimated lag itself
    leaves (:func:`lag_misfit_deg`), taken together, the model is fitted to the angle read
    the estimate's whole rows later (and one row either side); the best of those is corrected when it lowers the
    RMSE by :data:`MODEL_LAG_FALL`. Where the samples' own lags differ by more than :data:`LAG_SPLIT_MODEL_Z`
    standard errors (too few for :func:`estimate_lags` to split them alone: a backbone's relaxation biases one
    sample's estimate by tens of ms), each sample's own lag is tested so on that sample's rows first, and those
    confirmed are corrected, each by its own; so is a sample the regression's own split left uncorrected (its lag
    resolved, its residual barely lower: ``bench-heldout34``'s S2, 30.2 +- 1.6 ms beside S1's 52.2 +- 1.4). A sample
    whose own lag is unresolved is tested with the lags corrected in the others. Otherwise ``ins`` is returned as it
    is.
    """
    lg = ins.lag
    if lg.given or not ins.rates_hz:
        return ins
    if lg.corrected and not lg.per_sample:
        # one lag corrected in every sample; where the samples' own lags differ, each is tested on its own rows, read
        # as logged (a tracker 62 ms late beside a sample with none and a backbone relaxing on two time scales: S1
        # 57.6 +- 6.8, S2 -3.1 +- 5.3 ms, 7 standard errors apart; one lag of 31 ms over both corrected 25 ms in each,
        # and play and friction stood in for the rest, bench-heldout40)
        if not _own_lags_differ(ins):
            return ins
        as_logged = check_instruments(ins.raw, lag_ms=0.0, dropped=ins.dropped, n_dropped=ins.n_dropped,
                                      rezero=ins.rezero)
        split = _confirm_per_sample(replace(as_logged, lag=replace(lg, applied_ms=0.0)), model, fixed, fit_names)
        return ins if split is None else split
    split = _confirm_per_sample(ins, model, fixed, fit_names)
    if split is not None:
        return split
    if lg.per_sample:
        return ins
    if not math.isfinite(lg.se_ms):
        return ins
    dt_ms = 1e3 / float(np.median(list(ins.rates_hz.values())))
    if not _resolved(lg.lag_ms, lg.se_ms, dt_ms):
        return ins
    got = _model_lag(model, ins.data, fixed, fit_names, lg.lag_ms, dt_ms)
    if got is None:
        return ins
    new = check_instruments(ins.raw, lag_ms=got[2], dropped=ins.dropped, n_dropped=ins.n_dropped,
                            rezero=ins.rezero)
    return Instruments(new.data, new.raw, new.aside, new.kept, new.rates_hz, new.rate_changes,
                       Lag(lg.lag_ms, lg.se_ms, False, new.lag.applied_ms, lg.fall, (got[0], got[1]), own=lg.own,
                           against=lg.against),
                       new.dropped, new.n_dropped, new.zeros, new.rezero, new.limits)


#: Units a column is often logged in by mistake: ``(column, factor to the model's unit, the unit, the conversion)``.
#: A motor logged in um (or m, cm, inches), a load cell in mN (or grams-, kilograms-, pounds-force), a tracker in
#: radians.
UNIT_MISTAKES = (
    ("stroke_mm", 1e-3, "um", "divide it by 1000"),
    ("stroke_mm", 1e3, "m", "multiply it by 1000"),
    ("stroke_mm", 10.0, "cm", "multiply it by 10"),
    ("stroke_mm", 25.4, "inches", "multiply it by 25.4"),
    ("force_N", 1e-3, "mN", "divide it by 1000"),
    ("force_N", 9.80665e-3, "grams-force", "multiply it by 0.00980665"),
    ("force_N", 9.80665, "kilograms-force", "multiply it by 9.80665"),
    ("force_N", 4.4482216, "pounds-force", "multiply it by 4.448"),
    ("angle_deg", 180.0 / math.pi, "radians", "multiply it by 57.30"),
)
#: A unit read instead must lower the paper model's RMSE over the angle's standard deviation (in that unit) to this
#: share of the same as logged, at least.
UNIT_FALL = 0.2
#: Rows the units' check fits on (evenly thinned in time).
UNIT_ROWS = 2000
#: The units are tried where the tendon's fitted modulus is implausible, or where the angle spans less than this share
#: of what the paper model gives at the pattern's values (a tracker in radians: 1/57).
UNIT_ANGLE_SPAN = 0.1
#: Units that fit within this share of the best RMSE fit as well.
UNIT_TIE = 0.02


def unit_mistake(model, data: Dataset, fixed: Mapping[str, float], fit_names: Sequence[str],
                 modulus_range_gpa: tuple[float, float] = (1.0, 300.0)) -> str | None:
    """A column whose unit looks wrong, said with the evidence and the fix; None when the units look right.

    Where the tendon's modulus is fitted and the paper model fitted to ``data`` as logged puts it outside the plausible
    ``modulus_range_gpa`` (a stroke in um, a force in grams-force: no modulus makes the model's scale), or where the
    angle spans less than :data:`UNIT_ANGLE_SPAN` of what the paper model gives at the pattern's values (a tracker in
    radians), each unit of :data:`UNIT_MISTAKES` is tried in turn, one column at a time: one that brings the modulus
    into the range and lowers the RMSE over the angle's standard deviation to :data:`UNIT_FALL` of that as logged or
    less is named (of those within :data:`UNIT_TIE` of the best RMSE, the one whose modulus is nearest the pattern's:
    a force's unit is a factor the modulus takes up). A well-logged record costs one fit and one evaluation on
    :data:`UNIT_ROWS` rows."""
    from camtube.model.core.fit import FitError, fit
    from camtube.model.diagnose.search import thin

    if "E_t" not in fit_names or len(data) < 50:
        return None
    rows = thin(data, UNIT_ROWS)
    lo, hi = modulus_range_gpa

    def paper(d: Dataset):
        try:
            r = fit(model, d, list(fit_names), fixed)
        except FitError:
            return None
        return r if math.isfinite(r.rmse) else None

    with one_blas_thread():
        r0 = paper(rows)
        if r0 is None:
            return None
        # the angle's span against the paper model's at the pattern's values (E_t does not make up a tracker's unit)
        expected = float(np.ptp(model.predict(rows, model.initial_values(rows, fixed))))
        small = expected > 0 and float(np.ptp(rows.angle_deg)) < UNIT_ANGLE_SPAN * expected
        if lo <= r0.params["E_t"] <= hi and not small:
            return None
        def spread_miss(r, d: Dataset) -> float:
            """The misfit against the angle's own spread (a tracker's unit scales both)."""
            return r.rmse / (float(np.std(d.angle_deg)) or 1.0)

        miss0 = spread_miss(r0, rows)
        # two columns whose names were swapped (stroke and angle: a stroke of 30 mm, an angle of 2.5 "deg" read as
        # radians, and the conversion the line gave fitted E_t 1.9 GPa at 16 deg RMS, exit 0)
        swaps = []
        for a, b in (("stroke_mm", "angle_deg"), ("stroke_mm", "force_N"), ("force_N", "angle_deg")):
            d = replace(rows, **{a: np.asarray(getattr(rows, b), float), b: np.asarray(getattr(rows, a), float)})
            r = paper(d)
            if r is not None and lo <= r.params["E_t"] <= hi and r.rmse < r0.rmse and \
                    spread_miss(r, d) <= UNIT_FALL * miss0:
                swaps.append((spread_miss(r, d), r, a, b))
        tried = []
        for col, factor, unit, conversion in UNIT_MISTAKES:
            d = replace(rows, **{col: np.asarray(getattr(rows, col), float) * factor})
            r = paper(d)
            if r is not None and lo <= r.params["E_t"] <= hi and spread_miss(r, d) <= UNIT_FALL * miss0:
                tried.append((r, col, unit, conversion, spread_miss(r, d)))
    # a swap is named when it fits better than every unit, each against its own angle's spread (an angle in radians
    # against a stroke in mm is nearly linear either way round: the unit fits it far better)
    best_unit = min((ratio for *_, ratio in tried), default=math.inf)
    if swaps and min(t[0] for t in swaps) < best_unit:
        _, r, a, b = min(swaps, key=lambda t: t[0])
        return (f"columns {a!r} and {b!r} look swapped: as logged the paper model misses by {r0.rmse:.4g} deg RMS "
                f"(E_t = {r0.params['E_t']:.3g} GPa); with the two exchanged it misses by {r.rmse:.4g} deg with E_t = "
                f"{r.params['E_t']:.3g} GPa; fix: exchange the names {a!r} and {b!r} in the header")
    if not tried:
        return None
    # a force's unit is a factor E_t takes up (the same RMSE in mN and in grams-force): of the units that fit as well
    # as the best, the one whose modulus is nearest the pattern's
    e_t = float(fixed.get("E_t", DEFAULT_E_T_GPA))
    top = min(r.rmse for r, *_ in tried)
    r, col, unit, conversion, _ = min((t for t in tried if t[0].rmse <= (1.0 + UNIT_TIE) * top),
                                      key=lambda t: abs(math.log(t[0].params["E_t"] / e_t)))
    model_unit = {"stroke_mm": "mm", "force_N": "N", "angle_deg": "deg"}[col]
    e0 = r0.params["E_t"]
    logged = (f"E_t = {e0:.3g} GPa, outside {lo:g}-{hi:g}" if not lo <= e0 <= hi else
              f"the angle spans {float(np.ptp(rows.angle_deg)):.3g} against the {expected:.3g} deg the model gives")
    return (f"column {col!r} reads like {unit}, not {model_unit}: as logged the paper model misses by {r0.rmse:.4g} "
            f"deg RMS ({logged}); read as {unit} it misses by {r.rmse:.4g} deg with E_t = {r.params['E_t']:.3g} GPa; "
            f"fix: give {col} in {model_unit} ({conversion})")


def check_units(model, data: Dataset, fixed: Mapping[str, float], fit_names: Sequence[str], what: str,
                modulus_range_gpa: tuple[float, float] = (1.0, 300.0)) -> None:
    """Refuse ``data`` with a column whose unit looks wrong (:func:`unit_mistake`, the paper ``model``; tried where
    ``E_t`` is among ``fit_names``), naming ``what`` (the file), the column, the evidence and the conversion.

    Raises
    ------
    DataError
    """
    wrong = unit_mistake(model, data, fixed, [n for n in fit_names if n == "E_t"], modulus_range_gpa)
    if wrong:
        raise DataError(f"{what}: {wrong}")
