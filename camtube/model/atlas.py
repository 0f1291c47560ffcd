"""Old path of :mod:`camtube.model.diagnose.atlas`: importing it warns (``FutureWarning``); it goes in the next release."""
from __future__ import annotations

import warnings

from camtube.model.diagnose.atlas import Atlas, Panel, VARIABLES, binned, describe, residual_atlas, variable  # noqa: F401

warnings.warn("camtube path moved: camtube.model.atlas is camtube.model.diagnose.atlas; import it from there "
              "(the old path goes in the next release)", FutureWarning, stacklevel=2)
