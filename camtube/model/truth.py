"""Compatibility path: the contents moved to :mod:`camtube.model.sim.truth` (kept for existing imports)."""
from __future__ import annotations

from camtube.model.sim.truth import Hidden, Simulation, simulate  # noqa: F401
