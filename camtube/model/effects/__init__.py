"""The built-in effects: the physics the paper's base model leaves out.

:mod:`.builtin` defines them (one named term per physical effect, on one stage of the model chain),
:mod:`.history` the history operators they share. :data:`BUILTIN_EFFECTS` is the list the built-in
registry is made from (:func:`camtube.model.core.registry.builtin_registry`).
"""
from __future__ import annotations

from camtube.model.effects.builtin import (  # noqa: F401
    ANGLE_BIAS, BUILTIN_EFFECTS, BUILTINS, CARRIAGE_GAP, CARRIAGE_HOLD, CHORDS, CREEP, FLAT_WALLS, FORCE_ZERO, FRICTION, HARDSTOP, KERF,
    PLAY, PLAY_HELD,
    SERIES, SLACK, TOE, TOE_SHAPE, TOE_SOFT, VISCOELASTIC,
)
from camtube.model.effects.builtin import _flat_wall_ybar  # noqa: F401  (tests check it)
from camtube.model.effects.history import carriage_hold, first_order_lag, monotone_segments, play_operator  # noqa: F401
