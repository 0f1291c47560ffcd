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
from camtube.errors import PatternError
from camtube.progress import NO_PROGRESS, Progress

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
        Pass ordering (default: the first dialect's machine profile's ``ordering`` when dialects are
        given, else the planner's).
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
        Time estimate of the job on the first dialect's machine (motion-aware; ``toolpath`` and ``build``).
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


def design_extras(pattern) -> str:
    """What later stages say about a design for ``camtube design``: the model's predicted
    stroke-angle curve (the design stage itself never calls the model)."""
    if not pattern.notches:
        return ""
    from camtube.model.core.predict import design_summary

    return design_summary(pattern)


def plan(loaded: Loaded, ordering: str | None = None, progress: Progress = NO_PROGRESS):
    """The planned job of a loaded pattern."""
    from camtube.plan import plan_job

    kwargs = {} if ordering is None else {"ordering": ordering}
    try:
        return plan_job(loaded.pattern, progress=progress, **kwargs)
    except PatternError as exc:
        raise PatternError([_named(i, loaded) for i in exc.issues]) from None


def _named(issue, loaded: Loaded):
    """A planner's issue about ``cut[i]`` named by where that cut came from (the drawing's entity, the YAML key) and in
    the pattern's file (the planner knows neither: "cut[0] (hole at x ...): the contour vanishes" named no file)."""
    from dataclasses import replace

    from camtube.plan.planner import cut_of_key

    cut = cut_of_key(issue.key)
    key = issue.key
    if cut is not None and cut[0] < len(loaded.origins):
        key = f"{loaded.origins[cut[0]]} ({cut[1]})"
    return replace(issue, key=key, file=issue.file or loaded.pattern.source)


def outputs(loaded: Loaded, request: Request, progress: Progress = NO_PROGRESS):
    """Every file of ``request``: ``(files: dict[name, payload], job, estimate, cad)``.

    Toolpath files are lazy streams of text chunks (safety-checked chunk by chunk as
    they are written, so a job of 10^6 passes never sits in memory); the design DXF
    and the CAD files are computed here.

    Raises
    ------
    SafetyError
        The job fails the laser safety check (when its stream is written; nothing is
        published then).
    """
    pattern = loaded.pattern
    ordering = request.ordering
    if ordering is None and request.dialects:  # the machine's own ordering (linuxcnc-path: chained)
        ordering = getattr(getattr(request.dialects[0], "profile", None), "ordering", None)
    job = plan(loaded, ordering, progress)
    files: dict = {}
    est = cad = None
    if request.what in (TOOLPATH, BUILD):
        from camtube.export.dialects import DIALECTS
        from camtube.export.outputs import toolpath_streams
        from camtube.machine.motion_time import job_estimate

        if request.what == BUILD:
            from camtube.export.dxf import design_dxf

            files[f"{job.name}.design.dxf"] = design_dxf(pattern)
        dialects = tuple(request.dialects) if request.dialects else tuple(DIALECTS.values())
        from camtube.machine.kinematics import check_feeds, check_laser_values, check_speeds

        for d in dialects:  # a feed or laser value the G-code cannot carry makes the job meaningless: refused
            check_feeds(job, d)  # before writing
            check_laser_values(job, d)
            check_speeds(job, d)
        # the estimate on the first dialect's machine, computed once here: the G-code header and the
        # job file of that machine read the same one from the job's cache
        est = job_estimate(job, dialects[0])
        _add_outputs(files, toolpath_streams(job, dialects, progress))  # the exporter table, walked
    if request.what in (BUILD, CAD):
        from camtube.cad.outputs import cad_outputs

        o = request.cad
        cad = cad_outputs(pattern, job, step=o.step, pictures=o.pictures, segments=o.segments, kerf_mm=o.kerf_mm)
        _add_outputs(files, cad.files)
    return files, job, est, cad


def _add_outputs(files: dict, more: dict) -> None:
    """Add ``more`` to ``files``; two outputs of one name (a G-code suffix such as ``.job.json``) are refused."""
    from camtube.errors import CamtubeError

    clash = sorted(set(files) & set(more))
    if clash:
        raise CamtubeError(f"{clash[0]}: two outputs of this command would have this file name; fix: give the "
                           "machine profile a G-code suffix of its own (e.g. suffix: .ngc)")
    files.update(more)


def run(loaded: Loaded, outdir: str | os.PathLike, request: Request, progress: Progress = NO_PROGRESS,
        warn: Callable[[str], None] | None = None, inputs: Sequence[str | os.PathLike] = ()) -> Result:
    """Build the outputs of ``request`` for ``loaded`` and write them into ``outdir`` as one set.

    ``warn`` (e.g. a print to stderr) hears the laser-time warning of the job, if any,
    before the (possibly long) writing starts. ``inputs``: the files the job was read from; a set that would replace
    or remove one of them is refused before anything is written (:func:`check_inputs_kept`).
    """
    from camtube.io import write_set

    files, job, est, cad = outputs(loaded, request, progress)
    check_inputs_kept(Path(outdir), files, job.name, inputs)
    if warn is not None and est is not None:
        from camtube.machine.motion_time import slow_job_warning
        from camtube.plan.moves import time_warning

        from camtube.export.dialects import DIALECTS

        first = request.dialects[0] if request.dialects else next(iter(DIALECTS.values()))
        profile = getattr(first, "profile", None)  # the machine the estimate is for
        for w in (time_warning(job, est), slow_job_warning(job, est, profile)):
            if w:
                warn(w)
    paths = write_set(Path(outdir), files, job=job.name)  # it replaces the set written there for this job before
    return Result(paths, job, est, cad)


def check_inputs_kept(outdir: Path, files, job: str, inputs: Sequence[str | os.PathLike]) -> None:
    """Refuse a set for ``job`` in ``outdir`` that would replace an input file, or remove it as a file of the set written
    there before for that job (``build t.design.dxf -o .`` replaced the drawing it was reading with its own design
    DXF, exit 0: the CAD work lost)."""
    from camtube.errors import CamtubeError
    from camtube.io import JobSet, earlier_set

    names = set(files) | earlier_set(outdir, JobSet(files, job))
    for src in inputs:
        src = Path(src)
        if not src.is_file():
            continue
        for name in sorted(names):
            target = outdir / name
            try:
                same = target.exists() and os.path.samefile(target, src)
            except OSError:
                same = False
            if same:
                raise CamtubeError(f"-o {outdir}: the set of job {job!r} written there would replace its own input "
                                   f"{src} (as {name}); fix: write to another folder (-o), or give the job another "
                                   "name (--set name=...)")
