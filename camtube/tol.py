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
    chord : float
        Drawing import: largest distance between a drawn curve (arc, circle,
        ellipse, spline, polyline bulge) and the chords that replace it
        (25 nm; the cut equals the drawing within this: a 0.3 mm round hole
        loses 1e-4 of its area).
    gap : float
        Drawing import: two path ends closer than this are joined (1 um); a
        loop open by more is refused, naming the gap. Also the tolerance for
        a piece to lie on the seam or the outline's edge.
    outline : float
        Drawing import: the tube outline's height may differ from 2 pi r_o by
        this much (1 um) before the radius is called a mismatch.
    path : float
        Chord tolerance of a pass (1 um): a tangent-continuous run of a closed pass
        path (a flattened arc, spline, fillet or ellipse) is cut as chords that lie
        within this of the drawn path, and only on its inside
        (:func:`camtube.plan.paths.simplify_closed`). A machine that blends the
        chords adds its blending tolerance (``G64 P0.001`` on ``linuxcnc-path``):
        the beam stays within 2 um of the drawing, a tenth of a 20 um kerf
        (``MachineProfile.path_tolerance_mm``).
    rule : float
        A length at a design rule's limit within this (1 nm) is at the limit, not past it: the design rules
        (:mod:`camtube.design.rules`), the CAD verification (:mod:`camtube.cad.verify`) and the synthesis
        compare a web with ``rules.min_web`` with this one slack, so a web at the limit (or a float's
        rounding from it, e.g. a spacing of 0.0999999999 mm for 0.1) gets one verdict from all of them.
    corner_deg : float
        A vertex where the path turns by more than this (deg) is a true corner:
        the time-optimal bound stops there (:mod:`camtube.machine.bound`); below it
        the path is tangent-continuous, its speed limited only by its curvature.
    """

    merge: float = 1e-7
    zero: float = 1e-9
    safety: float = 1e-6
    chord: float = 2.5e-5
    gap: float = 1e-3
    outline: float = 1e-3
    path: float = 1e-3
    rule: float = 1e-9
    corner_deg: float = 5.0


TOL = Tolerances()
