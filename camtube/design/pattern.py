"""Immutable core values of a notch pattern: Tube, Notch, Hole, Process, Tendon, Pattern.

The unrolled frame used by every output of camtube:

- ``x`` (mm): along the tube axis, measured from the tip (x = 0) towards the base.
- ``y`` (mm): arc length on the *outer* surface, ``0 <= y < 2 pi r_o``;
  ``y = 0`` is rotary angle 0 and ``y = r_o * angle_rad``.

A cut is described by its centre ``(x_mm, angle_deg)`` and its extent on the
outer surface (axial ``width_mm``, circumferential ``arc_mm``). Notches and
square tendon holes share this description; they differ in kind and in which
rules apply to them.

A cut read from a drawing may carry its drawn ``outline`` (any polygon, or an
open path for a *slit*, in the unwrapped frame); its centre and extents are then
the outline's bounding values, so every rule and measure written for rectangles
still sees the right size and place.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

CutKind = Literal["notch", "hole", "slit"]


@dataclass(frozen=True)
class Tube:
    """A polymer tube.

    Attributes
    ----------
    outer_radius_mm, inner_radius_mm : float
        Radii r_o > r_i > 0.
    length_mm : float
        Length of the modelled tube segment, from the tip (x = 0).
    material : str
        Material name (``polyimide``); used for rule limits and the model.
    """

    outer_radius_mm: float
    inner_radius_mm: float
    length_mm: float
    material: str = "polyimide"

    @property
    def wall_mm(self) -> float:
        return self.outer_radius_mm - self.inner_radius_mm

    @property
    def circumference_mm(self) -> float:
        """Outer circumference 2 pi r_o: the height of the unrolled sheet."""
        return 2.0 * math.pi * self.outer_radius_mm


@dataclass(frozen=True)
class Cut:
    """A cut in the unrolled frame: a rectangle (notch or square hole), or a drawn outline.

    Attributes
    ----------
    kind : {"notch", "hole", "slit"}
        ``slit``: an open path the beam follows (only from a drawing; needs ``outline``).
    x_mm : float
        Axial position of the cut's centre from the tip.
    width_mm : float
        Axial extent (notch width h; hole side).
    arc_mm : float
        Circumferential extent on the outer surface (notch arc s; hole side).
    angle_deg : float
        Rotary angle of the cut's centre, in [0, 360).
    outline : tuple[tuple[float, float], ...] | None
        Drawn shape, ``(n, 2)`` vertices ``(x_mm, y_mm)`` in the unwrapped frame:
        a closed polygon (counter-clockwise, last point not repeated) for a notch
        or hole, the open path from first to last point for a slit. Its bounding
        box is ``[x_start, x_end] x y_range_mm(r_o)``. ``None``: the rectangle.
    """

    kind: CutKind
    x_mm: float
    width_mm: float
    arc_mm: float
    angle_deg: float
    outline: tuple[tuple[float, float], ...] | None = None

    @property
    def is_drawn(self) -> bool:
        """True when the cut has a drawn outline (not the plain rectangle)."""
        return self.outline is not None

    @property
    def x_start_mm(self) -> float:
        return self.x_mm - self.width_mm / 2.0

    @property
    def x_end_mm(self) -> float:
        return self.x_mm + self.width_mm / 2.0

    def y_center_mm(self, outer_radius_mm: float) -> float:
        """Centre of the cut in unrolled ``y`` (mm), in [0, 2 pi r_o)."""
        circ = 2.0 * math.pi * outer_radius_mm
        return (math.radians(self.angle_deg) * outer_radius_mm) % circ

    def y_range_mm(self, outer_radius_mm: float) -> tuple[float, float]:
        """Unwrapped ``(y0, y1)``; may extend below 0 or above 2 pi r_o (seam)."""
        yc = self.y_center_mm(outer_radius_mm)
        return yc - self.arc_mm / 2.0, yc + self.arc_mm / 2.0


def drawn(kind: CutKind, points, outer_radius_mm: float) -> Cut:
    """A cut with a drawn outline; centre and extents are the outline's bounding values.

    Parameters
    ----------
    kind : {"notch", "hole", "slit"}
    points : (n, 2) float
        Unwrapped ``(x_mm, y_mm)`` vertices (see :class:`Cut`). They are shifted
        by a whole turn, if needed, so the centre lies in ``[0, 2 pi r_o)``.
    outer_radius_mm : float
        r_o (maps ``y`` to the angle).
    """
    pts = [(float(x), float(y)) for x, y in points]
    xs = [p[0] for p in pts]
    ys = [p[1] for p in pts]
    circ = 2.0 * math.pi * outer_radius_mm
    yc = 0.5 * (min(ys) + max(ys))
    shift = math.floor(yc / circ) * circ
    if shift:
        pts = [(x, y - shift) for x, y in pts]
        yc -= shift
    angle = math.degrees(yc / outer_radius_mm) % 360.0
    return Cut(kind, 0.5 * (min(xs) + max(xs)), max(xs) - min(xs), max(ys) - min(ys), angle, tuple(pts))


def notch(x_mm: float, width_mm: float, arc_mm: float, angle_deg: float) -> Cut:
    return Cut("notch", x_mm, width_mm, arc_mm, angle_deg % 360.0)


def hole(x_mm: float, size_mm: float, angle_deg: float) -> Cut:
    return Cut("hole", x_mm, size_mm, size_mm, angle_deg % 360.0)


@dataclass(frozen=True)
class RepeatRule:
    """One row of the thickness -> repeats rule: up to ``max_depth_mm`` use ``repeats``."""

    max_depth_mm: float
    repeats: int


#: A beam's kerf (mm) assumed where the process gives none (``process.kerf = 0``, no kerf compensation): the CAD
#: simulation cuts with it, the design rules warn of webs it would thin below ``rules.min_web``, the synthesis draws
#: notches that much narrower.
ASSUMED_KERF_MM = 0.02


@dataclass(frozen=True)
class Process:
    """Femtosecond laser process (the paper's Table II plus the pass structure).

    Attributes
    ----------
    power_w, frequency_khz, scan_speed_mm_s, wavelength_nm : float
        Laser settings; cutting moves run at ``scan_speed_mm_s`` on the outer surface.
    drill_offset_mm : float
        Step between the successive cuts of one drill group (into the material removed).
    drill_passes : int
        Cuts per drill group (4 in the paper).
    defocus_mm : float
        Second focus level, this far *into* the material (focus group 2).
    repeats : int | None
        Repeats of the focus+defocus group; ``None`` means "from ``repeat_rule``".
    repeat_rule : tuple[RepeatRule, ...]
        Thickness rule: the first row whose ``max_depth_mm`` >= the beam depth wins.
    kerf_mm : float
        Kerf width (0 disables kerf compensation).
    rapid_speed_mm_s : float
        Speed of laser-off traverses (time estimate).
    focus_speed_mm_s : float
        Speed of Z focus moves (time estimate).
    max_time_h : float
        A job whose estimated laser time exceeds this many hours is warned about.
    """

    power_w: float = 2.0
    frequency_khz: float = 60.0
    scan_speed_mm_s: float = 25.0
    wavelength_nm: float = 1030.0
    drill_offset_mm: float = 0.005
    drill_passes: int = 4
    defocus_mm: float = 0.1
    repeats: int | None = None
    repeat_rule: tuple[RepeatRule, ...] = (
        RepeatRule(1.0, 4),
        RepeatRule(1.3, 6),
        RepeatRule(2.0, 8),
    )
    kerf_mm: float = 0.0
    rapid_speed_mm_s: float = 50.0
    focus_speed_mm_s: float = 5.0
    max_time_h: float = 8.0


@dataclass(frozen=True)
class Tendon:
    """Actuation tendon (UHMWPE in the paper).

    Attributes
    ----------
    radius_mm : float
        r_t.
    length_mm : float
        Unloaded length L0.
    modulus_gpa : float
        Young's modulus E_t (fitted; 28 GPa in the paper).
    material : str
    friction : float
        Capstan friction coefficient of the tendon on the notch edges (forward model; 0 = none).
    """

    radius_mm: float = 0.04
    length_mm: float = 70.0
    modulus_gpa: float = 28.0
    material: str = "UHMWPE"
    friction: float = 0.0

    @property
    def area_mm2(self) -> float:
        return math.pi * self.radius_mm**2


@dataclass(frozen=True)
class Rules:
    """Design-rule limits (mm unless named otherwise)."""

    min_backbone_arc_mm: float = 0.3
    min_web_mm: float = 0.1
    max_strain: float = 0.03
    max_stroke_mm: float = 2.0


@dataclass(frozen=True)
class Pattern:
    """A tube, its cuts, and the process and tendon that go with it.

    ``cuts`` are sorted by axial position, then angle. Notches come from the
    generator (see :func:`camtube.design.generate.uan`) and/or explicit lists;
    once built a pattern is plain data.
    """

    name: str
    tube: Tube
    cuts: tuple[Cut, ...]
    process: Process = field(default_factory=Process)
    tendon: Tendon = field(default_factory=Tendon)
    rules: Rules = field(default_factory=Rules)
    source: str | None = None

    @property
    def notches(self) -> tuple[Cut, ...]:
        return tuple(c for c in self.cuts if c.kind == "notch")

    @property
    def holes(self) -> tuple[Cut, ...]:
        return tuple(c for c in self.cuts if c.kind == "hole")

    @property
    def slits(self) -> tuple[Cut, ...]:
        return tuple(c for c in self.cuts if c.kind == "slit")

    def with_cuts(self, cuts) -> "Pattern":
        return replace(self, cuts=tuple(sorted(cuts, key=_cut_key)))


def _cut_key(c: Cut) -> tuple:
    return (c.x_mm, c.angle_deg, c.kind)


def sort_cuts(cuts) -> tuple[Cut, ...]:
    return tuple(sorted(cuts, key=_cut_key))
