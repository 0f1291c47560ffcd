"""Compatibility path: the contents moved to :mod:`camtube.model.data.dataset` (kept for existing imports)."""
from __future__ import annotations

from camtube.model.data.dataset import Dataset  # noqa: F401
