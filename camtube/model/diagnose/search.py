"""Diagnosis of missing physics: which effect would make the model fit, and is it worth adding?

``diagnose(model, data, fit_params=("E_t",), fixed=None, *, candidates=None, ...) -> Diagnosis``

Method
------
1. **Current model.** ``model`` (base plus the effects already chosen) is
   fitted to ``data`` (all selected rows: both directions, deadband kept, so
   slack, play and creep stay visible).
2. **Noise floor.** The sensor noise is white, the model error is smooth in
   time; so the noise shows in the high-order differences of the residual
   within each sample: ``sigma = 1.4826 MAD(diff^k r) / sqrt(C(2k, k))``
   for ``k = 2, 3, 4`` (the smallest is kept; the median ignores kinks at reversals). A
   perfect model leaves an RMSE of ``sigma``.
3. **Candidates.** Each registered effect not yet in the model is added in
   turn; the model's fitted parameters plus the effect's are fitted (on at
   most ``max_rows`` rows, evenly thinned in time so histories survive).
   Each candidate is scored by

   * the **held-out RMSE**: fitted on the odd cycles, tested on the even ones
     (alternate time blocks if there is one cycle), the model always run over
     the whole history;
   * **delta BIC** = ``n ln(SSE'/SSE) + dp ln n`` against the current model;
   * its parameters with standard errors and their correlation with the
     already fitted parameters.

   Candidates are ranked by held-out RMSE.
4. **Equivalences.** A candidate whose parameter correlates with a fitted
   parameter by ``|r| > 0.99`` is reported as confounded with it (a series
   compliance is a softer tendon: it then gains nothing and is not
   significant). Two useful candidates whose held-out RMSEs are within 3% of
   each other, or whose predictions differ by less than half the noise floor
   (rms), cannot be told apart from each other; a declared
   :attr:`Effect.family` is reported the same way. Among candidates that
   cannot be told apart from the best one, the lowest BIC leads the ranking.
5. **Greedy combination.** The best candidate is recommended and added if
   it is significant: ``delta BIC < -bic_threshold``, its held-out RMSE falls
   by at least ``min_gain`` (relative) and it explains at least
   ``min_excess`` of the held-out error left above the noise floor. Then the
   remaining candidates are tried on top, and so on. The search stops when
   the held-out RMSE is within ``stop_ratio`` of the noise floor, when nothing
   is significant, or after ``max_effects``.
6. **Waterfall.** The current model and each recommended step are refitted
   on all rows: RMSE overall and per sample, parameters with uncertainty.

No threshold depends on the data's scale: BIC is a likelihood ratio, the
others are ratios of errors.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np

from camtube.model.core.model import Effect, JointModel
from camtube.model.core.registry import Registry, builtin_registry
from camtube.model.data.csvfile import check_fittable
from camtube.model.data.dataset import Dataset
from camtube.model.core.fit import fit

#: Parameter correlation above which two parameters cannot be told apart.
CORR_LIMIT = 0.99
#: Held-out RMSEs within this fraction of each other: the data cannot tell the candidates apart.
EQUAL_HELDOUT = 0.03


@dataclass(frozen=True, eq=False)
class Fitted:
    """One least-squares fit of a model on some rows (internal to the search, also reported)."""

    model: JointModel
    names: tuple
    params: dict
    stderr: dict
    correlation: np.ndarray
    sse: float
    n: int
    rmse_deg: float
    bic: float
    at_bound: tuple
    predicted: np.ndarray


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
        In-sample RMSE (search rows) and held-out RMSE (test cycles).
    delta_bic : float
        BIC of the candidate minus BIC of the current model (negative: better).
    params : dict
        The effect's parameters: full name -> (value, stderr, unit).
    equivalent : tuple[str, ...]
        Candidates of the same round it cannot be told apart from.
    confounded : tuple[str, ...]
        Fitted parameters it cannot be told apart from (``name (r=...)``).
    significant : bool
        Passes every criterion of step 5.
    why : str
        Why it is not significant (empty if it is).
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


@dataclass(frozen=True, eq=False)
class Diagnosis:
    """Outcome of :func:`diagnose`.

    Attributes
    ----------
    data : Dataset
        The rows diagnosed.
    noise_floor_deg : float
    base_rmse_deg, base_heldout_rmse_deg : float
        The current model's errors (search rows / held-out).
    rounds : tuple[tuple[Candidate, ...], ...]
        Ranked candidates of each greedy round (round 0: on the current model).
    recommended : tuple[str, ...]
        Effects to add, in order.
    waterfall : tuple[Step, ...]
        The current model, then one step per recommended effect.
    fit_params : tuple[str, ...]
        Parameters fitted besides the effects' own.
    stop_reason : str
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

    @property
    def candidates(self) -> tuple:
        """Ranked candidates of the first round (each effect on the current model)."""
        return self.rounds[0] if self.rounds else ()

    @property
    def final(self) -> Step:
        return self.waterfall[-1]


# ----------------------------------------------------------------------------- pieces

def noise_floor(data: Dataset, residual_deg: np.ndarray) -> float:
    """White-noise standard deviation (deg) of a residual ``(n,)``, from its high-order differences per sample."""
    r = np.asarray(residual_deg, float)
    best = math.inf
    for k, norm in ((2, 6.0), (3, 20.0), (4, 70.0)):
        parts = []
        for _, sl in data.sample_slices():
            seg = r[sl]
            if seg.size > k + 4:
                parts.append(np.diff(seg, k))
        if not parts:
            continue
        d = np.concatenate(parts)
        best = min(best, 1.4826 * float(np.median(np.abs(d - np.median(d)))) / math.sqrt(norm))
    return best if math.isfinite(best) else float(np.std(r))


def thin(data: Dataset, max_rows: int) -> Dataset:
    """Every k-th row (time order kept) so that at most about ``max_rows`` remain."""
    n = len(data)
    if max_rows <= 0 or n <= max_rows:
        return data
    k = int(math.ceil(n / max_rows))
    return data.take(np.arange(0, n, k))


def holdout_mask(data: Dataset) -> np.ndarray:
    """(n,) bool: training rows (odd cycles; alternate time blocks if a sample has one cycle)."""
    cyc = np.asarray(data.cycle)
    train = np.zeros(len(data), bool)
    for _, sl in data.sample_slices():
        c = cyc[sl]
        if np.unique(c).size >= 2:
            train[sl] = (c - c.min()) % 2 == 0
        else:
            m = c.size
            train[sl] = (np.arange(m) * 8 // max(m, 1)) % 2 == 0
    return train


def _least_squares(model: JointModel, data: Dataset, names: Sequence[str], values: Mapping[str, float],
                   rows: np.ndarray | None = None, max_nfev: int = 120) -> Fitted:
    """Bounded least squares of ``names`` on ``rows`` (the model runs on all rows): :func:`fit`, searched loosely."""
    r = fit(model, data, tuple(names), values, max_nfev=max_nfev, rows=rows, tol=1e-8)
    return Fitted(model, r.fitted, dict(r.params), dict(r.stderr), r.correlation, r.sse, r.n_points,
                  r.rmse, r.bic, r.at_bound, r.predicted)


def _heldout(model: JointModel, data: Dataset, names: Sequence[str], start: Mapping[str, float],
             train: np.ndarray) -> float:
    """Held-out RMSE (deg): fit on ``train`` rows from ``start``, test on the others."""
    f = _least_squares(model, data, names, start, train, max_nfev=60)
    r = np.asarray(data.angle_deg, float)[~train] - f.predicted[~train]
    return float(np.sqrt(np.mean(r**2))) if r.size else f.rmse_deg


def _names_for(model: JointModel, fit_params: Sequence[str]) -> tuple:
    out = list(fit_params)
    for e in model.effects:
        out.extend(f"{e.name}.{p.name}" for p in e.params)
    return tuple(dict.fromkeys(out))


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
    stop_ratio: float = 1.15,
    registry: Registry | None = None,
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
    bic_threshold, min_gain, min_excess, stop_ratio : float
        Significance: delta BIC below ``-bic_threshold``; held-out RMSE down by
        ``min_gain`` (relative) and by ``min_excess`` of the held-out MSE above the
        noise floor; stop when the held-out RMSE is within ``stop_ratio`` x the floor.

    Returns
    -------
    Diagnosis
    """
    import time



    clock = {"start": time.perf_counter()}
    fixed = dict(fixed or {})
    reg = registry if registry is not None else builtin_registry()
    if candidates is None:
        pool = list(reg.effects)
    else:
        pool = [reg.get_effect(c) if isinstance(c, str) else c for c in candidates]
    have = {e.name for e in model.effects}
    pool = [e for e in pool if e.name not in have]

    check_fittable(data)
    full_names = _names_for(model, fit_params)
    base_full = fit(model, data, full_names, fixed)
    floor = noise_floor(data, base_full.residuals)
    clock["base"] = time.perf_counter()

    search = thin(data, max_rows)
    train = holdout_mask(search)
    current = model
    cur_names = full_names
    cur_vals = dict(base_full.params)
    cur = _least_squares(current, search, cur_names, cur_vals)
    cur_ho = _heldout(current, search, cur_names, cur.params, train)
    base_rmse, base_ho = cur.rmse_deg, cur_ho
    rounds: list[tuple[Candidate, ...]] = []
    recommended: list[str] = []
    chosen: list[Effect] = []
    stop = ""
    while True:
        if cur_ho <= stop_ratio * floor:
            stop = (f"the held-out RMSE {cur_ho:.3f} deg is within {stop_ratio:g} x the noise floor "
                    f"{floor:.3f} deg: nothing left to explain")
            break
        if len(recommended) >= max_effects:
            stop = f"stopped after {max_effects} effects"
            break
        if not pool:
            stop = "no candidate effects left"
            break
        ranked = _round(current, search, cur_names, cur, cur_ho, train, pool, floor,
                        bic_threshold, min_gain, min_excess)
        rounds.append(ranked)
        best = next((c for c in ranked if c.significant), None)
        if best is None:
            top = ranked[0] if ranked else None
            stop = ("no candidate improves the model significantly"
                    + (f" (best: {top.effect}: {top.why})" if top is not None else ""))
            break
        eff = next(e for e in pool if e.name == best.effect)
        recommended.append(eff.name)
        chosen.append(eff)
        current = model.with_effects(list(model.effects) + chosen)
        cur_names = cur_names + tuple(f"{eff.name}.{p.name}" for p in eff.params)
        start = dict(best.values)
        cur = _least_squares(current, search, cur_names, start)
        cur_ho = best.heldout_rmse_deg
        pool = [e for e in pool if e.name != best.effect]
    clock["search"] = time.perf_counter()

    # waterfall on all rows
    steps = []
    vals = dict(base_full.params)
    m = model
    names = full_names
    for k in range(len(recommended) + 1):
        if k:
            eff = chosen[k - 1]
            m = m.with_effects(list(m.effects) + [eff])
            names = names + tuple(f"{eff.name}.{p.name}" for p in eff.params)
            vals.update({n: v for n, v in cur.params.items() if n in names})
        r = base_full if k == 0 else fit(m, data, names, fixed, initial={n: vals[n] for n in names if n in vals})
        vals.update(r.params)
        steps.append(Step(tuple(e.name for e in m.effects), r.rmse, dict(r.rmse_per_sample), dict(r.params),
                          dict(r.stderr), dict(r.units), r.predicted, r.residuals))
    clock["waterfall"] = time.perf_counter()
    secs = {"base": clock["base"] - clock["start"], "search": clock["search"] - clock["base"],
            "waterfall": clock["waterfall"] - clock["search"], "total": clock["waterfall"] - clock["start"]}
    catalog = {e.name: e for e in list(model.effects) + list(pool) + chosen}
    return Diagnosis(data, model, floor, base_rmse, base_ho, tuple(rounds), tuple(recommended), tuple(steps),
                     tuple(fit_params), stop, fixed, secs, catalog)


def _round(current: JointModel, search: Dataset, cur_names: tuple, cur: Fitted, cur_ho: float,
           train: np.ndarray, pool: list[Effect], floor: float, bic_threshold: float, min_gain: float,
           min_excess: float) -> tuple[Candidate, ...]:
    """Every effect of ``pool`` on top of ``current``, ranked by held-out RMSE."""
    tried: list[Candidate] = []
    for eff in pool:
        m = current.with_effects(list(current.effects) + [eff])
        new = tuple(f"{eff.name}.{p.name}" for p in eff.params)
        start = m.initial_values(search, base=cur.params)
        f = _least_squares(m, search, cur_names + new, start)
        ho = _heldout(m, search, cur_names + new, f.params, train)
        dbic = f.bic - cur.bic
        params = {nm: (f.params[nm], f.stderr.get(nm, math.inf), m.param_specs[nm].unit) for nm in new}
        conf = []
        idx = {nm: i for i, nm in enumerate(f.names)}
        for a in new:
            for b in cur_names:
                rho = f.correlation[idx[a], idx[b]] if f.correlation.size else np.nan
                if not np.isfinite(rho) or abs(rho) > CORR_LIMIT:
                    conf.append(f"{b} (r={rho:+.3f})" if np.isfinite(rho) else f"{b} (degenerate)")
        why = []
        gain = 1.0 - ho / cur_ho if cur_ho > 0 else 0.0
        excess = cur_ho**2 - floor**2
        if not dbic < -bic_threshold:
            why.append(f"delta BIC {dbic:+.1f} is not below -{bic_threshold:g}")
        if gain < min_gain:
            why.append(f"held-out RMSE falls by {100 * gain:.1f}% < {100 * min_gain:g}%")
        elif excess > 0 and (cur_ho**2 - ho**2) < min_excess * excess:
            why.append(f"explains only {100 * (cur_ho**2 - ho**2) / excess:.0f}% of the error above the noise floor")
        moving = [nm for nm in new if nm not in f.at_bound]
        if new and not moving:
            why.append("its parameters end on their bounds")
        tried.append(Candidate(eff.name, tuple(e.name for e in m.effects), f.rmse_deg, ho, dbic, params,
                               confounded=tuple(conf), significant=not why, why="; ".join(why),
                               predicted=f.predicted, values=dict(f.params)))
    tried.sort(key=lambda c: (c.heldout_rmse_deg, c.effect))
    # equivalences: near-equal held-out error and predictions within half the noise floor
    fam = {e.name: e.family for e in pool}
    out = []
    useful = [c for c in tried if c.heldout_rmse_deg <= (1.0 - min_gain) * cur_ho]
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
        out.append(Candidate(c.effect, c.effects, c.rmse_deg, c.heldout_rmse_deg, c.delta_bic, c.params,
                             tuple(eq), c.confounded, c.significant, c.why, c.predicted, c.values))
    # among candidates that cannot be told apart from the best, the lowest BIC (the simplest) leads
    if out and out[0].equivalent:
        group = [c for c in out if c is out[0] or c.effect in out[0].equivalent]
        lead = min(group, key=lambda c: (not c.significant, c.delta_bic, c.effect))
        out.remove(lead)
        out.insert(0, lead)
    return tuple(out)
