"""Compatibility path: the contents moved to :mod:`camtube.model.diagnose.atlas` (kept for existing imports)."""
from __future__ import annotations

from camtube.model.diagnose.atlas import Atlas, Panel, VARIABLES, binned, describe, residual_atlas, variable  # noqa: F401
