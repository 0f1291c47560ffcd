"""The fit's guard against a model that is not finite at a trial point (camtube.model.core.fit.finite_residual)."""
from __future__ import annotations

import numpy as np

from camtube.model.core.fit import finite_residual


def test_non_finite_residuals_become_large_finite_ones():
    r = np.array([0.5, np.nan, np.inf, -np.inf, -0.0, -2.0])
    out = finite_residual(r)
    assert np.array_equal(out, [0.5, 1e3, 1e3, -1e3, 0.0, -2.0])
    assert np.isnan(r[1])                                   # the input is left alone


def test_finite_residuals_pass_unchanged_to_the_bit():
    r = np.array([1e-300, -0.0, 3.0, -1e300])
    out = finite_residual(r)
    assert np.array_equal(out, np.nan_to_num(r, nan=1e3, posinf=1e3, neginf=-1e3))
    assert np.array_equal(np.signbit(out), np.signbit(r))
