"""Old path of :mod:`camtube.model.report.fit`: importing it warns (``FutureWarning``); it goes in the next release."""
from __future__ import annotations

import warnings

from camtube.model.report.fit import fit_dict, fit_json, fit_text, param_table, rmse_table  # noqa: F401

warnings.warn("camtube path moved: camtube.model.report_fit is camtube.model.report.fit; import it from there "
              "(the old path goes in the next release)", FutureWarning, stacklevel=2)
