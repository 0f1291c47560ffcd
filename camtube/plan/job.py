"""The Job: an ordered list of laser passes in the unrolled frame.

A :class:`Pass` is one trip of the beam along one path at one set of laser
settings. Its ``contour`` is in the *unwrapped* unrolled frame of the designer
(x from the tip, y arc length on the outer surface, mm; y may leave
``[0, 2 pi r_o)`` for a cut straddling the seam, because the rotary axis is
continuous). A closed path starts and ends at ``contour.points[0]``; an open
one (a slit) runs from its first point to its last.

A planned job keeps its passes as arrays (:class:`~camtube.plan.packed.Packed`);
``job.passes`` is then a lazy :class:`~camtube.plan.packed.PassView` that builds
Pass objects only when they are asked for.
"""
from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Sequence

from camtube.design.contour import Contour
from camtube.design.pattern import Process


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


@dataclass(frozen=True)
class Job:
    """A planned laser job.

    Attributes
    ----------
    name : str
        Pattern (or DXF) name.
    outer_radius_mm : float
        Tube outer radius (the post-processor's wrap A = y / r_o).
    length_mm : float
        Tube length (nothing may be cut beyond it).
    design : tuple[Contour, ...]
        The design cut regions (unwrapped), indexed by ``Pass.cut_index``.
    passes : Sequence[Pass]
        In execution order: a tuple, or the planner's lazy
        :class:`~camtube.plan.packed.PassView` over :attr:`packed`.
    process : Process
        The process the passes were planned from.
    repeats : int
        Repeats actually used (explicit or from the thickness rule).
    ordering : str
        Name of the ordering strategy.
    """

    name: str
    outer_radius_mm: float
    length_mm: float
    design: tuple[Contour, ...]
    passes: Sequence[Pass]
    process: Process
    repeats: int
    ordering: str

    @property
    def cut_length_mm(self) -> float:
        """Total length of every pass (mm)."""
        pk = self.packed
        return float(pk.geom_length_mm[pk.pass_geom].sum())

    @cached_property
    def packed(self):
        """:class:`camtube.plan.packed.Packed` arrays of the passes (the planner's, or packed once and cached)."""
        from camtube.plan.packed import PassView, pack

        if isinstance(self.passes, PassView):
            return self.passes.packed
        return pack(self)

    def cached(self, key: str, make):
        """``make()``, computed once per Job object (the Job is immutable; e.g. its time estimate)."""
        d = self.__dict__
        if key not in d:
            d[key] = make()
        return d[key]
