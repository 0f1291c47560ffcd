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

from dataclasses import dataclass, field
from typing import Any, Callable, Sequence

from camtube.design.contour import Contour
from camtube.design.pattern import Process
from camtube.plan.packed import PassView, pack
from camtube.plan.passes import Pass

__all__ = ["Job", "JobCache", "Pass"]


@dataclass(eq=False)
class JobCache:
    """What is worked out once per Job and shared by every writer of it (owned by the Job).

    A Job is immutable, so whatever follows from it alone can be kept with it: the stages that
    compute these fill them in, the writers read them. ``dataclasses.replace`` on a Job gives
    the new Job a fresh, empty cache.

    Attributes
    ----------
    packed : camtube.plan.packed.Packed | None
        The passes packed into arrays, for a Job made from Pass objects (a planned Job has them).
    checked : bool
        The job's neutral moves passed the safety check (:func:`camtube.plan.safety.check_job`).
    estimate : camtube.plan.moves.Estimate | None
        The time estimate of the job's own moves (:func:`camtube.plan.moves.estimate`).
    regions : dict
        The safety check's prepared cut regions, per tolerance.
    motion : dict
        Motion-aware estimates per machine profile (:func:`camtube.machine.motion_time.job_estimate`).
    """

    checked: bool = False
    packed: Any = None
    estimate: Any = None
    regions: dict = field(default_factory=dict)
    motion: dict = field(default_factory=dict)

    @staticmethod
    def get(table: dict, key, make: Callable[[], Any]):
        """``table[key]``, made with ``make()`` the first time."""
        if key not in table:
            table[key] = make()
        return table[key]


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
    cache : JobCache
        What is computed once per Job (safety check, estimates), owned by it; not compared.
    """

    name: str
    outer_radius_mm: float
    length_mm: float
    design: tuple[Contour, ...]
    passes: Sequence[Pass]
    process: Process
    repeats: int
    ordering: str
    cache: JobCache = field(default_factory=JobCache, init=False, repr=False, compare=False)

    @property
    def cut_length_mm(self) -> float:
        """Total length of every pass (mm)."""
        pk = self.packed
        return float(pk.geom_length_mm[pk.pass_geom].sum())

    @property
    def link_length_mm(self) -> float:
        """Total length (mm) of the beam-on links between chained passes (the ``chained`` ordering; 0 otherwise).

        Not part of :attr:`cut_length_mm` (the passes' paths), so the lower bound stays the passes' length
        over the scan speed; the beam is on along the cut length plus this.
        """
        return self.packed.link_length_mm()

    @property
    def packed(self):
        """:class:`camtube.plan.packed.Packed` arrays of the passes (the planner's, or packed once, kept in the cache)."""
        if isinstance(self.passes, PassView):
            return self.passes.packed
        if self.cache.packed is None:
            self.cache.packed = pack(self)
        return self.cache.packed
