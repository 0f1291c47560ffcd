"""Old path of :mod:`camtube.model.sim.synth`: importing it warns (``FutureWarning``); it goes in the next release."""
from __future__ import annotations

import warnings

from camtube.model.sim.synth import MAX_ROWS, check_arguments, noise_floor_deg, rows_per_cycle, synthesize, to_csv, triangle_stroke, write  # noqa: F401

warnings.warn("camtube path moved: camtube.model.synth is camtube.model.sim.synth; import it from there "
              "(the old path goes in the next release)", FutureWarning, stacklevel=2)
