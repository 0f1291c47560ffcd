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
from camtube.io import write_set


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


def cad_models(pattern: Pattern, job, *, step: bool = True, segments: int | None = None,
               kerf_mm: float | None = None) -> Models:
    """Compute the design mesh, the kerf simulation of ``job`` and its mesh, and (if ``step``) the B-rep and its STEP.

    ``job`` is the planned job of ``pattern`` (the CAD stage simulates a job; it does not plan one).
    """
    from camtube.cad.ascut import simulate
    from camtube.cad.mesh import auto_segments, design_mesh, tube_mesh

    seg = segments or auto_segments(len(pattern.cuts))
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


@dataclass(frozen=True, eq=False)
class CadOutputs:
    """The CAD files of a pattern (name -> bytes, in writing order) and its verification report.

    Attributes
    ----------
    files : dict[str, bytes]
    report : camtube.cad.verify.Report
    """

    files: dict
    report: object
    notes: tuple = ()

    @property
    def passed(self) -> bool:
        return bool(self.report.passed)

    def verdict_lines(self) -> list[str]:
        """``verification: PASS (n/m checks passed)`` and one ``FAIL name: detail`` line per failed check."""
        r = self.report
        out = [f"verification: {'PASS' if r.passed else 'FAIL'} "
               f"({len(r.checks) - len(r.failures)}/{len(r.checks)} checks passed)"]
        out += [f"  FAIL {c.name}: {c.detail}" for c in r.failures]
        return out + [f"note: {n}" for n in self.notes]


def cad_outputs(pattern: Pattern, job, *, step: bool = True, pictures: bool = True,
                segments: int | None = None, kerf_mm: float | None = None) -> CadOutputs:
    """Compute every CAD output of ``pattern`` and its ``job`` in memory (no file is written).

    Parameters
    ----------
    pattern : Pattern
    job : camtube.plan.Job
        The planned job to simulate.
    step : bool
        Also build the exact B-rep and its STEP (build123d; slower); its volume is
        read back from the STEP text with OCCT for the report.
    pictures : bool
        Also render the PNG pictures.
    segments : int, optional
        Sides of the meshes' polygonal circles.
    kerf_mm : float, optional
        Beam kerf for the simulation (default: the process's, or 0.02 mm).
    """
    from camtube.io import import_whole

    # (a Ctrl-C while they import is raised here, once they are whole: see import_whole)
    import_whole("trimesh", *(("build123d",) if step else ()))
    from camtube.cad.mesh import stl_bytes
    from camtube.cad.solid import volume_mm3
    from camtube.cad.verify import report_json, report_text, verify

    name = pattern.name
    m = cad_models(pattern, job, step=step, segments=segments, kerf_mm=kerf_mm)
    files: dict[str, bytes] = {}
    step_volume = None
    if m.step is not None:
        files[f"{name}.design.step"] = m.step
        step_volume = _step_volume(m.step)
    files[f"{name}.design.stl"] = stl_bytes(m.design_mesh)
    files[f"{name}.ascut.stl"] = stl_bytes(m.ascut_mesh)
    report = verify(pattern, design_mesh=m.design_mesh, ascut=m.ascut, ascut_mesh=m.ascut_mesh,
                    solid_volume_mm3=volume_mm3(m.solid) if m.solid is not None else None,
                    step_volume_mm3=step_volume, segments=m.segments)
    files[f"{name}.verify.txt"] = report_text(report).encode("utf-8")
    files[f"{name}.verify.json"] = report_json(report).encode("utf-8")
    notes = []
    if pictures:
        from camtube.cad.render import TUBE_PNG_MAX_FACES, tube_png, unrolled_png

        notches = pattern.notches
        facing = (notches[0].angle_deg if notches else 180.0) + 60.0  # notches seen obliquely
        if len(m.design_mesh.faces) <= TUBE_PNG_MAX_FACES:
            files[f"{name}.tube.png"] = tube_png(m.design_mesh, facing_angle_deg=facing, title=f"{name} (design)")
        else:
            notes.append(f"{name}.tube.png not drawn: the mesh has {len(m.design_mesh.faces)} faces, more than "
                         f"{TUBE_PNG_MAX_FACES} (a picture of {len(pattern.cuts)} cuts would be unreadable); "
                         "the STL and the unrolled picture show it")
        files[f"{name}.unrolled.png"] = unrolled_png(job.design, pattern.tube.length_mm,
                                                     pattern.tube.outer_radius_mm, m.ascut, title=name)
    return CadOutputs(files, report, tuple(notes))


def _step_volume(step: bytes) -> float:
    """Volume (mm^3) of a STEP text, read back by OCCT from a private temporary file."""
    import tempfile

    from camtube.cad.solid import import_step_volume

    with tempfile.TemporaryDirectory(prefix="camtube-step-") as tmp:
        path = Path(tmp) / "readback.step"
        path.write_bytes(step)
        return import_step_volume(path)


def build_outputs(pattern: Pattern, job, outdir: str | os.PathLike, *, step: bool = True, pictures: bool = True,
                  segments: int | None = None, kerf_mm: float | None = None, log=None) -> list[Path]:
    """Compute the CAD outputs (:func:`cad_outputs`) and write them into ``outdir`` as one set.

    ``log`` (e.g. ``print``) receives the verification verdict lines. Returns the written paths.
    """
    out = cad_outputs(pattern, job, step=step, pictures=pictures, segments=segments, kerf_mm=kerf_mm)
    paths = write_set(outdir, out.files, job=job.name)
    for line in out.verdict_lines():
        (log or (lambda _msg: None))(line)
    return paths
