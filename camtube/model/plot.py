"""Compatibility path: the contents moved to :mod:`camtube.model.report.plot` (kept for existing imports)."""
from __future__ import annotations

from camtube.model.report.plot import fit_figure, fit_png  # noqa: F401
