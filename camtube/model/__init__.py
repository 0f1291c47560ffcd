"""Model stage: joint mechanics (tendon stroke -> joint angle), fitting, effects, diagnosis.

Owns: the measurements, the base model plus composable effects, bounded
least-squares fits, and the diagnosis of missing physics. Sub-packages, in the
order data flows through them:

``data``       the :class:`Dataset` value, CSV files, row selection (cycles, branch, deadband)
``core``       parameters (:class:`Parameters`), the :class:`JointModel` with its effects, the explicit
               effect registry, the fit, the stroke-only prediction, model set-up from user input
``effects``    the built-in effects (slack, play, creep, ...) and their history operators
``diagnose``   which effect is missing: the candidate search and the residual atlas
``report``     text, JSON, HTML and figures of fits and diagnoses
``sim``        synthetic data (``model synth``), the independent truth and bench simulators, raw instrument logs
``ingest``     the bench's instrument logs (tracker poses, DAQ, motor) to one measurement file (``model ingest``)

The command line is :mod:`camtube.commands` (``model``, ``diagnose``, ``effect``). ``api`` is the
stable import path for users' effect files (``from camtube.model.api import Effect, Param``);
``dataset``, ``fit``, ``predict``, ``synth``, ``truth``, ``atlas``, ``plot`` and ``report_fit`` are
old paths of the earlier flat layout: they warn (``FutureWarning``) and go in the next release.
"""
from __future__ import annotations

#: Names of the built-in effects, for ``--help`` without importing the effect code
#: (a test checks it against :data:`camtube.model.effects.BUILTINS`).
EFFECT_NAMES = ("slack", "play", "play_held", "carriage_hold", "carriage_gap", "creep", "creep_load", "friction", "capstan", "toe", "toe_shape", "toe_soft", "viscoelastic", "series", "kerf", "flat_walls",
                "chords", "hardstop", "rest_angle", "relaxation", "relaxation2", "angle_bias",
                "force_zero")
