"""Pictures: valid PNG, deterministic, the notches visible as gaps in the tube picture."""
from __future__ import annotations

import io

import matplotlib.image as mpimg

from camtube.cad.render import unrolled_png
from tests.cad.conftest import job_of, preset


def test_unrolled_png_deterministic():
    from camtube.cad.ascut import simulate

    p = preset("tube2")
    job = job_of("tube2")
    a = simulate(job)
    one = unrolled_png(job.design, p.tube.length_mm, p.tube.outer_radius_mm, a, title="tube2")
    assert one[:8] == b"\x89PNG\r\n\x1a\n"
    assert one == unrolled_png(job.design, p.tube.length_mm, p.tube.outer_radius_mm, a, title="tube2")
    img = mpimg.imread(io.BytesIO(one))
    assert img.shape[1] > img.shape[0]


def test_long_tube_picture_stays_small():
    """300 notches (L = 310 mm): the split for the painter's algorithm stays a few times the mesh, not (L/D)^2."""
    from camtube.cad.mesh import design_mesh
    from camtube.cad.render import picture_faces

    p = preset("tube1", "notch.count=300", "tube.length=310")
    m = design_mesh(p)
    _, faces = picture_faces(m)
    assert len(faces) < 10 * len(m.faces)


def test_too_big_a_mesh_is_noted_not_drawn(monkeypatch):
    import camtube.cad.render as render
    from camtube.cad.outputs import cad_outputs
    from camtube.plan import plan_job

    monkeypatch.setattr(render, "TUBE_PNG_MAX_FACES", 1000)  # the threshold only; the mesh is real
    p = preset("tube1")
    out = cad_outputs(p, plan_job(p), step=False)
    assert "tube1.tube.png" not in out.files and "tube1.unrolled.png" in out.files
    assert any("tube1.tube.png not drawn" in line for line in out.verdict_lines())
