"""One place for geometric tolerances and unit conventions.

All lengths in camtube are millimetres (mm). Angles carry their unit in the
name (``angle_deg``, ``theta_rad``). Times are seconds, speeds mm/s unless the
name says otherwise.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Tolerances:
    """Geometric tolerances, all in mm.

    Attributes
    ----------
    merge : float
        Two coordinates closer than this are the same point (DXF read-back,
        seam matching).
    zero : float
        Smallest meaningful length; anything shorter is degenerate.
    safety : float
        Allowance for a laser-on move to lie outside the cut region it belongs
        to (numerical slack for the safety check, not a process allowance).
    """

    merge: float = 1e-7
    zero: float = 1e-9
    safety: float = 1e-6


TOL = Tolerances()
