"""One laser pass: a path at one set of laser settings (its own module, so that the Job and its
packed arrays both use it without importing each other)."""
from __future__ import annotations

from dataclasses import dataclass

from camtube.design.contour import Contour


@dataclass(frozen=True)
class Pass:
    """One laser pass.

    Attributes
    ----------
    contour : Contour
        Path the beam follows, starting at ``contour.points[0]`` (closed, or an
        open slit cut from its first point to its last).
    cut_index : int
        Index of the cut in the job's ``design`` (and ``Pattern.cuts``).
    kind : str
        ``notch``, ``hole`` or ``cut``.
    repeat : int
        0-based repeat of the focus+defocus group.
    focus_level : int
        0 = focus on the surface, 1 = defocused into the material.
    focus_offset_mm : float
        How far the focus lies into the material (0 or the defocus), >= 0.
    drill_index : int
        0-based cut within the drill group.
    offset_mm : float
        Inward offset of the path from the design line (drill steps, kerf); 0 for a slit.
    power_w, frequency_khz, speed_mm_s : float
        Laser settings; ``speed_mm_s`` is on the outer surface.
    """

    contour: Contour
    cut_index: int
    kind: str
    repeat: int
    focus_level: int
    focus_offset_mm: float
    drill_index: int
    offset_mm: float
    power_w: float
    frequency_khz: float
    speed_mm_s: float

    @property
    def length_mm(self) -> float:
        return self.contour.length_mm
