"""Old path of :mod:`camtube.model.data.dataset`: importing it warns (``FutureWarning``); it goes in the next release."""
from __future__ import annotations

import warnings

from camtube.model.data.dataset import Dataset  # noqa: F401

warnings.warn("camtube path moved: camtube.model.dataset is camtube.model.data.dataset; import it from there "
              "(the old path goes in the next release)", FutureWarning, stacklevel=2)
