"""The effect API for users' effect files: ``from camtube.model.api import Effect, Param``.

Kept stable for effect files (``docs/diagnose.md``); the code lives in :mod:`camtube.model.core`.
"""
from __future__ import annotations

from camtube.model.core.model import Effect, Context, JointModel, BASE_PARAMS, STAGES, FitError  # noqa: F401
from camtube.model.core.params import Param, Parameter, Parameters  # noqa: F401
from camtube.model.core.registry import get_effect, load_effect_file, register, registry  # noqa: F401
