"""build123d B-rep and STEP: volume, OCCT read-back, determinism, frame agrees with the mesh."""
from __future__ import annotations

import pytest

from tests.cad.conftest import analytic_volume, preset

bd = pytest.importorskip("build123d")


@pytest.fixture(scope="module")
def tube1_solid():
    from camtube.cad.solid import design_solid

    return design_solid(preset("tube1"))


def test_volume_and_step_reimport(tube1_solid, tmp_path):
    from camtube.cad.solid import step_bytes
    from camtube.io import write_atomic

    p = preset("tube1")
    assert tube1_solid.is_valid
    assert abs(tube1_solid.volume / analytic_volume(p) - 1) < 1e-6
    path = write_atomic(tmp_path / "tube1.design.step", step_bytes(tube1_solid, "tube1.design.step"))
    back = bd.import_step(str(path))
    assert len(back.solids()) == 1
    assert abs(back.volume / tube1_solid.volume - 1) < 0.002
    bb = back.bounding_box()
    assert bb.min.X == pytest.approx(0.0, abs=1e-6) and bb.max.X == pytest.approx(p.tube.length_mm, abs=1e-6)
    assert bb.max.Y == pytest.approx(p.tube.outer_radius_mm, abs=1e-4)


def test_step_bytes_deterministic(tube1_solid):
    from camtube.cad.solid import design_solid, step_bytes

    a = step_bytes(tube1_solid, "x.step")
    assert a == step_bytes(design_solid(preset("tube1")), "x.step")
    assert b"FILE_NAME('x.step','2000-01-01T00:00:00'" in a


def test_notch_side_matches_mesh_frame():
    """Notch at 90 deg: the B-rep has no material at +Z inside the notch, material at -Z (frame of the mesh)."""
    from camtube.cad.solid import design_solid

    p = preset("tube1", "notch.angle_deg=90", "holes.0.angle_deg=90")
    s = design_solid(p)
    c = p.notches[0]
    r = 0.5 * (p.tube.outer_radius_mm + p.tube.inner_radius_mm)
    assert not s.is_inside(bd.Vector(c.x_mm, 0.0, r))
    assert s.is_inside(bd.Vector(c.x_mm, 0.0, -r))
    assert s.is_inside(bd.Vector(c.x_mm + c.width_mm, 0.0, r))  # the web between notches
    assert abs(s.volume / analytic_volume(p) - 1) < 1e-6
