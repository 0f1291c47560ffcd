"""Orchestration: the one place that builds a command's outputs for a pattern and hands them to the file layer.

A pattern comes from a YAML file or a drawing (:func:`camtube.design.source.load_source`);
from there every route is the same:

    Loaded pattern --plan_job--> Job --writers--> toolpath files (G-code per dialect, job file, toolpath DXF)
                   --design_dxf--> design drawing            (build)
                   --cad_outputs(pattern, job)--> CAD files + verification report   (build, cad)

Every output is computed (and safety-checked) first; then the whole set is written with
:func:`camtube.io.write_set`, so a command's files appear together or not at all. The
stages stay independent: ``plan`` does not call ``cad``, ``cad`` simulates the job it is
given and does not plan one; only this module ties them together.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

from camtube.design.loader import Loaded

#: What each command writes.
TOOLPATH, BUILD, CAD = "toolpath", "build", "cad"


@dataclass(frozen=True)
class CadOptions:
    """Options of the CAD outputs (see ``camtube cad --help``)."""

    step: bool = True
    pictures: bool = True
    segments: int | None = None
    kerf_mm: float | None = None


@dataclass(frozen=True)
class Request:
    """What to build.

    Attributes
    ----------
    what : {"toolpath", "build", "cad"}
        ``toolpath``: toolpath DXF, G-code per dialect, job file; ``build``: those plus the
        design DXF and the CAD outputs; ``cad``: the CAD outputs only.
    dialects : sequence of Dialect, optional
        G-code dialects (default: all).
    ordering : str, optional
        Pass ordering (default: the planner's).
    cad : CadOptions
    """

    what: str = BUILD
    dialects: Sequence | None = None
    ordering: str | None = None
    cad: CadOptions = field(default_factory=CadOptions)


@dataclass(frozen=True, eq=False)
class Result:
    """What a run produced.

    Attributes
    ----------
    paths : list[Path]
        Files written, in order.
    job : camtube.plan.Job
    estimate : camtube.plan.Estimate or None
        Time estimate of the job (``toolpath`` and ``build``).
    cad : camtube.cad.outputs.CadOutputs or None
        CAD outputs with the verification report (``build`` and ``cad``).
    """

    paths: list
    job: object
    estimate: object = None
    cad: object = None

    @property
    def verified(self) -> bool:
        """False when a CAD verification ran and failed."""
        return self.cad is None or self.cad.passed


def plan(loaded: Loaded, ordering: str | None = None):
    """The planned job of a loaded pattern."""
    from camtube.plan import plan_job

    kwargs = {} if ordering is None else {"ordering": ordering}
    return plan_job(loaded.pattern, **kwargs)


def outputs(loaded: Loaded, request: Request, progress: Callable[[int, int], None] | None = None):
    """Compute every file of ``request`` in memory: ``(files: dict[name, payload], job, estimate, cad)``.

    Raises
    ------
    SafetyError
        The job fails the laser safety check (before anything is returned).
    """
    pattern = loaded.pattern
    job = plan(loaded, request.ordering)
    files: dict = {}
    est = cad = None
    if request.what in (TOOLPATH, BUILD):
        from camtube.export.dialects import DIALECTS
        from camtube.plan.moves import estimate
        from camtube.plan.outputs import toolpath_texts

        if request.what == BUILD:
            from camtube.export.dxf import design_dxf

            files[f"{job.name}.design.dxf"] = design_dxf(pattern)
        dialects = tuple(request.dialects) if request.dialects else tuple(DIALECTS.values())
        files.update(toolpath_texts(job, dialects, progress))
        est = estimate(job)
    if request.what in (BUILD, CAD):
        from camtube.cad.outputs import cad_outputs

        o = request.cad
        cad = cad_outputs(pattern, job, step=o.step, pictures=o.pictures, segments=o.segments, kerf_mm=o.kerf_mm)
        files.update(cad.files)
    return files, job, est, cad


def run(loaded: Loaded, outdir: str | os.PathLike, request: Request,
        progress: Callable[[int, int], None] | None = None) -> Result:
    """Build the outputs of ``request`` for ``loaded`` and write them into ``outdir`` as one set."""
    from camtube.io import write_set

    files, job, est, cad = outputs(loaded, request, progress)
    paths = write_set(Path(outdir), files)
    return Result(paths, job, est, cad)
