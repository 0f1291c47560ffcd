"""Compatibility path: the contents moved to :mod:`camtube.model.report.fit` (kept for existing imports)."""
from __future__ import annotations

from camtube.model.report.fit import fit_dict, fit_json, fit_text, param_table, rmse_table  # noqa: F401
