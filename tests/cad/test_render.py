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
