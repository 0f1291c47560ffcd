"""Old path of :mod:`camtube.model.report.plot`: importing it warns (``FutureWarning``); it goes in the next release."""
from __future__ import annotations

import warnings

from camtube.model.report.plot import fit_figure, fit_png  # noqa: F401

warnings.warn("camtube path moved: camtube.model.plot is camtube.model.report.plot; import it from there "
              "(the old path goes in the next release)", FutureWarning, stacklevel=2)
