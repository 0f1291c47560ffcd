"""Diagnosis of missing physics: the search (:mod:`.search`) and the residual atlas (:mod:`.atlas`)."""
from __future__ import annotations

from camtube.model.diagnose.atlas import Atlas, Panel, describe, residual_atlas, variable  # noqa: F401
from camtube.model.diagnose.search import (  # noqa: F401
    Candidate, Diagnosis, Step, diagnose, holdout_mask, noise_floor, noise_typical, thin,
)
