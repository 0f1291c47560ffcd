"""Old path of :mod:`camtube.model.core.predict`: importing it warns (``FutureWarning``); it goes in the next release."""
from __future__ import annotations

import warnings

from camtube.model.core.predict import (  # noqa: F401
    POLYIMIDE_MODULUS_GPA, design_summary, joint_stiffness_nmm_per_rad, model_for_pattern, pattern_compliance_mm_per_N,
    pattern_values, predict_from_stroke, stiffness_from_data, stroke_only_angle_rad,
)

warnings.warn("camtube path moved: camtube.model.predict is camtube.model.core.predict; import it from there "
              "(the old path goes in the next release)", FutureWarning, stacklevel=2)
