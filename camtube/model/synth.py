"""Compatibility path: the contents moved to :mod:`camtube.model.sim.synth` (kept for existing imports)."""
from __future__ import annotations

from camtube.model.sim.synth import MAX_ROWS, check_arguments, noise_floor_deg, rows_per_cycle, synthesize, to_csv, triangle_stroke, write  # noqa: F401
