"""Compatibility path: the contents moved to :mod:`camtube.model.core.fit` (kept for existing imports)."""
from __future__ import annotations

from camtube.model.core.fit import FitError, FitResult, fit, grid_starts, rmse_by_sample  # noqa: F401
