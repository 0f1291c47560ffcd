"""Finite-element check of one notch: its bending stiffness and closure angle (scikit-fem, 3-D elasticity).

The model: a tube segment (r_i..r_o) of length ``lead + h + lead`` with one notch (arc ``s`` on the
outer surface, width ``h``, radial walls, centred on angle pi) in the middle, meshed with quadratic
tetrahedra (a structured grid in ``(r, angle, z)`` mapped to the cylinder, every cell split into six
tetrahedra, the grid lines on the notch's edges). The base face ``z = 0`` is clamped; the far face
carries the linear axial traction of a pure bending moment ``M`` about the axis normal to the notch's
plane of symmetry (exact for the plain tube, so the load causes no end disturbance).

From the solution:

* the far face's rotation ``phi`` (least-squares plane through its axial displacements);
* the notch's own rotation ``theta_n = phi - M (L - h) / (E I_tube)``: the plain tube's share is
  taken off (whatever the notch disturbs in the webs next to it stays with the notch);
* stiffness ``K_fe = M / theta_n`` (N mm/rad), to compare with the model's ``E I_backbone / h``;
* closure angle ``h theta / d_gap`` (of the middle notch, ``theta`` its own rotation below), where ``d_gap`` is how much the notch's gap at its mouth (angle pi,
  outer surface) shrinks: the notch closes when the mouth does; the model's is ``h / (r_o + ybar)``.

In a row (``count > 1``) each notch's own rotation is measured too: the rotation (least-squares plane) of the
cross-section in the middle of the web on each side (the clamped base and the loaded far face for the end
notches), minus the plain tube's share of the half-webs (and lead) between those sections. The middle
notch of a row of five is how a notch sits inside a pattern; the end notches, with plain tube on one side, are
softer.

scikit-fem is needed (``pip install scikit-fem``, in the ``test`` extra); it is imported only here.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camtube.design.geometry import joint_geometry


@dataclass(frozen=True)
class NotchFE:
    """FE result for one notch, beside the model's values.

    Attributes
    ----------
    stiffness_nmm_per_rad, model_stiffness_nmm_per_rad : float
        Notch bending stiffness from the FE model and from ``E I / h``.
    closure_deg, model_closure_deg : float
        Notch closure angle from the FE model and from ``h / (r_o + ybar)``.
    dofs : int
        Unknowns of the FE model.
    per_notch_nmm_per_rad : tuple[float, ...]
        Each notch's own stiffness (base to far end; one entry for a lone notch).
    widths_mm : tuple[float, ...]
        Each notch's width h (base to far end).
    per_notch_closure_deg : tuple[float, ...]
        Each notch's closure angle (``closure_deg`` is the middle one's).
    """

    outer_radius_mm: float
    inner_radius_mm: float
    arc_mm: float
    width_mm: float
    stiffness_nmm_per_rad: float
    model_stiffness_nmm_per_rad: float
    closure_deg: float
    model_closure_deg: float
    dofs: int
    per_notch_nmm_per_rad: tuple[float, ...] = ()
    widths_mm: tuple[float, ...] = ()
    per_notch_closure_deg: tuple[float, ...] = ()

    @property
    def middle_nmm_per_rad(self) -> float:
        """Stiffness of the middle notch of the row (of the notch, alone)."""
        return self.per_notch_nmm_per_rad[len(self.per_notch_nmm_per_rad) // 2]

    @property
    def stiffness_error(self) -> float:
        """(model - FE) / FE."""
        return self.model_stiffness_nmm_per_rad / self.stiffness_nmm_per_rad - 1.0

    @property
    def closure_error(self) -> float:
        return self.model_closure_deg / self.closure_deg - 1.0


def _axis(lo: float, hi: float, n: int) -> np.ndarray:
    return np.linspace(lo, hi, max(int(n), 1) + 1)


def notch_fe(outer_radius_mm: float, inner_radius_mm: float, arc_mm, width_mm,
             modulus_gpa: float = 2.5, poisson: float = 0.34, *, n_r: int = 2, n_backbone: int = 20,
             n_cut: int = 12, n_lead: int = 8, n_notch: int = 4, lead_mm: float | None = None,
             count: int = 1, web_mm: float = 0.5, n_web: int = 4, angles_deg=None) -> NotchFE:
    """Bending stiffness and closure angle of one notch by 3-D finite elements (see the module docstring).

    Parameters
    ----------
    outer_radius_mm, inner_radius_mm : float
        Tube.
    arc_mm : float or sequence of float
        The notch's arc on the outer surface, or each notch's (base to far end, as many as ``width_mm``'s).
    width_mm : float or sequence of float
        Axial width h of the notch, or of each notch of the row (base to far end; its length sets ``count``).
    modulus_gpa, poisson : float
        Tube material (2.5 GPa, 0.34: polyimide).
    n_r, n_backbone, n_cut, n_lead, n_notch : int
        Grid cells through the wall, around the backbone, around the cut, along each lead and along the notch.
    lead_mm : float, optional
        Plain tube on each side of the notch (default ``2 r_o``).
    count, web_mm, n_web : int, float, int
        A row of ``count`` equal notches ``web_mm`` apart (edge to edge, ``n_web`` cells per web), as in a
        pattern: the stiffness and closure are then per notch (the row's rotation over ``count``), so the
        webs' share of the compliance (which a single notch between long leads does not see) is counted;
        ``per_notch_nmm_per_rad`` holds each notch's own (the web's middle always gets a grid plane).
    angles_deg : sequence of 180 or 0, optional
        Each notch's side (default all 180: the notches the moment closes); a notch at 0 is cut on the backbone
        side of the others (an alternating two-direction pattern; the moment opens it: the same stiffness, no
        closure angle, nan).
    """
    import skfem
    from skfem.helpers import ddot, sym_grad, trace
    from skfem.models.elasticity import lame_parameters

    ro, ri = outer_radius_mm, inner_radius_mm
    if np.ndim(width_mm):
        hs = [float(x) for x in width_mm]
        count = len(hs)
    else:
        hs = [float(width_mm)] * count
    h = float(np.mean(hs))
    lead = 2.0 * ro if lead_mm is None else lead_mm
    arcs = [float(x) for x in arc_mm] if np.ndim(arc_mm) else [float(arc_mm)] * count
    if len(arcs) != count:
        raise ValueError(f"{len(arcs)} arcs for {count} notches")
    halves = []  # half-angle of each cut, centred on pi; cuts within 5 mrad share one (no sliver cells)
    for a in arcs:
        hf = a / (2.0 * ro)
        halves.append(next((x for x in halves if abs(x - hf) < 5e-3), hf))
    half = max(halves)
    sides = [180.0] * count if angles_deg is None else [float(a) % 360.0 for a in angles_deg]
    if len(sides) != count or any(a not in (0.0, 180.0) for a in sides):
        raise ValueError("angles_deg: one 0 or 180 per notch")
    back = [x for x, a in zip(halves, sides) if a == 0.0]  # cuts centred on angle 0
    e = modulus_gpa * 1e3
    r_nodes = _axis(ri, ro, n_r)
    t_nodes = np.unique(np.concatenate([
        _axis(-math.pi, -math.pi + half, max(2, n_cut // 2)),
        _axis(-math.pi + half, math.pi - half, n_backbone),
        _axis(math.pi - half, math.pi, max(2, n_cut // 2)),
        [math.pi - x for x, a in zip(halves, sides) if a == 180.0],
        [x - math.pi for x, a in zip(halves, sides) if a == 180.0],
        _axis(-max(back), max(back), n_cut) if back else [], back, [-x for x in back]]))  # lines on the cuts' edges
    starts = list(lead + np.concatenate([[0.0], np.cumsum(np.array(hs[:-1]) + web_mm)]))  # base-side edges
    length = 2.0 * lead + sum(hs) + (count - 1) * web_mm
    z_parts = [_axis(0.0, lead, n_lead), _axis(starts[-1] + hs[-1], length, n_lead)]
    mids = [0.0]  # cross-sections between the notches: the base, the webs' middles, the far face
    for k, z0 in enumerate(starts):
        z_parts.append(_axis(z0, z0 + hs[k], n_notch))
        if k + 1 < count:
            z_parts.append(_axis(z0 + hs[k], z0 + hs[k] + web_mm, n_web))
            mids.append(z0 + hs[k] + web_mm / 2.0)
            z_parts.append(np.array([mids[-1]]))
    mids.append(length)
    z_nodes = np.unique(np.round(np.concatenate(z_parts), 9))  # no near-duplicate planes where parts meet
    box = skfem.MeshTet.init_tensor(r_nodes, t_nodes, z_nodes)
    p, t = box.p.copy(), box.t.copy()
    # cells of the notch: z inside the notch and angle within the cut (near +-pi)
    c = p[:, t].mean(axis=1)
    in_notch = np.zeros(t.shape[1], bool)
    for z0, hk, hf, a in zip(starts, hs, halves, sides):
        across = (np.abs(c[1]) > math.pi - hf) if a == 180.0 else (np.abs(c[1]) < hf)
        in_notch |= (c[2] > z0) & (c[2] < z0 + hk) & across
    t = t[:, ~in_notch]
    # close the seam: nodes at angle +pi are the nodes at -pi
    seam = np.isclose(p[1], math.pi)
    partner = np.arange(p.shape[1])
    key = {(round(p[0, i], 9), round(p[2, i], 9)): i for i in np.flatnonzero(np.isclose(p[1], -math.pi))}
    for i in np.flatnonzero(seam):
        partner[i] = key[(round(p[0, i], 9), round(p[2, i], 9))]
    t = partner[t]
    used = np.unique(t)
    remap = -np.ones(p.shape[1], int)
    remap[used] = np.arange(used.size)
    rr, tt, zz = p[0, used], p[1, used], p[2, used]
    xyz = np.vstack([rr * np.cos(tt), rr * np.sin(tt), zz])  # x towards the backbone (angle 0)
    mesh = skfem.MeshTet(xyz, remap[t])
    elem = skfem.ElementVector(skfem.ElementTetP2())
    basis = skfem.Basis(mesh, elem, intorder=3)
    lam, mu = lame_parameters(e, poisson)

    @skfem.BilinearForm
    def stiffness(u, v, w):
        eps_u, eps_v = sym_grad(u), sym_grad(v)
        return 2.0 * mu * ddot(eps_u, eps_v) + lam * trace(eps_u) * trace(eps_v)

    i_tube = math.pi / 4.0 * (ro**4 - ri**4)
    moment = 1.0  # N mm; linear: any value

    far = mesh.facets_satisfying(lambda x: np.isclose(x[2], length))
    fbasis = skfem.FacetBasis(mesh, elem, facets=far, intorder=4)

    @skfem.LinearForm
    def traction(v, w):
        # axial stress M x / I: tension on the backbone side, compression on the notch side
        return moment * w.x[0] / i_tube * v[2]

    a = stiffness.assemble(basis)
    b = traction.assemble(fbasis)
    fixed = basis.get_dofs(lambda x: np.isclose(x[2], 0.0)).all()
    u = skfem.solve(*skfem.condense(a, b, D=fixed))
    # nodal displacements (vertex dofs come first in the P2 basis)
    uz = u[basis.nodal_dofs[2]]
    pts = mesh.p

    def rotation(z: float) -> float:
        """du_z/dx of the least-squares plane through the section at ``z``: its rotation about y (rad)."""
        on = np.isclose(pts[2], z)
        g = np.c_[np.ones(on.sum()), pts[0, on], pts[1, on]]
        return float(np.linalg.lstsq(g, uz[on], rcond=None)[0][1])

    rot = [rotation(z) for z in mids]
    phi = rot[-1]  # the far face
    theta_n = (phi - moment * (length - sum(hs)) / (e * i_tube)) / count  # per notch
    per_notch = tuple(moment / (rot[k + 1] - rot[k] - moment * (mids[k + 1] - mids[k] - hs[k]) / (e * i_tube))
                      for k in range(count))
    mouth = np.isclose(np.hypot(pts[0], pts[1]), ro) & np.isclose(np.abs(np.arctan2(pts[1], pts[0])), math.pi, atol=1e-9)
    # each gap shrinks by this much (mean over the row's notches)
    # closure of each notch: h times its own rotation over its gap's shrinkage at the mouth
    closures = tuple(math.degrees(hk * (moment / kk) / (uz[mouth & np.isclose(pts[2], z0)].mean()
                                                        - uz[mouth & np.isclose(pts[2], z0 + hk)].mean()))
                     if a == 180.0 else math.nan for z0, hk, kk, a in zip(starts, hs, per_notch, sides))
    mid = count // 2
    hm = hs[mid]
    g_model = joint_geometry(ro, ri, arcs[mid], hm)
    return NotchFE(ro, ri, arcs[mid], hm, moment / theta_n, e * g_model.second_moment_mm4 / hm,
                   closures[mid], math.degrees(g_model.closure_angle_rad),
                   int(basis.N), per_notch, tuple(hs), closures)
