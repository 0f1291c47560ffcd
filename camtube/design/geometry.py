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


def tendon_compliance_mm_per_N(length_mm: float, modulus_gpa: float, radius_mm: float) -> float:
    """Tendon compliance ``C = L0 / (E_t pi r_t^2)`` in mm/N (E_t in GPa = 1e3 N/mm^2)."""
    return float(length_mm) / (float(modulus_gpa) * 1e3 * math.pi * float(radius_mm) ** 2)


def notches_by_direction(pattern: Pattern) -> list[tuple[float, list]]:
    """``(direction deg in [0, 360), its notches)`` per bending direction, by direction.

    Each direction has its own tendon, which pulls only its own notches.
    """
    groups: dict[float, list] = {}
    for n in pattern.notches:
        groups.setdefault(round(n.angle_deg % 360.0, 9), []).append(n)
    return sorted(groups.items())


#: Young's modulus (GPa) of tube materials, for the bending stiffness of the backbone.
#: Polyimide: 2.5 GPa, a typical figure for polyimide tubing (the source paper does not give one).
MATERIAL_MODULUS_GPA = {"polyimide": 2.5}


@dataclass(frozen=True)
class DirectionBend:
    """How the notches of one bending direction behave at a given tendon stroke (base model, stroke only).

    The tendon of a direction bends its notches in series: moment M = F arm, notch i bends
    theta_i = M h_i / (E I_i); the stroke is arm * theta + F L0 / (E_t pi r_t^2).

    Attributes
    ----------
    angle_deg : float
        Direction (rotary angle of the notch centres).
    notches : int
        Notches in this direction.
    stroke_mm : float
        The tendon stroke analysed (``rules.max_stroke``).
    bend_rad : float
        Joint bend of this direction at ``stroke_mm``.
    strain : float
        Largest backbone strain of its notches at that bend.
    elastic_bend_rad, elastic_stroke_mm : float
        Largest bend (and the stroke that gives it) with every notch within ``strain_limit``.
    closure_rad : float
        Bend at which every notch of the direction is closed (sum of h / (r_o + ybar)).
    closing_stroke_mm : float
        Stroke at which the first notch closes (inf if never within the analysis).
    strain_limit : float
        The material's elastic strain limit used (``rules.max_strain``).
    """

    angle_deg: float
    notches: int
    stroke_mm: float
    bend_rad: float
    strain: float
    elastic_bend_rad: float
    elastic_stroke_mm: float
    closure_rad: float
    closing_stroke_mm: float
    strain_limit: float

    @property
    def closes(self) -> bool:
        """True when a notch closes before ``stroke_mm`` is reached."""
        return self.closing_stroke_mm < self.stroke_mm


def bends_at_stroke(pattern: Pattern, stroke_mm: float | None = None,
                    modulus_gpa: float | None = None) -> tuple[DirectionBend, ...]:
    """Per bending direction: the bend, strain and notch closure at ``stroke_mm`` (default ``rules.max_stroke``).

    Returns ``()`` when the pattern has no notches or the tube material has no known modulus
    (:data:`MATERIAL_MODULUS_GPA`) and none is given.
    """
    t = pattern.tube
    e_gpa = modulus_gpa if modulus_gpa is not None else MATERIAL_MODULUS_GPA.get(t.material)
    if e_gpa is None or not pattern.notches:
        return ()
    e = e_gpa * 1e3  # N/mm^2
    stroke = pattern.rules.max_stroke_mm if stroke_mm is None else stroke_mm
    td = pattern.tendon
    compliance = tendon_compliance_mm_per_N(td.length_mm, td.modulus_gpa, td.radius_mm)
    out = []
    for ang, notches in notches_by_direction(pattern):
        geos = [joint_geometry(t.outer_radius_mm, t.inner_radius_mm, n.arc_mm, n.width_mm, td.radius_mm)
                for n in notches]
        arm = geos[0].moment_arm_mm
        flex = [g.notch_width_mm / (e * g.second_moment_mm4) for g in geos]  # rad per N mm
        k = 1.0 / sum(flex)
        per_rad = arm + k * compliance / arm  # stroke per rad of bend
        bend = stroke / per_rad
        moment = k * bend
        strain = max(g.extreme_fibre_mm * moment * f / g.notch_width_mm for g, f in zip(geos, flex))
        scale = pattern.rules.max_strain / strain if strain > 0 else math.inf
        close_moment = min(g.closure_angle_rad / f for g, f in zip(geos, flex))
        out.append(DirectionBend(
            angle_deg=ang, notches=len(notches), stroke_mm=stroke, bend_rad=bend, strain=strain,
            elastic_bend_rad=bend * scale, elastic_stroke_mm=stroke * scale,
            closure_rad=sum(g.closure_angle_rad for g in geos),
            closing_stroke_mm=close_moment / k * per_rad, strain_limit=pattern.rules.max_strain))
    return tuple(out)
