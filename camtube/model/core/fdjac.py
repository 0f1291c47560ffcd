"""Forward-difference Jacobian of a fit's residual that perturbs a parameter's per-sample copies together.

Why: with per-sample parameters (``name@S1``, ``name@S2``, ...) the model runs each sample on its own
(:meth:`~camtube.model.core.model.JointModel.predict`), so the copy of sample S changes sample S's rows
only. scipy's ``'2-point'`` Jacobian spends one model evaluation per copy; one evaluation with every copy
of ``name`` stepped gives all their columns at once (each read on its own sample's rows).

The columns are the ones scipy computes, to the bit: the same step rule (``scipy.optimize._numdiff``:
relative step ``sqrt(eps) * max(1, |x|)`` with the sign of ``x``, turned back or shortened at a bound),
the same step ``dx = (x + h) - x``, the same difference ``(f(x + h) - f(x)) / dx`` (a row of another
sample takes ``f(x)`` there, as scipy's own evaluation gives it), the same memory layout. So
:func:`scipy.optimize.least_squares` takes the same path and the fit gives the same result, faster.
"""
from __future__ import annotations

from typing import Callable, Mapping, Sequence

import numpy as np

__all__ = ["GroupedJacobian", "forward_steps", "sample_groups"]

#: scipy's relative step of a 2-point difference in float64: sqrt(machine epsilon).
REL_STEP = np.finfo(np.float64).eps ** 0.5


def forward_steps(x: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Absolute steps ``h`` (n,) of scipy's 2-point difference at ``x`` within ``[lo, hi]``.

    The rule of ``_compute_absolute_step`` (no ``diff_step``) and ``_adjust_scheme_to_bounds`` ('1-sided',
    one step): a step that would leave the box is reversed when the reversed one fits, else it goes to the
    farther bound.
    """
    sign = (x >= 0).astype(float) * 2 - 1
    h = REL_STEP * sign * np.maximum(1.0, np.abs(x))
    if np.all((lo == -np.inf) & (hi == np.inf)):
        return h
    out = h.copy()
    below, above = x - lo, hi - x
    trial = x + h
    violated = (trial < lo) | (trial > hi)
    fitting = np.abs(h) <= np.maximum(below, above)
    out[violated & fitting] *= -1
    forward = (above >= below) & ~fitting
    out[forward] = above[forward]
    backward = (above < below) & ~fitting
    out[backward] = -below[backward]
    return out


def sample_groups(names: Sequence[str]) -> list[list[int]]:
    """Indices of ``names`` to step together: the per-sample copies of one parameter, one group each; every
    other name alone. In order of first appearance."""
    groups: dict[str, list[int]] = {}
    for i, nm in enumerate(names):
        base, at, smp = nm.partition("@")
        groups.setdefault(base if at else f"\0{nm}", []).append(i)
    return list(groups.values())


class GroupedJacobian:
    """``jac(x) -> (m, n)`` for :func:`scipy.optimize.least_squares`, from ``fun`` (the residual) stepping
    the members of each group in one evaluation.

    Parameters
    ----------
    fun : callable
        The residual ``(n,) -> (m,)``; call it through :meth:`residual` so the value at the solver's current
        point is known when its Jacobian is asked for (scipy's difference starts from that value too).
    lo, hi : (n,) float
        The bounds given to the solver.
    groups : list of list of int
        Column indices stepped together (:func:`sample_groups`).
    rows : mapping int -> (m,) bool
        For each member of a group of two or more, the residual rows its parameter can change (its sample).
        Members of one group must have disjoint rows.
    """

    def __init__(self, fun: Callable[[np.ndarray], np.ndarray], lo: np.ndarray, hi: np.ndarray,
                 groups: Sequence[Sequence[int]], rows: Mapping[int, np.ndarray]):
        self.fun = fun
        self.lo = np.asarray(lo, float)
        self.hi = np.asarray(hi, float)
        self.groups = [list(g) for g in groups]
        self.rows = {i: np.asarray(r, bool) for i, r in rows.items()}
        self._last: tuple[np.ndarray, np.ndarray] | None = None
        self.evaluations = 0

    def residual(self, x: np.ndarray) -> np.ndarray:
        """``fun(x)``, remembered as the starting value of the next Jacobian at ``x``."""
        f = np.atleast_1d(self.fun(x))
        self._last = (np.array(x, float, copy=True), f)
        return f

    def _f0(self, x: np.ndarray) -> np.ndarray:
        """The residual at ``x``: the solver asks for a Jacobian where it has just evaluated the residual."""
        if self._last is not None and np.array_equal(self._last[0], x):
            return self._last[1]
        return self.residual(x)

    def __call__(self, x: np.ndarray) -> np.ndarray:
        x = np.asarray(x, float)
        f0 = self._f0(x)
        h = forward_steps(x, self.lo, self.hi)
        jac_t = np.empty((x.size, f0.size))
        for group in self.groups:
            x1 = x.copy()
            for i in group:
                x1[i] = x[i] + h[i]
            f1 = np.atleast_1d(self.fun(x1))
            self.evaluations += 1
            for i in group:
                dx = (x[i] + h[i]) - x[i]
                if len(group) == 1:
                    jac_t[i] = (f1 - f0) / dx
                else:
                    # this copy moves its own sample's rows only: elsewhere f(x + h_i) is f(x)
                    mine = np.where(self.rows[i], f1, f0)
                    jac_t[i] = (mine - f0) / dx
        return jac_t.T
