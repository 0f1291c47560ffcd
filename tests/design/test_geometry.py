"""Joint geometry against the paper's formulae and independent numerical integration."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design import joint_geometry, load_pattern, pattern_geometry
from tests.conftest import PATTERNS

# The issue's acceptance numbers, from the paper's formulae (Table I tubes).
EXPECTED = {"tube1": (2.510, 0.464, 0.874), "tube2": (None, 0.537, 1.047), "tube3": (None, 0.772, 1.482)}


@pytest.mark.parametrize("name", sorted(EXPECTED))
def test_preset_geometry_matches_issue(name):
    g = pattern_geometry(load_pattern(PATTERNS / f"{name}.yaml")).first
    phi, ybar, arm = EXPECTED[name]
    if phi is not None:
        assert round(g.phi_rad, 3) == phi
    assert round(g.ybar_mm, 3) == ybar
    assert round(g.moment_arm_mm, 3) == arm


def _polar_grid(ro, ri, phi, n=1500):
    r = np.linspace(ri, ro, n + 1)
    t = np.linspace(-phi / 2, phi / 2, n + 1)
    rm, tm = (r[1:] + r[:-1]) / 2, (t[1:] + t[:-1]) / 2
    R, T = np.meshgrid(rm, tm)
    dA = R * (r[1] - r[0]) * (t[1] - t[0])
    return R * np.cos(T), dA  # coordinate along the backbone direction


@pytest.mark.parametrize("ro,ri,s", [(0.75, 0.45, 2.83), (1.25, 0.75, 4.71), (1.0, 0.2, 1.0), (1.0, 0.9, 5.5)])
def test_area_centroid_second_moment_by_integration(ro, ri, s):
    g = joint_geometry(ro, ri, s, 0.5)
    y, dA = _polar_grid(ro, ri, g.phi_rad)
    area = dA.sum()
    ybar = (y * dA).sum() / area
    i_c = ((y - ybar) ** 2 * dA).sum()
    assert g.area_mm2 == pytest.approx(area, rel=1e-5)
    assert g.ybar_mm == pytest.approx(ybar, rel=1e-5)
    assert g.second_moment_mm4 == pytest.approx(i_c, rel=1e-4)
    extreme = np.abs(y - ybar).max()
    assert g.extreme_fibre_mm == pytest.approx(extreme, rel=2e-3)


def test_closure_angle_and_strain():
    g = joint_geometry(0.75, 0.45, 2.83, 0.5)
    assert g.closure_angle_rad == pytest.approx(0.5 / (0.75 + g.ybar_mm))
    assert g.strain_at(0.01) == pytest.approx(g.extreme_fibre_mm * 0.01 / 0.5)
    assert g.closure_strain > g.strain_at(g.closure_angle_rad / 2)


def test_full_ring_centroid_limit():
    # a vanishing notch leaves (almost) a full ring: centroid on the axis
    g = joint_geometry(1.0, 0.5, 1e-6, 0.5)
    assert abs(g.ybar_mm) < 1e-5
    assert g.phi_rad == pytest.approx(2 * math.pi, rel=1e-6)
