"""The time-optimal bound of a job on a machine: stop at every true corner, nowhere else.

Beside the lower bound (cut length / scan speed), which no machine reaches, this is
the time of the fastest motion a machine with the profile's limits could make along
the job's paths when it must come to rest at every true corner (a turn above
``TOL.corner_deg``) and at both ends of every beam-on run (a pass, or a chain of
passes joined by beam-on links, whose turns are taken at the speed their
curvature allows like any other vertex), and may run anywhere else as
fast as the scan speed, its axes' velocity limits and the path's curvature allow:

- along a chord of direction ``t`` the speed changes at most at
  ``min_i a_i / |t_i|`` (the largest acceleration along ``t`` the axis limits allow);
- at a vertex inside a tangent-continuous run, turning by ``phi`` between chords
  ``L1`` and ``L2`` (curvature ``phi / ((L1 + L2) / 2)``), the speed is at most
  ``sqrt(a_n rho)``, ``a_n`` the largest acceleration the axes allow along the
  vertex's normal;
- rapid and focus moves are straight moves from rest to rest at the axes' limits.

Tangential and normal acceleration are bounded separately (each may use the axes'
whole limit), which makes the figure a bound: no motion obeying the limits and the
stops is faster. Lengths on the outer surface (mm); a rotary axis' limits become
surface limits ``radians(limit) r_o``. Times in s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camtube.plan.moves import CUT, FOCUS, LEAD, LINK, RAPID, iter_moves
from camtube.tol import TOL


def surface_limits(profile, outer_radius_mm: float) -> tuple[np.ndarray, np.ndarray]:
    """((3,) velocity mm/s, (3,) acceleration mm/s^2) of the axial, circumferential and focus axes on the surface."""
    v, a = [], []
    for k, letter in enumerate(profile.axes):
        lim = profile.axis(letter)
        f = math.radians(1.0) * outer_radius_mm if (k == 1 and profile.rotary) else 1.0
        v.append(lim.max_velocity * f)
        a.append(lim.max_acceleration * f)
    return np.array(v), np.array(a)


def _along(limits: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(m,) the largest magnitude along unit directions ``u`` (m, k) that per-axis ``limits`` (k,) allow."""
    with np.errstate(divide="ignore"):
        r = np.where(np.abs(u) > 1e-12, limits[None, :] / np.abs(u), np.inf)
    return r.min(axis=1)


def _trapezoids(L, v0, v1, vmax, a) -> np.ndarray:
    vp = np.sqrt(np.maximum(a * L + 0.5 * (v0 * v0 + v1 * v1), 0.0))
    vc = np.minimum(vp, vmax)
    with np.errstate(divide="ignore", invalid="ignore"):
        cruise = np.maximum(L - (vc * vc - v0 * v0) / (2 * a) - (vc * vc - v1 * v1) / (2 * a), 0.0)
        t = (vc - v0) / a + (vc - v1) / a + np.where(vc > 0, cruise / vc, 0.0)
    return np.where(L > 0, t, 0.0)


def design_corners(job, corner_deg: float = TOL.corner_deg) -> np.ndarray:
    """(c, 2) float: the true corners of the job's design cuts (vertices turning by more than ``corner_deg``).

    Read on the design contours, whose curves are flattened finely (``TOL.chord``): there a curve
    turns by a fraction of a degree per vertex and only drawn corners turn more; the pass paths'
    chords (``TOL.path``) turn by more along a tight curve and cannot tell the two apart.
    """
    from camtube.plan.paths import turn_angles_deg

    out = [np.asarray(c.points, float)[turn_angles_deg(c.points, c.closed) > corner_deg] for c in job.design]
    return np.concatenate(out) if out else np.zeros((0, 2))


def _corner_flags(px, py, corners: np.ndarray, reach: np.ndarray) -> np.ndarray:
    """(m,) bool: the points lie within ``reach`` of a design corner (a pass's inward offset moves it)."""
    if len(corners) == 0 or len(px) == 0:
        return np.zeros(len(px), bool)
    from scipy.spatial import cKDTree

    dist, _ = cKDTree(corners).query(np.column_stack([px, py]))
    return dist <= reach


@dataclass(frozen=True)
class OptimalTime:
    """The time-optimal bound of a job on a machine, in parts (s).

    Attributes
    ----------
    path_s : float
        Along the passes' paths (stops at true corners and pass ends, curvature-limited).
    free_s : float
        Rapid and focus moves, each from rest to rest.
    stops : int
        Stops along the paths (true corners and the ends of beam-on runs: a pass, or a chain of linked
        passes).
    """

    path_s: float
    free_s: float
    stops: int

    @property
    def total_s(self) -> float:
        return self.path_s + self.free_s


def true_corner_flags(points, corners: np.ndarray, offset_mm: float = 0.0) -> np.ndarray:
    """(k,) bool: the vertices of a pass path (moved ``offset_mm`` inward) that are true corners of the drawing."""
    p = np.asarray(points, float).reshape(-1, 2)
    return _corner_flags(p[:, 0], p[:, 1], corners, math.sqrt(2.0) * offset_mm + TOL.path + TOL.safety)


def time_optimal_s(job, profile, corner_deg: float = TOL.corner_deg) -> float:
    """The time-optimal bound (s) of ``job`` on ``profile`` (module docstring; :func:`time_optimal`)."""
    return time_optimal(job, profile, corner_deg).total_s


def time_optimal(job, profile, corner_deg: float = TOL.corner_deg) -> OptimalTime:
    """The time-optimal bound of ``job`` on ``profile`` (module docstring), in parts.

    Parameters
    ----------
    job : camtube.plan.Job
    profile : camtube.machine.MachineProfile
    corner_deg : float
        Turns above this (deg) are true corners, where the motion stops.
    """
    vlim, alim = surface_limits(profile, job.outer_radius_mm)
    corners = design_corners(job, corner_deg)
    offsets = job.packed.pass_offset
    path_s = free_s = 0.0
    stops = 0
    cos_corner = math.cos(math.radians(corner_deg))
    for mv in iter_moves(job):
        x0, y0, z0 = mv.starts()
        d = np.column_stack([mv.x - x0, mv.y - y0, mv.z - z0])
        L = np.linalg.norm(d, axis=1)
        ok = L > 1e-12
        u = np.zeros_like(d)
        u[ok] = d[ok] / L[ok, None]
        free = (mv.kind == RAPID) | (mv.kind == FOCUS)
        vmax = _along(vlim, u)
        a = _along(alim, u)
        free_s += float(_trapezoids(L[free & ok], 0.0, 0.0, vmax[free & ok], a[free & ok]).sum())
        path = ((mv.kind == CUT) | (mv.kind == LEAD) | (mv.kind == LINK)) & ok
        idx = np.flatnonzero(path)
        if len(idx) == 0:
            continue
        vcap = np.minimum(vmax[idx], mv.speed[idx])
        # junction after path row k (to row k + 1): consecutive rows of the same pass (or of a chain of linked
        # passes: the next row is a link), turn below the corner angle
        nxt = np.concatenate((idx[1:], [-1]))
        nn = np.maximum(nxt, 0)
        same = (nxt == idx + 1) & ((mv.pass_index[nn] == mv.pass_index[idx]) | (mv.kind[nn] == LINK)) & (nxt >= 0)
        ua, ub = u[idx], u[np.maximum(nxt, 0)]
        cosphi = np.clip(np.einsum("ij,ij->i", ua, ub), -1.0, 1.0)
        reach = math.sqrt(2.0) * offsets[mv.pass_index[idx]] + TOL.path + TOL.safety
        smooth = same & ~(_corner_flags(mv.x[idx], mv.y[idx], corners, reach) & (cosphi < cos_corner))
        phi = np.arccos(cosphi)
        Lb = L[np.maximum(nxt, 0)]
        with np.errstate(divide="ignore", invalid="ignore"):
            rho = np.where(phi > 1e-12, 0.5 * (L[idx] + Lb) / phi, np.inf)
            normal = ub - ua
            nn = np.linalg.norm(normal, axis=1)
            normal = np.where(nn[:, None] > 1e-15, normal / np.where(nn > 1e-15, nn, 1.0)[:, None], 0.0)
            a_n = np.where(nn > 1e-15, _along(alim, normal), np.inf)
            v_curve = np.sqrt(a_n * rho)
        vnext = np.concatenate((vcap[1:], [0.0]))
        vj = np.where(smooth, np.minimum(np.minimum(vcap, vnext), v_curve), 0.0).tolist()
        Ll, al = L[idx].tolist(), a[idx].tolist()
        m = len(idx)
        nxt_v = 0.0
        for i in range(m - 1, -1, -1):  # backward: able to slow down for what follows
            if vj[i] > 0:
                vj[i] = min(vj[i], math.sqrt(nxt_v * nxt_v + 2 * al[i + 1] * Ll[i + 1]))
            nxt_v = vj[i]
        prev = 0.0
        for i in range(m):  # forward: able to reach it
            if vj[i] > 0:
                vj[i] = min(vj[i], math.sqrt(prev * prev + 2 * al[i] * Ll[i]))
            prev = vj[i]
        v1 = np.array(vj)
        v0 = np.concatenate(([0.0], v1[:-1]))
        path_s += float(_trapezoids(L[idx], v0, v1, vcap, a[idx]).sum())
        stops += int(np.count_nonzero(~smooth))
    return OptimalTime(path_s, free_s, stops)
