"""Joint stage: the notch-by-notch forward model of a cut pattern (design -> mechanics).

It owns what a pattern does when its tendons are pulled: per-notch bend angles from each
backbone sector's stiffness and geometry, capstan friction along the tendon, notch closure
(contact), tendon elongation, and the tip pose. It imports only the design stage; the
measurement-fitted effects enter as plain numbers (:class:`Mechanics`), never through the
model package.
"""
from __future__ import annotations

from camtube.joint.forward import (  # noqa: F401
    DirectionState, JointState, Mechanics, NotchSet, direction_notches, notch_set, simulate, stroke_table,
)
