"""The model core: parameters, the joint model with its effects, the registry, the fit, the prediction.

Modules: :mod:`.params` (:class:`Param`, :class:`Parameters`, tendon defaults and compliance),
:mod:`.model` (:class:`JointModel`, :class:`Effect`, :class:`Context`, stages), :mod:`.registry`
(explicit effect tables, user effect files), :mod:`.fit` (bounded least squares, multi-start),
:mod:`.predict` (a pattern's model, the stroke-only prediction), :mod:`.build` (model set-up from
command-line style input).
"""
from __future__ import annotations

from camtube.model.core.model import BASE_PARAMS, STAGES, Context, Effect, FitError, JointModel  # noqa: F401
from camtube.model.core.params import (  # noqa: F401
    DEFAULT_E_T_GPA, DEFAULT_L0_MM, Param, Parameter, Parameters, tendon_compliance_mm_per_N,
)
from camtube.model.core.registry import (  # noqa: F401
    EffectError, Registry, builtin_registry, get_effect, load_effect_file, register, registry,
)
