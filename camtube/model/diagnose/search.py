"""Diagnosis of missing physics: which effect would make the model fit, and can the answer be trusted?

``diagnose(model, data, fit_params=("E_t",), fixed=None, *, candidates=None, ...) -> Diagnosis``

Method
------
1. **Current model.** ``model`` (base plus the effects already chosen) is
   fitted to every row of ``data`` (both directions, deadband kept, so slack,
   play and creep stay visible) exactly as ``camtube model fit`` would.
2. **Noise floor.** The sensor noise is white, the model error is smooth in
   time; so the noise shows in the high-order differences of the residual
   within each sample: ``sigma = 1.4826 MAD(diff^k r) / sqrt(C(2k, k))``
   for ``k = 2, 3, 4`` (the smallest is kept). Its uncertainty has two parts
   added in quadrature: statistical (the spread of the same estimate over
   blocks of cycles) and systematic (the range of seven estimators that all
   agree for white Gaussian noise: MAD and standard deviation of the 2nd-4th
   differences, and one allowing a lag-1 correlation), see :func:`noise_floor_parts`.
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
   standard error of that fall (paired over the blocks), ``delta BIC`` is
   below ``-bic_threshold`` and the fall is a real share of the error above
   the floor. It is **trusted** when its new parameters are off their bounds
   with finite standard errors and the data can resolve them: time
   constants between three sample intervals and the record length, lengths
   within the stroke span, ``E_t`` within ``modulus_range_gpa``. A candidate
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
   final model leaves worse than the current one.
   The next round retries only the candidates whose held-out RMSE fell by ``min_gain`` in this one.
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
   not a stand-in); the ``unexplained`` analysis then describes what is left.
   Otherwise a structured misfit remains that the library does not explain:
   the effects are listed as ``partial`` (each lowers the error, none is a
   fix), nothing is recommended (a built-in of the wrong form is not offered
   for physics the library lacks), and ``unexplained`` describes what is left.

No threshold depends on the data's scale: BIC is a likelihood ratio, the
others are ratios of errors or multiples of standard errors.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Mapping, Sequence

import numpy as np

from camtube.model.core.fit import FitResult, fit
from camtube.model.core.model import Effect, JointModel
from camtube.model.core.registry import Registry, builtin_registry
from camtube.model.data.csvfile import check_fittable
from camtube.model.data.dataset import Cache, Dataset

#: Parameter correlation above which two parameters cannot be told apart.
CORR_LIMIT = 0.99
#: Held-out RMSEs within this fraction of each other: the data cannot tell the candidates apart.
EQUAL_HELDOUT = 0.03
#: Grid values per new parameter in the multi-start fits (also ``--starts`` of the printed command).
GRID = 3
#: Effects every real joint may show, which the diagnosis takes into its baseline (tried before every round)
#: instead of recommending them as missing physics: friction in the joint holds the unloaded joint bent.
BASELINE = ("rest_angle",)
#: A chain of effects is recommended only when its all-rows RMSE is within this multiple of the noise floor.
REACH_RATIO = 1.15
#: A chain above :data:`REACH_RATIO` x the floor is still recommended (labelled a partial explanation) when it
#: explains at least this share of the mean squared misfit above the floor ...
PARTIAL_SHARE = 0.95
#: ... and ends within this multiple of the floor. A built-in of the wrong form standing in for physics the
#: library lacks stays short of one or the other on the foreign-effect batches (72-96 % at 1.16-2.84 x), so it
#: is listed as partial and not recommended, as before.
PARTIAL_RATIO = 1.5
#: Candidates (best held-out first) also tried with per-sample parameters in each round: samples that differ
#: a lot make the shared version of the right effect rank low (two slacks 4x apart), so more than the top two.
PER_SAMPLE_TRIES = 4
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
    cache: Cache = field(default_factory=Cache, init=False, compare=False, repr=False)

    @property
    def candidates(self) -> tuple:
        """Ranked candidates of the first round (each effect on the current model)."""
        return self.rounds[0] if self.rounds else ()

    @property
    def final(self) -> Step:
        return self.waterfall[-1]


# ----------------------------------------------------------------------------- pieces

#: Orders of the differences and ``C(2k, k)``, the variance of a k-th difference of unit white noise.
_ORDERS = ((2, 6.0), (3, 20.0), (4, 70.0))


def _floor_estimates(parts: list) -> dict[tuple[str, int], float]:
    """Every estimate of the white-noise sigma (deg) of the residual ``parts`` (contiguous runs).

    ``("mad", k)``: ``1.4826 MAD(diff^k r) / sqrt(C(2k, k))`` (robust to the kinks at reversals);
    ``("sd", k)``: the standard deviation of the same differences; ``("sd_lag1", 2)``: the same for
    noise with a correlation ``rho`` between neighbouring rows, ``rho`` solved from the lag-1
    covariance of the 2nd differences. Each is unbiased for white Gaussian noise; they disagree when
    the noise is not quite white or Gaussian or when the model's error leaks into the differences.
    """
    out: dict[tuple[str, int], float] = {}
    for k, norm in _ORDERS:
        ds = [np.diff(seg, k) for seg in parts if seg.size > k + 4]
        if not ds:
            continue
        d = np.concatenate(ds)
        out[("mad", k)] = 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(norm)
        out[("sd", k)] = float(np.std(d)) / math.sqrt(norm)
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


def _floor_of(parts: list) -> float:
    est = [v for (kind, _), v in _floor_estimates(parts).items() if kind == "mad"]
    return min(est) if est else math.inf


def noise_floor(data: Dataset, residual_deg: np.ndarray) -> float:
    """White-noise standard deviation (deg) of a residual ``(n,)``, from its high-order differences per sample."""
    r = np.asarray(residual_deg, float)
    best = _floor_of([r[sl] for _, sl in data.sample_slices()])
    return best if math.isfinite(best) else float(np.std(r))


def noise_floor_parts(data: Dataset, residual_deg: np.ndarray, blocks: np.ndarray) -> tuple[float, float]:
    """The two parts (deg) of the uncertainty of :func:`noise_floor`: ``(statistical, systematic)``.

    *Statistical*: the standard error of the estimate from its spread over the ``blocks`` ``(n,)`` int of
    the rows (blocks of cycles).
    *Systematic*: the range (largest minus smallest) of seven estimates of the same sigma -- the median
    absolute deviation and the standard deviation of the 2nd, 3rd and 4th differences, and the standard
    deviation of the 2nd differences allowing a correlation between neighbouring rows. For white Gaussian
    noise they agree within their statistical error; they part when the residual is not that: a weak
    correlation between neighbouring rows (the force noise passes into the angle error through the model,
    with a gain that changes along the stroke), noise whose size changes along the stroke (no force noise
    where the tendon is slack), or model error that leaks into the differences. Which of them is right is
    not known from the data, so their whole range is the systematic uncertainty.
    """
    r = np.asarray(residual_deg, float)
    est = list(_floor_estimates([r[sl] for _, sl in data.sample_slices()]).values())
    systematic = float(max(est) - min(est)) if len(est) > 1 else 0.0
    vals = []
    for b in np.unique(blocks):
        idx = np.flatnonzero(blocks == b)
        # contiguous runs only (a block is contiguous within a sample)
        cut = np.flatnonzero(np.diff(idx) > 1) + 1
        v = _floor_of([r[seg] for seg in np.split(idx, cut)])
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
    return data.take(np.arange(0, n, k))


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
                   init: Mapping[str, float], grid: int, per_sample: Sequence[str] = ()) -> FitResult:
    """The fit ``camtube model fit ... --init NAME=VALUE ... --starts GRID [--per-sample ...]`` makes.

    ``init`` is rounded to :data:`INIT_DIGITS` significant digits first, as the printed command has it.
    """
    params = model.make_params(data, names, fixed, initial=_rounded(init), per_sample=per_sample)
    return fit(model, data, params=params, grid=grid)


def _search_fit(model: JointModel, data: Dataset, names: Sequence[str], values: Mapping[str, float],
                fixed: Mapping[str, float], grid: int = 0, grid_names: Sequence[str] | None = None,
                per_sample: Sequence[str] = (), rows: np.ndarray | None = None, max_nfev: int = 100,
                keep: int = 1, starts: Sequence[Mapping[str, float]] = ()) -> FitResult:
    """A looser, capped fit of the search: starts at ``values`` (every name, per-sample copies included)."""
    params = model.make_params(data, names, fixed, per_sample=per_sample)
    params = params.with_values({k: v for k, v in values.items() if k in params})
    starts = [{k: v for k, v in st.items() if k in params} for st in starts]
    return fit(model, data, params=params, grid=grid, grid_names=grid_names, rows=rows, max_nfev=max_nfev,
               tol=1e-8, keep=keep, starts=[st for st in starts if st])


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
        dts = [np.median(np.diff(t[sl])) for _, sl in data.sample_slices() if sl.stop - sl.start > 2]
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
            out.append(f"{nm} = {v:.4g}{unit} is on its bound")
        elif not math.isfinite(se):
            out.append(f"{nm} has an infinite standard error (the data do not depend on it)")
        if spec.kind == "time":
            if v < 3 * dt:
                out.append(f"{nm} = {v:.3g} s is shorter than three sample intervals ({3 * dt:.3g} s)")
            elif v > record:
                out.append(f"{nm} = {v:.3g} s is longer than the record ({record:.3g} s)")
        elif spec.kind == "length" and abs(v) > span:
            out.append(f"{nm} = {v:.3g} mm exceeds the stroke span ({span:.3g} mm)")
        elif spec.kind == "modulus" and not (modulus_range_gpa[0] <= v <= modulus_range_gpa[1]):
            out.append(f"{nm} = {v:.4g} GPa is outside the plausible range {modulus_range_gpa[0]:g}-"
                       f"{modulus_range_gpa[1]:g} GPa (widen it with --modulus-range)")
    return out


def _step(r: FitResult, per_sample: Sequence[str] = (), init: Mapping[str, float] | None = None) -> Step:
    return Step(tuple(e.name for e in r.model.effects), r.rmse, dict(r.rmse_per_sample), dict(r.params),
                dict(r.stderr), dict(r.units), r.predicted, r.residuals, tuple(per_sample),
                _rounded(init or {}))


# ----------------------------------------------------------------------------- the search

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
) -> Diagnosis:
    """Find the effects missing from ``model`` (see the module docstring).

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
    baseline : sequence, optional
        Effects (or names in ``registry``) taken into the baseline, not recommended, when the data show them
        (default :data:`BASELINE`; ``()``: none, they are then ordinary candidates). Before every round
        each is tried on top of the current chain; it joins when it is significant and trusted and the
        chain rebuilt with it from the start still lowers the RMSE at every step.

    Returns
    -------
    Diagnosis
    """
    clock = {"start": time.perf_counter()}
    fixed = dict(fixed or {})
    reg = registry if registry is not None else builtin_registry()
    if candidates is None:
        pool = list(reg.effects)
    else:
        pool = [reg.get_effect(c) if isinstance(c, str) else c for c in candidates]
    have = {e.name for e in model.effects}
    names_b = BASELINE if baseline is None else baseline
    pending = [reg.get_effect(b) if isinstance(b, str) else b for b in names_b
               if not isinstance(b, str) or b in reg]
    pending = [e for e in pending if e.name not in have]
    pool = [e for e in pool if e.name not in have and e.name not in {b.name for b in pending}]
    check_fittable(data)

    full_names = _names_for(model, fit_params)
    base_full = refit_all_rows(model, data, full_names, fixed, {}, grid)
    block_all, _ = cycle_blocks(data)
    floor = noise_floor(data, base_full.residuals)
    floor_parts = noise_floor_parts(data, base_full.residuals, block_all)
    floor_se = math.hypot(*floor_parts)
    clock["base"] = time.perf_counter()

    search = thin(data, max_rows)
    block, fold = cycle_blocks(search)
    strata = block_strata(search, block)
    current = model
    cur_names = full_names
    cur_ps: list[str] = []
    cur = _search_fit(current, search, cur_names, base_full.params, fixed)
    cur_ho, cur_mse = _cv(current, search, cur_names, cur.params, fixed, fold, block)
    base_rmse, base_ho = cur.rmse, cur_ho
    steps = [_step(base_full)]
    given = steps[0]
    baseline_added: list[str] = []
    baseline_gain: dict[str, tuple] = {}
    prev_all = base_full
    rounds: list[tuple[Candidate, ...]] = []
    recommended: list[str] = []
    rejected: list[tuple[Candidate, str]] = []  # (candidate, why it failed the all-rows check)
    chosen: list[Effect] = []
    replaced: list[tuple[tuple, str]] = []
    chosen_round: dict[str, int] = {}
    swaps_tried = False
    full_retry = False
    retry_prev: tuple = ()
    retry_pool: list[Effect] = []
    dropped: list[str] = []
    all_pool = list(pool)
    first_useful: list[Effect] = []
    notes_late: list[str] = []
    stop = ""
    while True:
        # (not again before a full retry: the chain is the one the last try saw)
        for eff in ([] if retry_pool else list(pending)):
            got = _baseline_try(eff, model, current, search, data, cur_names, cur, cur_ho, cur_mse, fold, block,
                                floor, fixed, bic_threshold, min_gain, min_excess, z, grid, modulus_range_gpa,
                                cur_ps, strata, prev_all, chosen, fit_params)
            if got is None:
                continue
            baseline_gain[eff.name] = (tuple(e.name for e in chosen), prev_all.rmse, got[3].rmse)
            model, current, cur_names, prev_all, steps, cb = got
            cur = _search_fit(current, search, cur_names, cb.values, fixed, per_sample=cur_ps)
            cur_ho, cur_mse = cb.heldout_rmse_deg, cb.block_mse
            baseline_added.append(eff.name)
            pending.remove(eff)
        # the held-out RMSE at full resolution: the all-rows RMSE times the held-out / in-sample ratio of the
        # search rows (thinned rows see a coarser history and a shorter force average than all rows do)
        ho_full = prev_all.rmse * cur_ho / cur.rmse if cur.rmse > 0 else cur_ho
        swaps_only = False
        if stop_ratio is not None and ho_full <= stop_ratio * floor:
            stop = (f"the held-out RMSE {ho_full:.3f} deg (all rows) is within {stop_ratio:g} x the noise floor "
                    f"{floor:.3f} deg: nothing left to explain")
            # before stopping, one round of swaps: an effect chosen early may stand in for a later one (slack
            # for a sharp toe behind play) and reach the stop ratio with it; a candidate that explains what it
            # did (its parameters go to a bound) and is significantly better in its place replaces it
            if not chosen or swaps_tried:
                break
            swaps_only = swaps_tried = True
        if not swaps_only and len(recommended) >= max_effects:
            stop = f"stopped after {max_effects} effects"
            # the same swaps and drops before this stop: a full chain may hold stand-ins
            if swaps_tried:
                break
            swaps_only = swaps_tried = True
        if not pool:
            stop = "no candidate effects left"
            break
        if swaps_only and len(chosen) > 1:
            # ... and first, each chosen effect is tried away: one that a later effect made redundant (tendon-sheath
            # friction standing in for play until play came in) goes when the chain without it is not
            # significantly worse on held-out cycles
            got = _drop_try(model, current, search, data, cur_names, cur, cur_mse, fold, block, fixed,
                            bic_threshold, z, grid, modulus_range_gpa, cur_ps, strata, chosen, fit_params,
                            prev_all)
            if got is not None:
                old, current, cur_names, cur_ps, prev_all, steps, cur, cur_ho, cur_mse = got
                dropped.append(old.name)
                chosen = [e for e in chosen if e.name != old.name]
                recommended = [e.name for e in chosen]
                swaps_tried = False
                continue
        # the swap round tries every effect that helped the model as given (one that explained little on top
        # of the stand-in, as a sharp toe on top of slack, may explain more in its place)
        tried_pool = ([e for e in first_useful if e.name not in {x.name for x in chosen}][:SWAP_TRIES]
                      if swaps_only else retry_pool or pool)
        ranked = _round(current, search, cur_names, cur, cur_ho, cur_mse, fold, block, tried_pool, floor, fixed,
                        bic_threshold, min_gain, min_excess, z, grid, modulus_range_gpa, cur_ps, strata,
                        per_sample and len(search.samples) > 1 and not swaps_only, init, tuple(chosen),
                        swap_all=swaps_only, measured=data)
        if retry_pool and not swaps_only:
            ranked = tuple(sorted(tuple(retry_prev) + tuple(ranked),
                                  key=lambda c: (not c.significant, c.heldout_rmse_deg, c.effect, c.replaces)))
            retry_prev, retry_pool = (), []
        ranked_base_ho = cur_ho
        accepted = None
        n_rejected = len(rejected)
        for c in ranked:
            if not c.significant or (swaps_only and not c.replaces):
                continue
            eff = next((e for e in tried_pool if e.name == c.effect), None)
            if eff is None:  # a candidate of the narrowed round, already tried (merged into the full retry)
                continue
            keep = [e for e in chosen if e.name not in c.replaces]
            m, names, ps = _without(current, cur_names, cur_ps, [e for e in chosen if e.name in c.replaces])
            m = m.with_effects(list(m.effects) + [eff])
            names += eff.full_names()
            ps += list(c.per_sample)
            init = {k: v for k, v in c.values.items() if k.split("@")[0] in names}
            r = refit_all_rows(m, data, names, fixed, init, grid, per_sample=ps)
            problems = []
            if not r.rmse < prev_all.rmse:
                problems.append(f"its refit on all rows does not lower the RMSE ({prev_all.rmse:.3f} -> "
                                f"{r.rmse:.3f} deg)")
            # every fitted parameter, not only the new ones: a new effect may push E_t to its bound
            problems += _resolution_problems(m, list(r.fitted), r.params, r.stderr, r.at_bound, data,
                                             modulus_range_gpa)
            # the floor seen through this model's residual (a model error inflates the estimate a little)
            f_c = min(floor, noise_floor(data, r.residuals))
            parts_c = noise_floor_parts(data, r.residuals, block_all)
            se_c = math.hypot(*parts_c)
            if r.rmse < f_c - 2.0 * se_c:
                problems.append(f"its RMSE {r.rmse:.3f} deg undercuts the noise floor {f_c:.3f} +- "
                                f"{se_c:.3f} deg (statistical {parts_c[0]:.3f}, systematic {parts_c[1]:.3f}; "
                                "it would fit noise)")
            inter: list[Step] = []
            if not problems and c.replaces:
                # the waterfall without the replaced effects: every step must still lower the RMSE
                inter = _chain_steps(model, keep, range(1, len(keep) + 1), data, fit_params, fixed, r.params, grid,
                                     ps)
                if not _each_lower([steps[0].rmse_deg] + [x.rmse_deg for x in inter] + [r.rmse]):
                    problems.append(f"without {', '.join(c.replaces)} a step of the chain does not lower the RMSE")
            if problems:
                rejected.append((c, "; ".join(problems)))
                continue
            accepted = (c, eff, m, names, r, {k: v for k, v in init.items() if k in r.fitted}, ps, keep, inter)
            break
        if swaps_only and accepted is None:
            del rejected[n_rejected:]  # no swap: the diagnosis stops as it would have
            # ... but a swap as good as the chain (held-out within EQUAL_HELDOUT) is an alternative the data
            # cannot rule out: declared indistinguishable from the effect it would replace
            alts = _swap_alternatives(ranked, cur_ho)
            rounds = _declare_alternatives(rounds, chosen_round, alts)
            for old, found in alts.items():
                notes_late.append(f"{', '.join(found)} in place of {old} explain the data as well (held-out RMSE "
                                  f"within {100 * EQUAL_HELDOUT:g} %): the data cannot tell them apart from {old}")
            break
        ranked = tuple(_mark_rejected(ranked, rejected))
        rounds.append(ranked)
        if accepted is None and not full_retry:
            # the pool was narrowed to the effects that helped the round before (speed); one that explained
            # nothing while a bigger effect dominated (play under a viscoelastic tendon) may be what is left:
            # before giving up, the round is run again with every effect not yet chosen
            again = [e for e in all_pool if e.name not in {x.name for x in chosen} | {x.name for x in pool}]
            full_retry = True
            if again:
                # only the effects left out are fitted; the round is recorded with both
                retry_prev, retry_pool = rounds.pop(), again
                pool = pool + again
                continue
        if accepted is None:
            top = ranked[0] if ranked else None
            stop = ("no candidate improves the model significantly and reliably"
                    + (f" (best: {top.effect}: {top.why})" if top is not None and top.why else ""))
            break
        c, eff, m, names, r, init, ps, keep, inter = accepted
        swaps_tried = False
        floor, floor_se, floor_parts = f_c, se_c, parts_c
        cur_ps = ps
        rejected = [(rc, w) for rc, w in rejected if rc.effect != eff.name]
        if c.replaces:
            replaced.append((tuple(c.replaces), eff.name))
            chosen = keep
            recommended = [e.name for e in keep]
            steps = steps[:1] + inter
        recommended.append(eff.name)
        chosen.append(eff)
        chosen_round[eff.name] = len(rounds) - 1
        current, cur_names, prev_all = m, names, r
        steps.append(_step(r, cur_ps, init))
        cur = _search_fit(current, search, cur_names, c.values, fixed, per_sample=cur_ps)
        cur_ho, cur_mse = c.heldout_rmse_deg, c.block_mse
        # the next round tries only the effects that helped in this one (held-out RMSE down by min_gain):
        # one that explained nothing on the simpler model is not retried (speed; see the module docstring)
        useful = {x.effect for x in ranked if x.heldout_rmse_deg <= (1.0 - min_gain) * ranked_base_ho}
        if len(rounds) == 1:
            # the swap round's candidates: the best SWAP_TRIES of the first round that helped
            order = [x.effect for x in sorted(ranked, key=lambda x: x.heldout_rmse_deg) if not x.replaces]
            first_useful = sorted([e for e in pool if e.name in useful], key=lambda e: order.index(e.name))
        pool = [e for e in pool if e.name != eff.name and e.name in useful]
    clock["search"] = time.perf_counter()

    # per-sample parameters of the recommended effects
    ps_names: list[str] = []
    notes: list[str] = []
    if per_sample and len(data.samples) > 1 and chosen:
        ps_names, notes, final = _per_sample(current, data, search, cur_names, cur, cur_ho, cur_mse, fold, block,
                                             chosen, fixed, floor, floor_se, prev_all, bic_threshold, z, grid,
                                             cur_ps, strata)
        if final is not None:
            steps.append(final)
        ps_names = list(steps[-1].per_sample)
    notes += _offset_notes(data, steps[-1], chosen, floor)
    notes += notes_late
    base_ps = given.rmse_per_sample
    fin_ps = steps[-1].rmse_per_sample
    for smp in base_ps:
        if fin_ps.get(smp, 0.0) > 1.02 * base_ps[smp]:
            notes.append(f"sample {smp} ends worse than with the current model: RMSE {base_ps[smp]:.3f} -> "
                         f"{fin_ps[smp]:.3f} deg (the shared parameters suit the other samples)")
    clock["waterfall"] = time.perf_counter()
    secs = {"base": clock["base"] - clock["start"], "search": clock["search"] - clock["base"],
            "per_sample": clock["waterfall"] - clock["search"], "total": clock["waterfall"] - clock["start"]}
    catalog = {e.name: e for e in list(model.effects) + list(pool) + chosen}
    for rnd in rounds:
        for c in rnd:
            if c.effect not in catalog and c.effect in reg:
                catalog[c.effect] = reg[c.effect]
    # recommended only when the chain reaches the floor: otherwise a structured misfit remains, and effects
    # that merely lower it (a bias, a softer tendon standing in for missing physics) are listed as partial
    partial: tuple = ()
    partial_steps: tuple = ()
    label = explanation_label(steps[0].rmse_deg, steps[-1].rmse_deg, floor) if recommended else ""
    if label == "partial":
        stop += (f"; with {', '.join(recommended)} the RMSE is {steps[-1].rmse_deg / floor:.2f} x the noise floor "
                 f"(above {REACH_RATIO:g} x: a partial explanation), but they explain "
                 f"{100 * explained_share(steps[0].rmse_deg, steps[-1].rmse_deg, floor):.1f} % of the misfit above "
                 "the floor, so they are recommended")
    elif recommended and not steps[-1].rmse_deg <= REACH_RATIO * floor:
        label = ""
        partial, partial_steps = tuple(recommended), tuple(steps)
        stop += (f"; with {', '.join(recommended)} the RMSE stays at {steps[-1].rmse_deg / floor:.2f} x the noise "
                 f"floor (above {REACH_RATIO:g} x): a structured misfit remains, so nothing is recommended "
                 f"(listed as partial)")
        recommended, steps, ps_names = [], steps[:1], []
        notes = [f"partial model: {n}" for n in notes]
    return Diagnosis(data, model, floor, base_rmse, base_ho, tuple(rounds), tuple(recommended), tuple(steps),
                     tuple(fit_params), stop, fixed, secs, catalog, floor_se, tuple({rc.label: w for rc, w in rejected}.items()),
                     tuple(ps_names),
                     tuple(notes), grid, partial, partial_steps, floor_parts, tuple(replaced),
                     {k: chosen_round[k] for k in recommended or partial if k in chosen_round},
                     given, tuple(baseline_added), baseline_gain, tuple(dropped), label)


def explained_share(base_rmse_deg: float, final_rmse_deg: float, floor_deg: float) -> float:
    """Share of the mean squared misfit above the noise floor that a chain explains:
    ``(base^2 - final^2) / (base^2 - floor^2)`` (0 when the base is at the floor)."""
    excess = base_rmse_deg ** 2 - floor_deg ** 2
    return (base_rmse_deg ** 2 - final_rmse_deg ** 2) / excess if excess > 0 else 0.0


def explanation_label(base_rmse_deg: float, final_rmse_deg: float, floor_deg: float) -> str:
    """``complete`` (within :data:`REACH_RATIO` x the floor), ``partial`` (above it, but the chain explains at
    least :data:`PARTIAL_SHARE` of the misfit above the floor and ends within :data:`PARTIAL_RATIO` x the
    floor: recommended, with what is left described), or ``""`` (not recommended: listed as partial effects)."""
    if final_rmse_deg <= REACH_RATIO * floor_deg:
        return "complete"
    if (final_rmse_deg <= PARTIAL_RATIO * floor_deg
            and explained_share(base_rmse_deg, final_rmse_deg, floor_deg) >= PARTIAL_SHARE):
        return "partial"
    return ""


def _without(model: JointModel, names: Sequence[str], per_sample: Sequence[str],
             effects: Sequence[Effect]) -> tuple[JointModel, tuple, list]:
    """``model``, its fitted ``names`` and its ``per_sample`` names with ``effects`` (and their parameters) removed."""
    drop = {e.name for e in effects}
    gone = {n for e in effects for n in e.full_names()}
    return (model.with_effects([e for e in model.effects if e.name not in drop]),
            tuple(n for n in names if n not in gone), [n for n in per_sample if n.split("@")[0] not in gone])


def _chain_steps(start: JointModel, effects: Sequence[Effect], counts, data: Dataset, fit_params: Sequence[str],
                 fixed: Mapping[str, float], values: Mapping[str, float], grid: int,
                 per_sample: Sequence[str]) -> list[Step]:
    """Waterfall steps of ``start`` plus ``effects[:i]`` for each ``i`` of ``counts``, each refitted on all rows
    from ``values`` (per-sample names kept where the step has the parameter)."""
    out = []
    for i in counts:
        mi = start.with_effects(list(start.effects) + list(effects[:i]))
        ni = _names_for(mi, fit_params)
        psi = [n for n in per_sample if n.split("@")[0] in ni]
        ri = refit_all_rows(mi, data, ni, fixed, {k: v for k, v in values.items() if k.split("@")[0] in ni}, grid,
                            per_sample=psi)
        out.append(_step(ri, psi))
    return out


def _each_lower(rmse_deg: Sequence[float]) -> bool:
    """Every value below the one before it (every step of a waterfall lowers the RMSE)."""
    return all(b < a for a, b in zip(rmse_deg, rmse_deg[1:]))


def _baseline_try(eff: Effect, model: JointModel, current: JointModel, search: Dataset, data: Dataset,
                  cur_names: tuple, cur: FitResult, cur_ho: float, cur_mse: np.ndarray, fold: np.ndarray,
                  block: np.ndarray, floor: float, fixed: Mapping[str, float], bic_threshold: float, min_gain: float,
                  min_excess: float, z: float, grid: int, modulus_range_gpa: tuple[float, float], cur_ps: list,
                  strata, prev_all: FitResult, chosen: Sequence[Effect], fit_params: Sequence[str]):
    """The baseline effect ``eff`` on top of the current chain, if it joins: ``(model, current, names, fit on all
    rows, waterfall, candidate)`` with ``eff`` in the model from the start; None when it does not.

    It joins when it passes a round's tests (significant on held-out cycles, lower BIC, parameters trusted),
    its refit on all rows lowers the RMSE with every parameter off its bounds, and the chain rebuilt with it
    from the start (model + eff, + each chosen effect in turn) lowers the RMSE at every step.
    """
    ranked = _round(current, search, cur_names, cur, cur_ho, cur_mse, fold, block, [eff], floor, fixed,
                    bic_threshold, min_gain, min_excess, z, grid, modulus_range_gpa, cur_ps, strata, measured=data)
    c = next((c for c in ranked if not c.replaces), None)
    if c is None or not c.significant:
        return None
    chain = current.with_effects(list(current.effects) + [eff])
    names = cur_names + tuple(eff.full_names())
    init = {k: v for k, v in c.values.items() if k.split("@")[0] in names}
    r = refit_all_rows(chain, data, names, fixed, init, grid, per_sample=cur_ps)
    if not r.rmse < prev_all.rmse or _resolution_problems(chain, list(r.fitted), r.params, r.stderr, r.at_bound,
                                                          data, modulus_range_gpa):
        return None
    start = model.with_effects(list(model.effects) + [eff])
    steps = _chain_steps(start, chosen, range(len(chosen)), data, fit_params, fixed, r.params, grid, cur_ps)
    steps.append(_step(r, cur_ps, {k: v for k, v in init.items() if k in r.fitted}))
    if not _each_lower([st.rmse_deg for st in steps]):
        return None
    return start, chain, names, r, steps, c


def _drop_try(model: JointModel, current: JointModel, search: Dataset, data: Dataset, cur_names: tuple,
              cur: FitResult, cur_mse: np.ndarray, fold: np.ndarray, block: np.ndarray, fixed: Mapping[str, float],
              bic_threshold: float, z: float, grid: int, modulus_range_gpa: tuple[float, float], cur_ps: list,
              strata, chosen: Sequence[Effect], fit_params: Sequence[str], prev_all: FitResult):
    """The chosen effect whose removal costs least, if the chain is not significantly better with it (held-out
    gain within ``z`` standard errors and search BIC within ``bic_threshold``, or all-rows BIC within
    ``bic_threshold``) and the chain without it passes the all-rows checks with every step lowering the RMSE:
    ``(effect, model, names, per-sample names, fit on all rows, waterfall, search fit, held-out RMSE, block
    MSE)``; None when every effect is needed."""
    tries = []
    for old in chosen:
        gone = set(old.full_names())
        m, names, ps = _without(current, cur_names, cur_ps, [old])
        start = {k: v for k, v in cur.params.items() if k.split("@")[0] not in gone}
        f = _search_fit(m, search, names, start, fixed, per_sample=ps)
        ho, mse = _cv(m, search, names, f.params, fixed, fold, block, per_sample=ps)
        dm, se = _gain(mse, cur_mse, strata)  # what keeping the effect gains
        tries.append((not (dm > z * se or f.bic - cur.bic >= bic_threshold), ho, old, m, names, ps, f, mse))
    for held_out_ok, ho, old, m, names, ps, f, mse in sorted(tries, key=lambda t: (not t[0], t[1], t[2].name)):
        init = {k: v for k, v in f.params.items() if k in names or k.split("@")[0] in names}
        r = refit_all_rows(m, data, names, fixed, init, grid, per_sample=ps)
        # the thinned search rows see a coarser history (a play operator that misses the stroke's peaks): an
        # effect that helps only there is not needed either when every row does without it (BIC)
        if not held_out_ok and r.bic - prev_all.bic >= bic_threshold:
            continue
        if _resolution_problems(m, list(r.fitted), r.params, r.stderr, r.at_bound, data, modulus_range_gpa):
            continue
        keep = [e for e in chosen if e.name != old.name]
        steps = _chain_steps(model, keep, range(len(keep)), data, fit_params, fixed, r.params, grid, ps)
        steps.append(_step(r, ps, {k: v for k, v in init.items() if k in r.fitted}))
        if _each_lower([st.rmse_deg for st in steps]):
            return old, m, names, ps, r, steps, f, ho, mse
    return None


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


def _gain(cur_mse: np.ndarray, new_mse: np.ndarray, strata: np.ndarray | None = None) -> tuple[float, float]:
    """Mean fall of the per-block held-out MSE and its standard error (paired over blocks).

    With ``strata`` (the sample of each block) the standard error is the stratified one: samples may differ
    (an effect present in one sample only), only the spread within a sample is noise.
    """
    d = np.asarray(cur_mse) - np.asarray(new_mse)
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


def _round(current: JointModel, search: Dataset, cur_names: tuple, cur: FitResult, cur_ho: float,
           cur_mse: np.ndarray, fold: np.ndarray, block: np.ndarray, pool: list[Effect], floor: float,
           fixed: Mapping[str, float], bic_threshold: float, min_gain: float, min_excess: float, z: float,
           grid: int, modulus_range_gpa: tuple[float, float], cur_ps: Sequence[str] = (),
           strata: np.ndarray | None = None, try_per_sample: bool = False,
           init: Mapping[str, float] | None = None, swappable: Sequence[Effect] = (),
           swap_all: bool = False, measured: Dataset | None = None) -> tuple[Candidate, ...]:
    """Every effect of ``pool`` on top of ``current``, ranked by held-out RMSE.

    With ``try_per_sample``, the best :data:`PER_SAMPLE_TRIES` effects are also fitted with per-sample
    parameters; that version replaces the shared one when its held-out error is significantly lower. When a candidate's fit
    puts a parameter of an effect of ``swappable`` (chosen earlier in this diagnosis) on a bound, the
    candidate explains what that effect did: it is also tried *instead of* it (stepwise selection with
    replacement), so an early stand-in (slack for a sharp toe) does not stay in the model. With ``swap_all``
    each candidate is tried only instead of each effect of ``swappable`` (not on top of them).
    """
    fits = []
    for eff in (pool if swap_all else ()):
        # instead of each effect of swappable only (the stop ratio is reached: nothing is to be added)
        new = eff.full_names()
        for old in swappable:
            gone = set(old.full_names())
            m2, names2, ps2 = _without(current, cur_names, cur_ps, [old])
            m2 = m2.with_effects(list(m2.effects) + [eff])
            names2 += tuple(new)
            start = m2.initial_values(search, base={k: v for k, v in cur.params.items()
                                                     if k.split("@")[0] not in gone})
            f2 = _search_fit(m2, search, names2, start, fixed, grid=grid, grid_names=new, per_sample=ps2)
            ho2, mse2 = _cv(m2, search, names2, f2.params, fixed, fold, block, per_sample=ps2)
            fits.append([eff, m2, new, f2, ho2, mse2, (), (old.name,)])
    for eff in (() if swap_all else pool):
        m = current.with_effects(list(current.effects) + [eff])
        new = eff.full_names()
        start = m.initial_values(search, base=cur.params)
        f = _search_fit(m, search, cur_names + new, start, fixed, grid=grid, grid_names=new, per_sample=cur_ps,
                        starts=[init] if init else ())
        ho, mse = _cv(m, search, cur_names + new, f.params, fixed, fold, block, per_sample=cur_ps)
        fits.append([eff, m, new, f, ho, mse, ()])
    if try_per_sample:
        for row in sorted([r for r in fits if r[2]], key=lambda r: r[4])[:PER_SAMPLE_TRIES]:
            eff, m, new, f, ho, mse, _ = row
            ps = list(cur_ps) + list(new)
            f2 = _search_fit(m, search, cur_names + new, f.params, fixed, per_sample=ps)
            ho2, mse2 = _cv(m, search, cur_names + new, f2.params, fixed, fold, block, per_sample=ps)
            dm, se = _gain(mse, mse2, strata)
            if dm > z * se and f2.bic < f.bic - bic_threshold:
                row[3:7] = [f2, ho2, mse2, tuple(new)]
    for row in ([] if swap_all else list(fits)):
        eff, m, new, f = row[:4]
        for old in swappable:
            gone = set(old.full_names())
            if not any(n.split("@")[0] in gone for n in f.at_bound):
                continue
            m2, names2, ps2 = _without(current, cur_names, cur_ps, [old])
            m2 = m2.with_effects(list(m2.effects) + [eff])
            names2 += tuple(new)
            start = {k: v for k, v in f.params.items() if k.split("@")[0] not in gone}
            f2 = _search_fit(m2, search, names2, start, fixed, grid=grid, grid_names=new, per_sample=ps2)
            ho2, mse2 = _cv(m2, search, names2, f2.params, fixed, fold, block, per_sample=ps2)
            fits.append([eff, m2, new, f2, ho2, mse2, (), (old.name,)])
    tried: list[Candidate] = []
    for eff, m, new, f, ho, mse, eff_ps, *swap in fits:
        dbic = f.bic - cur.bic
        shown = [n for n in f.fitted if n.split("@")[0] in new] if eff_ps else list(new)
        params = {nm: (f.params[nm], f.stderr.get(nm, math.inf), m.spec(nm).unit) for nm in shown}
        conf = []
        idx = {nm: i for i, nm in enumerate(f.fitted)}
        for a in new:
            for b in cur_names:
                if a not in idx or b not in idx:
                    continue
                rho = f.correlation[idx[a], idx[b]] if f.correlation.size else np.nan
                if not np.isfinite(rho) or abs(rho) > CORR_LIMIT:
                    conf.append(f"{b} (r={rho:+.3f})" if np.isfinite(rho) else f"{b} (degenerate)")
        why = []
        gain = 1.0 - ho / cur_ho if cur_ho > 0 else 0.0
        excess = cur_ho**2 - floor**2
        dm, se = _gain(cur_mse, mse, strata)
        gz = dm / se if se > 0 and math.isfinite(se) else (math.inf if dm > 0 else 0.0)
        if not dbic < -bic_threshold:
            why.append(f"delta BIC {dbic:+.1f} is not below -{bic_threshold:g}")
        if gain < min_gain:
            why.append(f"held-out RMSE falls by {100 * gain:.1f}% < {100 * min_gain:g}%")
        elif excess > 0 and (cur_ho**2 - ho**2) < min_excess * excess:
            why.append(f"explains only {100 * (cur_ho**2 - ho**2) / excess:.0f}% of the error above the noise floor")
        if gain >= min_gain and not gz > z:
            why.append(f"the held-out gain is {gz:.1f} standard errors, not more than {z:g} (within the noise)")
        if new and not why:
            why += _resolution_problems(m, list(f.fitted), f.params, f.stderr, f.at_bound, measured or search,
                                        modulus_range_gpa)
        tried.append(Candidate(eff.name, tuple(e.name for e in m.effects), f.rmse, ho, dbic, params,
                               confounded=tuple(conf), significant=not why, why="; ".join(why),
                               predicted=f.predicted, values=dict(f.params), gain_z=gz, block_mse=mse,
                               per_sample=eff_ps, replaces=tuple(swap[0]) if swap else ()))
    tried.sort(key=lambda c: (c.heldout_rmse_deg, c.effect, c.replaces))
    # equivalences: near-equal held-out error and predictions within half the noise floor
    fam = {e.name: e.family for e in pool}
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


def _per_sample(current, data, search, cur_names, cur, cur_ho, cur_mse, fold, block, chosen, fixed, floor, floor_se,
                prev_all, bic_threshold, z, grid, cur_ps=(), strata=None):
    """Try each recommended effect's parameters per sample; returns (names, notes, final step or None)."""
    ps: list[str] = list(cur_ps)
    notes: list[str] = []
    base_fit = cur
    base_mse = cur_mse
    changed = False
    for eff in chosen:
        if not eff.params or all(n in ps for n in eff.full_names()):
            continue
        trial = ps + [n for n in eff.full_names() if n not in ps]
        f = _search_fit(current, search, cur_names, base_fit.params, fixed, per_sample=trial)
        ho, mse = _cv(current, search, cur_names, f.params, fixed, fold, block, per_sample=trial)
        dm, se = _gain(base_mse, mse, strata)
        dbic = f.bic - base_fit.bic
        if dm > z * se and dbic < -bic_threshold:
            ps = trial
            base_fit, base_mse = f, mse
            changed = True
    if not ps:
        return [], notes, None
    final = None
    r = prev_all
    if changed:
        init = {k: v for k, v in base_fit.params.items() if k in base_fit.fitted}
        r = refit_all_rows(current, data, cur_names, fixed, init, grid, per_sample=ps)
        if not r.rmse < prev_all.rmse or r.rmse < floor - 2.0 * floor_se:
            notes.append("per-sample parameters were better on held-out cycles but not on all rows: kept as before")
            return list(cur_ps), notes, None
        final = _step(r, ps, init)
    samples = data.samples
    for nm in ps:
        vals = [(s, r.params[f"{nm}@{s}"], r.stderr.get(f"{nm}@{s}", math.inf)) for s in samples]
        unit = current.spec(nm).unit
        diff = []
        for i in range(len(vals)):
            for j in range(i + 1, len(vals)):
                (sa, va, ea), (sb, vb, eb) = vals[i], vals[j]
                if abs(va - vb) > 3.0 * math.hypot(ea, eb):
                    diff.append(f"{sa} vs {sb}: {va:.4g} vs {vb:.4g} {unit}".rstrip())
        if diff:
            notes.append(f"samples differ in {nm}: " + "; ".join(diff))
        else:
            notes.append(f"{nm} per sample: " + ", ".join(f"{s} {v:.4g}" for s, v, _ in vals) + " (within errors)")
    return ps, notes, final
