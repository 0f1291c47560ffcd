"""Render the CAD figures of docs/cad.md into docs/img/ (deterministic PNGs).

    python scripts/render_pictures.py

- ``docs/img/cad-tube1.png``: shaded 3-D picture of the tube1 design mesh;
- ``docs/img/cad-tube1-unrolled.png``: the unrolled tube1 sheet with the simulated cut;
- ``docs/img/cad-broken-unrolled.png``: a broken job (one pass of notch 5 moved 0.15 mm, notch 7's
  contour with a gap on one side): overcut in red, the slug left standing in blue.
"""
from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main() -> int:
    from camtube.cad.ascut import simulate
    from camtube.cad.mesh import design_mesh
    from camtube.cad.render import tube_png, unrolled_png
    from camtube.design.contour import Contour
    from camtube.design.loader import load_pattern
    from camtube.io import write_atomic
    from camtube.plan import job_moves, plan_job

    out = ROOT / "docs" / "img"
    p = load_pattern(ROOT / "patterns" / "tube1.yaml")
    job = plan_job(p)
    t = p.tube
    written = [
        write_atomic(out / "cad-tube1.png", tube_png(design_mesh(p), facing_angle_deg=p.notches[0].angle_deg + 60.0,
                                                      title="tube1 as designed (camtube cad)")),
        write_atomic(out / "cad-tube1-unrolled.png", unrolled_png(job.design, t.length_mm, t.outer_radius_mm,
                                                                  simulate(job), title="tube1 as cut")),
    ]
    # a broken job: one pass of cut 5 shifted by 0.15 mm in y; cut 7 never cut on its far axial side
    passes = list(job.passes)
    i = next(k for k, q in enumerate(passes) if q.cut_index == 5 and q.drill_index == 1)
    q = passes[i]
    passes[i] = dataclasses.replace(q, contour=Contour(tuple((x, y - 0.15) for x, y in q.contour.points),
                                                       q.contour.kind, q.contour.cut_index))
    bad = dataclasses.replace(job, passes=tuple(passes))
    bad.__dict__.pop("packed", None)
    mv = job_moves(bad)
    x0, _, _ = mv.starts()
    cut = np.asarray(bad.packed.pass_cut)[mv.pass_index]
    xmid = 0.5 * (job.design[7].bounds[0] + job.design[7].bounds[2])
    gap = mv.laser & (cut == 7) & (x0 == mv.x) & (mv.x > xmid)
    a = simulate(bad, dataclasses.replace(mv, laser=mv.laser & ~gap))
    written.append(write_atomic(out / "cad-broken-unrolled.png", unrolled_png(
        job.design, t.length_mm, t.outer_radius_mm, a, title="broken job (pass of cut 5 moved, gap in cut 7)")))
    for w in written:
        print(f"wrote {w.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
