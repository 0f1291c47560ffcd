"""Compatibility path: the contents moved to :mod:`camtube.model.core.predict` (kept for existing imports)."""
from __future__ import annotations

from camtube.model.core.predict import (  # noqa: F401
    POLYIMIDE_MODULUS_GPA, design_summary, joint_stiffness_nmm_per_rad, model_for_pattern, pattern_compliance_mm_per_N,
    pattern_values, predict_from_stroke, stiffness_from_data, stroke_only_angle_rad,
)
