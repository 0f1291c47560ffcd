"""An independent re-simulation of a pattern from the cut geometry its job produces.

Written apart from :mod:`camtube.joint.forward` and sharing none of its formulas, so a
mistake in one is not repeated in the other:

* **geometry from the job**: the job is planned and its kerf swept (:func:`camtube.cad.ascut.simulate`);
  each notch's as-cut width is the removed region's axial extent along the notch's centre line,
  and its as-cut arc the removed region's circumferential extent through the notch's middle;
* **section by numerical integration**: the backbone left at the notch (the annulus minus the
  removed angular range) is integrated on a polar grid for its area, centroid, second moment
  about its own centroid and extreme fibre (no closed-form sector formulas);
* **mechanics with exact chord geometry**: the notch's neutral fibre bends into an arc of radius
  ``R = h / theta``; the tendon, ``a`` from it on the notch side, crosses the notch as a straight chord
  of length ``2 (R - a) sin(theta / 2)``; the tendon force along that chord has the moment arm
  ``R (1 - cos(theta/2)) + a cos(theta/2)`` about the fibre's middle, and ``theta = M L / (E I)`` is
  solved notch by notch (``brentq``) with capstan friction over each notch's wrap; the bending length ``L`` is
  the hinge model's (``h`` for ``beam``; ``h`` plus the root length of :func:`camtube.joint.forward.hinge_extra_mm`
  for ``fe_fit`` and ``fe_row``, with this module's own backbone angle and as-cut webs): the one formula shared;
* the motor-side force follows from ``stroke = slack + sum (h - chord) + F C``.
* the tip direction of a several-direction (3-D) pattern composes every notch's turn with scipy's
  ``Rotation`` (:func:`tip_direction`).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camtube.design.geometry import MATERIAL_MODULUS_GPA
from camtube.design.pattern import Pattern

#: Polar grid of the section integration (radial x angular cells).
GRID_R, GRID_T = 40, 2880


@dataclass(frozen=True)
class Section:
    """Numerically integrated backbone section (mm, mm^2, mm^4)."""

    area_mm2: float
    centroid_mm: float  # distance of the centroid from the axis, towards the backbone
    second_moment_mm4: float
    extreme_fibre_mm: float


def section(outer_radius_mm: float, inner_radius_mm: float, removed_arc_mm: float) -> Section:
    """The annulus minus a removed outer-surface arc ``removed_arc_mm`` centred on angle pi, integrated on a grid.

    The backbone is centred on angle 0; bending is about the axis through its centroid, normal to the
    symmetry plane.
    """
    ro, ri = outer_radius_mm, inner_radius_mm
    half_cut = removed_arc_mm / (2.0 * ro)
    dr = (ro - ri) / GRID_R
    dt = 2.0 * math.pi / GRID_T
    r = ri + (np.arange(GRID_R) + 0.5) * dr
    t = -math.pi + (np.arange(GRID_T) + 0.5) * dt
    keep = np.abs(t) < math.pi - half_cut  # material: away from the cut centred on +-pi
    rr, tt = np.meshgrid(r, t[keep], indexing="ij")
    da = rr * dr * dt
    y = rr * np.cos(tt)  # towards the backbone
    area = float(da.sum())
    yc = float((y * da).sum() / area)
    i_c = float((((y - yc) ** 2) * da).sum())
    # extreme fibre over the true boundary (corners of the cells' outer edges)
    edge_r = np.array([ri, ro])
    tb = np.concatenate([t[keep], [math.pi - half_cut, -(math.pi - half_cut)]])
    ys = (edge_r[:, None] * np.cos(tb[None, :])).ravel()
    return Section(area, yc, i_c, float(np.max(np.abs(ys - yc))))


@dataclass(frozen=True)
class AsCutNotch:
    """One notch as the job cuts it (mm)."""

    x_mm: float
    angle_deg: float
    width_mm: float
    arc_mm: float


def as_cut_notches(pattern: Pattern, kerf_mm: float | None = None) -> tuple[AsCutNotch, ...]:
    """Every notch's as-cut width and arc, from the planned job's kerf simulation."""
    from shapely.geometry import LineString

    from camtube.cad.ascut import simulate as simulate_kerf
    from camtube.plan import plan_job

    job = plan_job(pattern)
    ac = simulate_kerf(job, kerf_mm=kerf_mm)
    out = []
    big = 10.0 * (pattern.tube.length_mm + pattern.tube.circumference_mm)
    for contour, removed in zip(job.design, ac.removed_by_cut):
        c = pattern.cuts[contour.cut_index]
        if c.kind != "notch":
            continue
        pts = np.asarray(contour.points, float)
        xc = 0.5 * (pts[:, 0].min() + pts[:, 0].max())
        yc = 0.5 * (pts[:, 1].min() + pts[:, 1].max())  # unwrapped, like the removed region
        along = removed.intersection(LineString([(xc - big, yc), (xc + big, yc)]))
        across = removed.intersection(LineString([(xc, yc - big), (xc, yc + big)]))
        out.append(AsCutNotch(c.x_mm, c.angle_deg, float(along.length), float(across.length)))
    return tuple(out)


@dataclass(frozen=True)
class Resimulated:
    """One direction re-simulated at its stroke.

    Attributes
    ----------
    angle_deg, stroke_mm : float
    bend_deg : float
        Sum of the notch angles.
    force_N : float
        Motor-side tendon force.
    max_strain : float
    notch_angles_deg : (n,) float
        Base to tip.
    """

    angle_deg: float
    stroke_mm: float
    bend_deg: float
    force_N: float
    max_strain: float
    notch_angles_deg: np.ndarray


def _notch_angle(tension: float, h: float, a: float, ei: float, length: float | None = None) -> float:
    """theta with theta E I / L = T (R (1 - cos(theta/2)) + a cos(theta/2)), R = h / theta (L: the bending
    length, h by default)."""
    from scipy.optimize import brentq

    if tension <= 0.0:
        return 0.0

    def f(th: float) -> float:
        r = h / th
        arm = r * (1.0 - math.cos(th / 2.0)) + a * math.cos(th / 2.0)
        return th * ei / (h if length is None else length) - tension * arm

    hi = 0.5
    while f(hi) < 0.0 and hi < 3.0:
        hi *= 1.5
    return float(brentq(f, 1e-12, hi, xtol=1e-14))


def resimulate(pattern: Pattern, strokes: dict[float, float], *, friction: float | None = None,
               tube_modulus_gpa: float | None = None, kerf_mm: float | None = None,
               notches: tuple[AsCutNotch, ...] | None = None, hinge: str | None = None) -> tuple[Resimulated, ...]:
    """Re-simulate each pulled direction of ``pattern`` from its as-cut notches (see the module docstring).

    Parameters
    ----------
    strokes : {angle_deg: stroke_mm}
    friction : float, optional
        Capstan coefficient (default ``pattern.tendon.friction``).
    tube_modulus_gpa : float, optional
        Default: the material's.
    kerf_mm : float, optional
        Beam kerf of the simulation (default: the process's, or the simulation's default).
    notches : optional
        As-cut notches (default: :func:`as_cut_notches`).
    hinge : str, optional
        The hinge model of the bending length (default: the forward model's default, ``Mechanics().hinge``).
    """
    from scipy.optimize import brentq

    from camtube.joint.forward import Mechanics, hinge_extra_mm

    t = pattern.tube
    td = pattern.tendon
    mu = td.friction if friction is None else friction
    e = (tube_modulus_gpa or MATERIAL_MODULUS_GPA.get(t.material, 2.5)) * 1e3
    comp = td.length_mm / (td.modulus_gpa * 1e3 * math.pi * td.radius_mm**2)
    cut = as_cut_notches(pattern, kerf_mm) if notches is None else notches
    out = []
    for ang, stroke in strokes.items():
        mine = sorted((n for n in cut if abs((n.angle_deg - ang + 180.0) % 360.0 - 180.0) < 1e-6),
                      key=lambda n: -n.x_mm)
        secs = [section(t.outer_radius_mm, t.inner_radius_mm, n.arc_mm) for n in mine]
        a = [s.centroid_mm + t.inner_radius_mm - td.radius_mm for s in secs]
        ei = [e * s.second_moment_mm4 for s in secs]
        h = [n.width_mm for n in mine]
        gaps = [abs(p.x_mm - q.x_mm) - (p.width_mm + q.width_mm) / 2.0 for p, q in zip(mine, mine[1:])]
        webs = [(gaps[k - 1] if k else math.inf, gaps[k] if k < len(gaps) else math.inf) for k in range(len(mine))]
        ln = [hk + hinge_extra_mm(t.outer_radius_mm, 2.0 * math.pi - n.arc_mm / t.outer_radius_mm,
                                  hinge or Mechanics().hinge, inner_radius_mm=t.inner_radius_mm, webs_mm=w)
              for hk, n, w in zip(h, mine, webs)]

        def angles(force: float) -> list[float]:
            tension, res = force, []
            for k in range(len(mine)):
                th = _notch_angle(tension, h[k], a[k], ei[k], ln[k])
                res.append(th)
                tension *= math.exp(-mu * th)
            return res

        def travel(force: float) -> float:
            th = angles(force)
            short = sum(hk - 2.0 * (hk / x - ak) * math.sin(x / 2.0) if x > 1e-12 else ak * x
                        for hk, ak, x in zip(h, a, th))
            return short + comp * force - stroke

        hi = 1.0
        while travel(hi) < 0.0:
            hi *= 2.0
        f = float(brentq(travel, 0.0, hi, xtol=1e-12))
        th = np.array(angles(f))
        strain = max(s.extreme_fibre_mm * x / lk for s, x, lk in zip(secs, th, ln))
        out.append(Resimulated(ang, stroke, math.degrees(float(th.sum())), f, float(strain), np.degrees(th)))
    return tuple(out)


def tip_direction(pattern: Pattern, results: tuple[Resimulated, ...],
                  notches: tuple[AsCutNotch, ...] | None = None) -> np.ndarray:
    """Unit tip direction (tube frame: ``z`` along the straight tube from the base) of the re-simulated notch angles.

    Every notch, base to tip, turns the tube's own frame about ``z x u`` (``u`` the notch's side in that frame) by
    its angle; the rotations are composed with ``scipy.spatial.transform.Rotation`` (not the forward model's
    chain). Directions not in ``results`` do not bend.
    """
    from scipy.spatial.transform import Rotation

    cut = as_cut_notches(pattern) if notches is None else notches
    turns = []
    for r in results:
        mine = sorted((n for n in cut if abs((n.angle_deg - r.angle_deg + 180.0) % 360.0 - 180.0) < 1e-6),
                      key=lambda n: -n.x_mm)
        turns += [(n.x_mm, n.angle_deg, th) for n, th in zip(mine, r.notch_angles_deg)]
    rot = Rotation.identity()
    for _, ang, th in sorted(turns, key=lambda t: -t[0]):
        a = math.radians(ang)
        rot = rot * Rotation.from_rotvec(np.array([-math.sin(a), math.cos(a), 0.0]) * math.radians(th))
    return rot.apply([0.0, 0.0, 1.0])
