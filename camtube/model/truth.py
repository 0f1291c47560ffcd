"""Old path of :mod:`camtube.model.sim.truth`: importing it warns (``FutureWarning``); it goes in the next release."""
from __future__ import annotations

import warnings

from camtube.model.sim.truth import Hidden, Simulation, simulate  # noqa: F401

warnings.warn("camtube path moved: camtube.model.truth is camtube.model.sim.truth; import it from there "
              "(the old path goes in the next release)", FutureWarning, stacklevel=2)
