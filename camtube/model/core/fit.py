"""Bounded least-squares fit of a :class:`~camtube.model.core.model.JointModel` to measurements.

API (stable)
------------
``fit(model, data, fit_params=("E_t",), fixed=None, *, initial=None, bounds=None,
max_nfev=None) -> FitResult``

* ``model`` : any :class:`~camtube.model.core.model.JointModel` (base plus effects).
* ``data`` : the :class:`~camtube.model.data.dataset.Dataset` rows to fit (already
  selected: cycles, branch, deadband; see :mod:`camtube.model.data`).
* ``fit_params`` : full parameter names to fit (``"E_t"``, ``"arm_scale"``,
  ``"slack.deadband_mm"``, ...). Every other parameter is held at its value
  in ``fixed`` or, if absent there, at its initial value
  (:meth:`JointModel.initial_values`, i.e. the :class:`~camtube.model.core.params.Param` spec).
* ``fixed`` : ``{name: value}``; values of held parameters, and the starting
  value of a fitted one (typically ``pattern_values(pattern)``: E_t, L0 from the pattern).
* ``initial`` : ``{name: value}`` starting values that win over ``fixed`` and the specs.
* ``bounds`` : ``{name: (lo, hi)}`` overriding the Param spec's bounds.

The residual is ``measured - model`` angle (deg), one per row, in data order.
The problem is solved with :func:`scipy.optimize.least_squares` (``trf``,
bounds from the specs, ``x_scale`` from the starting values), so one fitted
parameter is a 1-D problem of a few model evaluations.

:class:`FitResult` holds (all angles deg):

``params`` (every value the model used, fitted or held), ``fitted`` (names, in
order), ``stderr`` (fitted names -> standard error, from the Jacobian and the
residual variance: ``cov = s^2 (J^T J)^-1``, ``s^2 = SSE / (n - p)``),
``units``, ``residuals`` ``(n,)``, ``predicted`` ``(n,)``, ``rmse``,
``rmse_per_sample`` (sample -> deg), ``aic`` = ``n ln(SSE/n) + 2p``,
``bic`` = ``n ln(SSE/n) + p ln n`` (Gaussian errors, ``p`` = fitted
parameters), ``n_points``, ``n_params``, ``covariance`` and ``correlation``
``(p, p)`` in ``fitted`` order, ``at_bound`` (fitted names that ended on a
bound: their stderr is not meaningful), ``success``, ``message``, ``nfev``,
``model``, ``data``, ``rows`` (the row mask of a held-out fit, else ``None``),
and ``predict(data) -> (m,)`` deg for any rows.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np

from camtube.model.core.fdjac import GroupedJacobian, sample_groups
from camtube.model.core.model import FitError, JointModel, unknown_parameter
from camtube.model.core.parallel import map_forked
from camtube.model.core.params import Parameters
from camtube.model.core.threads import one_blas_thread
from camtube.model.data.dataset import Dataset

__all__ = ["FitError", "FitResult", "fit", "grid_starts", "rmse_by_sample"]


@dataclass(frozen=True, eq=False)
class FitResult:
    """Outcome of :func:`fit` (see the module docstring for every field)."""

    model: JointModel
    data: Dataset
    params: dict
    fitted: tuple
    stderr: dict
    units: dict
    residuals: np.ndarray
    predicted: np.ndarray
    covariance: np.ndarray
    correlation: np.ndarray
    rmse: float
    rmse_per_sample: dict
    aic: float
    bic: float
    n_points: int
    n_params: int
    at_bound: tuple = ()
    success: bool = True
    message: str = ""
    nfev: int = 0
    initial: dict = field(default_factory=dict)
    rows: np.ndarray | None = None
    parameters: Parameters | None = None
    starts_tried: int = 1
    start: dict = field(default_factory=dict)

    @property
    def sse(self) -> float:
        """Sum of squared residuals of the fitted rows (deg^2)."""
        r = self.residuals if self.rows is None else self.residuals[self.rows]
        return float(np.dot(r, r))

    @property
    def dof(self) -> int:
        """Degrees of freedom n - p."""
        return self.n_points - self.n_params

    def predict(self, data: Dataset | None = None) -> np.ndarray:
        """Model angle (deg), shape ``(m,)``, for ``data`` (default: the fitted rows)."""
        return self.model.predict(self.data if data is None else data, self.params)

    def residuals_for(self, data: Dataset) -> np.ndarray:
        """``measured - model`` (deg), shape ``(m,)``, for other rows (e.g. all cycles)."""
        return np.asarray(data.angle_deg, float) - self.predict(data)

    def value(self, name: str) -> float:
        return float(self.params[name])

    @property
    def unidentified(self) -> dict[str, str]:
        """Fitted parameters the rows cannot pin down: ``{name: reason}`` (empty when all are identified).

        A parameter is unidentified when it ended on a bound (its value is the
        bound, not an estimate) or when its standard error is infinite or
        undefined (the data do not depend on it).
        """
        out = {}
        for nm in self.fitted:
            se = self.stderr.get(nm, math.inf)
            if nm in self.at_bound:
                u = self.units.get(nm, "")
                unit = f" {u}" if u else ""
                out[nm] = f"ended on its bound ({self.params[nm]:.4g}{unit})"
            elif not math.isfinite(se):
                out[nm] = "its standard error is infinite (the rows do not depend on it)"
        return out

    def correlation_of(self, a: str, b: str) -> float:
        """Correlation coefficient of two fitted parameters."""
        i, j = self.fitted.index(a), self.fitted.index(b)
        return float(self.correlation[i, j])


def rmse_by_sample(data: Dataset, residuals: np.ndarray) -> dict[str, float]:
    """RMSE (deg) of ``residuals`` ``(n,)`` per sample of ``data``, in sample order."""
    r = np.asarray(residuals, float)
    return {s: float(np.sqrt(np.mean(r[sl] ** 2))) for s, sl in data.sample_slices()}


def _unknown(name: str, known: Sequence[str]) -> FitError:
    return unknown_parameter(name, known)


#: Points of the one-parameter scan across a declared range, per grid value (``grid=3``: 60 points).
SCAN_PER_GRID = 20
#: A fit's starts run on the machine's cores (:func:`~camtube.model.core.parallel.map_forked`) when its rows times
#: its fitted parameters reach this (a refit on every row of a 60,000-row record: 0.3-1 million; a fit of the
#: diagnosis's 4,000 search rows, far below, where forking would cost more than it saves).
PARALLEL_STARTS_MIN_WORK = 200_000


def grid_starts(params: Parameters, names: Sequence[str], n: int = 3, cap: int = 27,
                scan: int = 0) -> list[dict[str, float]]:
    """Start points on a grid across the declared ranges of ``names`` (log-spaced for scales).

    The full grid (``n`` values per parameter) when it has at most ``cap``
    points; otherwise each parameter's ``n`` values with the others at their
    current value. With ``scan``, each parameter that declares no
    :attr:`~camtube.model.core.params.Param.starts` is also scanned alone at
    ``scan`` values across its range (the others at their current value): a
    multimodal parameter (a period) has local minima closer together than a
    coarse grid. Deterministic.
    """
    import itertools

    axes = [(nm, params[nm].grid(n)) for nm in names if params[nm].vary]
    axes = [(nm, g) for nm, g in axes if g]
    if not axes:
        return []
    total = 1
    for _, g in axes:
        total *= len(g)
    if total <= cap:
        out = [dict(zip([a for a, _ in axes], combo)) for combo in itertools.product(*[g for _, g in axes])]
    else:
        out = [{nm: v} for nm, g in axes for v in g]
    if scan > n:
        for nm, _ in axes:
            if not params[nm].starts:
                out += [{nm: v} for v in params[nm].grid(scan)]
    return out


def finite_residual(r: np.ndarray) -> np.ndarray:
    """``r`` with NaN and +inf as 1e3 and -inf as -1e3 deg: a trial step may leave an effect's valid region, and
    a large finite residual steers it back. ``r`` itself when all is finite (speed: the usual case)."""
    if np.isfinite(r).all():
        return r
    return np.nan_to_num(r, nan=1e3, posinf=1e3, neginf=-1e3)


def _residual_and_jacobian(model: JointModel, data: Dataset, names: Sequence[str], values: Mapping[str, float],
                           sel: np.ndarray, residual, lo: np.ndarray, hi: np.ndarray):
    """``(fun, jac)`` for :func:`scipy.optimize.least_squares`: ``(residual, "2-point")``, or, when per-sample
    copies of one parameter are fitted, a :class:`~camtube.model.core.fdjac.GroupedJacobian` that steps them
    in one model evaluation (the same columns, fewer evaluations).

    The grouping rests on :meth:`JointModel.predict` running each sample alone when any value is per-sample
    (``values``: every name the model gets); a model class with its own ``predict`` keeps scipy's Jacobian.
    """
    groups = sample_groups(names)
    per_sample = any("@" in k for k in values) and type(model).predict is JointModel.predict
    if not per_sample or all(len(g) == 1 for g in groups):
        return residual, "2-point"
    slices = data.sample_slices()
    rows = {}
    for g in groups:
        for i in (g if len(g) > 1 else ()):
            mask = np.zeros(len(data), bool)
            for smp, sl in slices:
                mask[sl] |= smp == names[i].partition("@")[2]
            rows[i] = mask[sel]
    jac = GroupedJacobian(residual, lo, hi, groups, rows)
    return jac.residual, jac


def fit(
    model: JointModel,
    data: Dataset,
    fit_params: Sequence[str] = ("E_t",),
    fixed: Mapping[str, float] | None = None,
    *,
    initial: Mapping[str, float] | None = None,
    bounds: Mapping[str, tuple[float, float]] | None = None,
    max_nfev: int | None = None,
    rows: np.ndarray | None = None,
    tol: float = 1e-10,
    params: Parameters | None = None,
    per_sample: Sequence[str] = (),
    starts: Sequence[Mapping[str, float]] = (),
    grid: int = 0,
    grid_names: Sequence[str] | None = None,
    keep: int = 2,
) -> FitResult:
    """Fit the varying parameters of ``model`` to ``data`` by bounded least squares, from one or more starts.

    Parameters
    ----------
    model : JointModel
    data : Dataset
        ``n`` rows; ``n`` must exceed the number of fitted parameters.
    fit_params : sequence of str
        Full names of the parameters to fit (may be empty: then the result
        only evaluates the model at ``fixed``); ``name@S`` fits sample S's own copy.
    fixed : dict, optional
        Values of held parameters and starting values of fitted ones.
    initial : dict, optional
        Starting values (win over ``fixed``).
    bounds : dict, optional
        ``{name: (lo, hi)}`` overriding the Param specs.
    max_nfev : int, optional
        Cap on model evaluations per start (default: scipy's).
    rows : (n,) bool array, optional
        Only these rows' residuals enter the fit (held-out fits). The model
        still runs on every row, because history effects (play, creep,
        viscoelasticity) need the whole record. ``residuals`` and
        ``predicted`` stay ``(n,)``; every statistic (RMSE, SSE, AIC/BIC,
        standard errors, ``n_points``) counts the selected rows only.
    tol : float
        ``xtol``, ``ftol`` and ``gtol`` of the solver (looser is faster).
    params : Parameters, optional
        The whole parameter set (values, vary, bounds, per-sample copies);
        replaces ``fit_params``, ``fixed``, ``initial``, ``bounds`` and ``per_sample``.
    per_sample : sequence of str
        Parameter (or effect) names fitted with one value per sample.
    starts : sequence of dict
        Further start points (``{name: value}``, other names at their start value).
    grid : int
        Grid values per parameter for a multi-start search over the declared
        ranges of ``grid_names`` (default: every varying effect parameter);
        0 = no grid. Each such parameter without declared ``starts`` is also
        scanned alone at ``SCAN_PER_GRID * grid`` values (see :func:`grid_starts`).
        Grid points are ranked by their SSE and the best ``keep`` are refined.
        Deterministic: the same call gives the same result.

    Returns
    -------
    FitResult
        From the start whose fit has the lowest SSE (``starts_tried`` counts the refined starts).
    """
    from scipy.optimize import least_squares

    if params is None:
        params = model.make_params(data, fit_params, fixed, initial=initial, bounds=bounds, per_sample=per_sample)
    names = params.varying
    for st in starts:
        for nm in st:
            if nm not in params:
                raise _unknown(nm, list(params))
    sel = np.ones(len(data), bool) if rows is None else np.asarray(rows, bool)
    n = int(sel.sum())
    p = len(names)
    if n == 0:
        raise FitError("no data rows to fit; fix: check the cycle, branch and deadband selection (--cycles, "
                       "--branch, --no-deadband)")
    if n <= p:
        raise FitError(f"{n} data rows cannot fit {p} parameters; fix: give more rows (--cycles all, --branch "
                       "both, a longer record) or fit fewer parameters (--fix NAME=VALUE)")
    lo = np.array([params[nm].lo for nm in names], float)
    hi = np.array([params[nm].hi for nm in names], float)
    if np.any(lo >= hi):
        bad = [nm for nm, a, b in zip(names, lo, hi) if a >= b]
        raise FitError(f"empty bounds for {', '.join(bad)}: lo must be < hi; fix: widen the Param's range in "
                       "its effect, or hold it with --fix NAME=VALUE")
    span = hi - lo
    values = params.values

    def clip(x: np.ndarray) -> np.ndarray:
        return np.clip(x, lo + 1e-9 * np.where(np.isfinite(span), span, 0.0),
                       hi - 1e-9 * np.where(np.isfinite(span), span, 0.0))

    x0 = clip(np.array([values[nm] for nm in names], float))
    start = dict(values)
    start.update(zip(names, map(float, x0)))

    measured = np.asarray(data.angle_deg, float)
    work = dict(start)

    every_row = rows is None

    def residual(x: np.ndarray) -> np.ndarray:
        for nm, v in zip(names, x):
            work[nm] = float(v)
        r = measured - model.predict(data, work)
        return r if every_row else r[sel]   # speed: no copy when every row is fitted

    r0 = residual(x0)
    if not np.all(np.isfinite(r0)):
        k = int(np.flatnonzero(sel)[np.flatnonzero(~np.isfinite(r0))[0]])
        users = [f"{e.name} ({e.source})" for e in getattr(model, "effects", ()) if e.source]
        who = f"an effect returned NaN or inf (check {', '.join(users)})" if users else "check the effects' values"
        raise FitError(f"the model gives a non-finite angle at row {k} with the starting values "
                       f"{ {nm: start[nm] for nm in names} }; fix: {who}, or start elsewhere with --init NAME=VALUE")

    def guarded(x: np.ndarray) -> np.ndarray:
        return finite_residual(residual(x))

    # start points: the given values, explicit starts, the best grid points (ranked by their SSE)
    xs = [x0]
    for st in starts:
        xs.append(clip(np.array([float(st.get(nm, start[nm])) for nm in names], float)))
    if grid and p:
        if grid_names is None:
            gnames = [nm for nm in names if "." in nm]  # every effect parameter (base ones start well)
        else:
            gnames = [nm for nm in grid_names if nm in names]
        cands = []
        for g in grid_starts(params, gnames, grid, scan=SCAN_PER_GRID * grid):
            x = clip(np.array([float(g.get(nm, start[nm])) for nm in names], float))
            r = guarded(x)
            cands.append((float(np.dot(r, r)), len(cands), x))
        cands.sort(key=lambda c: (c[0], c[1]))
        xs += [c[2] for c in cands[:keep]]
    uniq = []
    for x in xs:
        if not any(np.array_equal(x, u) for u in uniq):
            uniq.append(x)

    def refine(i: int) -> tuple:
        """The solver's fit from start ``i`` of ``uniq``: ``(cost, x, jac, success, message, nfev, start)``."""
        xstart = uniq[i]
        if not p:
            return (float(np.dot(r0, r0)), xstart, np.zeros((n, 0)), True, "nothing to fit", 1, xstart)
        scale = np.maximum(np.abs(xstart), 1e-3 * np.where(np.isfinite(span), span, 1.0))
        scale = np.where(scale > 0, scale, 1.0)
        fun, jac = _residual_and_jacobian(model, data, names, work, sel, guarded, lo, hi)
        with one_blas_thread():   # tall, thin linear algebra: threads bring nothing (camtube.model.core.threads)
            sol = least_squares(fun, xstart, jac=jac, bounds=(lo, hi), x_scale=scale, method="trf",
                                max_nfev=max_nfev, xtol=tol, ftol=tol, gtol=tol)
        return (2.0 * float(sol.cost), sol.x, np.atleast_2d(sol.jac), bool(sol.success), str(sol.message),
                int(sol.nfev), xstart)

    # speed: the starts of a fit on many rows (a refit on every row of a record) are independent solver runs, one
    # per core; each gives what it gives in turn (the same numbers), and the best is picked in the starts' order
    if p and len(uniq) > 1 and n * p >= PARALLEL_STARTS_MIN_WORK:
        cands = map_forked(refine, len(uniq))
    else:
        cands = [refine(i) for i in range(len(uniq))]
    with one_blas_thread():
        best = None
        for cand in cands:
            if best is None or cand[0] < best[0] * (1.0 - 1e-12):
                best = cand
        _, x, jac, success, message, nfev, x_start = best

        final = dict(start)
        final.update(zip(names, map(float, x)))
        pred = model.predict(data, final)
        res = measured - pred
        sse = float(np.dot(res[sel], res[sel]))

        cov = np.full((p, p), np.nan)
        if p:
            s2 = sse / (n - p)
            _, sv, vt = np.linalg.svd(jac, full_matrices=False)
            tol_sv = sv.max() * max(jac.shape) * np.finfo(float).eps if sv.size else 0.0
            # the covariance of the directions the data see (a pseudo-inverse: an unseen direction's 1/sv^2 as an
            # infinity would turn every entry into nan through 0 x inf, and every parameter's error infinite) ...
            inv = np.where(sv > tol_sv, 1.0 / np.where(sv > tol_sv, sv, 1.0) ** 2, 0.0)
            cov = (vt.T * inv) @ vt * s2
            # ... and a direction the data cannot see: infinite variance along it, for the parameters it moves
            for k in np.flatnonzero(~(sv > tol_sv)):
                dirn = np.abs(vt[k]) > 1e-12
                cov[np.ix_(dirn, dirn)] = np.inf
        var = np.diag(cov) if p else np.zeros(0)
        stderr = {nm: float(math.sqrt(v)) if np.isfinite(v) and v >= 0 else math.inf
                  for nm, v in zip(names, var)}
        with np.errstate(invalid="ignore", divide="ignore"):
            sd = np.sqrt(var)
            corr = cov / np.outer(sd, sd) if p else np.zeros((0, 0))
        if p:
            corr = np.where(np.isfinite(corr), corr, np.nan)
            np.fill_diagonal(corr, 1.0)

    tol_b = 1e-6 * np.where(np.isfinite(span), span, 1.0)
    at_bound = tuple(nm for nm, v, a, b, t in zip(names, x, lo, hi, tol_b) if v - a <= t or b - v <= t)
    mse = sse / n
    logl = n * math.log(mse) if mse > 0 else -math.inf
    out_params = params.with_values(final, stderr)
    return FitResult(
        model=model,
        data=data,
        params=final,
        fitted=names,
        stderr=stderr,
        units={nm: out_params[nm].unit for nm in out_params},
        residuals=res,
        predicted=pred,
        covariance=cov,
        correlation=corr,
        rmse=float(math.sqrt(mse)),
        rmse_per_sample=rmse_by_sample(data, res) if rows is None else
        rmse_by_sample(data.take(sel), res[sel]),
        aic=logl + 2 * p,
        bic=logl + p * math.log(n),
        n_points=n,
        n_params=p,
        at_bound=at_bound,
        success=success,
        message=message,
        nfev=nfev,
        initial={nm: start[nm] for nm in names},
        rows=None if rows is None else sel,
        parameters=out_params,
        starts_tried=len(uniq),
        start=dict(zip(names, map(float, x_start))),
    )
