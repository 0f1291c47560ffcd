"""When no effect fits: what the final residual still follows, and a starter effect for it.

* :func:`analyse` (``analysis``): the ``unexplained`` section of a diagnosis from plain arrays
  (residual and the variables): share above the noise floor, the variables it follows
  (cross-validated smoothing), periodic parts (Lomb-Scargle), shape, samples, a sentence.
* :func:`starter_source` (``starter``): the text of an effect file that runs as written, from a
  diagnosis JSON's ``unexplained`` section or from a stage and a variable.
* :func:`register_effect_commands` (``cli``): ``camtube model effect new NAME --from DIAG.json``.
"""
from __future__ import annotations

from camtube.model.unexplained.analysis import analyse, describe, first_cycle_mask, sentence, variables_of

__all__ = ["analyse", "describe", "first_cycle_mask", "sentence", "variables_of"]
