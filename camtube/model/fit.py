"""Bounded least-squares fit of a :class:`~camtube.model.api.JointModel` to measurements.

API (stable)
------------
``fit(model, data, fit_params=("E_t",), fixed=None, *, initial=None, bounds=None,
max_nfev=None) -> FitResult``

* ``model`` : any :class:`~camtube.model.api.JointModel` (base plus effects).
* ``data`` : the :class:`~camtube.model.dataset.Dataset` rows to fit (already
  selected: cycles, branch, deadband; see :mod:`camtube.model.data`).
* ``fit_params`` : full parameter names to fit (``"E_t"``, ``"arm_scale"``,
  ``"slack.deadband_mm"``, ...). Every other parameter is held at its value
  in ``fixed`` or, if absent there, at its initial value
  (:meth:`JointModel.initial_values`, i.e. the :class:`~camtube.model.api.Param` spec).
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

import contextlib
import difflib
import math
from dataclasses import dataclass, field
from typing import Mapping, Sequence

import numpy as np

from camtube.errors import CamtubeError
from camtube.model.api import JointModel
from camtube.model.dataset import Dataset


class FitError(CamtubeError, ValueError):
    """A fit could not be set up (unknown parameter, no data, non-finite model)."""


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
        specs = self.model.param_specs
        for nm in self.fitted:
            se = self.stderr.get(nm, math.inf)
            if nm in self.at_bound:
                spec = specs.get(nm)
                unit = f" {spec.unit}" if spec is not None and spec.unit else ""
                out[nm] = f"ended on its bound ({self.params[nm]:.4g}{unit})"
            elif not math.isfinite(se):
                out[nm] = "its standard error is infinite (the rows do not depend on it)"
        return out

    def correlation_of(self, a: str, b: str) -> float:
        """Correlation coefficient of two fitted parameters."""
        i, j = self.fitted.index(a), self.fitted.index(b)
        return float(self.correlation[i, j])


def _blas_single_thread():
    """Limit BLAS to one thread while fitting, if threadpoolctl is installed.

    The fit's linear algebra is tall and thin (n x p, p small): threads bring
    nothing, and on a busy machine OpenBLAS threads waiting for a core make each
    matrix-vector product a hundred times slower.
    """
    try:
        from threadpoolctl import threadpool_limits
    except ModuleNotFoundError:
        return contextlib.nullcontext()
    return threadpool_limits(1, user_api="blas")


def rmse_by_sample(data: Dataset, residuals: np.ndarray) -> dict[str, float]:
    """RMSE (deg) of ``residuals`` ``(n,)`` per sample of ``data``, in sample order."""
    r = np.asarray(residuals, float)
    return {s: float(np.sqrt(np.mean(r[sl] ** 2))) for s, sl in data.sample_slices()}


def _unknown(name: str, known: Sequence[str]) -> FitError:
    hint = difflib.get_close_matches(name, list(known), n=1)
    return FitError(f"unknown model parameter {name!r}"
                    + (f"; did you mean {hint[0]!r}?" if hint else "")
                    + f" (this model has: {', '.join(known)})")


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
) -> FitResult:
    """Fit ``fit_params`` of ``model`` to ``data`` by bounded least squares.

    Parameters
    ----------
    model : JointModel
    data : Dataset
        ``n`` rows; ``n`` must exceed the number of fitted parameters.
    fit_params : sequence of str
        Full names of the parameters to fit (may be empty: then the result
        only evaluates the model at ``fixed``).
    fixed : dict, optional
        Values of held parameters and starting values of fitted ones.
    initial : dict, optional
        Starting values (win over ``fixed``).
    bounds : dict, optional
        ``{name: (lo, hi)}`` overriding the Param specs.
    max_nfev : int, optional
        Cap on model evaluations (default: scipy's).
    rows : (n,) bool array, optional
        Only these rows' residuals enter the fit (held-out fits). The model
        still runs on every row, because history effects (play, creep,
        viscoelasticity) need the whole record. ``residuals`` and
        ``predicted`` stay ``(n,)``; every statistic (RMSE, SSE, AIC/BIC,
        standard errors, ``n_points``) counts the selected rows only.
    tol : float
        ``xtol``, ``ftol`` and ``gtol`` of the solver (looser is faster).

    Returns
    -------
    FitResult
    """
    from scipy.optimize import least_squares

    specs = model.param_specs
    names = tuple(dict.fromkeys(fit_params))
    for nm in list(names) + list(fixed or {}) + list(initial or {}) + list(bounds or {}):
        if nm not in specs:
            raise _unknown(nm, list(specs))
    sel = np.ones(len(data), bool) if rows is None else np.asarray(rows, bool)
    n = int(sel.sum())
    p = len(names)
    if n == 0:
        raise FitError("no data rows to fit (check the cycle, branch and deadband selection)")
    if n <= p:
        raise FitError(f"{n} data rows cannot fit {p} parameters")

    values = model.initial_values(data, base=dict(fixed or {}))
    values.update({k: float(v) for k, v in (initial or {}).items()})
    lo = np.array([float((bounds or {}).get(nm, (specs[nm].lo, specs[nm].hi))[0]) for nm in names])
    hi = np.array([float((bounds or {}).get(nm, (specs[nm].lo, specs[nm].hi))[1]) for nm in names])
    if np.any(lo >= hi):
        bad = [nm for nm, a, b in zip(names, lo, hi) if a >= b]
        raise FitError(f"empty bounds for {', '.join(bad)}: lo must be < hi")
    x0 = np.array([values[nm] for nm in names], float)
    span = hi - lo
    x0 = np.clip(x0, lo + 1e-9 * span, hi - 1e-9 * span)
    start = dict(values)
    start.update(zip(names, map(float, x0)))

    measured = np.asarray(data.angle_deg, float)
    work = dict(start)

    def residual(x: np.ndarray) -> np.ndarray:
        for nm, v in zip(names, x):
            work[nm] = float(v)
        return (measured - model.predict(data, work))[sel]

    r0 = residual(x0)
    if not np.all(np.isfinite(r0)):
        k = int(np.flatnonzero(sel)[np.flatnonzero(~np.isfinite(r0))[0]])
        raise FitError(f"the model gives a non-finite angle at row {k} with the starting values "
                       f"{ {nm: start[nm] for nm in names} }")

    def guarded(x: np.ndarray) -> np.ndarray:
        # a trial step may leave an effect's valid region: a large finite residual steers it back
        return np.nan_to_num(residual(x), nan=1e3, posinf=1e3, neginf=-1e3)

    with _blas_single_thread():
        if p:
            scale = np.maximum(np.abs(x0), 1e-3 * np.where(np.isfinite(span), span, 1.0))
            scale = np.where(scale > 0, scale, 1.0)
            sol = least_squares(guarded, x0, bounds=(lo, hi), x_scale=scale, method="trf",
                                max_nfev=max_nfev, xtol=tol, ftol=tol, gtol=tol)
            x = sol.x
            jac = np.atleast_2d(sol.jac)
            success, message, nfev = bool(sol.success), str(sol.message), int(sol.nfev)
        else:
            x = x0
            jac = np.zeros((n, 0))
            success, message, nfev = True, "nothing to fit", 1

        final = dict(start)
        final.update(zip(names, map(float, x)))
        pred = model.predict(data, final)
        res = measured - pred
        sse = float(np.dot(res[sel], res[sel]))

        cov = np.full((p, p), np.nan)
        if p:
            s2 = sse / (n - p)
            _, sv, vt = np.linalg.svd(jac, full_matrices=False)
            tol = sv.max() * max(jac.shape) * np.finfo(float).eps if sv.size else 0.0
            inv = np.where(sv > tol, 1.0 / np.where(sv > tol, sv, 1.0) ** 2, np.inf)
            with np.errstate(invalid="ignore"):
                cov = (vt.T * inv) @ vt * s2
            # a direction the data cannot see: infinite variance along it
            for k in np.flatnonzero(~(sv > tol)):
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
    return FitResult(
        model=model,
        data=data,
        params=final,
        fitted=names,
        stderr=stderr,
        units={nm: specs[nm].unit for nm in specs},
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
    )
