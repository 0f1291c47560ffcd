"""Old path of :mod:`camtube.model.core.fit`: importing it warns (``FutureWarning``); it goes in the next release."""
from __future__ import annotations

import warnings

from camtube.model.core.fit import FitError, FitResult, fit, grid_starts, rmse_by_sample  # noqa: F401

warnings.warn("camtube path moved: camtube.model.fit is camtube.model.core.fit; import it from there "
              "(the old path goes in the next release)", FutureWarning, stacklevel=2)
