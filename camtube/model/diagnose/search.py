"""Diagnosis of missing physics: which effect would make the model fit, and can the answer be trusted?

``diagnose(model, data, fit_params=("E_t",), fixed=None, *, candidates=None, ...) -> Diagnosis``

Method
------
1. **Current model.** ``model`` (base plus the effects already chosen) is
   fitted to every row of ``data`` (both directions, deadband kept, so slack,
   play and creep stay visible) exactly as ``camtube model fit`` would.
2. **Noise floor.** The sensor noise is white, the model error is smooth in
   time; so the noise shows in the high-order differences of the residual
   within each sample. The *floor* (:func:`noise_floor`) is their root mean
   square, from the MAD in windows of :data:`FLOOR_WINDOW` differences
   (robust to a spike or a kink), for ``k = 2, 3, 4`` (the smallest is kept):
   the RMSE a model without error leaves, also where the noise's size changes
   along the stroke. The labels and every ratio reported read it. The search's
   own tests (its stop, the sample-wise search, the error above the noise an
   effect must explain) read the noise's *typical size* (:func:`noise_typical`,
   ``1.4826 MAD(diff^k r) / sqrt(C(2k, k))`` over the record), equal to the floor
   for noise of one size and below it where the size changes: the search looks
   a little below the line of the labels. The floor's uncertainty has two parts
   added in quadrature: statistical (the spread of the same estimate over
   blocks of cycles) and systematic (the range of ten estimators that all
   agree for white Gaussian noise: MAD over the record and in windows and standard
   deviation of the 2nd-4th differences, and one allowing a lag-1 correlation),
   see :func:`noise_floor_parts`.
3. **Cross-validation by blocks of cycles.** Each sample's cycles are cut
   into (up to) eight blocks; the blocks alternate between two folds, the
   first block (with cycle 1) in fold 0 for the first sample and in fold 1
   for the next, so every cycle, the first included, is tested by a fit that
   did not see it (alternate time blocks for one-cycle data). The model
   always runs over the whole history.
4. **Candidates.** Each effect not yet in the model is added in turn and
   fitted from several starts (the current fit plus the effect's defaults,
   and the best point of a grid over each new parameter's declared range,
   log-spaced for scales). A candidate is **significant** when
   its held-out mean squared error falls by more than ``z`` times the
   standard error of that fall (paired over the blocks), or its logarithm
   by more than ``z + 1`` (:func:`_significant`), ``delta BIC`` is
   below ``-bic_threshold`` and the fall is a real share of the error above
   the floor. It is **trusted** when its new parameters are off their bounds
   with finite standard errors and the data can resolve them: time
   constants between three sample intervals and the record length, lengths
   within the stroke span, ``E_t`` within ``modulus_range_gpa``; and the
   effect's own ``check`` of its form finds nothing the data contradict (a
   hard stop must level the measured angle off). A candidate
   that fails a check is listed with the reason and never recommended.
   Among candidates that cannot be told apart, the lowest BIC leads, unless one with fewer parameters
   is within ``bic_threshold`` of it (then the simpler one leads).
5. **All-rows check.** The best trusted, significant candidate is refitted
   on every row, exactly as the printed ``model fit`` command does (same
   rows, same starts: ``--init`` values and ``--starts``). It is recommended
   only when that refit lowers the RMSE, keeps its parameters identified and
   resolvable, and does not undercut the noise floor (re-estimated from its
   residual) by more than twice the floor's uncertainty (fitting noise);
   otherwise the next candidate is tried.
   **Replacement.** When a candidate's fit puts a parameter of an effect
   chosen earlier on a bound, the candidate explains what that effect did
   (a sharp toe first taken for slack): it is also tried *instead of* it.
   Such a replacement leads when its held-out error is within
   ``EQUAL_HELDOUT`` of the best candidate's (it ends with fewer effects); it
   is accepted only if the chain without the replaced effect still lowers
   the RMSE at every step (``Diagnosis.replaced`` records it).
6. **Per-sample parameters.** With several samples, each recommended
   effect's parameters are tried per sample; they are kept when the held-out
   error falls significantly. The output says which samples differ (values
   more than three combined standard errors apart) and names any sample the
   final model leaves worse than the current one. Where a sample's copies are not
   resolved (on a bound: that sample does not show the effect, or the effect stands in
   for another one there), they are held at the effect's ``off`` values and the effect
   is fitted in the other samples only (``Candidate.held``, ``Diagnosis.held``); a
   per-sample version with unresolved copies never replaces the shared one. A
   replacement of an effect fitted per sample is fitted per sample too, and may take the
   replaced effect's place in the chain.
   The next round retries only the candidates whose held-out RMSE fell by ``min_gain`` in this one; once,
   before the search gives up or when that leaves none, every effect not yet chosen is tried again.
7. The search stops when the held-out RMSE is within ``stop_ratio`` of the
   noise floor (the held-out RMSE at full resolution: the all-rows RMSE times the
   held-out / in-sample ratio of the search rows, which see a coarser history)
   (``stop_ratio=None`` turns the rule off: the significance
   tests alone must then stop it), when nothing qualifies, or after
   ``max_effects``.
8. **Offsets the first rest contradicts.** A recommended constant offset
   (``angle_bias``, ``force_zero``) is checked against the rows at the start
   of the record where the model holds the joint unloaded: a sensor offset
   leaves no residual there; one that does is called out in the notes (the
   joint rests bent once loaded -- joint friction, a permanent set -- or the
   toe law is wrong at low force).
9. **Complete or partial.** The chain of accepted effects is a *complete*
   explanation when its all-rows RMSE is within :data:`REACH_RATIO` (1.15) x
   the noise floor. Above that it is still recommended, labelled *partial*,
   when it explains at least :data:`PARTIAL_SHARE` of the mean squared misfit
   above the floor and ends within :data:`PARTIAL_RATIO` x the floor (an
   effect that takes the error from 16x to 1.3x the floor is the answer,
   not a stand-in), or explains at least :data:`PARTIAL_SHARE_FAR` of it and
   ends within :data:`PARTIAL_RATIO_FAR` x (a backbone with three relaxing
   arms, from 79x to 1.8x with the library's two); the ``unexplained``
   analysis then describes what is left.
   Otherwise a structured misfit remains that the library does not explain:
   the effects are listed as ``partial`` (each lowers the error, none is a
   fix), nothing is recommended (a built-in of the wrong form is not offered
   for physics the library lacks), and ``unexplained`` describes what is left.

No threshold depends on the data's scale: BIC is a likelihood ratio, the
others are ratios of errors or multiples of standard errors.
"""
from __future__ import annotations

import itertools
import math
import time
from dataclasses import dataclass, field, replace
from typing import Mapping, NamedTuple, Sequence

import numpy as np

from camtube.errors import DataError
from camtube.model.core.fit import FitResult, fit
from camtube.model.core.model import Effect, FitError, JointModel, check_reads_chain, form_problem, sample_views
from camtube.model.core.noise import ORDERS
from camtube.model.core.parallel import map_forked
from camtube.model.core.registry import Registry, builtin_registry
from camtube.model.core.threads import one_blas_thread
from camtube.model.data.csvfile import check_fittable
from camtube.model.data.dataset import Cache, Dataset

#: Parameter correlation above which two parameters cannot be told apart.
CORR_LIMIT = 0.99
#: A gain's fall on the log scale of the blocks' MSE (:func:`_significant`) must clear ``z`` by this many standard
#: errors more than its plain fall: a second look at one gain (with it, noise passes about as often as before).
LOG_SCALE_EXTRA_Z = 1.0
#: Held-out RMSEs within this fraction of each other: the data cannot tell the candidates apart.
EQUAL_HELDOUT = 0.03
#: A sample's per-sample copies of an effect whose off values raise that sample's RMSE by at most this share do
#: nothing there: the sample does not show the effect (:func:`inert_in_sample`).
INERT_SHARE = 1e-3
#: Grid values per new parameter in the multi-start fits (also ``--starts`` of the printed command).
GRID = 3
#: Effects every real joint may show, which the diagnosis takes into its baseline (tried before every round)
#: instead of recommending them as missing physics: friction in the joint holds the unloaded joint bent.
BASELINE = ("rest_angle",)
#: Candidates that may take a baseline effect's place: each is also fitted with that effect held at its ``off``
#: values (a relaxing backbone holds the unloaded joint bent for a while, as friction holds it for good; where
#: the relaxation explains the bent rest the constant rest angle goes to zero, on its bound; a carriage held by its
#: rail holds the tendon taut and the joint bent while the motor rests at zero).
BASELINE_STAND_INS = {"rest_angle": ("relaxation", "relaxation2", "carriage_hold", "carriage_gap")}

#: A chain of effects is recommended only when its all-rows RMSE is within this multiple of the noise floor.
REACH_RATIO = 1.15
#: A chain above :data:`REACH_RATIO` x the floor is still recommended (labelled a partial explanation) when it
#: explains at least this share of the mean squared misfit above the floor ...
PARTIAL_SHARE = 0.95
#: ... and ends within this multiple of the floor. A built-in of the wrong form standing in for physics the
#: library lacks stays short of one or the other on the foreign-effect batches (72-96 % at 1.16-2.84 x), so it
#: is listed as partial and not recommended, as before.
PARTIAL_RATIO = 1.5
#: A chain that explains at least this share of the mean squared misfit above the floor is recommended (partial) up to
#: :data:`PARTIAL_RATIO_FAR` x the floor: the built-ins standing in for physics the library lacks explain at most 96 % on
#: the foreign-effect batches, and a three-arm backbone beside the library's two-arm one was silent at 79x -> 1.8x
#: (99.96 %) and 17x -> 2.0x (98.6 %) (bench-heldout54).
PARTIAL_SHARE_FAR = 0.98
PARTIAL_RATIO_FAR = 3.0
#: Candidates (best held-out first) also tried with per-sample parameters in each round: samples that differ
#: a lot make the shared version of the right effect rank low (two slacks 4x apart), so more than the top two.
PER_SAMPLE_TRIES = 4
#: Solver steps (per start) a candidate's refit on all rows may take: one that needs more has a direction the
#: data barely resolve (an effect that trades with E_t); the refits of accepted candidates take 4-20.
CHECK_MAX_NFEV = 60
#: Solver steps (per start) the refit of the samples' union may take (:meth:`Search.try_sample_wise`): a union of
#: several effects fitted per sample from each sample's own values converges slower than one candidate (a five-effect
#: union: 64 steps).
UNION_MAX_NFEV = 4 * CHECK_MAX_NFEV
#: An effect a sample diagnosed alone recommends that explains less than this share of what the samples' effects
#: explain together is minor: where the samples fitted together cannot resolve its copy in that sample, the union is
#: fitted without that copy (:meth:`Search.try_sample_wise`) rather than refused.
MINOR_SHARE = 0.01
#: Before stopping, this many of the first round's best candidates are tried in place of each chosen effect.
SWAP_TRIES = 3
#: Significant digits of the start values printed with ``--init`` (and used by the diagnosis itself).
INIT_DIGITS = 6


@dataclass(frozen=True, eq=False)
class Candidate:
    """One effect tried on top of the current model.

    Attributes
    ----------
    effect : str
        The effect added.
    effects : tuple[str, ...]
        Every effect of the candidate model.
    rmse_deg, heldout_rmse_deg : float
        In-sample RMSE (search rows) and held-out RMSE (every block tested once).
    delta_bic : float
        BIC of the candidate minus BIC of the current model (negative: better).
    params : dict
        The effect's parameters: full name -> (value, stderr, unit).
    equivalent : tuple[str, ...]
        Candidates of the same round it cannot be told apart from.
    confounded : tuple[str, ...]
        Fitted parameters it cannot be told apart from (``name (r=...)``).
    significant : bool
        Passes every check (significance, identifiability, resolution); the all-rows
        check decides whether it is recommended.
    why : str
        Why it is not significant or not trusted (empty if it passes).
    gain_z : float
        Fall of the held-out MSE over its standard error.
    replaces : tuple[str, ...]
        Effects chosen earlier that this candidate takes the place of: with it in the model their
        parameters went to a bound (it explains what they did), so it is also tried without them.
    held : dict
        Per-sample copies of the effect held at its ``off`` values (``name@S -> value``): the effect is
        fitted in the other samples only (in sample S its copies were not resolved).
    """

    effect: str
    effects: tuple
    rmse_deg: float
    heldout_rmse_deg: float
    delta_bic: float
    params: dict
    equivalent: tuple = ()
    confounded: tuple = ()
    significant: bool = False
    why: str = ""
    predicted: np.ndarray | None = None
    values: dict = field(default_factory=dict)
    gain_z: float = 0.0
    block_mse: np.ndarray | None = None
    per_sample: tuple = ()
    replaces: tuple = ()
    held: dict = field(default_factory=dict)

    @property
    def label(self) -> str:
        """The effect, and the chosen effects it takes the place of (``toe_shape (replacing slack)``)."""
        return self.effect + (f" (replacing {', '.join(self.replaces)})" if self.replaces else "")


@dataclass(frozen=True, eq=False)
class Step:
    """One bar of the waterfall: the model with ``effects``, refitted on all rows."""

    effects: tuple
    rmse_deg: float
    rmse_per_sample: dict
    params: dict
    stderr: dict
    units: dict
    predicted: np.ndarray
    residuals: np.ndarray
    per_sample: tuple = ()
    init: dict = field(default_factory=dict)


@dataclass(frozen=True, eq=False)
class Diagnosis:
    """Outcome of :func:`diagnose`.

    Attributes
    ----------
    data : Dataset
        The rows diagnosed.
    noise_floor_deg, noise_floor_se_deg : float
        The estimated sensor floor and its standard error.
    base_rmse_deg, base_heldout_rmse_deg : float
        The current model's errors (search rows / held-out).
    rounds : tuple[tuple[Candidate, ...], ...]
        Ranked candidates of each greedy round (round 0: on the current model).
    recommended : tuple[str, ...]
        Effects to add, in order.
    rejected : tuple[tuple[str, str], ...]
        Candidates that passed the search but failed the all-rows check: (effect, reason).
    waterfall : tuple[Step, ...]
        The current model (with the baseline effects that joined), then one step per recommended effect (the last is what the command reproduces).
    fit_params : tuple[str, ...]
        Parameters fitted besides the effects' own.
    per_sample : tuple[str, ...]
        Parameters fitted per sample in the final model.
    sample_notes : tuple[str, ...]
        Which samples differ and by how much; samples the final model leaves worse.
    grid : int
        Grid values per new parameter used by the fits (``--starts``).
    partial : tuple[str, ...]
        Effects that passed every check and lowered the error, but whose chain leaves the final RMSE above
        :data:`REACH_RATIO` x the noise floor: a structured misfit remains, so they are not recommended
        (``recommended`` is then empty and ``waterfall`` holds the current model only).
    partial_steps : tuple[Step, ...]
        The current model, then one step per partial effect (refitted on all rows), as ``waterfall`` would.
    noise_floor_parts_deg : (float, float)
        Statistical and systematic parts of ``noise_floor_se_deg`` (see :func:`noise_floor_parts`).
    noise_lag_rows : int
        The largest row spacing the floor is read at (:func:`noise_lag`; 1: white noise, else noise correlated between
        neighbouring rows, read from rows this far apart), on the final model's residual.
    noise_lags_rows : dict[str, int]
        Each sample's row spacing the floor is read at (:func:`noise_lags`), on the final model's residual.
    alone : dict
        Each sample diagnosed alone, when the samples differ in that some are explained alone (something recommended)
        and some are not (their built-ins leave them partial), so no union could be fitted: ``{sample: {"recommended",
        "explanation", "partial", "before_deg", "after_deg", "floor_deg"}}``; empty otherwise.
    stiffness_note : str
        Why the search ran again with E_t per sample (:meth:`Search.stiffness_differs`) when that answer was kept;
        ``""`` otherwise.
    max_effects : int or None
        The most effects the search could recommend (``--max-effects``; 0: none was searched for).
    replaced : tuple[tuple[tuple[str, ...], str], ...]
        Effects chosen earlier and dropped for a later one that explains what they did: ``((old, ...), new)``.
    chosen_round : dict
        The round (index into ``rounds``) in which each recommended (or partial) effect was chosen.
    given : Step
        The model as given, refitted on all rows (``waterfall[0]`` unless a baseline effect joined).
    baseline : tuple[str, ...]
        Baseline effects (:data:`BASELINE`) that joined the model: ``waterfall`` starts from the model with them.
    baseline_gain : dict
        ``{effect: (chain, rmse_before_deg, rmse_after_deg)}``: the all-rows RMSE of the chain of effects
        chosen when the baseline effect joined, without and with it.
    dropped : tuple[str, ...]
        Effects chosen in an earlier round and dropped before stopping: the chain without them was not
        significantly worse on held-out cycles (a later effect explains what they did).
    stop_reason : str
    instruments : Instruments or None
        The instruments' check the rows went through (:func:`camtube.model.diagnose.instruments.check_instruments`):
        rows set aside, the angle's lag; set by the caller.
    explanation : str
        ``complete`` or ``partial`` (see :func:`explanation_label`) when something is recommended, else ``""``.
    cache : Cache
        Derived results computed once per diagnosis (the ``unexplained`` analysis); not part of the value.
    seconds : dict
        Wall time of the parts (not written to JSON: output is deterministic).
    """

    data: Dataset
    model: JointModel
    noise_floor_deg: float
    base_rmse_deg: float
    base_heldout_rmse_deg: float
    rounds: tuple
    recommended: tuple
    waterfall: tuple
    fit_params: tuple
    stop_reason: str
    fixed: dict = field(default_factory=dict)
    seconds: dict = field(default_factory=dict)
    catalog: dict = field(default_factory=dict)
    noise_floor_se_deg: float = 0.0
    rejected: tuple = ()
    per_sample: tuple = ()
    sample_notes: tuple = ()
    grid: int = GRID
    partial: tuple = ()
    partial_steps: tuple = ()
    noise_floor_parts_deg: tuple = ()
    replaced: tuple = ()
    chosen_round: dict = field(default_factory=dict)
    given: Step | None = None
    baseline: tuple = ()
    baseline_gain: dict = field(default_factory=dict)
    dropped: tuple = ()
    explanation: str = ""
    instruments: object = None
    held: dict = field(default_factory=dict)
    noise_lag_rows: int = 1
    noise_lags_rows: dict = field(default_factory=dict)
    alone: dict = field(default_factory=dict)
    stiffness_note: str = ""
    max_effects: int | None = None
    cache: Cache = field(default_factory=Cache, init=False, compare=False, repr=False)

    @property
    def candidates(self) -> tuple:
        """Ranked candidates of the first round (each effect on the current model)."""
        return self.rounds[0] if self.rounds else ()

    @property
    def final(self) -> Step:
        return self.waterfall[-1]


# ----------------------------------------------------------------------------- pieces



#: The floor's MAD is taken in windows of this many differences (within a contiguous run) and the windows' squares
#: averaged: the root mean square of noise whose size changes along the record, each window robust to a spike or a kink.
FLOOR_WINDOW = 32
#: What that windowed estimate reads on white Gaussian noise of unit sigma, per order of the differences (the mean
#: square of a short window's MAD exceeds the square of its mean): measured on 32 million draws, +-0.0002
#: (``tests/model/test_diagnose_reach.py`` checks it on fresh noise).
FLOOR_WINDOW_GAIN = {2: 1.0388, 3: 1.0524, 4: 1.0640}


def _windowed_mad(ds: list, k: int) -> float:
    """Root mean square over windows of :data:`FLOOR_WINDOW` of ``1.4826 MAD`` of the differences ``ds`` (a list of
    arrays, one per contiguous run; a run shorter than one window is one window), over :data:`FLOOR_WINDOW_GAIN`."""
    squares = []
    for d in ds:
        nw = d.size // FLOOR_WINDOW
        x = d[: nw * FLOOR_WINDOW].reshape(nw, FLOOR_WINDOW) if nw else d.reshape(1, -1)
        mad = np.median(np.abs(x - np.median(x, axis=1, keepdims=True)), axis=1)
        squares.append((1.4826 * mad) ** 2)
    return math.sqrt(float(np.mean(np.concatenate(squares)))) / FLOOR_WINDOW_GAIN[k]


def _floor_estimates(parts: list) -> dict[tuple[str, int], float]:
    """Every estimate of the white-noise sigma (deg) of the residual ``parts`` (contiguous runs).

    ``("mad", k)``: ``1.4826 MAD(diff^k r) / sqrt(C(2k, k))`` (robust to the kinks at reversals);
    ``("sd", k)``: the standard deviation of the same differences; ``("wmad", k)``: the MAD in short windows,
    their root mean square (:func:`_windowed_mad`); ``("sd_lag1", 2)``: the standard deviation for
    noise with a correlation ``rho`` between neighbouring rows, ``rho`` solved from the lag-1
    covariance of the 2nd differences. Each is unbiased for white Gaussian noise; they disagree when
    the noise is not quite white or Gaussian or when the model's error leaks into the differences.
    Where the noise's size changes along the stroke (the load cell's noise passes into the angle error
    only where the model lets the force act, not at rest or where the tendon is slack) the MAD estimates
    the typical size, below the root mean square the RMSE is compared with; the standard deviations and the
    windowed MAD estimate that root mean square, the windowed MAD robust to a spike or a kink at a reversal
    (where a model error leaks into the differences).
    """
    out: dict[tuple[str, int], float] = {}
    for k, norm in ORDERS:
        ds = [np.diff(seg, k) for seg in parts if seg.size > k + 4]
        if not ds:
            continue
        d = np.concatenate(ds)
        out[("mad", k)] = 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(norm)
        out[("sd", k)] = float(np.std(d)) / math.sqrt(norm)
        out[("wmad", k)] = _windowed_mad(ds, k) / math.sqrt(norm)
        if k == 2:
            # allow a correlation rho between neighbouring rows: var(diff^2) = s^2 (6 - 8 rho) and the lag-1
            # covariance of diff^2 is s^2 (-4 + 7 rho); solved for s (rho = 0: white noise, the same as "sd")
            var = float(np.var(d))
            mu = float(np.mean(d))
            lag = float(np.mean(np.concatenate([(x[:-1] - mu) * (x[1:] - mu) for x in ds])))
            q = lag / var if var > 0 else -2.0 / 3.0
            rho = float(np.clip((6.0 * q + 4.0) / (7.0 + 8.0 * q), -0.3, 0.3)) if 7.0 + 8.0 * q > 0 else 0.0
            out[("sd_lag1", k)] = math.sqrt(var / (6.0 - 8.0 * rho))
    return out


#: Noise correlated between neighbouring rows (a tracker or a load cell that filters its readings) reads low in
#: differences of neighbouring rows. It shows as a rise of the estimate from rows 1 to :data:`NOISE_CORR_PROBE` apart
#: (every ``L``-th row, each phase a run of its own) by more than this share; white noise reads the same at every
#: spacing, and a model's smooth error does not reach the highest order's differences at such short spacings ...
NOISE_CORR_RISE = 0.08
#: ... (the spacing of that test, in rows) ...
NOISE_CORR_PROBE = 4
#: ... and then the floor is read from rows as far apart as this span (s) allows (a power of 2 rows): the readings'
#: filters hold for tens of ms (beside them the white part of the noise, the load cell's through the model, keeps the
#: rise from one spacing to the next small), the joint's motion takes seconds ...
NOISE_CORR_MAX_S = 0.2
#: ... when there the 2nd-, 3rd- and 4th-difference estimates agree within this share, as they do for noise whose
#: rows that far apart are independent. A model error that changes within a few rows (a lead screw's periodic error
#: at a low rate) also rises with the spacing, but reads less in each higher order: it is not noise.
NOISE_CORR_AGREE = 0.05


def _every(parts: list, lag: int) -> list:
    """The runs ``parts`` taken every ``lag``-th row, each phase a run of its own."""
    return parts if lag <= 1 else [seg[p::lag] for seg in parts for p in range(lag)]


def _sample_spacing(dt_s: float, part: np.ndarray) -> int:
    """The row spacing one sample's residual ``part`` (rows ``dt_s`` apart) is read at: 1 for white noise; for noise
    correlated from row to row (the estimate of :func:`_floor_estimates`, ``("wmad", k)``, smallest over the orders,
    rises by :data:`NOISE_CORR_RISE` from 1 to :data:`NOISE_CORR_PROBE` rows apart) the largest power of 2 within
    :data:`NOISE_CORR_MAX_S`, when the orders agree there (:data:`NOISE_CORR_AGREE`)."""
    if not dt_s > 0:
        return 1
    widest = 1
    while 2 * widest * dt_s <= NOISE_CORR_MAX_S:
        widest *= 2
    if widest < 2:
        return 1
    near = _smallest(_floor_estimates([part]), "wmad")
    probe = _smallest(_floor_estimates(_every([part], min(NOISE_CORR_PROBE, widest))), "wmad")
    if not (math.isfinite(near) and near > 0.0 and probe > (1.0 + NOISE_CORR_RISE) * near):
        return 1
    far = [v for (kind, _), v in _floor_estimates(_every([part], widest)).items() if kind == "wmad"]
    if len(far) < 2 or not max(far) <= (1.0 + NOISE_CORR_AGREE) * min(far):
        return 1
    return widest


def _spaced_estimates(data: Dataset, parts: list) -> tuple[tuple[int, ...], dict]:
    """``(spacings, estimates)``: each sample's row spacing (:func:`_sample_spacing`, in the order of
    :meth:`Dataset.sample_slices`) and :func:`_floor_estimates` of the residual ``parts`` (one run per sample), each
    read at its sample's spacing.

    The test is made per sample: two samples logged by two trackers, one filtering its readings and one not, are
    not one kind of noise (pooled, the white sample's estimate diluted the filtered one's rise below the test's line
    and the floor read 15 % low: ``bench-heldout29``'s tracker drift)."""
    steps = data.median_steps_s(positive=True)
    lags = tuple(_sample_spacing(dt, p) for dt, p in zip(steps, parts))
    if all(L == 1 for L in lags):
        return lags, _floor_estimates(parts)
    return lags, _floor_estimates([seg for p, L in zip(parts, lags) for seg in _every([p], L)])


def noise_lags(data: Dataset, parts: list) -> tuple[int, ...]:
    """Each sample's row spacing the floor of the residual ``parts`` (one run per sample) is read at
    (:func:`_sample_spacing`): 1 for white noise, more for noise correlated from row to row."""
    return _spaced_estimates(data, parts)[0]


def noise_lag(data: Dataset, parts: list) -> int:
    """The largest of :func:`noise_lags`: 1 when every sample's noise is white."""
    return max(noise_lags(data, parts), default=1)


def _smallest(est: dict, kind: str) -> float:
    """The smallest over the orders of the estimates ``est`` (of :func:`_floor_estimates`) of ``kind``; inf for none."""
    vals = [v for (k, _), v in est.items() if k == kind]
    return min(vals) if vals else math.inf


def _spaced_residual(data: Dataset, residual_deg: np.ndarray) -> tuple[tuple[int, ...], dict]:
    """:func:`_spaced_estimates` of a residual ``(n,)``, one run per sample: what :func:`noise_reading` and
    :func:`noise_floor_parts` both read (computed once where a caller needs both)."""
    r = np.asarray(residual_deg, float)
    return _spaced_estimates(data, [r[sl] for _, sl in data.sample_slices()])


def noise_reading(data: Dataset, residual_deg: np.ndarray,
                  spaced: tuple[tuple[int, ...], dict] | None = None) -> tuple[float, float, tuple[int, ...]]:
    """``(floor, typical size, spacings)``: :func:`noise_levels` and each sample's row spacing they were read at
    (:func:`noise_lags`), from one pass (``spaced``: :func:`_spaced_residual` of this residual, when at hand)."""
    r = np.asarray(residual_deg, float)
    lags, est = spaced if spaced is not None else _spaced_residual(data, r)
    out = [_smallest(est, kind) for kind in ("wmad", "mad")]
    floor, typical = (v if math.isfinite(v) else float(np.std(r)) for v in out)
    return floor, typical, lags


def noise_levels(data: Dataset, residual_deg: np.ndarray) -> tuple[float, float]:
    """``(floor, typical size)`` (deg) of a residual ``(n,)``: :func:`noise_floor` and :func:`noise_typical` from one
    pass over its differences per sample (the standard deviation of the residual where the record is too short)."""
    return noise_reading(data, residual_deg)[:2]


def floor_seen(current: tuple[float, float, tuple[int, ...]],
               reading: tuple[float, float, tuple[int, ...]]) -> tuple[float, float, tuple[int, ...]]:
    """The floor ``(root mean square, typical size, spacings)`` once a better model's residual gives ``reading``, the
    floor so far being ``current`` (both of :func:`noise_reading`).

    A model's error can only add to the estimate, so the smaller of the two stands, as a rule. But where the new
    residual reads a sample from rows further apart, its noise is correlated from row to row: the model's larger
    error before kept the orders from agreeing there (the test of :func:`_sample_spacing`), and the estimate from
    neighbouring rows read that noise low. The new reading then stands (``bench-heldout27``'s toe: two filtered
    trackers, the paper model's 22x misfit; the floor kept at 0.184 deg from neighbouring rows, against 0.240 true,
    while the final model's residual read both samples 8 rows apart).
    """
    if any(new > old for new, old in zip(reading[2], current[2])):
        return reading
    return (min(current[0], reading[0]), min(current[1], reading[1]),
            tuple(max(a, b) for a, b in zip(current[2], reading[2])))


def noise_floor(data: Dataset, residual_deg: np.ndarray) -> float:
    """White-noise standard deviation (deg) of a residual ``(n,)``, from its high-order differences per sample:
    the smallest over the orders 2-4 of their MAD in short windows, averaged as squares (``("wmad", k)`` of
    :func:`_floor_estimates`). It estimates the root mean square of the noise, the RMSE a model without error
    leaves, also where the noise's size changes along the stroke (one MAD over the record reads the typical size:
    up to 8 % below it on bench records, where the force noise is absent at rest); each window's median keeps it
    robust to a spike or a kink, and the smallest order keeps the model's error out."""
    return noise_levels(data, residual_deg)[0]


def noise_typical(data: Dataset, residual_deg: np.ndarray) -> float:
    """The typical size (deg) of the white noise in a residual ``(n,)``: the smallest over the orders 2-4 of
    ``1.4826 MAD(diff^k r) / sqrt(C(2k, k))`` over each sample (``("mad", k)`` of :func:`_floor_estimates`). Equal
    to :func:`noise_floor` where the noise keeps its size, below it where the size changes along the stroke; the
    search's own tests (its stop, the error above the noise an effect must explain) compare with it, so the search
    looks for effects a little below the line of the labels (see :class:`Search`)."""
    return noise_levels(data, residual_deg)[1]


def noise_floor_parts(data: Dataset, residual_deg: np.ndarray, blocks: np.ndarray,
                      spaced: tuple[tuple[int, ...], dict] | None = None) -> tuple[float, float]:
    """The two parts (deg) of the uncertainty of :func:`noise_floor`: ``(statistical, systematic)`` (``spaced``:
    :func:`_spaced_residual` of this residual, when at hand).

    *Statistical*: the standard error of the estimate from its spread over the ``blocks`` ``(n,)`` int of
    the rows (blocks of cycles).
    *Systematic*: the range (largest minus smallest) of ten estimates of the same sigma -- the median
    absolute deviation (over the record and in short windows) and the standard deviation of the 2nd, 3rd and
    4th differences, and the standard deviation of the 2nd differences allowing a correlation between
    neighbouring rows. For white Gaussian
    noise they agree within their statistical error; they part when the residual is not that: a weak
    correlation between neighbouring rows (the force noise passes into the angle error through the model,
    with a gain that changes along the stroke), noise whose size changes along the stroke (no force noise
    where the tendon is slack), or model error that leaks into the differences. Which of them is right is
    not known from the data, so their whole range is the systematic uncertainty.
    """
    r = np.asarray(residual_deg, float)
    lags, est_at = spaced if spaced is not None else _spaced_residual(data, r)
    lag_of = dict(zip((smp for smp, _ in data.sample_slices()), lags))
    sample = np.asarray(data.sample)
    est = list(est_at.values())
    systematic = float(max(est) - min(est)) if len(est) > 1 else 0.0
    vals = []
    for b in np.unique(blocks):
        idx = np.flatnonzero(blocks == b)
        # contiguous runs only (a block is contiguous within a sample)
        cut = np.flatnonzero(np.diff(idx) > 1) + 1
        v = _smallest(_floor_estimates(_every([r[seg] for seg in np.split(idx, cut)], lag_of[sample[idx[0]]])),
                      "wmad")
        if math.isfinite(v):
            vals.append(v)
    if len(vals) < 3:
        statistical = 0.05 * noise_floor(data, r)
    else:
        statistical = float(np.std(vals, ddof=1) / math.sqrt(len(vals)))
    return statistical, systematic


def noise_floor_se(data: Dataset, residual_deg: np.ndarray, blocks: np.ndarray) -> float:
    """Uncertainty (deg) of :func:`noise_floor`: statistical and systematic parts (:func:`noise_floor_parts`)
    added in quadrature."""
    return float(math.hypot(*noise_floor_parts(data, residual_deg, blocks)))


#: The search keeps at least this many rows per cycle (it may then exceed ``max_rows``, up to 4x).
MIN_ROWS_PER_CYCLE = 25
#: Fewest rows ``max_rows`` may ask for (0 asks for all): each candidate is fitted on half of the blocks of
#: cycles and tested on the other half, with several parameters; a handful of rows is no test at all.
MIN_SEARCH_ROWS = 100


def thin(data: Dataset, max_rows: int) -> Dataset:
    """Every k-th row (time order kept) so that at most about ``max_rows`` remain.

    Long records keep at least :data:`MIN_ROWS_PER_CYCLE` rows per cycle (up to ``4 max_rows``) so
    that history effects stay visible within each cycle.
    """
    n = len(data)
    if max_rows > 0:
        cycles = sum(int(np.unique(np.asarray(data.cycle)[sl]).size) for _, sl in data.sample_slices())
        max_rows = min(max(max_rows, MIN_ROWS_PER_CYCLE * cycles), 4 * max_rows)
    if max_rows <= 0 or n <= max_rows:
        return data
    k = int(math.ceil(n / max_rows))
    # the speed and the smoothed force of the full record (a step between kept rows averages over the dropped
    # ones; a mean over the kept rows alone would keep more of the noise)
    return data.with_full_rate_columns().take(np.arange(0, n, k))


def cycle_blocks(data: Dataset, per_sample: int = 8) -> tuple[np.ndarray, np.ndarray]:
    """Blocks of whole cycles and their fold: ``(block (n,) int, fold (n,) int in {0, 1})``.

    Each sample's cycles are cut into up to ``per_sample`` contiguous blocks
    (alternate time blocks when a sample has one cycle); blocks alternate
    between the folds, starting with fold 0 for the first sample and fold 1
    for the second (and so on), so cycle 1 is a test block in both folds'
    turn when there are several samples.
    """
    cyc = np.asarray(data.cycle)
    block = np.zeros(len(data), int)
    fold = np.zeros(len(data), int)
    nb = 0
    for k, (_, sl) in enumerate(data.sample_slices()):
        c = cyc[sl]
        uc = np.unique(c)
        m = c.size
        if uc.size >= 2:
            nbk = min(per_sample, uc.size)
            rank = np.searchsorted(uc, c)
            b = rank * nbk // uc.size
        else:
            nbk = per_sample
            b = np.arange(m) * nbk // max(m, 1)
        block[sl] = nb + b
        fold[sl] = (b + k) % 2
        nb += nbk
    return block, fold


def block_strata(data: Dataset, block: np.ndarray) -> np.ndarray:
    """The sample index of each block id (``np.unique(block)`` order)."""
    smp = np.zeros(len(data), int)
    for k, (_, sl) in enumerate(data.sample_slices()):
        smp[sl] = k
    ids, first = np.unique(block, return_index=True)
    return smp[first]


def holdout_mask(data: Dataset) -> np.ndarray:
    """(n,) bool: rows of fold 0 (see :func:`cycle_blocks`): the training rows of the first fit."""
    return cycle_blocks(data)[1] == 0


def _rounded(values: Mapping[str, float]) -> dict[str, float]:
    return {k: float(f"{float(v):.{INIT_DIGITS}g}") for k, v in values.items()}


def refit_all_rows(model: JointModel, data: Dataset, names: Sequence[str], fixed: Mapping[str, float],
                   init: Mapping[str, float], grid: int, per_sample: Sequence[str] = (),
                   max_nfev: int | None = None) -> FitResult:
    """The fit ``camtube model fit ... --init NAME=VALUE ... --starts GRID [--per-sample ...]`` makes.

    ``init`` is rounded to :data:`INIT_DIGITS` significant digits first, as the printed command has it.
    ``max_nfev`` caps each start's solver (a candidate's check: a fit that has not converged by then is
    refused, so an accepted one is the command's fit).
    """
    params = model.make_params(data, names, fixed, initial=_rounded(init), per_sample=per_sample)
    return fit(model, data, params=params, grid=grid, max_nfev=max_nfev)


def _off_on_bound(catalog: Mapping[str, Effect], params: Mapping[str, float]) -> dict:
    """Per-sample copies (``name@S``) among ``params`` at their effect's ``off`` value where that value is a
    bound of the parameter: ``name@S -> off value``."""
    out = {}
    for nm, v in params.items():
        base, at, _ = nm.partition("@")
        eff_name, _, pname = base.partition(".")
        eff = catalog.get(eff_name)
        if not at or eff is None or pname not in (eff.off or {}):
            continue
        spec = next(p for p in eff.params if p.name == pname)   # Effect checks that off names its parameters
        off = float(eff.off[pname])
        tol = 1e-9 * max(1.0, spec.hi - spec.lo)
        if min(abs(off - spec.lo), abs(off - spec.hi)) <= tol and abs(float(v) - off) <= tol:
            out[nm] = off
    return out


def _search_fit(model: JointModel, data: Dataset, names: Sequence[str], values: Mapping[str, float],
                fixed: Mapping[str, float], **fit_options) -> FitResult:
    """A looser, capped fit of the search: starts at ``values`` (every name, per-sample copies included).

    ``fit_options`` go to :func:`fit`: ``grid``, ``grid_names``, ``rows``, ``max_nfev`` (default 100), ``keep``
    (default 1), and ``per_sample`` (names fitted per sample) and ``starts`` (extra start values).
    """
    per_sample = fit_options.pop("per_sample", ())
    starts = fit_options.pop("starts", ())
    params = model.make_params(data, names, fixed, per_sample=per_sample)
    # held values stay held (per-sample copies held off, a baseline effect a stand-in holds off)
    params = params.with_values({k: v for k, v in values.items()
                                 if k in params and not (k in fixed and k not in names)})
    starts = [{k: v for k, v in st.items() if k in params} for st in starts]
    options = {"max_nfev": 100, "keep": 1, "tol": 1e-8, **fit_options}
    return fit(model, data, params=params, starts=[st for st in starts if st], **options)


def _cv(model: JointModel, data: Dataset, names: Sequence[str], start: Mapping[str, float],
        fixed: Mapping[str, float], fold: np.ndarray, block: np.ndarray,
        per_sample: Sequence[str] = ()) -> tuple[float, np.ndarray]:
    """Held-out RMSE (deg) and per-block held-out MSE: fit on one fold, test on the other, both ways."""
    measured = np.asarray(data.angle_deg, float)
    res = np.empty(len(data))
    for f in (0, 1):
        test = fold == f
        if not test.any() or test.all():
            continue
        r = _search_fit(model, data, names, start, fixed, rows=~test, per_sample=per_sample, max_nfev=40)
        res[test] = measured[test] - r.predicted[test]
    if (fold == fold[0]).all():  # one fold only: fall back to the in-sample residual
        r = _search_fit(model, data, names, start, fixed, per_sample=per_sample, max_nfev=40)
        res = measured - r.predicted
    ids = np.unique(block)
    mse = np.array([float(np.mean(res[block == b] ** 2)) for b in ids])
    return float(np.sqrt(np.mean(res**2))), mse


def _names_for(model: JointModel, fit_params: Sequence[str]) -> tuple:
    out = list(fit_params)
    for e in model.effects:
        out.extend(e.full_names())
    return tuple(dict.fromkeys(out))




def _resolution_scales(data: Dataset) -> tuple[float, float, float]:
    """``(sample interval s, record length s, stroke span mm)`` of ``data``, cached per Dataset."""
    hit = data.cache.get("search.resolution_scales")
    if hit is None:
        t = np.asarray(data.time_s, float)
        dts = [h for (_, sl), h in zip(data.sample_slices(), data.median_steps_s()) if sl.stop - sl.start > 2]
        dt = float(np.median(dts)) if dts else 0.0
        record = max((float(np.ptp(t[sl])) for _, sl in data.sample_slices()), default=0.0)
        span = float(np.ptp(np.asarray(data.stroke_mm, float))) if len(data) else 0.0
        hit = data.cache.set("search.resolution_scales", (dt, record, span))
    return hit


def _resolution_problems(model: JointModel, names: Sequence[str], values: Mapping[str, float],
                         stderr: Mapping[str, float], at_bound: Sequence[str], data: Dataset,
                         modulus_range_gpa: tuple[float, float]) -> list[str]:
    """Why the fitted ``names`` cannot be trusted: on a bound, infinite stderr, not resolvable by ``data`` (all
    the rows measured: the search's thinned rows have a longer interval but resolve the same time constants)."""
    return [msg for _, msg in _resolution_findings(model, names, values, stderr, at_bound, data, modulus_range_gpa)]


def _resolution_findings(model: JointModel, names: Sequence[str], values: Mapping[str, float],
                         stderr: Mapping[str, float], at_bound: Sequence[str], data: Dataset,
                         modulus_range_gpa: tuple[float, float]) -> list[tuple[str, str]]:
    """:func:`_resolution_problems` as ``(name, why)`` pairs."""
    dt, record, span = _resolution_scales(data)
    out = []
    free_base = {nm.split("@")[0] for nm in names if nm not in at_bound and math.isfinite(stderr.get(nm, math.inf))}
    for nm in names:
        spec = model.spec(nm)
        v = float(values[nm])
        se = float(stderr.get(nm, math.inf))
        unit = f" {spec.unit}" if spec.unit else ""
        if ("@" in nm and nm.split("@")[0] in free_base and spec.lo == 0.0 and abs(v) <= 1e-6 * max(spec.hi, 1.0)
                and nm in at_bound):
            continue  # the effect is absent in this sample only (its value is zero): reported per sample
        if nm in at_bound:
            out.append((nm, f"{nm} = {v:.4g}{unit} is on its bound"))
        elif not math.isfinite(se):
            out.append((nm, f"{nm} has an infinite standard error (the data do not depend on it)"))
        if spec.kind == "time":
            if v < 3 * dt:
                out.append((nm, f"{nm} = {v:.3g} s is shorter than three sample intervals ({3 * dt:.3g} s)"))
            elif v > record:
                out.append((nm, f"{nm} = {v:.3g} s is longer than the record ({record:.3g} s)"))
        elif spec.kind == "length" and abs(v) > span:
            out.append((nm, f"{nm} = {v:.3g} mm exceeds the stroke span ({span:.3g} mm)"))
        elif spec.kind == "modulus" and not (modulus_range_gpa[0] <= v <= modulus_range_gpa[1]):
            out.append((nm, f"{nm} = {v:.4g} GPa is outside the plausible range {modulus_range_gpa[0]:g}-"
                            f"{modulus_range_gpa[1]:g} GPa (widen it with --modulus-range)"))
    return out


def inert_in_sample(eff: Effect, model: JointModel, data: Dataset, values: Mapping[str, float],
                     predicted_deg: np.ndarray, sample: str) -> bool:
    """True when ``eff``'s per-sample copies of ``sample`` do nothing there: with the copies named in ``eff.off``
    set at their off values, that sample's RMSE rises by at most :data:`INERT_SHARE` over its RMSE at ``values``
    (``predicted_deg`` ``(n,)``: the model at ``values`` on ``data``). The data do not depend on such copies, so
    they cannot be resolved (a carriage that the rail of that sample holds for a few rows only, at a ratio far
    below the other sample's): the sample does not show the effect. False when no copy of it has an off value."""
    got = _on_and_off(eff, model, data, values, predicted_deg, sample)
    if got is None:
        return False
    fitted, off = got
    return math.isfinite(off) and off <= (1.0 + INERT_SHARE) * fitted


def _on_and_off(eff: Effect, model: JointModel, data: Dataset, values: Mapping[str, float],
                predicted_deg: np.ndarray, sample: str = "") -> tuple[float, float] | None:
    """``(RMSE, RMSE with eff switched off)`` on the rows of ``sample`` (every row: ``""``) at ``values``
    (``predicted_deg`` ``(n,)``: the model at ``values`` on ``data``; switched off: :func:`_switched_off`); None when
    ``values`` holds none of its ``off`` parameters there, or ``data`` no such sample."""
    vals = _switched_off(eff, values, sample)
    sl = next((s for name, s in data.sample_slices() if name == sample), None) if sample else slice(None)
    if vals is None or sl is None:
        return None
    meas = np.asarray(data.angle_deg[sl], float)
    off = float(np.sqrt(np.mean((meas - model.predict(data, vals)[sl]) ** 2)))
    fitted = float(np.sqrt(np.mean((meas - np.asarray(predicted_deg, float)[sl]) ** 2)))
    return fitted, off


def _switched_off(eff: Effect, values: Mapping[str, float], sample: str = "") -> dict | None:
    """``values`` with ``eff`` switched off: the parameters named in ``eff.off`` at their off values, in ``sample``
    only (its copies ``name@S``) or, with no sample, the shared ones and every sample's copy; None when ``values`` has
    none of them."""
    vals = dict(values)
    moved = False
    for k, v in (eff.off or {}).items():
        key = f"{eff.name}.{k}"
        for nm in values:
            if nm == f"{key}@{sample}" if sample else (nm == key or nm.startswith(key + "@")):
                vals[nm] = float(v)
                moved = True
    return vals if moved else None


def _step(r: FitResult, per_sample: Sequence[str] = (), init: Mapping[str, float] | None = None) -> Step:
    return Step(tuple(e.name for e in r.model.effects), r.rmse, dict(r.rmse_per_sample), dict(r.params),
                dict(r.stderr), dict(r.units), r.predicted, r.residuals, tuple(per_sample),
                _rounded(init or {}))


# ----------------------------------------------------------------------------- the search

@dataclass(frozen=True)
class SearchSettings:
    """The settings of a :class:`Search` (see :func:`diagnose` for each)."""

    fit_params: tuple = ("E_t",)
    fixed: dict = field(default_factory=dict)
    max_rows: int = 4000
    max_effects: int = 4
    bic_threshold: float = 10.0
    min_gain: float = 0.02
    min_excess: float = 0.1
    stop_ratio: float | None = 1.15
    z: float = 2.0
    grid: int = GRID
    modulus_range_gpa: tuple = (1.0, 300.0)
    per_sample: bool = True
    init: dict = field(default_factory=dict)
    given_per_sample: tuple = ()


class _Union(NamedTuple):
    """The union of the samples' chains fitted on every row (:meth:`Search._sample_union`)."""

    fit: FitResult
    model: JointModel
    names: tuple                # fitted names
    per_sample: list            # of them, those fitted per sample
    held: dict                  # per-sample copies held off
    effects: list               # the effects added
    base_new: list              # baseline effects that joined in some samples alone
    base_split: list            # baseline effects of the chain split by sample
    base_model: JointModel      # the model before the effects
    failed: bool                # not converged, or not below the chain's RMSE and BIC
    problems: list              # resolution findings, (name, why)


class _Tested(NamedTuple):
    """A chain as the samples' stiffness test takes it (:meth:`Search.stiffness_differs`): as it was when the search
    held it."""

    model: JointModel
    names: tuple                # fitted names
    per_sample: list            # of them, those fitted per sample
    fit: FitResult              # on the search rows
    heldout_rmse_deg: float
    block_mse: np.ndarray
    held: dict                  # the values held then (:meth:`Search._fx`)


@dataclass
class _Chain:
    """The chain of effects the search stands on: the model and its fits (search rows and all rows)."""

    model: JointModel        # the model as given, with the baseline effects that joined
    current: JointModel      # ... plus the effects chosen so far
    names: tuple             # fitted parameter names of ``current``
    per_sample: list         # of them, those fitted per sample
    fit: FitResult           # ``current`` fitted on the search rows
    heldout_rmse_deg: float
    block_mse: np.ndarray
    all_rows: FitResult      # ``current`` refitted on every row
    steps: list              # the waterfall: the model as given, then one step per chosen effect
    chosen: list             # the effects chosen, in order


def diagnose(
    model: JointModel,
    data: Dataset,
    fit_params: Sequence[str] = ("E_t",),
    fixed: Mapping[str, float] | None = None,
    *,
    candidates: Sequence[str | Effect] | None = None,
    max_rows: int = 4000,
    max_effects: int = 4,
    bic_threshold: float = 10.0,
    min_gain: float = 0.02,
    min_excess: float = 0.1,
    stop_ratio: float | None = 1.15,
    registry: Registry | None = None,
    z: float = 2.0,
    grid: int = GRID,
    modulus_range_gpa: tuple[float, float] = (1.0, 300.0),
    per_sample: bool = True,
    init: Mapping[str, float] | None = None,
    baseline: Sequence[str | Effect] | None = None,
    given_per_sample: Sequence[str] = (),
) -> Diagnosis:
    """Find the effects missing from ``model`` (see the module docstring): ``Search(...).run()``.

    Parameters
    ----------
    model : JointModel
        The current model (base plus effects already chosen).
    data : Dataset
        Rows to diagnose (selected cycles, both directions, deadband kept).
    fit_params : sequence of str
        Base parameters to fit (effects' parameters are always fitted).
    fixed : dict, optional
        Values of held parameters and starting values (e.g. E_t, L0 from the pattern).
    candidates : sequence, optional
        Effects (or names in ``registry``) to try (default: every effect of ``registry`` not in ``model``).
    registry : Registry, optional
        The effects known to this call (default: the built-ins; add a user's file's effects with
        :meth:`Registry.with_effects`).
    max_rows : int
        Rows used by the candidate search (thinned evenly in time); 0 = all.
    max_effects : int
        Most effects recommended.
    bic_threshold, min_gain, min_excess : float
        Significance besides the ``z`` test: delta BIC below ``-bic_threshold``; held-out RMSE down by
        ``min_gain`` (relative) and by ``min_excess`` of the held-out MSE above the noise floor.
    stop_ratio : float or None
        Stop when the held-out RMSE is within ``stop_ratio`` x the floor; None: no stop rule.
    z : float
        A step must lower the held-out MSE by more than ``z`` standard errors of that fall.
    grid : int
        Grid values per new parameter for the multi-start fits.
    modulus_range_gpa : (float, float)
        Plausible tendon moduli; a fitted E_t outside is not trusted.
    per_sample : bool
        Test per-sample parameters for the recommended effects (several samples only).
    init : dict, optional
        Extra start values ``{full name: value}`` for candidates' parameters (``--init``): each candidate
        is also fitted from them (useful for multimodal parameters such as a period).
    given_per_sample : sequence of str
        Parameters of ``model`` (full names: its effects', or a base parameter's) fitted per sample from the start
        (``--per-sample``): an effect added after an earlier diagnosis whose samples differ in it.
    baseline : sequence, optional
        Effects (or names in ``registry``) taken into the baseline, not recommended, when the data show them
        (default :data:`BASELINE`; ``()``: none, they are then ordinary candidates). Before every round
        each is tried on top of the current chain; it joins when it is significant and trusted and the
        chain rebuilt with it from the start still lowers the RMSE at every step.

    Returns
    -------
    Diagnosis
    """
    settings = SearchSettings(tuple(fit_params), dict(fixed or {}), max_rows, max_effects, bic_threshold, min_gain,
                              min_excess, stop_ratio, z, grid, tuple(modulus_range_gpa), per_sample, dict(init or {}),
                              tuple(given_per_sample))
    with one_blas_thread():  # speed: tall, thin linear algebra (see camtube.model.core.threads)
        search = Search(model, data, settings, candidates=candidates, registry=registry, baseline=baseline)
        d = search.run()
        if not d.recommended and _at_floor(d):
            return d   # nothing to add, at the floor: no answer with fewer effects could replace it (_stiffer_answer)
        note = search.stiffness_differs(d)
        if not note:
            return d
        # the samples' tendons differ in stiffness: the search again, E_t per sample from the start (as
        # --per-sample E_t does), kept when it ends lower
        again = replace(settings, given_per_sample=tuple(settings.given_per_sample) + ("E_t",))
        d2 = Search(model, data, again, candidates=candidates, registry=registry, baseline=baseline).run()
        if not _stiffer_answer(d, d2):
            return d
        return replace(d2, stiffness_note=note + _modulus_values(d2))


class Search:
    """The diagnosis search as an object (the way lmfit's ``Minimizer`` holds a fit): the rows, the settings,
    the chain of effects chosen so far, the candidates and the rounds live on ``self``; each step of the
    method is a method a test can run alone; :meth:`run` runs them all and returns a :class:`Diagnosis`.

    ``Search(model, data, settings).fit_base()`` fits the model as given and estimates the noise floor;
    :meth:`try_baseline`, :meth:`rank` (one round of candidates on the current chain), :meth:`check_all_rows`,
    :meth:`accept`, :meth:`try_drop` and :meth:`try_per_sample` each do one step; :meth:`result` builds the
    :class:`Diagnosis` from the state.
    """

    def __init__(self, model: JointModel, data: Dataset, settings: SearchSettings = SearchSettings(), *,
                 candidates: Sequence[str | Effect] | None = None, registry: Registry | None = None,
                 baseline: Sequence[str | Effect] | None = None):
        self.clock = {"start": time.perf_counter()}
        self.settings = settings
        self.fixed = dict(settings.fixed)
        #: per-sample copies held off (an effect fitted in some samples only): ``name@S -> value``
        self.held: dict = {}
        self.cand_held: dict = {}
        self.given_model = model
        self.data = data
        self.registry = registry if registry is not None else builtin_registry()
        reg = self.registry
        pool = list(reg.effects) if candidates is None else [reg.get_effect(c) if isinstance(c, str) else c
                                                              for c in candidates]
        have = {e.name for e in model.effects}
        names_b = BASELINE if baseline is None else baseline
        pending = [reg.get_effect(b) if isinstance(b, str) else b for b in names_b
                   if not isinstance(b, str) or b in reg]
        self.pending = [e for e in pending if e.name not in have]
        self.pool = [e for e in pool if e.name not in have and e.name not in {b.name for b in self.pending}]
        self.all_pool = list(self.pool)
        check_fittable(data)
        self.chain: _Chain | None = None
        self.rounds: list[tuple[Candidate, ...]] = []
        self.recommended: list[str] = []
        self.rejected: list[tuple[Candidate, str]] = []  # (candidate, why it failed the all-rows check)
        self.replaced: list[tuple[tuple, str]] = []
        self.chosen_round: dict[str, int] = {}
        self.dropped: list[str] = []
        self.baseline_added: list[str] = []
        self.baseline_gain: dict[str, tuple] = {}
        self.first_useful: list[Effect] = []
        self.notes_late: list[str] = []
        # the extra starts of a round (``--init``); as before, once a candidate has been checked on all rows its
        # values are the next round's extra starts
        self.round_init: dict = dict(settings.init)
        self.swaps_tried = False
        self.full_retry = False
        #: each sample diagnosed alone, when some are explained and some are not (see Diagnosis.alone)
        self.alone: dict = {}
        self.retry_prev: tuple = ()
        self.retry_pool: list[Effect] = []
        self.stop = ""
        #: the chain once its first effect was chosen: where the samples' stiffness is tested besides the model as
        #: given (:meth:`stiffness_differs`)
        self.first_chain: _Tested | None = None

    def _fx(self, model: JointModel, held: Mapping[str, float] | None = None) -> dict:
        """The held values for a fit of ``model``: the user's ``fixed``, plus the per-sample copies held off
        (the chain's and ``held``) of the effects ``model`` has."""
        specs = model.param_specs
        out = dict(self.fixed)
        for src in (self.held, _whole_held(held or {})):
            out.update({k: v for k, v in src.items() if k.split("@")[0] in specs})
        return out

    # ------------------------------------------------------------------ the model as given
    def fit_base(self) -> "Search":
        """Fit the model as given on every row, estimate the noise floor, thin the search rows, cut the blocks."""
        s, data = self.settings, self.data
        names = _names_for(self.given_model, s.fit_params)
        ps = [n for n in s.given_per_sample if n in names] if len(data.samples) > 1 else []
        base_full = refit_all_rows(self.given_model, data, names, self.fixed, {}, s.grid, per_sample=ps)
        self.block_all, _ = cycle_blocks(data)
        spaced = _spaced_residual(data, base_full.residuals)
        self.floor_rms, self.floor, self.floor_lags = noise_reading(data, base_full.residuals, spaced)
        self.floor_parts = noise_floor_parts(data, base_full.residuals, self.block_all, spaced)
        self.floor_se = math.hypot(*self.floor_parts)
        self.clock["base"] = time.perf_counter()
        self.search = thin(data, s.max_rows)
        self.block, self.fold = cycle_blocks(self.search)
        self.strata = block_strata(self.search, self.block)
        cur = _search_fit(self.given_model, self.search, names, base_full.params, self.fixed, per_sample=ps)
        cur_ho, cur_mse = _cv(self.given_model, self.search, names, cur.params, self.fixed, self.fold, self.block,
                              per_sample=ps)
        self.base_rmse, self.base_ho = cur.rmse, cur_ho
        self.base_fit, self.base_mse, self.base_names, self.base_ps = cur, cur_mse, names, list(ps)
        self.given = _step(base_full, ps)
        self.chain = _Chain(self.given_model, self.given_model, names, list(ps), cur, cur_ho, cur_mse, base_full,
                            [self.given], [])
        return self

    def _refit_search(self, values: Mapping[str, float]) -> None:
        ch = self.chain
        ch.fit = _search_fit(ch.current, self.search, ch.names, values, self._fx(ch.current), per_sample=ch.per_sample)

    # ------------------------------------------------------------------ baseline
    def try_baseline(self) -> None:
        """Each pending baseline effect on top of the chain; those that join go into the model as given."""
        for eff in list(self.pending):
            got = self.baseline_try(eff)
            if got is None:
                continue
            ch = self.chain
            self.baseline_gain[eff.name] = (tuple(e.name for e in ch.chosen), ch.all_rows.rmse, got[3].rmse)
            ch.model, ch.current, ch.names, ch.all_rows, ch.steps, cb = got
            self._refit_search(cb.values)
            ch.heldout_rmse_deg, ch.block_mse = cb.heldout_rmse_deg, cb.block_mse
            self.baseline_added.append(eff.name)
            self.pending.remove(eff)

    def baseline_try(self, eff: Effect):
        """The baseline effect ``eff`` on top of the current chain, if it joins: ``(model, current, names, fit on
        all rows, waterfall, candidate)`` with ``eff`` in the model from the start; None when it does not.

        It joins when it passes a round's tests (significant on held-out cycles, lower BIC, parameters trusted),
        its refit on all rows lowers the RMSE with every parameter off its bounds, and the chain rebuilt with it
        from the start (model + eff, + each chosen effect in turn) lowers the RMSE at every step.
        """
        s, ch, data = self.settings, self.chain, self.data
        ranked = self.rank([eff])
        c = next((c for c in ranked if not c.replaces), None)
        if c is None or not c.significant:
            return None
        chain = ch.current.with_effects(list(ch.current.effects) + [eff])
        names = ch.names + tuple(eff.full_names())
        init = {k: v for k, v in c.values.items() if k.split("@")[0] in names}
        r = refit_all_rows(chain, data, names, self._fx(chain), init, s.grid, per_sample=ch.per_sample)
        if not r.rmse < ch.all_rows.rmse or _resolution_problems(chain, list(r.fitted), r.params, r.stderr,
                                                                 r.at_bound, data, s.modulus_range_gpa):
            return None
        start = ch.model.with_effects(list(ch.model.effects) + [eff])
        steps = self.chain_steps(start, ch.chosen, range(len(ch.chosen)), r.params, ch.per_sample)
        steps.append(_step(r, ch.per_sample, {k: v for k, v in init.items() if k in r.fitted}))
        if not _each_lower([st.rmse_deg for st in steps]):
            return None
        return start, chain, names, r, steps, c

    def chain_steps(self, start: JointModel, effects: Sequence[Effect], counts, values: Mapping[str, float],
                    per_sample: Sequence[str]) -> list[Step]:
        """Waterfall steps of ``start`` plus ``effects[:i]`` for each ``i`` of ``counts``, each refitted on all
        rows from ``values`` (per-sample names kept where the step has the parameter)."""
        out = []
        for i in counts:
            mi = start.with_effects(list(start.effects) + list(effects[:i]))
            ni = _drop_names(_names_for(mi, self.settings.fit_params), self.held)
            psi = [n for n in per_sample if n.split("@")[0] in ni]
            ri = refit_all_rows(mi, self.data, ni, self._fx(mi),
                                {k: v for k, v in values.items() if k.split("@")[0] in ni}, self.settings.grid,
                                per_sample=psi)
            out.append(_step(ri, psi))
        return out

    # ------------------------------------------------------------------ one round
    def rank(self, pool: list[Effect], try_per_sample: bool = False, init: Mapping[str, float] | None = None,
             swappable: Sequence[Effect] = (), swap_all: bool = False) -> tuple[Candidate, ...]:
        """Every effect of ``pool`` on top of the current chain, ranked by held-out RMSE.

        With ``try_per_sample``, the best :data:`PER_SAMPLE_TRIES` effects are also fitted with per-sample
        parameters; that version replaces the shared one when its held-out error is significantly lower. When
        a candidate's fit puts a parameter of an effect of ``swappable`` (chosen earlier in this diagnosis) on a
        bound, the candidate explains what that effect did: it is also tried *instead of* it (stepwise
        selection with replacement), so an early stand-in (slack for a sharp toe) does not stay in the model.
        With ``swap_all`` each candidate is tried only instead of each effect of ``swappable``.
        """
        fits = self._fit_candidates(pool, try_per_sample, init, swappable, swap_all)
        tried = [self._judge(*row) for row in fits]
        tried.sort(key=lambda c: (c.heldout_rmse_deg, c.effect, c.replaces))
        s = self.settings
        return _order_candidates(tried, {e.name: e.family for e in pool}, self.floor,
                                 self.chain.heldout_rmse_deg, s.min_gain, s.bic_threshold)

    def _fit_one(self, m: JointModel, names: tuple, start: Mapping[str, float], per_sample: Sequence[str],
                 held: Mapping[str, float] | None = None, **opts) -> tuple[FitResult, float, np.ndarray]:
        """``m`` fitted on the search rows and cross-validated: ``(fit, held-out RMSE, block MSE)``."""
        fx = self._fx(m, held)
        f = _search_fit(m, self.search, names, start, fx, per_sample=per_sample, **opts)
        ho, mse = _cv(m, self.search, names, f.params, fx, self.fold, self.block, per_sample=per_sample)
        return f, ho, mse

    def _fit_held(self, m: JointModel, names: tuple, start: Mapping[str, float], per_sample: Sequence[str],
                  eff: Effect, held: Mapping[str, float]) -> tuple[FitResult, float, np.ndarray]:
        """:meth:`_fit_one` with ``eff``'s copies ``held`` off, from a grid over its copies that stay fitted."""
        kept = [f"{n}@{smp}" for n in eff.full_names() for smp in self.search.samples if f"{n}@{smp}" not in held]
        return self._fit_one(m, names, start, per_sample, held=held, grid=self.settings.grid, grid_names=kept)

    def _chain_names(self, held: Mapping[str, float], new: Sequence[str], new_per_sample: Sequence[str]) -> tuple:
        """``(fitted names, per-sample names)`` of the chain plus ``new`` (``new_per_sample`` of them per sample),
        without the parameters ``held`` (a baseline effect a stand-in holds off)."""
        ch = self.chain
        return (_drop_names(tuple(ch.names) + tuple(new), held),
                list(_drop_names(tuple(ch.per_sample) + tuple(new_per_sample), held)))

    def _baseline_off(self, eff: Effect) -> dict:
        """``{parameter: off value}`` of the baseline effects in the chain that ``eff`` may take the place of
        (:data:`BASELINE_STAND_INS`); empty when there is none."""
        out = {}
        for b in self.chain.current.effects:
            if b.name in self.baseline_added and eff.name in BASELINE_STAND_INS.get(b.name, ()) and b.off:
                out.update({f"{b.name}.{k}": float(v) for k, v in b.off.items()})
        return {k: v for k, v in out.items() if k in self.chain.names}

    def _absent(self, eff: Effect, m: JointModel, f: FitResult) -> dict:
        """Per-sample copies of ``eff`` to hold off: in each sample where a copy of ``f`` (a per-sample fit) is
        not resolved (on a bound, a time or length outside what the record resolves) or where its copies do nothing
        (:func:`inert_in_sample`), every copy of that sample, those named in ``eff.off`` at their off values and the
        others where they are; empty when there
        is no such sample, when ``eff`` has no ``off`` values, or when it would be off in every sample."""
        if not eff.off:
            return {}
        samples = list(self.search.samples)
        bad = []
        for smp in samples:
            mine = [f"{n}@{smp}" for n in eff.full_names() if f"{n}@{smp}" in f.fitted]
            # bounds and ranges only: one sample's unresolved copies make every standard error infinite
            if mine and (_resolution_problems(m, mine, f.params, {n: 1.0 for n in mine},
                                              [n for n in f.at_bound if n in mine], self.data,
                                              self.settings.modulus_range_gpa)
                         or inert_in_sample(eff, m, f.data, f.params, f.predicted, smp)):
                bad.append(smp)
        if not bad or len(bad) == len(samples):
            return {}
        return _copies_off(eff, bad, f.params)

    def _refused(self, eff: Effect, m: JointModel, shared: FitResult, f: FitResult, held: Mapping[str, float]) -> dict:
        """Per-sample copies of ``eff`` to hold off where the shared version ``shared`` (``eff`` fitted for every
        sample) is refused in some samples only, as :meth:`_absent` holds them: where the data refuse its form (its
        ``check``), every copy of each sample whose own rows refuse ``f`` (``eff`` fitted per sample); else every
        copy of each sample where it takes an effect of the chain's place (:meth:`_crowded`). Empty when ``eff``
        has no ``off`` values, or when no sample would keep it (``held``: copies already held off)."""
        if not eff.off:
            return {}
        samples = list(self.search.samples)
        gone = {k.partition("@")[2] for k in held}
        if form_problem(eff, shared.data, shared.predicted, m.effects):
            pred = np.asarray(f.predicted, float)
            bad = [smp for smp, sl, sub in sample_views(f.data) if form_problem(eff, sub, pred[sl], m.effects)]
        else:
            bad = self._crowded(shared)
        bad = [smp for smp in bad if smp not in gone]
        if not bad or len(gone | set(bad)) >= len(samples):
            return {}
        return _copies_off(eff, bad, f.params)

    def _crowded(self, shared: FitResult) -> list[str]:
        """The samples where a candidate, fitted for every sample as ``shared``, takes an effect of the chain's
        place: an effect of the chain whose parameters the chain's fit resolves and ``shared`` does not (an infinite
        standard error), which does its work in one sample (switched off, it raises the other samples' RMSE by at
        most ``min_gain`` of what it raises that sample's): that sample (a joint's relaxation that stands in, in the
        sample whose carriage its rail holds, for the drive's effect; the candidate's own sample is another)."""
        ch = self.chain
        resolved = {n for n, se in ch.fit.stderr.items() if math.isfinite(se)}
        loose = {n.split("@")[0].partition(".")[0] for n in shared.fitted
                 if n in resolved and not math.isfinite(shared.stderr.get(n, 0.0))}
        data = ch.fit.data
        meas = np.asarray(data.angle_deg, float)
        on = meas - np.asarray(ch.fit.predicted, float)
        fitted = {smp: float(np.sqrt(np.mean(on[sl] ** 2))) for smp, sl in data.sample_slices()}
        out = []
        for e in ch.current.effects:
            vals = _switched_off(e, ch.fit.params) if e.name in loose else None
            if vals is None:
                continue
            off = meas - ch.current.predict(data, vals)
            rise = {smp: float(np.sqrt(np.mean(off[sl] ** 2))) - fitted[smp] for smp, sl in data.sample_slices()}
            top = max(rise, key=rise.get)
            if rise[top] > 0.0 and all(v <= self.settings.min_gain * rise[top] for k, v in rise.items() if k != top):
                out.append(top)
        return out

    def _faint(self, eff: Effect, m: JointModel, r: FitResult) -> dict:
        """Per-sample copies of ``eff`` to hold off after its refit ``r`` on every row: in each sample where a copy
        is unresolved (on a bound, an infinite standard error) and the effect does at most ``min_gain`` of what it
        does in the sample where it does most (what switching it off there adds to that sample's RMSE), every copy
        of that sample (:func:`_copies_off`); empty when there is none. (A guide's hold on its bound in the sample
        whose guide barely acts: the copies there add 0.001 deg, those of the other sample 1.8 deg.)"""
        samples = list(r.data.samples)
        unresolved = r.unidentified
        does, loose = {}, set()
        for smp in samples:
            got = _on_and_off(eff, m, r.data, r.params, r.predicted, smp)
            if got is None:
                return {}
            does[smp] = got[1] - got[0]
            if any(f"{n}@{smp}" in unresolved for n in eff.full_names()):
                loose.add(smp)
        top = max(does.values(), default=0.0)
        faint = [smp for smp in samples if smp in loose and does[smp] <= self.settings.min_gain * top]
        if not faint or len(faint) == len(samples) or not top > 0.0:
            return {}
        return _copies_off(eff, faint, r.params)

    def _instead_model(self, eff: Effect, old: Effect) -> tuple[JointModel, tuple, list]:
        """The chain with ``eff`` in place of ``old``: ``(model, fitted names, per-sample names)``."""
        ch = self.chain
        m2, names2, ps2 = _without(ch.current, ch.names, ch.per_sample, [old])
        return m2.with_effects(list(m2.effects) + [eff]), names2 + tuple(eff.full_names()), ps2

    def _forked_fits(self, fn, models: Sequence[JointModel]) -> list:
        """``[fn(0), ..., fn(n - 1)]`` one per core (speed; the same fits as one after another), each a tuple whose
        first item is a fit, or None. The fit crosses back from its worker without its model and rows (a model need
        not pickle: a user's effect file may hold lambdas) and is given ``models[i]`` and the search rows here."""
        def stripped(i: int):
            got = fn(i)
            return None if got is None else (replace(got[0], model=None, data=None),) + tuple(got[1:])

        return [None if got is None else (replace(got[0], model=m, data=self.search),) + got[1:]
                for m, got in zip(models, map_forked(stripped, len(models)))]

    def _instead(self, eff: Effect, old: Effect, values: Mapping[str, float], initial: bool) -> tuple:
        """``eff`` fitted in place of ``old`` (a swap): ``(fit, held-out RMSE, block MSE, per-sample names of ``eff``,
        copies held off or None)`` (:meth:`_swaps` makes it a row of :meth:`_fit_candidates`)."""
        ch, grid = self.chain, self.settings.grid
        gone = set(old.full_names())
        new = eff.full_names()
        m2, names2, ps2 = self._instead_model(eff, old)
        kept = {k: v for k, v in values.items() if k.split("@")[0] not in gone}
        start = m2.initial_values(self.search, base=kept) if initial else kept
        f2, ho2, mse2 = self._fit_one(m2, names2, start, ps2, grid=grid, grid_names=new)
        out = (f2, ho2, mse2, (), None)
        if any(n.split("@")[0] in gone for n in ch.per_sample) and eff.off:
            # the effect replaced was fitted per sample: so is its replacement, off where a sample does not show it
            ps3 = list(ps2) + list(new)
            f3, ho3, mse3 = self._fit_one(m2, names2, f2.params, ps3)
            held = self._absent(eff, m2, f3)
            if held:
                f3, ho3, mse3 = self._fit_held(m2, names2, f3.params, ps3, eff, held)
            if ho3 < ho2:
                out = (f3, ho3, mse3, tuple(new), held)
        return out

    def _swaps(self, jobs: Sequence[tuple]) -> list:
        """Rows of :meth:`_fit_candidates` for the swaps ``jobs`` (``(effect, old, values, initial)`` each, see
        :meth:`_instead`), fitted one per core (speed; the same fits as one after another)."""
        rows = []
        models = [self._instead_model(eff, old)[0] for eff, old, _, _ in jobs]
        for (eff, old, _, _), m2, (f, ho, mse, eff_ps, held) in zip(
                jobs, models, self._forked_fits(lambda i: self._instead(*jobs[i]), models)):
            if held is not None:
                self.cand_held[(eff.name, (old.name,))] = held
            rows.append([eff, m2, eff.full_names(), f, ho, mse, eff_ps, (old.name,)])
        return rows

    def _fit_candidates(self, pool, try_per_sample, init, swappable, swap_all) -> list:
        """Rows ``[effect, model, new names, fit, held-out RMSE, block MSE, per-sample names(, replaces)]``."""
        ch, s = self.chain, self.settings
        self.cand_held = {}
        fits = []
        # instead of each effect of swappable only (the stop ratio is reached: nothing is to be added)
        fits += self._swaps([(eff, old, ch.fit.params, True) for eff in (pool if swap_all else ()) for old in swappable])
        adding = list(() if swap_all else pool)
        models = [ch.current.with_effects(list(ch.current.effects) + [eff]) for eff in adding]

        def added(i: int):
            """``adding[i]`` added to the chain and fitted: ``(fit, held-out RMSE, block MSE, the baseline's values it
            holds off or None)``."""
            eff, m = adding[i], models[i]
            new = eff.full_names()
            start = m.initial_values(self.search, base=ch.fit.params)
            f, ho, mse = self._fit_one(m, ch.names + new, start, ch.per_sample, grid=s.grid, grid_names=new,
                                       starts=[init] if init else ())
            held = None
            unresolved = _unresolved(m, self.search, f, eff, s.min_gain)
            if unresolved:
                # a parameter that the rows kept barely depend on ended on a bound (a load cell at its limit sets
                # aside the dwells at the top, where a guide's hold shows): held at its start value
                names, ps = self._chain_names(unresolved, new, ())
                f, ho, mse = self._fit_one(m, names, f.params, ps, held=unresolved)
                held = unresolved
            off = self._baseline_off(eff)
            if off:
                # in the place of the baseline effect it may stand in for (that effect held at its off values)
                both = {**(held or {}), **off}
                names, ps = self._chain_names(both, new, ())
                f2, ho2, mse2 = self._fit_one(m, names, start, ps, held=both, grid=s.grid,
                                              grid_names=_drop_names(new, both), starts=[init] if init else ())
                if ho2 < ho or _off_at_bound(f, off):
                    f, ho, mse, held = f2, ho2, mse2, both
            return f, ho, mse, held

        # the candidates are independent: one per core
        for eff, m, (f, ho, mse, held) in zip(adding, models, self._forked_fits(added, models)):
            if held is not None:
                self.cand_held[(eff.name, ())] = held
            fits.append([eff, m, eff.full_names(), f, ho, mse, ()])
        if try_per_sample:
            tries = sorted([r for r in fits if r[2]], key=lambda r: r[4])[:PER_SAMPLE_TRIES]
            # the tries are independent: one per core
            for row, got in zip(tries, self._forked_fits(lambda i: self._per_sample_try(tries[i]),
                                                         [r[1] for r in tries])):
                if got is not None:
                    f2, ho2, mse2, held = got
                    row[3:7] = [f2, ho2, mse2, tuple(row[2])]
                    if held:
                        self.cand_held[(row[0].name, ())] = held
        jobs = []
        for row in ([] if swap_all else list(fits)):
            eff, m, new, f = row[:4]
            for old in swappable:
                if any(n.split("@")[0] in set(old.full_names()) for n in f.at_bound):
                    jobs.append((eff, old, f.params, False))
        return fits + self._swaps(jobs)

    def _per_sample_try(self, row: list):
        """The candidate of ``row`` (a row of :meth:`_fit_candidates`, shared) fitted with per-sample parameters:
        ``(fit, held-out RMSE, block MSE, copies held off)`` when that version replaces the
        shared one (its held-out gain significant and its BIC lower), else None (the fit's model and rows are
        given back by :meth:`_forked_fits`)."""
        s = self.settings
        eff, m, new, f, ho, mse, _ = row
        off = self.cand_held.get((eff.name, ()), {})   # a baseline effect it stands in for
        names, ps = self._chain_names(off, new, new)
        f2, ho2, mse2 = self._fit_one(m, names, f.params, ps, held=off)
        off_all = self._baseline_off(eff)
        if off_all and not set(off_all) <= set(off) and _off_at_bound(f2, off_all):
            off = {**off, **off_all}   # per sample, it takes the baseline effect's place
            names, ps = self._chain_names(off, new, new)
            f2, ho2, mse2 = self._fit_one(m, names, f2.params, ps, held=off)
        unresolved = _unresolved(m, self.search, f2, eff, s.min_gain)
        if unresolved:   # a sample's copy its rows barely depend on, on a bound: held at its start value
            off = {**off, **unresolved}
            names, ps = self._chain_names(off, new, new)
            f2, ho2, mse2 = self._fit_one(m, names, f2.params, ps, held=off)
        # in a sample that does not show the effect its copies are not resolved (a time constant on a bound, a
        # stand-in for another effect): the effect fitted in the other samples only
        held = self._absent(eff, m, f2)
        # where the shared version is refused for what it does in some samples only (its form: a joint resting bent
        # by itself beside a tendon its carriage holds taut at rest; an effect of the chain whose place it takes
        # there): held off in those, the effect in the others only
        refused = self._refused(eff, m, f, f2, held)
        held = {**held, **refused}
        if held:
            # (where it took the place of another effect in a sample, that effect starts from the chain's values)
            start = {**f2.params, **self.chain.fit.params} if refused else f2.params
            f3, ho3, mse3 = self._fit_held(m, names, start, ps, eff, {**off, **held})
            if refused and not form_problem(eff, f3.data, f3.predicted, m.effects):
                return f3, ho3, mse3, {**off, **held}   # judged against the chain as any candidate is
            if _significant(_gain_zs(mse, mse3, self.strata), s.z) and f3.bic < f.bic - s.bic_threshold:
                return f3, ho3, mse3, {**off, **held}
            return None   # a per-sample version with unresolved copies does not replace the shared one
        if _significant(_gain_zs(mse, mse2, self.strata), s.z) and f2.bic < f.bic - s.bic_threshold:
            return f2, ho2, mse2, off
        return None

    def _judge(self, eff, m, new, f, ho, mse, eff_ps, *swap) -> Candidate:
        """A fitted candidate against the current chain: significant? trusted? (see the module docstring)."""
        ch, s, floor = self.chain, self.settings, self.floor
        cur_ho = ch.heldout_rmse_deg
        dbic = f.bic - ch.fit.bic
        shown = [n for n in f.fitted if n.split("@")[0] in new] if eff_ps else list(new)
        params = {nm: (f.params[nm], f.stderr.get(nm, math.inf), m.spec(nm).unit) for nm in shown}
        conf = []
        idx = {nm: i for i, nm in enumerate(f.fitted)}
        for a in new:
            for b in ch.names:
                if a not in idx or b not in idx:
                    continue
                rho = f.correlation[idx[a], idx[b]] if f.correlation.size else np.nan
                if not np.isfinite(rho) or abs(rho) > CORR_LIMIT:
                    conf.append(f"{b} (r={rho:+.3f})" if np.isfinite(rho) else f"{b} (degenerate)")
        why = []
        gain = 1.0 - ho / cur_ho if cur_ho > 0 else 0.0
        excess = cur_ho**2 - floor**2
        zs = _gain_zs(ch.block_mse, mse, self.strata)
        gz = zs[0]
        if not dbic < -s.bic_threshold:
            why.append(f"delta BIC {dbic:+.1f} is not below -{s.bic_threshold:g}")
        if gain < s.min_gain:
            why.append(f"held-out RMSE falls by {100 * gain:.1f}% < {100 * s.min_gain:g}%")
        elif excess > 0 and (cur_ho**2 - ho**2) < s.min_excess * excess:
            why.append(f"explains only {100 * (cur_ho**2 - ho**2) / excess:.0f}% of the error above the noise floor")
        if gain >= s.min_gain and not _significant(zs, s.z):
            why.append(f"the held-out gain is {gz:.1f} standard errors ({zs[1]:.1f} on the log scale), not more than "
                       f"{s.z:g} ({s.z + LOG_SCALE_EXTRA_Z:g}) (within the noise)")
        if new and not why:
            why += _resolution_problems(m, list(f.fitted), f.params, f.stderr, f.at_bound, self.data,
                                        s.modulus_range_gpa)
        if new and not why:
            reason = form_problem(eff, f.data, f.predicted, m.effects)
            if reason:
                why.append(reason)
        # per-sample copies held off (absent in a sample), and a baseline effect a stand-in holds off
        held = dict(self.cand_held.get((eff.name, tuple(swap[0]) if swap else ()), {}))
        if not eff_ps:
            held = {k: v for k, v in held.items() if "@" not in k}
        return Candidate(eff.name, tuple(e.name for e in m.effects), f.rmse, ho, dbic, params,
                         confounded=tuple(conf), significant=not why, why="; ".join(why),
                         predicted=f.predicted, values=dict(f.params), gain_z=gz, block_mse=mse,
                         per_sample=eff_ps, replaces=tuple(swap[0]) if swap else (), held=held)

    # ------------------------------------------------------------------ the all-rows check and the chain
    def check_all_rows(self, c: Candidate, eff: Effect):
        """The candidate ``c`` (of effect ``eff``) refitted on every row, exactly as the printed command does:
        ``(c, eff, model, names, fit, init, per-sample names, the chain's effects in order with the candidate among
        them, the waterfall's steps before the last, floor (typical size), floor se, floor parts, floor (root mean
        square), each sample's spacing)`` when it passes
        (the floor as :func:`floor_seen` takes it with this model), else the reasons (list of str)."""
        ch, s, data = self.chain, self.settings, self.data
        # the chain's effects in order once the candidate joins: at the end, or as below for a replacement
        keep = [e for e in ch.chosen if e.name not in c.replaces] + [eff]
        m, names, ps = _without(ch.current, ch.names, ch.per_sample, [e for e in ch.chosen if e.name in c.replaces])
        m = m.with_effects(list(m.effects) + [eff])
        names = _drop_names(names + eff.full_names(), c.held)
        ps = list(_drop_names(ps, c.held)) + list(c.per_sample)
        init = {k: v for k, v in c.values.items() if k.split("@")[0] in names}
        self.round_init = init
        r = refit_all_rows(m, data, names, self._fx(m, c.held), init, s.grid, per_sample=ps, max_nfev=CHECK_MAX_NFEV)
        unresolved = _unresolved(m, data, r, eff, s.min_gain)
        if c.per_sample and not unresolved:
            # a sample the search's rows read as showing the effect and every row does not: its copies unresolved
            # there, where the effect does next to nothing; held off in that sample, as the search does (_absent)
            unresolved = self._faint(eff, m, r)
        if unresolved:
            # on every row too, a parameter of the candidate the rows barely depend on is held, not a reason to refuse
            # the effect (bench-heldout21's friction beside a backbone: the guide's hold on its bound in the sample
            # where the guide barely acts, and nothing recommended at 6.6x the floor)
            c = replace(c, held=_whole_held({**c.held, **unresolved}))
            names, ps = _drop_names(names, c.held), list(_drop_names(ps, c.held))
            init = {k: v for k, v in init.items() if k not in c.held}
            r = refit_all_rows(m, data, names, self._fx(m, c.held), init, s.grid, per_sample=ps,
                               max_nfev=CHECK_MAX_NFEV)
        problems = []
        if r.nfev >= CHECK_MAX_NFEV:
            problems.append(f"its refit on all rows had not converged after {CHECK_MAX_NFEV} steps (a direction the "
                            "data barely resolve)")
        if not r.rmse < ch.all_rows.rmse:
            problems.append(f"its refit on all rows does not lower the RMSE ({ch.all_rows.rmse:.3f} -> "
                            f"{r.rmse:.3f} deg)")
        # every fitted parameter, not only the new ones: a new effect may push E_t to its bound
        problems += _resolution_problems(m, list(r.fitted), r.params, r.stderr, r.at_bound, data,
                                         s.modulus_range_gpa)
        # the floor seen through this model's residual (a model error inflates the estimate a little)
        spaced = _spaced_residual(data, r.residuals)
        rms_c, f_c, lags_c = floor_seen((self.floor_rms, self.floor, self.floor_lags),
                                        noise_reading(data, r.residuals, spaced))
        parts_c = noise_floor_parts(data, r.residuals, self.block_all, spaced)
        se_c = math.hypot(*parts_c)
        if r.rmse < f_c - 2.0 * se_c:
            problems.append(f"its RMSE {r.rmse:.3f} deg undercuts the noise's typical size {f_c:.3f} +- "
                            f"{se_c:.3f} deg (statistical {parts_c[0]:.3f}, systematic {parts_c[1]:.3f}; "
                            "it would fit noise)")
        inter: list[Step] = []
        if not problems and c.replaces:
            # the replacement in the place of the effect it replaces (it does what that one did there), else at the
            # end of the chain: the first order in which every step of the waterfall still lowers the RMSE.
            # (Until bench-heldout32 the end was tried first: bench-heldout29's lost motion read force_zero, then
            # carriage_gap, though carriage_gap took the place of carriage_hold, first, and explained far more)
            at = min(i for i, e in enumerate(ch.chosen) if e.name in c.replaces)
            in_place = [e for e in ch.chosen[:at] if e.name not in c.replaces] + [eff] + \
                [e for e in ch.chosen[at:] if e.name not in c.replaces]
            for order in (in_place, keep) if in_place != keep else (in_place,):
                steps = self.chain_steps(ch.model, order, range(1, len(order)), r.params, ps)
                if _each_lower([ch.steps[0].rmse_deg] + [x.rmse_deg for x in steps] + [r.rmse]):
                    keep, inter = order, steps
                    break
            else:
                problems.append(f"without {', '.join(c.replaces)} a step of the chain does not lower the RMSE")
        if problems:
            return problems
        return (c, eff, m, names, r, {k: v for k, v in init.items() if k in r.fitted}, ps, keep, inter,
                f_c, se_c, parts_c, rms_c, lags_c)

    def first_passing(self, ranked, tried_pool, swaps_only: bool):
        """The first significant candidate of ``ranked`` that passes :meth:`check_all_rows` (those that fail
        are listed in ``rejected``), or None."""
        for c in ranked:
            if not c.significant or (swaps_only and not c.replaces):
                continue
            eff = next((e for e in tried_pool if e.name == c.effect), None)
            if eff is None:  # a candidate of the narrowed round, already tried (merged into the full retry)
                continue
            got = self.check_all_rows(c, eff)
            if isinstance(got, list):
                self.rejected.append((c, "; ".join(got)))
                continue
            return got
        return None

    def accept(self, accepted, ranked, ranked_base_ho: float) -> None:
        """Put the accepted candidate into the chain; narrow the next round to the effects that helped."""
        c, eff, m, names, r, init, ps, keep, inter, f_c, se_c, parts_c, rms_c, lags_c = accepted
        ch = self.chain
        self.swaps_tried = False
        self.floor, self.floor_se, self.floor_parts = f_c, se_c, parts_c
        self.floor_rms, self.floor_lags = rms_c, lags_c
        ch.per_sample = ps
        self.rejected = [(rc, w) for rc, w in self.rejected if rc.effect != eff.name]
        self.held = {k: v for k, v in self.held.items() if k.split(".")[0] not in set(c.replaces) | {eff.name}}
        self.held.update(c.held)
        if c.replaces:
            self.replaced.append((tuple(c.replaces), eff.name))
            ch.steps = ch.steps[:1] + inter
        ch.chosen = keep
        self.recommended = [e.name for e in keep]
        self.chosen_round[eff.name] = len(self.rounds) - 1
        ch.current, ch.names, ch.all_rows = m, names, r
        ch.steps.append(_step(r, ch.per_sample, init))
        self._refit_search(c.values)
        ch.heldout_rmse_deg, ch.block_mse = c.heldout_rmse_deg, c.block_mse
        if self.first_chain is None:
            self.first_chain = _Tested(ch.current, ch.names, list(ch.per_sample), ch.fit, ch.heldout_rmse_deg,
                                       ch.block_mse, self._fx(ch.current))
        # the next round tries only the effects that helped in this one (held-out RMSE down by min_gain):
        # one that explained nothing on the simpler model is not retried (speed; see the module docstring)
        useful = {x.effect for x in ranked if x.heldout_rmse_deg <= (1.0 - self.settings.min_gain) * ranked_base_ho}
        if len(self.rounds) == 1:
            # the swap round's candidates: the best SWAP_TRIES of the first round that helped
            order = [x.effect for x in sorted(ranked, key=lambda x: x.heldout_rmse_deg) if not x.replaces]
            self.first_useful = sorted([e for e in self.pool if e.name in useful], key=lambda e: order.index(e.name))
        self.pool = [e for e in self.pool if e.name != eff.name and e.name in useful]

    def try_drop(self) -> bool:
        """Drop the chosen effect whose removal costs least when the chain is not significantly better with
        it (see :meth:`drop_candidate`); True when one went."""
        got = self.drop_candidate()
        if got is None:
            return False
        ch = self.chain
        old, ch.current, ch.names, ch.per_sample, ch.all_rows, ch.steps, ch.fit, ch.heldout_rmse_deg, \
            ch.block_mse = got
        self.dropped.append(old.name)
        self.held = {k: v for k, v in self.held.items() if k.split(".")[0] != old.name}
        ch.chosen = [e for e in ch.chosen if e.name != old.name]
        self.recommended = [e.name for e in ch.chosen]
        self.swaps_tried = False
        return True

    def drop_candidate(self):
        """The chosen effect whose removal costs least, if the chain is not significantly better with it
        (held-out gain within ``z`` standard errors and search BIC within ``bic_threshold``, or all-rows BIC
        within ``bic_threshold``) and the chain without it passes the all-rows checks (its refit converged within
        :data:`CHECK_MAX_NFEV` steps, as an added candidate's must) with every step lowering the RMSE: ``(effect, model, names, per-sample names, fit on all rows, waterfall, search fit, held-out
        RMSE, block MSE)``; None when every effect is needed."""
        ch, s, data = self.chain, self.settings, self.data

        rest = [_without(ch.current, ch.names, ch.per_sample, [old]) for old in ch.chosen]

        def without(i: int):
            """The chain without its ``i``-th chosen effect, fitted on the search rows and cross-validated."""
            gone = set(ch.chosen[i].full_names())
            m, names, ps = rest[i]
            start = {k: v for k, v in ch.fit.params.items() if k.split("@")[0] not in gone}
            return self._fit_one(m, names, start, ps)

        tries = []
        # the chosen effects' removals are independent: one per core
        for old, (m, names, ps), (f, ho, mse) in zip(ch.chosen, rest, self._forked_fits(without, [r[0] for r in rest])):
            keeps = _significant(_gain_zs(mse, ch.block_mse, self.strata), s.z)  # what keeping the effect gains
            tries.append((not (keeps or f.bic - ch.fit.bic >= s.bic_threshold), ho, old, m, names, ps, f,
                          mse))
        for held_out_ok, ho, old, m, names, ps, f, mse in sorted(tries, key=lambda t: (not t[0], t[1], t[2].name)):
            init = {k: v for k, v in f.params.items() if k in names or k.split("@")[0] in names}
            r = refit_all_rows(m, data, names, self._fx(m), init, s.grid, per_sample=ps, max_nfev=CHECK_MAX_NFEV)
            if r.nfev >= CHECK_MAX_NFEV:
                # not converged: a direction the data barely resolve without the effect, refused as an added
                # candidate's refit would be (speed too: uncapped, one such refit of bench-heldout24's toe beside lost
                # motion took 518 steps, 17 s of a 106 s diagnosis, and was not the drop)
                continue
            # the thinned search rows see a coarser history (a play operator that misses the stroke's peaks):
            # an effect that helps only there is not needed either when every row does without it (BIC)
            if not held_out_ok and r.bic - ch.all_rows.bic >= s.bic_threshold:
                continue
            if _resolution_problems(m, list(r.fitted), r.params, r.stderr, r.at_bound, data, s.modulus_range_gpa):
                continue
            if _chain_form_problems(m, data, r.predicted):
                continue
            keep = [e for e in ch.chosen if e.name != old.name]
            steps = self.chain_steps(ch.model, keep, range(len(keep)), r.params, ps)
            steps.append(_step(r, ps, {k: v for k, v in init.items() if k in r.fitted}))
            if _each_lower([st.rmse_deg for st in steps]):
                return old, m, names, ps, r, steps, f, ho, mse
        return None

    # ------------------------------------------------------------------ the loop
    def _stop_check(self) -> tuple[bool, bool]:
        """``(stop now, swaps only)`` before a round: the stop ratio and ``max_effects`` first allow one round
        of swaps and drops (an effect chosen early may stand in for a later one)."""
        s, ch = self.settings, self.chain
        # the held-out RMSE at full resolution: the all-rows RMSE times the held-out / in-sample ratio of the
        # search rows (thinned rows see a coarser history and a shorter force average than all rows do)
        ho_full = ch.all_rows.rmse * ch.heldout_rmse_deg / ch.fit.rmse if ch.fit.rmse > 0 else ch.heldout_rmse_deg
        swaps_only = False
        if s.stop_ratio is not None and ho_full <= s.stop_ratio * self.floor:
            self.stop = (f"the held-out RMSE {ho_full:.3f} deg (all rows) is within {s.stop_ratio:g} x the noise's "
                         f"typical size {self.floor:.3f} deg (the floor, its root mean square: {self.floor_rms:.3f} "
                         "deg): nothing left to explain")
            if not ch.chosen or self.swaps_tried:
                return True, False
            swaps_only = self.swaps_tried = True
        if not swaps_only and len(self.recommended) >= s.max_effects:
            self.stop = f"stopped after {s.max_effects} effects"
            # the same swaps and drops before this stop: a full chain may hold stand-ins
            if self.swaps_tried:
                return True, False
            swaps_only = self.swaps_tried = True
        if not self.pool:
            # the round narrowed to nothing (no effect but the one chosen helped the round before): once, every
            # effect not yet chosen (on a joint whose backbone relaxes only ``relaxation`` helps the model as
            # given; the tracker's offset it leaves shows once it is in)
            self.pool = self._left_out()
            if not self.pool:
                self.stop = "no candidate effects left"
                return True, False
        return False, swaps_only

    def _no_swap(self, ranked, n_rejected: int) -> None:
        """No swap passed: the diagnosis stops as it would have; a swap as good as the chain (held-out within
        :data:`EQUAL_HELDOUT`) is declared indistinguishable from the effect it would replace."""
        del self.rejected[n_rejected:]
        alts = _swap_alternatives(ranked, self.chain.heldout_rmse_deg)
        self.rounds = _declare_alternatives(self.rounds, self.chosen_round, alts)
        for old, found in alts.items():
            self.notes_late.append(f"{', '.join(found)} in place of {old} explain the data as well (held-out RMSE "
                                   f"within {100 * EQUAL_HELDOUT:g} %): the data cannot tell them apart from {old}")

    def _left_out(self) -> list[Effect]:
        """The first time it is asked (once per search, the full retry): every effect neither chosen nor in the
        pool; after that, none."""
        if self.full_retry:
            return []
        self.full_retry = True
        taken = {x.name for x in self.chain.chosen} | {x.name for x in self.pool}
        return [e for e in self.all_pool if e.name not in taken]

    def _retry(self) -> bool:
        """Before giving up, run the round again with every effect not yet chosen (the pool was narrowed to the
        effects that helped the round before; one that explained nothing while a bigger effect dominated, play
        under a viscoelastic tendon, may be what is left). True when there is such a retry."""
        again = self._left_out()
        if not again:
            return False
        # only the effects left out are fitted; the round is recorded with both
        self.retry_prev, self.retry_pool = self.rounds.pop(), again
        self.pool = self.pool + again
        return True

    def step(self) -> bool:
        """One pass of the search: the baseline, the stop rules, drops, a round of candidates, the all-rows
        check and the acceptance. False when the search is over."""
        if not self.retry_pool:  # (not again before a full retry: the chain is the one the last try saw)
            self.try_baseline()
        over, swaps_only = self._stop_check()
        if over:
            return False
        ch, s = self.chain, self.settings
        if swaps_only and len(ch.chosen) > 1 and self.try_drop():
            return True
        # the swap round tries every effect that helped the model as given (one that explained little on top
        # of the stand-in, as a sharp toe on top of slack, may explain more in its place)
        tried_pool = ([e for e in self.first_useful if e.name not in {x.name for x in ch.chosen}][:SWAP_TRIES]
                      if swaps_only else self.retry_pool or self.pool)
        ranked = self.rank(tried_pool, s.per_sample and len(self.search.samples) > 1 and not swaps_only,
                           self.round_init, tuple(ch.chosen), swap_all=swaps_only)
        if self.retry_pool and not swaps_only:
            ranked = tuple(sorted(tuple(self.retry_prev) + tuple(ranked),
                                  key=lambda c: (not c.significant, c.heldout_rmse_deg, c.effect, c.replaces)))
            self.retry_prev, self.retry_pool = (), []
        ranked_base_ho = ch.heldout_rmse_deg
        n_rejected = len(self.rejected)
        accepted = self.first_passing(ranked, tried_pool, swaps_only)
        if swaps_only and accepted is None:
            self._no_swap(ranked, n_rejected)
            return False
        ranked = tuple(_mark_rejected(ranked, self.rejected))
        self.rounds.append(ranked)
        if accepted is None and self._retry():
            return True
        if accepted is None:
            top = ranked[0] if ranked else None
            self.stop = ("no candidate improves the model significantly and reliably"
                         + (f" (best: {top.effect}: {top.why})" if top is not None and top.why else ""))
            return False
        self.accept(accepted, ranked, ranked_base_ho)
        return True

    def run(self) -> Diagnosis:
        """Fit the model as given, search until a stop rule holds, try per-sample values; the result."""
        if self.chain is None:
            self.fit_base()
        while self.step():
            pass
        self.try_sample_wise()
        self.clock["search"] = time.perf_counter()
        return self.result()

    def _samples_alone(self, samples: Sequence[str]):
        """Each sample diagnosed alone (one per core): ``(recommended, baseline effects in force, final parameters,
        what each effect explains)`` each by sample, or None when a sample cannot be fitted or is left partial
        (stand-ins that leave it unexplained: no answer to combine)."""
        data, sub_settings = self.data, replace(self.settings, per_sample=False, given_per_sample=())

        def alone(i: int):
            """Sample ``i`` diagnosed alone: ``None`` when it cannot be fitted, else (partial, recommended, the
            baseline effects that joined and are in force (not held off by a stand-in), the final parameters when
            something joined, what each recommended step explains: its rows times the fall of the mean squared
            error)."""
            sub = data.take(np.asarray(data.sample) == samples[i])
            try:
                d_s = Search(self.given_model, sub, sub_settings, candidates=list(self.all_pool),
                             registry=self.registry).run()
            except (FitError, DataError):   # (a sample of a handful of rows, or one whose angle never changes)
                return None
            rmse = [w.rmse_deg for w in d_s.waterfall]
            explained = {e: len(sub) * (a * a - b * b) for e, a, b in zip(d_s.recommended, rmse, rmse[1:])}
            # a recommended stand-in of a baseline effect that joined is credited with the baseline's gain too (a
            # carriage its rail holds bends the joint at rest as a rest angle does: see baseline_stand_ins)
            stands = baseline_stand_ins(d_s.baseline, d_s.recommended)
            if stands:
                explained[stands[0][1]] += len(sub) * max(d_s.given.rmse_deg ** 2 - rmse[0] ** 2, 0.0)
            base = [b for b in d_s.baseline
                    if not all(n in d_s.held for n in self.registry[b].full_names())]
            last = d_s.partial_steps[-1] if d_s.partial else d_s.final
            summary = {"recommended": list(d_s.recommended), "explanation": d_s.explanation,
                       "partial": list(d_s.partial), "before_deg": float(d_s.waterfall[0].rmse_deg),
                       "after_deg": float(last.rmse_deg), "floor_deg": float(d_s.noise_floor_deg)}
            return (tuple(d_s.partial), list(d_s.recommended), base,
                    dict(d_s.final.params) if d_s.recommended or base else {}, explained, summary)

        # the samples' searches are independent: one per core (speed; the same results as one after another)
        found = map_forked(alone, len(samples))
        chains: dict[str, list[str]] = {}
        bases: dict[str, list[str]] = {}
        inits: dict[str, dict] = {}
        explained: dict[str, float] = {}
        if any(got is None for got in found):
            return None
        summaries = {smp: got[-1] for smp, got in zip(samples, found)}
        for smp, got in zip(samples, found):
            partial, chains[smp], bases[smp], inits[smp], gains, _ = got
            if partial:
                # no answer to combine; but where another sample is explained alone, the samples differ: said per
                # sample (bench-heldout56's toe beside a three-arm backbone: one sample's backbone took a set of
                # 110 deg, beyond every built-in, and the other sample's toe, explained alone, went unsaid)
                if any(v["recommended"] for v in summaries.values()):
                    self.alone = summaries
                return None
            for e, g in gains.items():
                explained[e] = explained.get(e, 0.0) + g
        return chains, bases, inits, explained

    def _union_fit(self, m: JointModel, names: tuple, ps: list, held: dict, init: dict, effs: Sequence[Effect]):
        """The union of :meth:`try_sample_wise` (model ``m``, its effects ``effs``, each copy of ``held`` off) fitted on
        every row: ``(fit, fitted names, per-sample names, held)``, with the copies the rows barely depend on, and those
        that end at their effect's off value, held."""
        s, data = self.settings, self.data
        r = refit_all_rows(m, data, names, {**self.fixed, **held}, init, s.grid, per_sample=ps,
                           max_nfev=UNION_MAX_NFEV)
        unresolved = {}
        for e in effs:
            unresolved.update(_unresolved(m, data, r, e, s.min_gain))
        # a sample's copy the rows barely depend on (a toe's shape where the toe is 0.01 mm) is held, as in a
        # candidate's check on all rows, not a reason to refuse the union (bench-heldout23's lost motion beside
        # a toe: the union at 0.96x the floor refused for toe_shape.shape@S1 on its bound, nothing recommended).
        # Then a sample's copy that ends on its bound at its effect's off value: beside the other effects that
        # sample does not need it, so it is held off there (as the result holds such a copy), not a reason to refuse
        # the union either (bench-heldout32's toe beside a three-arm backbone: the joint's rest angle in the toe's
        # sample went to 0 beside toe_shape and capstan, and the union, 0.21 deg against the chain's 1.74, was
        # refused for it)
        r, names, ps, held = self._union_held(m, r, names, ps, held, unresolved)
        off = _off_on_bound({e.name: e for e in effs}, {k: v for k, v in r.params.items() if k in r.fitted})
        return self._union_held(m, r, names, ps, held, off)

    def _union_held(self, m: JointModel, r: FitResult, names: tuple, ps: list, held: dict, more: dict):
        """The union's fit ``r`` refitted with the copies ``more`` held too (itself when there are none):
        ``(fit, fitted names, per-sample names, held)``."""
        if not more:
            return r, names, ps, held
        held = {**held, **more}
        names = _drop_names(names, more)
        ps = list(_drop_names(ps, more))   # (a sample's copy stays per sample, held in that one)
        init = {k: v for k, v in r.params.items() if k in r.fitted and k not in more}
        r = refit_all_rows(m, self.data, names, {**self.fixed, **held}, init, self.settings.grid, per_sample=ps,
                           max_nfev=UNION_MAX_NFEV)
        return r, names, ps, held

    def _first_lowering_order(self, base_model: JointModel, effects: Sequence[Effect], start_rmse_deg: float,
                              r: FitResult, ps: Sequence[str]) -> tuple[list | None, list]:
        """The first order of ``effects`` (in :func:`itertools.permutations`' order) whose waterfall from
        ``base_model``, each step refitted on all rows from the union's values ``r``, lowers the RMSE at every step
        from ``start_rmse_deg`` down to ``r``'s: ``(order, its steps before the last)``, or ``(None, [])``.

        speed: a step depends on the effects before it only, so each is refitted once however many orders share it
        (a union of four effects: 40 refits at most instead of 72), and the orders that begin with a step that does not
        lower the RMSE are passed over without a refit (they would fail the same test). The same order and steps as
        refitting every order in turn."""
        steps: dict[tuple, Step] = {}
        for perm in itertools.permutations(effects):
            inter, last = [], start_rmse_deg
            for i in range(1, len(perm)):
                key = tuple(e.name for e in perm[:i])
                if key not in steps:
                    steps[key] = self.chain_steps(base_model, list(perm), [i], r.params, ps)[0]
                if not steps[key].rmse_deg < last:
                    break
                inter.append(steps[key])
                last = steps[key].rmse_deg
            else:
                if r.rmse < last:
                    return list(perm), inter
        return None, []

    def _sample_union(self, samples: Sequence[str], chains: dict, bases: dict, inits: dict,
                      explained: dict) -> "_Union | None":
        """The union of the samples' chains (each diagnosed alone, :meth:`_samples_alone`) fitted on every row
        (:class:`_Union`); None when there is no union to fit (nothing to add, or every sample shows the same)."""
        ch, s, data = self.chain, self.settings, self.data
        # the union in the order of what each effect explains in its samples, most first: the waterfall then says
        # what to add first (with one sample's effects first, a shared parameter, E_t, bent by the other sample's
        # misfit leaves the first steps explaining nothing)
        union = sorted(dict.fromkeys(e for smp in samples for e in chains[smp]), key=lambda e: -explained[e])
        if not union or all(chains[smp] == chains[samples[0]] and bases[smp] == bases[samples[0]]
                            for smp in samples):
            return None
        have = {x.name for x in ch.model.effects}
        effects = [self.registry[e] for e in union if e not in have]
        # a baseline effect that joined in some samples alone (a joint resting bent after a slack tendon, beside
        # a sample whose backbone relaxes instead) joins here in those samples, held off in the others: without
        # it the union leaves the samples that needed it far from the floor
        base_new = [self.registry[b] for b in dict.fromkeys(b for smp in samples for b in bases[smp])
                    if b not in have and b not in union]
        # one that joined the joint search (shared) but is in force in some samples alone only (a stand-in holds
        # it off in the others): per sample, held off where it is not in force (shared, a rest angle one sample
        # needs bends the other sample's relaxation to its bounds)
        base_split = [e for e in ch.model.effects if e.name in self.baseline_added
                      and any(e.name in bases[smp] for smp in samples)
                      and not all(e.name in bases[smp] for smp in samples)]
        if not effects:
            return None
        base_model = ch.model.with_effects(list(ch.model.effects) + base_new) if base_new else ch.model
        m = base_model.with_effects(list(base_model.effects) + effects)
        names = _names_for(m, s.fit_params)
        ps = [n for n in self.chain.per_sample if n in s.given_per_sample] + \
            [n for e in base_split + base_new + effects for n in e.full_names()]
        start = m.initial_values(data)
        shows = {smp: set(chains[smp]) | set(bases[smp]) for smp in samples}
        held = {}
        for e in base_split + base_new + effects:
            for smp in samples:
                if e.name not in shows[smp] and e.off:
                    for p in e.params:
                        nm = f"{e.name}.{p.name}"
                        held[f"{nm}@{smp}"] = float(e.off[p.name]) if p.name in e.off else float(start[nm])
        init = {k: v for k, v in ch.all_rows.params.items() if k.split("@")[0] in names and "@" not in k}
        for smp in samples:
            init.update({f"{k}@{smp}": v for k, v in inits[smp].items()
                         if "@" not in k and k in ps and f"{k}@{smp}" not in held})
        r, names, ps, held = self._union_fit(m, names, ps, held, init, base_split + base_new + effects)
        failed = (r.nfev >= UNION_MAX_NFEV or not r.rmse < ch.all_rows.rmse
                  or not r.bic < ch.all_rows.bic - s.bic_threshold)
        problems = _resolution_findings(m, list(r.fitted), r.params, r.stderr, r.at_bound, data, s.modulus_range_gpa)
        return _Union(r, m, names, ps, held, effects, base_new, base_split, base_model, failed, problems)

    @staticmethod
    def _minor_copies(problems: Sequence[tuple[str, str]], effects: Sequence[Effect], explained: dict) -> dict:
        """``{(effect, sample): why}``: the per-sample copies among the union's ``problems`` of an effect (with
        ``off`` values) that explains less than :data:`MINOR_SHARE` of what the samples' effects explain together
        (``explained``: effect -> its gain in the samples alone)."""
        total = sum(explained.values())
        out: dict = {}
        for nm, why in problems:
            base, _, smp = nm.partition("@")
            for e in effects:
                if smp and e.off and base in e.full_names() and explained.get(e.name, 0.0) < MINOR_SHARE * total:
                    out.setdefault((e.name, smp), why)
        return out

    def _samples_differ(self) -> bool:
        """The chain holds chosen effects off in at least two samples (a per-sample copy at its ``off`` value, on
        its bound, or held so): the samples show different effects. A chain can then reach the floor with a stand-in
        that serves both samples first (``bench-heldout51``: a toe for one sample's slack and part of the other's guide
        friction, then ``capstan`` and ``force_zero``, at 0.92x the floor), where each sample diagnosed alone names its
        own (``slack``; ``capstan``): :meth:`try_sample_wise` then tries the samples' union too, taken only where it
        lowers the error and the BIC."""
        chosen = {e.name: e for e in self.chain.chosen}
        off = _off_on_bound(chosen, self.chain.all_rows.params)
        # each of two samples lacks an effect the chain holds off there (one sample lacking one effect, the chain's
        # first in both, is a chain of shared effects with a sliver in one sample: bench-shapes' weak lost motion,
        # relaxation held off in S1, the samples alone changed nothing and took 11 s)
        def held_off(k: str, v: float) -> bool:
            """``k`` is held at its effect's off value (not a copy held because the rows barely depend on it)."""
            eff_name, _, pname = k.split("@")[0].partition(".")
            e = chosen.get(eff_name)
            return e is not None and pname in (e.off or {}) and abs(float(v) - float(e.off[pname])) <= 1e-12
        lacking = {k.partition("@")[2] for k in off} | {k.partition("@")[2] for k, v in self.held.items()
                                                        if held_off(k, v)}
        return len(lacking - {""}) >= 2

    def try_sample_wise(self) -> bool:
        """When the chain leaves the error above :data:`REACH_RATIO` x the floor, or reaches it holding effects off in
        two samples (:meth:`_samples_differ`), and there are several samples:
        diagnose each sample alone; when each is explained (something recommended, or nothing to add) and they
        show different effects, fit the union with each effect held off
        (at its ``off`` values) in the samples that do not show it, and take it as the chain when it lowers the
        all-rows error and BIC with every parameter resolved and a waterfall that lowers at every step. Two
        samples that each need a different first effect defeat the joint greedy search (a stand-in that
        serves both wins its first round); one sample at a time does not. True when the chain changed."""
        ch, s, data = self.chain, self.settings, self.data
        samples = list(data.samples)
        if not s.per_sample or len(samples) < 2:
            return False
        if ch.all_rows.rmse <= REACH_RATIO * self.floor and not self._samples_differ():
            return False
        got = self._samples_alone(samples)
        if got is None:
            return False
        chains, bases, inits, explained = got
        built = self._sample_union(samples, chains, bases, inits, explained)
        if built is None:
            return False
        minor = self._minor_copies(built.problems, built.effects, explained)
        left_out = ""
        if minor and not built.failed:   # (minor copies are among the problems)
            # an effect one sample alone added last for a sliver of its misfit, whose copy there the union cannot
            # resolve: the union is fitted without that copy rather than refused whole (bench-heldout44's toe beside
            # slack: relaxation2 explained 0.001 % of what the samples' effects explain, its time on its bound in
            # the union, and the union at 0.96x the true floor was refused, nothing recommended at 34x)
            chains = {smp: [e for e in chains[smp] if (e, smp) not in minor] for smp in samples}
            total = sum(explained.values())
            left_out = "; ".join(f"{e} left out in {smp} (it explains {100 * explained[e] / total:.2g} % of what the "
                                 f"samples' effects explain, and the samples fitted together do not resolve it: {why})"
                                 for (e, smp), why in minor.items())
            built = self._sample_union(samples, chains, bases, inits, explained)
            if built is None:
                return False
        r, m, names, ps, held, effects, base_new, base_split, base_model, failed, problems = built
        if failed or problems:
            return False
        fixed = {**self.fixed, **held}
        old_held, self.held = self.held, held
        first = (self.chain_steps(base_model, [], [0], r.params, ps) if base_new or base_split else ch.steps[:1])
        order, inter = self._first_lowering_order(base_model, effects, first[0].rmse_deg, r, ps)
        if order is None:
            self.held = old_held
            return False
        r2 = r
        if order != effects:  # effects of one stage compose in the model's order: refit in the chain's order
            m = base_model.with_effects(list(base_model.effects) + order)
            r2 = refit_all_rows(m, data, names, fixed, {k: v for k, v in r.params.items() if k in r.fitted}, s.grid,
                                per_sample=ps)
        if base_new:  # what the baseline effects add to the union: the union refitted without them
            without = self.chain_steps(ch.model, order, [len(order)], r2.params, ps)[0]
            for b in base_new:
                self.baseline_gain[b.name] = (tuple(e.name for e in order), without.rmse_deg, r2.rmse)
                self.baseline_added.append(b.name)
                self.pending = [e for e in self.pending if e.name != b.name]
        ch.model = base_model
        ch.current, ch.names, ch.per_sample, ch.all_rows, ch.chosen = m, names, ps, r2, order
        ch.steps = first + inter + [_step(r2, ps, {k: v for k, v in r.params.items() if k in r.fitted})]
        self.recommended = [e.name for e in order]
        self._refit_search(r2.params)
        said = "; ".join(f"{smp} shows {', '.join(chains[smp]) or 'nothing'}"
                         + (f" (with the baseline's {', '.join(bases[smp])})"
                            if bases[smp] and (base_new or base_split) else "")
                         for smp in samples)
        self.notes_late.append(f"each sample diagnosed alone: {said}; fitted so, each effect held off in the "
                               "samples that do not show it" + (f"; {left_out}" if left_out else ""))
        return True

    # ------------------------------------------------------------------ per sample and the result
    def try_per_sample(self) -> tuple[list[str], list[str], Step | None]:
        """Try each chosen effect's parameters per sample; returns (names, notes, final step or None)."""
        ch, s, data = self.chain, self.settings, self.data
        ps: list[str] = list(ch.per_sample)
        notes: list[str] = []
        base_fit, base_mse = ch.fit, ch.block_mse
        changed = False
        for eff in ch.chosen:
            if not eff.params or all(n in ps for n in eff.full_names()):
                continue
            trial = ps + [n for n in eff.full_names() if n not in ps]
            f, ho, mse = self._fit_one(ch.current, ch.names, base_fit.params, trial)
            if _significant(_gain_zs(base_mse, mse, self.strata), s.z) and f.bic - base_fit.bic < -s.bic_threshold:
                ps = trial
                base_fit, base_mse = f, mse
                changed = True
        if not ps:
            return [], notes, None
        final = None
        r = ch.all_rows
        if changed:
            init = {k: v for k, v in base_fit.params.items() if k in base_fit.fitted}
            r = refit_all_rows(ch.current, data, ch.names, self._fx(ch.current), init, s.grid, per_sample=ps)
            if not r.rmse < ch.all_rows.rmse or r.rmse < self.floor - 2.0 * self.floor_se:
                notes.append("per-sample parameters were better on held-out cycles but not on all rows: kept as "
                             "before")
                return list(ch.per_sample), notes, None
            final = _step(r, ps, init)
        return ps, notes + _sample_notes(ch.current, r, data.samples, ps), final

    def stiffness_differs(self, d: Diagnosis) -> str:
        """Why the search should run again with E_t per sample, or "" (the usual answer).

        Two tubes on one bench rarely share their tendon's stiffness to the percent: each is tied with its own
        tendon, of its own length (L0) and make, and the tendon's stretch is most of the stroke. 5 % between two
        samples of the paper's physics left the model at 7-11x the floor, read as a kerf on its bound and a drift
        in time; 0.7 % was read as a toe, complete at 1.12x (an independent bench simulator).
        With several samples and E_t fitted and shared, tried on the model as given (an effect of a complete answer
        may stand in for it), on the chain with its first effect and, where the answer is not complete, on the final
        chain: on the search rows E_t per sample must lower the held-out error significantly (``z``), by
        ``min_gain``, with a BIC lower by ``bic_threshold``, and explain :data:`STIFFNESS_SHARE` of the held-out
        misfit above the floor (a joint whose moment arm changes with the angle, beyond the library, was read as
        moduli 0.3 % apart explaining a quarter).
        """
        s, ch = self.settings, self.chain
        if not s.per_sample or len(self.data.samples) < 2 or "E_t" not in self.base_names or "E_t" in self.base_ps:
            return ""

        def lowers(model: JointModel, names: tuple, ps: Sequence[str], fit: FitResult, ho0: float,
                   mse0: np.ndarray, fx: dict) -> float | None:
            """The held-out RMSE with E_t per sample when it passes the tests, else None (``fx``: the values held
            while that chain was the search's)."""
            trial = list(ps) + ["E_t"]
            try:
                f = _search_fit(model, self.search, names, fit.params, fx, per_sample=trial)
                ho, mse = _cv(model, self.search, names, f.params, fx, self.fold, self.block, per_sample=trial)
            except FitError:   # (a test of the samples' stiffness that cannot be fitted tells nothing)
                return None
            excess = ho0 ** 2 - self.floor ** 2
            ok = (_significant(_gain_zs(mse0, mse, self.strata), s.z) and f.bic - fit.bic < -s.bic_threshold
                  and ho <= (1.0 - s.min_gain) * ho0 and ho ** 2 - self.floor ** 2 <= (1.0 - STIFFNESS_SHARE) * excess)
            return ho if ok else None

        # ``(where, chain)`` in turn: the model as given (a complete answer may have an effect standing in for the
        # samples' stiffness: a toe took a control's 6 % at 1.12x the floor), the chain with its first effect (where
        # that effect is most of the misfit, the samples' stiffness is less than half of it on the model as given:
        # slack beside moduli 1.8 % apart, read as a viscoelastic tendon per sample), then the final chain where the
        # answer is not complete
        given = self.given_model
        tries = [(" (the model as given)", _Tested(given, self.base_names, self.base_ps, self.base_fit, self.base_ho,
                                                    self.base_mse, self._fx(given)))]
        first = self.first_chain
        if first is not None and first.model is not ch.current:
            added = ", ".join(e.name for e in first.model.effects if e not in given.effects)
            tries.append((f" (the model with {added})", first))
        if d.explanation != "complete" and ch.current is not given:
            tries.append(("", _Tested(ch.current, ch.names, ch.per_sample, ch.fit, ch.heldout_rmse_deg, ch.block_mse,
                                      self._fx(ch.current))))
        for where, chain in tries:
            ho = lowers(*chain)
            if ho is not None:
                return (f"the samples' tendons differ in stiffness: with E_t per sample the held-out RMSE falls from "
                        f"{chain.heldout_rmse_deg:.3f} to {ho:.3f} deg{where}, so the search ran again with E_t per sample from the "
                        "start (each tube tied with its own tendon: another length L0 or make; --per-sample E_t)")
        return ""

    def _notes(self) -> tuple[list[str], list[str]]:
        """Per-sample names and the notes of the final model (per-sample steps run here)."""
        ch, s = self.chain, self.settings
        ps_names: list[str] = []
        notes: list[str] = []
        if s.per_sample and len(self.data.samples) > 1 and ch.chosen:
            ps_names, notes, final = self.try_per_sample()
            if final is not None:
                ch.steps.append(final)
            ps_names = list(ch.steps[-1].per_sample)
        notes += _offset_notes(self.data, ch.steps[-1], ch.chosen, self.floor)
        notes += self.notes_late
        base_ps = self.given.rmse_per_sample
        fin_ps = ch.steps[-1].rmse_per_sample
        for smp in base_ps:
            if fin_ps.get(smp, 0.0) > 1.02 * base_ps[smp]:
                notes.append(f"sample {smp} ends worse than with the current model: RMSE {base_ps[smp]:.3f} -> "
                             f"{fin_ps[smp]:.3f} deg (the shared parameters suit the other samples)")
        return ps_names, notes

    def result(self) -> Diagnosis:
        """The :class:`Diagnosis` of the state (per-sample values tried first)."""
        ch, s = self.chain, self.settings
        ps_names, notes = self._notes()
        clock = self.clock
        clock["waterfall"] = time.perf_counter()
        secs = {"base": clock["base"] - clock["start"], "search": clock.get("search", clock["waterfall"]) - clock["base"],
                "per_sample": clock["waterfall"] - clock.get("search", clock["waterfall"]),
                "total": clock["waterfall"] - clock["start"]}
        catalog = {e.name: e for e in list(ch.model.effects) + list(self.pool) + ch.chosen}
        for rnd in self.rounds:
            for c in rnd:
                if c.effect not in catalog and c.effect in self.registry:
                    catalog[c.effect] = self.registry[c.effect]
        # the labels and every ratio reported read the floor, the noise's root mean square
        recommended, steps, floor, stop = list(self.recommended), list(ch.steps), self.floor_rms, self.stop
        # a sample's copy that ended on the bound where its effect is off: that sample does not show the effect.
        # Held there (the same fit), the printed command holds it (--fix NAME@S=VALUE) instead of refusing it
        self.held.update(_off_on_bound(catalog, steps[-1].params))
        # complete, partial (recommended), or partial effects that are not recommended (see explanation_label)
        partial: tuple = ()
        partial_steps: tuple = ()
        # the share is counted from the model as given where a recommended effect stands in for the baseline
        stands = baseline_stand_ins(self.baseline_added, recommended)
        base = self.given.rmse_deg if stands else steps[0].rmse_deg
        label = explanation_label(base, steps[-1].rmse_deg, floor) if recommended else ""
        if label == "partial":
            why = "; ".join(f"{e} can stand in for the baseline's {b}" for b, e in stands)
            stop += (f"; with {', '.join(recommended)} the RMSE is {steps[-1].rmse_deg / floor:.2f} x the noise "
                     f"floor (above {REACH_RATIO:g} x: a partial explanation), but they explain "
                     f"{100 * explained_share(base, steps[-1].rmse_deg, floor):.1f} % of the misfit "
                     f"above the floor{f' (from the model as given: {why})' if stands else ''}, so they are "
                     "recommended")
        elif recommended and not steps[-1].rmse_deg <= REACH_RATIO * floor:
            partial, partial_steps = tuple(recommended), tuple(steps)
            stop += (f"; with {', '.join(recommended)} the RMSE stays at {steps[-1].rmse_deg / floor:.2f} x the "
                     f"noise floor (above {REACH_RATIO:g} x): a structured misfit remains, so nothing is "
                     f"recommended (listed as partial)")
            recommended, steps, ps_names = [], steps[:1], []
            notes = [f"partial model: {n}" for n in notes]
        lags = dict(zip((smp for smp, _ in self.data.sample_slices()),
                        noise_lags(self.data, [steps[-1].residuals[sl] for _, sl in self.data.sample_slices()])))
        return Diagnosis(self.data, ch.model, floor, self.base_rmse, self.base_ho, tuple(self.rounds),
                         tuple(recommended), tuple(steps), tuple(s.fit_params), stop, self.fixed, secs, catalog,
                         self.floor_se, tuple({rc.label: w for rc, w in self.rejected}.items()), tuple(ps_names),
                         tuple(notes), s.grid, partial, partial_steps, self.floor_parts, tuple(self.replaced),
                         {k: self.chosen_round[k] for k in recommended or partial if k in self.chosen_round},
                         self.given, tuple(self.baseline_added), self.baseline_gain, tuple(self.dropped), label,
                         held={k: v for k, v in self.held.items() if k.split(".")[0] in set(recommended)
                               or ("@" in k and recommended and k.split(".")[0] in set(self.baseline_added))
                               or set(BASELINE_STAND_INS.get(k.split(".")[0], ())) & set(recommended)},
                         noise_lag_rows=max(lags.values(), default=1), noise_lags_rows=lags, alone=dict(self.alone),
                         max_effects=s.max_effects)


#: The share of the held-out misfit above the floor that E_t per sample must explain for the search to run again
#: with it (:meth:`Search.stiffness_differs`): two samples' moduli 5 % apart explain all of it.
STIFFNESS_SHARE = 0.5


def _stiffer_answer(d: Diagnosis, d2: Diagnosis) -> bool:
    """The answer with E_t per sample (``d2``) replaces ``d``: it ends lower; where ``d`` already reached the floor, it
    reaches it too with fewer effects (one that stood in for the samples' stiffness goes, though per-sample copies of
    it may have ended a little lower: slack alone at 0.248 deg against slack and a viscoelastic tendon per sample at
    0.241, the floor 0.237; an answer at the floor is not traded for another of as many effects)."""
    if _at_floor(d):
        return len(d2.recommended) < len(d.recommended) and _at_floor(d2)
    return d2.final.rmse_deg < d.final.rmse_deg


def _at_floor(d: Diagnosis) -> bool:
    """``d``'s final RMSE within :data:`REACH_RATIO` x its noise floor."""
    return d.final.rmse_deg <= REACH_RATIO * d.noise_floor_deg


def _modulus_values(d: Diagnosis) -> str:
    """``"; E_t S1 27.1, S2 28.9 GPa"`` from the final step's per-sample copies (empty when there are none)."""
    vals = {k.split("@")[1]: v for k, v in d.final.params.items() if k.startswith("E_t@")}
    return f"; E_t {', '.join(f'{smp} {v:.3g}' for smp, v in vals.items())} GPa" if vals else ""


def _sample_notes(model: JointModel, r: FitResult, samples: Sequence[str], ps: Sequence[str]) -> list[str]:
    """Which samples differ in each per-sample parameter (values more than three combined errors apart)."""
    notes = []
    for nm in ps:
        vals = [(smp, r.params[f"{nm}@{smp}"], r.stderr.get(f"{nm}@{smp}", math.inf)) for smp in samples]
        unit = model.spec(nm).unit
        diff = []
        for i in range(len(vals)):
            for j in range(i + 1, len(vals)):
                (sa, va, ea), (sb, vb, eb) = vals[i], vals[j]
                if abs(va - vb) > 3.0 * math.hypot(ea, eb):
                    diff.append(f"{sa} vs {sb}: {va:.4g} vs {vb:.4g} {unit}".rstrip())
        if diff:
            notes.append(f"samples differ in {nm}: " + "; ".join(diff))
        else:
            notes.append(f"{nm} per sample: " + ", ".join(f"{smp} {v:.4g}" for smp, v, _ in vals) + " (within errors)")
    return notes


def _order_candidates(tried: list, families: Mapping[str, str], floor: float, cur_ho: float, min_gain: float,
                      bic_threshold: float) -> tuple[Candidate, ...]:
    """Declare equivalences and order the candidates of a round (``tried`` sorted by held-out RMSE)."""
    # equivalences: near-equal held-out error and predictions within half the noise floor
    fam = families
    out = []
    useful = [c for c in tried if c.heldout_rmse_deg <= (1.0 - min_gain) * cur_ho and not c.replaces]
    for c in tried:
        eq = []
        for o in (useful if c in useful else ()):
            if o is c:
                continue
            same_fam = bool(fam.get(c.effect)) and fam.get(c.effect) == fam.get(o.effect)
            lo = min(o.heldout_rmse_deg, c.heldout_rmse_deg)
            close = (abs(o.heldout_rmse_deg - c.heldout_rmse_deg) <= EQUAL_HELDOUT * lo
                     or float(np.sqrt(np.mean((o.predicted - c.predicted) ** 2))) <= 0.5 * floor)
            if same_fam or close:
                eq.append(o.effect)
        out.append(replace(c, equivalent=tuple(eq)))
    # among candidates that cannot be told apart from the best, the lowest BIC (the simplest) leads
    if out and out[0].equivalent:
        # ... but a member of the group does not jump ahead of a significant candidate it is clearly worse than
        # (a family member of an untrusted best candidate: a quadratic toe far behind slack)
        sig = [c.heldout_rmse_deg for c in out if c.significant]
        cap = (1.0 + EQUAL_HELDOUT) * min(sig) if sig else math.inf
        group = [c for c in out if (c is out[0] or c.effect in out[0].equivalent)
                 and (c.heldout_rmse_deg <= cap or not c.significant)]
        lead = min(group, key=lambda c: (not c.significant, c.delta_bic, c.effect))
        # Occam: an indistinguishable candidate with fewer parameters whose BIC is within the threshold leads
        simpler = [c for c in group if c.significant == lead.significant and len(c.params) < len(lead.params)
                   and c.delta_bic <= lead.delta_bic + bic_threshold]
        if simpler:
            lead = min(simpler, key=lambda c: (len(c.params), c.delta_bic, c.effect))
        out.remove(lead)
        out.insert(0, lead)
    # parsimony: a significant replacement as good as the leader (within EQUAL_HELDOUT) leads, as it ends
    # with fewer effects
    if out and not out[0].replaces:
        swaps = [c for c in out if c.replaces and c.significant
                 and c.heldout_rmse_deg <= (1.0 + EQUAL_HELDOUT) * out[0].heldout_rmse_deg]
        if swaps:
            lead = min(swaps, key=lambda c: (c.heldout_rmse_deg, c.effect))
            out.remove(lead)
            out.insert(0, lead)
    # trusted, significant candidates first (in that order), then the rest
    out.sort(key=lambda c: not c.significant)
    return tuple(out)


def baseline_stand_ins(baseline: Sequence[str], recommended: Sequence[str]) -> list[tuple[str, str]]:
    """``(baseline effect, stand-in)`` pairs, in the order recommended: a recommended effect that can take the place
    of a baseline effect that joined (:data:`BASELINE_STAND_INS`). There the baseline's gain is the stand-in's own
    physics as much as the joint's: a carriage its rail holds keeps the joint bent at rest as a rest angle does (a
    lost-motion file: the rest angle takes 1.63 -> 0.41 deg and leaves the carriage 0.41 -> 0.40), so it is counted
    with the chain's (the explained share of the label; the order of the samples' union)."""
    return [(b, e) for e in recommended for b in baseline if e in BASELINE_STAND_INS.get(b, ())]


def explained_share(base_rmse_deg: float, final_rmse_deg: float, floor_deg: float) -> float:
    """Share of the mean squared misfit above the noise floor that a chain explains:
    ``(base^2 - final^2) / (base^2 - floor^2)`` (0 when the base is at the floor)."""
    excess = base_rmse_deg ** 2 - floor_deg ** 2
    return (base_rmse_deg ** 2 - final_rmse_deg ** 2) / excess if excess > 0 else 0.0


def explanation_label(base_rmse_deg: float, final_rmse_deg: float, floor_deg: float) -> str:
    """``complete`` (within :data:`REACH_RATIO` x the floor), ``partial`` (above it, but the chain explains at
    least :data:`PARTIAL_SHARE` of the misfit above the floor and ends within :data:`PARTIAL_RATIO` x the
    floor, or at least :data:`PARTIAL_SHARE_FAR` and within :data:`PARTIAL_RATIO_FAR` x: recommended, with what is
    left described), or ``""`` (not recommended: listed as partial effects)."""
    if final_rmse_deg <= REACH_RATIO * floor_deg:
        return "complete"
    share = explained_share(base_rmse_deg, final_rmse_deg, floor_deg)
    if ((final_rmse_deg <= PARTIAL_RATIO * floor_deg and share >= PARTIAL_SHARE)
            or (final_rmse_deg <= PARTIAL_RATIO_FAR * floor_deg and share >= PARTIAL_SHARE_FAR)):
        return "partial"
    return ""


def _without(model: JointModel, names: Sequence[str], per_sample: Sequence[str],
             effects: Sequence[Effect]) -> tuple[JointModel, tuple, list]:
    """``model``, its fitted ``names`` and its ``per_sample`` names with ``effects`` (and their parameters) removed."""
    drop = {e.name for e in effects}
    gone = {n for e in effects for n in e.full_names()}
    return (model.with_effects([e for e in model.effects if e.name not in drop]),
            tuple(n for n in names if n not in gone), [n for n in per_sample if n.split("@")[0] not in gone])


def _off_at_bound(f: FitResult, off: Mapping[str, float]) -> bool:
    """Whether ``f`` ended with a parameter of ``off`` on its bound at its off value (that effect is not needed)."""
    return any(n in f.at_bound and abs(float(f.params[n]) - v) <= 1e-6 * max(1.0, abs(v)) for n, v in off.items())


def _unresolved(model: JointModel, data: Dataset, f: FitResult, eff: Effect, share: float) -> dict:
    """Parameters of ``eff`` (shared, or a sample's copy) that ``f``, a fit of ``model`` on ``data``, left on a bound
    or with an infinite standard error (a guide's hold in the sample whose dwells at the top were set aside), and
    that the rows barely depend on against what the effect does there: moved across the parameter's whole range,
    the others at ``f``'s values, the RMSE of the rows it acts on (its sample's, for a copy) changes by at most
    ``share`` of what switching the effect off (its ``off`` values, in that sample for a copy) adds to that RMSE.
    A parameter of kind ``sharp`` on its lower bound (the law's sharp limit: a guide that switches within a row)
    passes when the bound and a decade above it move the error by as little. ``name -> value held``: the start
    value, or the bound for a sharp limit; empty when there are none, or when ``eff`` has no ``off`` values. (A
    guide's hold where the dwells at the top were set aside moves the error by 0.003 deg of the 4.5 deg the guide's law takes
    off; where an effect does little in a sample, or nothing, its copy there moves the error by as much as the
    effect does, and the sample does not show it: :meth:`Search._absent`.)"""
    out = {}
    measured = np.asarray(data.angle_deg, float)
    slices = dict(data.sample_slices())
    start = None
    mine = set(eff.full_names())
    does_in: dict = {}   # sample ("": all rows) -> (RMSE there at f, what switching the effect off adds to it)

    def rmse(predicted: np.ndarray, sl: slice) -> float:
        return float(np.sqrt(np.mean((measured[sl] - predicted[sl]) ** 2)))

    # on a bound or with an infinite standard error (FitResult.unidentified), those on a bound first
    for nm in sorted(f.unidentified, key=lambda n: n not in f.at_bound):
        base, _, smp = nm.partition("@")
        if base not in mine:
            continue
        sl = slices.get(smp, slice(None)) if smp else slice(None)
        if smp not in does_in:
            got = _on_and_off(eff, model, data, f.params, f.predicted, smp)
            does_in[smp] = (got[0], got[1] - got[0]) if got is not None else (0.0, 0.0)
        fitted, does = does_in[smp]
        if not does > 0.0:
            continue
        spec, vals = model.spec(nm), dict(f.params)
        moved = []
        for v in (spec.lo, spec.hi):
            vals[nm] = float(v)
            moved.append(rmse(model.predict(data, vals), sl))
        if all(math.isfinite(r) and abs(r - fitted) <= share * does for r in moved):
            start = start or model.initial_values(data, base={k: v for k, v in f.params.items()
                                                              if k.split("@")[0] not in mine})
            out[nm] = float(start[base])
        elif spec.kind == "sharp" and nm in f.at_bound:
            # a law at its sharp limit: its fit on the lower bound, and the bound and a decade above it read as the
            # fit does (a guide whose friction switches within a row), held on the bound as that limit. Only where
            # the fit reached the bound: held wherever it is unresolved (an infinite standard error below the
            # slowest speed the rows log), a guide's law stood in for a joint's play on a triangle of constant
            # speed (test_diagnose_replace)
            read = []
            for v in (spec.lo, min(10.0 * spec.lo, spec.hi)):
                vals[nm] = float(v)
                read.append(rmse(model.predict(data, vals), sl))
            if all(math.isfinite(r) and abs(r - fitted) <= share * does for r in read):
                out[nm] = float(spec.lo)
    return out


def _copies_off(eff: Effect, samples: Sequence[str], values: Mapping[str, float]) -> dict:
    """``eff`` held off in each of ``samples``: its copies named in ``eff.off`` at their off values, the others at
    ``values`` (those fitted per sample)."""
    out = {}
    for smp in samples:
        for p in eff.params:
            nm = f"{eff.name}.{p.name}@{smp}"
            if p.name in eff.off:
                out[nm] = float(eff.off[p.name])
            elif nm in values:   # (not a parameter held for every sample: the rows do not resolve it)
                out[nm] = float(values[nm])
    return out


def _chain_form_problems(m: JointModel, data: Dataset, predicted_deg: np.ndarray) -> list[str]:
    """Why the data contradict an effect of ``m`` whose check reads the rest of the chain (``check`` taking
    ``effects``), fitted as ``predicted_deg``: a joint's resting effect (friction, a relaxing backbone) the drive's
    effect allowed beside a taut tendon at rest, once that drive effect is gone."""
    out = []
    for e in m.effects:
        reason = form_problem(e, data, predicted_deg, m.effects) if check_reads_chain(e) else ""
        if reason:
            out.append(f"{e.name}: {reason}")
    return out


def _whole_held(held: Mapping[str, float]) -> dict:
    """``held`` without the per-sample copies (``name@S``) of a parameter it also holds whole (``name``): the whole
    holds every sample's value. (A copy held off in the sample that does not show the effect, and then the parameter
    held whole because every row barely depends on it, made a fit refuse the copy of a parameter not fitted per
    sample: ``model diagnose --effects slack`` on a bench file stopped with a fix the user could not apply.)"""
    return {k: v for k, v in held.items() if not ("@" in k and k.split("@")[0] in held)}


def _drop_names(names: Sequence[str], held: Mapping[str, float]) -> tuple:
    """``names`` without those ``held`` (whole parameters held at a value; per-sample keys ``name@S`` do not
    remove their shared name)."""
    return tuple(n for n in names if n not in held)


def _each_lower(rmse_deg: Sequence[float]) -> bool:
    """Every value below the one before it (every step of a waterfall lowers the RMSE)."""
    return all(b < a for a, b in zip(rmse_deg, rmse_deg[1:]))


def _swap_alternatives(ranked, cur_ho: float) -> dict[str, list[str]]:
    """``{chosen effect: [effect, ...]}``: swaps of the final round whose held-out RMSE is within
    :data:`EQUAL_HELDOUT` of the chain's (alternatives the data cannot rule out)."""
    out: dict[str, list[str]] = {}
    for c in ranked:
        if c.replaces and c.heldout_rmse_deg <= (1.0 + EQUAL_HELDOUT) * cur_ho:
            out.setdefault(c.replaces[0], []).append(c.effect)
    return out


def _declare_alternatives(rounds: list, chosen_round: Mapping[str, int], alts: Mapping[str, list]) -> list:
    """``rounds`` with the alternatives ``alts`` added to the ``equivalent`` of each chosen effect's candidate."""
    out = []
    for i, rnd in enumerate(rounds):
        row = []
        for c in rnd:
            more = [n for n in alts.get(c.effect, ()) if n not in c.equivalent and n != c.effect]
            if more and chosen_round.get(c.effect) == i and c.significant:
                c = replace(c, equivalent=tuple(c.equivalent) + tuple(more))
            row.append(c)
        out.append(tuple(row))
    return out


def first_rest_rows(data: Dataset, predicted: np.ndarray, tol_deg: float) -> np.ndarray:
    """Indices of the rows at the start of each sample where the model holds the joint at its first angle
    (within ``tol_deg``): the joint has not yet been loaded (the first tension goes into slack or a toe)."""
    out = []
    for _, sl in data.sample_slices():
        pr = np.asarray(predicted[sl], float)
        if pr.size == 0:
            continue
        moved = np.flatnonzero(np.abs(pr - pr[0]) > tol_deg)
        n = int(moved[0]) if moved.size else pr.size
        out.extend(range(sl.start, sl.start + n))
    return np.asarray(out, dtype=np.intp)


def _offset_notes(data: Dataset, final: Step, chosen: Sequence[Effect], floor: float) -> list[str]:
    """A constant offset that the record's first rest contradicts is not (only) the sensor's: say so.

    A sensor offset reads the same before the joint was ever loaded as after; an offset fitted because the
    joint rests bent once it has been loaded (friction in the joint, a permanent set) or because the toe law
    is wrong at low force does not. The final model's residual on the first-rest rows is then far from zero.
    """
    offsets = [e for e in chosen if e.family == "offset"]
    if not offsets or floor <= 0:
        return []
    rows = first_rest_rows(data, final.predicted, 0.5 * floor)
    if rows.size < 4:
        return []
    r = float(np.mean(final.residuals[rows]))
    se = floor / math.sqrt(rows.size)
    if abs(r) <= 3.0 * se:
        return []
    names = ", ".join(e.name for e in offsets)
    return [f"{names}: before the joint was first loaded ({rows.size} rows at the start of the record) the "
            f"final model is off by {r:+.3f} +- {se:.3f} deg, so the offset appears only once the joint has been "
            "loaded: it is not (only) a sensor offset; expect a joint that rests bent after loading (friction in "
            "the joint, a permanent set) or a toe law that is wrong at low force; read the sensor with the joint "
            "unloaded to tell"]


def _mark_rejected(ranked, rejected):
    why = {rc.label: w for rc, w in rejected}
    for c in ranked:
        if c.label in why and c.significant:
            yield replace(c, significant=False, why="all-rows check: " + why[c.label])
        else:
            yield c


def _paired(d: np.ndarray, strata: np.ndarray | None = None) -> tuple[float, float]:
    """Mean of the per-block differences ``d`` and its standard error (stratified by ``strata``, the sample of
    each block, when there are several: samples may differ, an effect present in one only; only the spread within a
    sample is noise)."""
    d = np.asarray(d, float)
    if d.size < 2:
        return float(d.mean()) if d.size else 0.0, math.inf
    if strata is None or np.unique(strata).size < 2:
        return float(d.mean()), float(d.std(ddof=1) / math.sqrt(d.size))
    var = 0.0
    for sv in np.unique(strata):
        ds = d[strata == sv]
        v = float(ds.var(ddof=1)) if ds.size > 1 else float(d.var(ddof=1))
        var += ds.size * v
    return float(d.mean()), math.sqrt(var) / d.size


def _gain(cur_mse: np.ndarray, new_mse: np.ndarray, strata: np.ndarray | None = None) -> tuple[float, float]:
    """Mean fall of the per-block held-out MSE and its standard error (paired over blocks, stratified by
    ``strata``: :func:`_paired`)."""
    return _paired(np.asarray(cur_mse, float) - np.asarray(new_mse, float), strata)


def _z(mean: float, se: float) -> float:
    return mean / se if se > 0 and math.isfinite(se) else (math.inf if mean > 0 else 0.0)


def _gain_zs(cur_mse: np.ndarray, new_mse: np.ndarray, strata: np.ndarray | None = None) -> tuple[float, float]:
    """How many standard errors the held-out error falls by over the blocks of cycles: ``(z of the fall of the
    per-block MSE (:func:`_gain`), z of the fall of its logarithm, paired the same way)``. See :func:`_significant`."""
    cur, new = np.asarray(cur_mse, float), np.asarray(new_mse, float)
    tiny = 1e-12 * max(float(np.max(cur, initial=0.0)), float(np.max(new, initial=0.0)), 1e-300)
    return _z(*_gain(cur, new, strata)), _z(*_paired(np.log((cur + tiny) / (new + tiny)), strata))


def _significant(zs: tuple[float, float], z: float) -> bool:
    """Whether a gain ``zs`` (:func:`_gain_zs`) is beyond the noise: the fall of the MSE by more than ``z`` standard
    errors, or that of its logarithm by more than ``z +`` :data:`LOG_SCALE_EXTRA_Z`.

    Why the log scale: a block's MSE scales with its misfit, so the plain fall is carried by the blocks with the most
    (a first cycle that differs, a load cell's limit leaving a few rows of a cycle) and their spread can hide a fall
    in every block: ``bench-heldout33``'s three-arm backbone, every block's error 2.3-100 times lower with
    ``relaxation2``, read 1.5 standard errors. On the log scale each block counts by the factor it falls by (5.5 there).
    It is a second look at one gain, so it must clear more: together the two refuse noise as often as the plain one
    alone (``tests/model/test_diagnose_gain.py``), and a fall of a few per cent in every block beside one block explained
    (a stand-in for a first cycle that differs) stays refused as before."""
    return zs[0] > z or zs[1] > z + LOG_SCALE_EXTRA_Z


