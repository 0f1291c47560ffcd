"""Design mesh (manifold3d): watertight, volume, backbone angle from trimesh sections, frame."""
from __future__ import annotations

import math

import numpy as np
import trimesh

from camtube.cad.mesh import design_mesh, stl_bytes, tube_mesh
from camtube.design.contour import Contour, rectangle
from tests.cad.conftest import analytic_volume, mesh_of, preset


def _material_angles(mesh, x):
    """Sorted angles (rad) of the section x = const's vertices (trimesh section, not camtube.cad.measure)."""
    sec = mesh.section(plane_origin=[x, 0.0, 0.0], plane_normal=[1.0, 0.0, 0.0])
    v = np.asarray(sec.vertices)
    return np.sort(np.mod(np.arctan2(v[:, 2], v[:, 1]), 2 * math.pi)), v


def test_presets_watertight_volume_and_phi(preset_name):
    p = preset(preset_name)
    m = mesh_of(preset_name)
    assert m.is_watertight and m.is_winding_consistent
    assert abs(m.volume / analytic_volume(p) - 1) < 0.005
    ro = p.tube.outer_radius_mm
    for c in p.notches:
        a, v = _material_angles(m, c.x_mm)
        gaps = np.diff(np.concatenate([a, [a[0] + 2 * math.pi]]))
        phi = 2 * math.pi - gaps.max()
        want = (2 * math.pi * ro - c.arc_mm) / ro
        assert abs(phi / want - 1) < 0.01, (c, phi, want)
        # the gap is centred on the notch angle
        k = int(np.argmax(gaps))
        centre = (a[k] + gaps[k] / 2) % (2 * math.pi)
        assert abs(math.remainder(centre - math.radians(c.angle_deg), 2 * math.pi)) < 1e-6
        r = np.hypot(v[:, 1], v[:, 2])
        assert r.min() > p.tube.inner_radius_mm * 0.999 and r.max() < ro * 1.0001


def test_frame_angle_origin_and_direction():
    """Rotary angle 0 is +Y and 90 deg is +Z; x = 0 at the tip."""
    p = preset("tube1", "notch.angle_deg=90", "holes.0.angle_deg=90")
    m = design_mesh(p)
    assert np.allclose(m.bounds[:, 0], [0.0, p.tube.length_mm])
    c = p.notches[0]
    a, _ = _material_angles(m, c.x_mm)
    assert not np.any((a > math.radians(60)) & (a < math.radians(120)))  # +Z side is removed
    assert np.any((a > math.radians(250)) & (a < math.radians(290)))  # -Z side has material


def test_stl_round_trip_and_deterministic(tmp_path):
    p = preset("tube2")
    data = stl_bytes(design_mesh(p))
    assert data == stl_bytes(design_mesh(p))
    path = tmp_path / "t.stl"
    path.write_bytes(data)
    back = trimesh.load(path, force="mesh")
    assert back.is_watertight
    assert abs(back.volume / analytic_volume(p) - 1) < 0.005


def test_seam_crossing_and_free_polygon():
    """A cut straddling the seam y = 0 and a non-rectangular region wrap periodically."""
    ro, ri, L = 1.0, 0.8, 6.0
    seam = rectangle(1.0, -0.5, 2.0, 0.5)  # 1 rad across angle 0
    tri = Contour(((3.0, 2.0), (4.0, 2.0), (3.5, 3.0)))
    m = tube_mesh(ro, ri, L, [seam, tri])
    assert m.is_watertight
    ring = ro ** 2 - ri ** 2
    want = math.pi * ring * L - (1.0 / ro) / 2 * ring * 1.0 - (0.5 / ro) / 2 * ring
    assert abs(m.volume / want - 1) < 0.003
    a, _ = _material_angles(m, 1.5)
    # nothing left within 0.5 rad of angle 0, on either side of the seam
    assert not np.any((a > 0.01) & (a < 0.49)) and not np.any((a > 2 * math.pi - 0.49) & (a < 2 * math.pi - 0.01))
    assert np.any(np.isclose(a, 0.5)) and np.any(np.isclose(a, 2 * math.pi - 0.5))
    # the triangle at x = 3.05 spans y 2.0 .. 2.1 (its slanted side y = 2 + 2 (x - 3))
    a, _ = _material_angles(m, 3.05)
    assert np.any(np.isclose(a, 2.0 / ro, atol=1e-9)) and np.any(np.isclose(a, 2.1 / ro, atol=2e-3))
    assert not np.any((a > 2.01 / ro) & (a < 2.09 / ro))


def test_removed_region_spanning_more_than_a_turn_is_cut():
    """A region whose polygons together (or one polygon alone) span more than a turn is still cut.

    Truth: the same polygons passed one by one, and the removed volume of an annular sector
    (wrapped area x (r_o^2 - r_i^2) / (2 r_o)).
    """
    from shapely.geometry import MultiPolygon, box

    ro, ri, L = 0.75, 0.45, 6.0
    circ = 2 * math.pi * ro
    # two notches 180 deg apart: together they span 5.2 mm of unwrapped y (> circumference 4.71)
    a = box(1.0, -1.4, 1.5, 1.4)
    b = box(2.0, circ / 2 - 1.4 + 0.9, 2.5, circ / 2 + 1.4 + 0.9)
    whole = tube_mesh(ro, ri, L, [MultiPolygon([a, b])], 128)
    single = tube_mesh(ro, ri, L, [a, b], 128)
    assert whole.is_watertight and abs(whole.volume - single.volume) < 1e-9
    # one L-shaped polygon spanning 1.2 turns: removed volume = area x (r_o^2 - r_i^2) / (2 r_o)
    poly = box(3.0, 0.0, 3.4, 1.2 * circ).union(box(3.0, 0.0, 4.0, 0.5))
    m = tube_mesh(ro, ri, L, [poly], 256)
    full = tube_mesh(ro, ri, L, [], 256)
    # the part beyond one turn overlaps the start: the material removed is the wrapped area
    from camtube.cad.ascut import wrap_sheet

    area = wrap_sheet(poly, circ).area
    want = area * (ro * ro - ri * ri) / (2 * ro)
    assert m.is_watertight
    assert abs((full.volume - m.volume) / want - 1) < 0.01
