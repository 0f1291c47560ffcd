"""Joint geometry of a notched section: phi, ybar, moment arm, area, second moment.

Cross-section at a notch: the backbone is the annular sector that remains,
of angle ``phi = (2 pi r_o - s) / r_o`` (rad), symmetric about the backbone
direction. ``ybar`` is the distance from the tube axis to the backbone's
centroid (towards the backbone); the tendon runs inside the lumen on the notch
side at ``r_i - r_t`` from the axis, so the moment arm of the tendon about the
backbone's neutral axis is ``ybar + r_i - r_t``.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from camtube.design.pattern import Pattern


def backbone_angle_rad(outer_radius_mm: float, arc_mm: float) -> float:
    """phi = (2 pi r_o - s) / r_o, the angle of the material left (rad)."""
    return (2.0 * math.pi * outer_radius_mm - arc_mm) / outer_radius_mm


def centroid_mm(outer_radius_mm: float, inner_radius_mm: float, phi_rad: float) -> float:
    """ybar = 4 sin(phi/2) (r_o^3 - r_i^3) / (3 phi (r_o^2 - r_i^2))."""
    ro, ri = outer_radius_mm, inner_radius_mm
    return 4.0 * math.sin(phi_rad / 2.0) * (ro**3 - ri**3) / (3.0 * phi_rad * (ro**2 - ri**2))


@dataclass(frozen=True)
class JointGeometry:
    """Derived geometry of one notch (all notches of a UAN pattern share it).

    Attributes
    ----------
    phi_rad : float
        Backbone angle.
    ybar_mm : float
        Backbone centroid distance from the axis.
    moment_arm_mm : float
        ybar + r_i - r_t.
    area_mm2 : float
        Backbone cross-section area, phi/2 (r_o^2 - r_i^2).
    second_moment_mm4 : float
        Second moment of area of the backbone about its own centroidal
        (neutral) axis, perpendicular to the plane of bending.
    extreme_fibre_mm : float
        Largest distance of backbone material from the neutral axis.
    closure_angle_rad : float
        Bend at which one notch closes: h / (r_o + ybar).
    notch_width_mm : float
        h of the notch this geometry was computed for.
    """

    outer_radius_mm: float
    inner_radius_mm: float
    tendon_radius_mm: float
    notch_width_mm: float
    arc_mm: float
    phi_rad: float
    ybar_mm: float
    moment_arm_mm: float
    area_mm2: float
    second_moment_mm4: float
    extreme_fibre_mm: float
    closure_angle_rad: float

    def strain_at(self, notch_angle_rad: float) -> float:
        """Peak backbone strain when one notch bends by ``notch_angle_rad``.

        The notch's backbone of length h bends to curvature theta / h, so
        strain = extreme_fibre * theta / h (dimensionless).
        """
        return self.extreme_fibre_mm * notch_angle_rad / self.notch_width_mm

    @property
    def closure_strain(self) -> float:
        """Peak backbone strain when the notch closes."""
        return self.strain_at(self.closure_angle_rad)


def joint_geometry(
    outer_radius_mm: float,
    inner_radius_mm: float,
    arc_mm: float,
    notch_width_mm: float,
    tendon_radius_mm: float = 0.04,
) -> JointGeometry:
    """Geometry of one notch of arc ``s`` and width ``h`` in a tube (r_o, r_i)."""
    ro, ri = outer_radius_mm, inner_radius_mm
    phi = backbone_angle_rad(ro, arc_mm)
    ybar = centroid_mm(ro, ri, phi)
    area = phi / 2.0 * (ro**2 - ri**2)
    # second moment about the axis through the tube centre, then parallel-axis shift
    i_axis = (ro**4 - ri**4) / 8.0 * (phi + math.sin(phi))
    i_c = i_axis - area * ybar**2
    half = phi / 2.0
    y_min = ri * math.cos(half) if half <= math.pi / 2 else ro * math.cos(half)
    extreme = max(ro - ybar, ybar - y_min)
    closure = notch_width_mm / (ro + ybar)
    return JointGeometry(
        outer_radius_mm=ro,
        inner_radius_mm=ri,
        tendon_radius_mm=tendon_radius_mm,
        notch_width_mm=notch_width_mm,
        arc_mm=arc_mm,
        phi_rad=phi,
        ybar_mm=ybar,
        moment_arm_mm=ybar + ri - tendon_radius_mm,
        area_mm2=area,
        second_moment_mm4=i_c,
        extreme_fibre_mm=extreme,
        closure_angle_rad=closure,
    )


@dataclass(frozen=True)
class PatternGeometry:
    """Geometry of a whole pattern: per-notch geometry plus totals.

    Attributes
    ----------
    notches : tuple[JointGeometry, ...]
        One per notch, in axial order.
    total_closure_angle_rad : float
        Sum of the per-notch closure angles (joint angle when all notches close).
    notched_length_mm : float
        Sum of notch widths (length of tube that bends).
    """

    notches: tuple[JointGeometry, ...]
    tube_length_mm: float
    total_closure_angle_rad: float
    notched_length_mm: float

    @property
    def first(self) -> JointGeometry:
        return self.notches[0]

    @property
    def uniform(self) -> bool:
        """True when every notch has the same cross-section (phi and h)."""
        a = self.notches[0]
        return all(
            abs(n.phi_rad - a.phi_rad) < 1e-12 and abs(n.notch_width_mm - a.notch_width_mm) < 1e-12
            for n in self.notches
        )


def pattern_geometry(pattern: Pattern) -> PatternGeometry:
    """Per-notch geometry of ``pattern`` (needs at least one notch)."""
    t = pattern.tube
    rt = pattern.tendon.radius_mm
    per = tuple(
        joint_geometry(t.outer_radius_mm, t.inner_radius_mm, n.arc_mm, n.width_mm, rt)
        for n in pattern.notches
    )
    if not per:
        raise ValueError("pattern has no notches: joint geometry is undefined")
    return PatternGeometry(
        notches=per,
        tube_length_mm=t.length_mm,
        total_closure_angle_rad=sum(g.closure_angle_rad for g in per),
        notched_length_mm=sum(g.notch_width_mm for g in per),
    )


def beam_depth_mm(outer_radius_mm: float, arc_mm: float) -> float:
    """Depth the beam must cut through to open a notch of arc ``s``.

    Measured along the beam from the top of the tube (the beam's entry) to the
    deepest point that must be removed: the chord that bounds the backbone,
    ``r_o (1 - cos(s / 2 r_o))``. Wall thickness alone cannot rank the paper's
    tubes (tubes 1 and 2 share a 0.30 mm wall yet need 4 vs 6 repeats): what
    grows from tube to tube is how deep the notch reaches into the tube, and
    with it how far the ablation front must travel and how much debris must
    escape through the narrowing kerf.
    """
    return outer_radius_mm * (1.0 - math.cos(arc_mm / (2.0 * outer_radius_mm)))
