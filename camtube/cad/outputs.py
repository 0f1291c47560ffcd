"""Build every CAD output of a pattern and its job, then write them atomically.

File names in the output directory, for a pattern called ``NAME``:

- ``NAME.design.step``: exact B-rep of the tube as designed (build123d, mm);
- ``NAME.design.stl``: mesh of the same (manifold3d, binary STL, mm);
- ``NAME.ascut.stl``: mesh of the tube as the job cuts it (kerf simulation, freed slugs removed);
- ``NAME.verify.txt`` / ``NAME.verify.json``: the verification report;
- ``NAME.tube.png``: shaded 3-D picture of the design mesh; ``NAME.unrolled.png``: the sheet with the
  design outlines and the simulated overcut/undercut.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from camtube.design.pattern import Pattern
from camtube.io import write_atomic


@dataclass(frozen=True, eq=False)
class Models:
    """Everything computed for a pattern/job (no files).

    Attributes
    ----------
    design_mesh, ascut_mesh : trimesh.Trimesh
    ascut : camtube.cad.ascut.AsCut
    solid : build123d Solid or None
    step : bytes or None
        STEP text of ``solid``.
    segments : int
    """

    design_mesh: object
    ascut: object
    ascut_mesh: object
    solid: object
    step: bytes | None
    segments: int


def cad_models(pattern: Pattern, job=None, *, step: bool = True, segments: int | None = None,
               kerf_mm: float | None = None) -> Models:
    """Compute the design mesh, the kerf simulation and its mesh, and (if ``step``) the B-rep and its STEP.

    ``job`` defaults to ``camtube.plan.plan_job(pattern)``.
    """
    from camtube.cad.ascut import simulate
    from camtube.cad.mesh import auto_segments, design_mesh, tube_mesh

    seg = segments or auto_segments(len(pattern.cuts))
    if job is None:
        from camtube.plan import plan_job

        job = plan_job(pattern)
    t = pattern.tube
    dm = design_mesh(pattern, seg)
    a = simulate(job, kerf_mm=kerf_mm)
    am = tube_mesh(t.outer_radius_mm, t.inner_radius_mm, t.length_mm, [a.removed], seg)
    solid = data = None
    if step:
        from camtube.cad.solid import design_solid, step_bytes

        solid = design_solid(pattern)
        data = step_bytes(solid, f"{pattern.name}.design.step")
    return Models(dm, a, am, solid, data, seg)


def build_outputs(pattern: Pattern, job, outdir: str | os.PathLike, *, step: bool = True, pictures: bool = True,
                  segments: int | None = None, kerf_mm: float | None = None, log=None) -> list[Path]:
    """Write the CAD models, pictures and verification report; return the paths in order.

    Parameters
    ----------
    pattern : Pattern
    job : camtube.plan.Job or None
        The job to simulate (``None``: plan it with the defaults).
    outdir : path
    step : bool
        Also build the exact B-rep and write the STEP (build123d; slower).
    pictures : bool
        Write the PNG pictures.
    segments : int, optional
        Sides of the meshes' polygonal circles.
    kerf_mm : float, optional
        Beam kerf for the simulation (default: the process's, or 0.02 mm).
    log : callable, optional
        Called with one line of text per step (e.g. ``print``).
    """
    from camtube.cad.mesh import stl_bytes
    from camtube.cad.verify import report_json, report_text, verify

    say = log or (lambda _msg: None)
    out = Path(outdir)
    name = pattern.name
    m = cad_models(pattern, job, step=step, segments=segments, kerf_mm=kerf_mm)
    paths: list[Path] = []
    step_volume = None
    if m.step is not None:
        from camtube.cad.solid import import_step_volume

        p = write_atomic(out / f"{name}.design.step", m.step)
        paths.append(p)
        step_volume = import_step_volume(p)
    paths.append(write_atomic(out / f"{name}.design.stl", stl_bytes(m.design_mesh)))
    paths.append(write_atomic(out / f"{name}.ascut.stl", stl_bytes(m.ascut_mesh)))
    report = verify(pattern, design_mesh=m.design_mesh, ascut=m.ascut, ascut_mesh=m.ascut_mesh,
                    solid_volume_mm3=float(m.solid.volume) if m.solid is not None else None,
                    step_volume_mm3=step_volume, segments=m.segments)
    paths.append(write_atomic(out / f"{name}.verify.txt", report_text(report)))
    paths.append(write_atomic(out / f"{name}.verify.json", report_json(report)))
    say(f"verification: {'PASS' if report.passed else 'FAIL'} "
        f"({len(report.checks) - len(report.failures)}/{len(report.checks)} checks passed)")
    for c in report.failures:
        say(f"  FAIL {c.name}: {c.detail}")
    if pictures:
        from camtube.cad.render import tube_png, unrolled_png

        notches = pattern.notches
        facing = (notches[0].angle_deg if notches else 180.0) + 60.0  # notches seen obliquely
        paths.append(write_atomic(out / f"{name}.tube.png", tube_png(m.design_mesh, facing_angle_deg=facing,
                                                                     title=f"{name} (design)")))
        paths.append(write_atomic(out / f"{name}.unrolled.png", unrolled_png(
            job.design if job is not None else _contours(pattern),
            pattern.tube.length_mm, pattern.tube.outer_radius_mm, m.ascut, title=name)))
    return paths


def _contours(pattern: Pattern):
    from camtube.design.contour import cut_contours

    return cut_contours(pattern)
