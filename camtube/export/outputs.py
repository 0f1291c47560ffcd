"""A job's toolpath files as streams of text chunks, and writing them all-or-nothing.

File names in the output directory, for a job called ``NAME``:

- ``NAME.toolpath.dxf``: per-pass toolpath DXF;
- ``NAME<suffix>`` per dialect: ``NAME.ngc`` (LinuxCNC rotary), ``NAME.nc`` (GRBL flat bed);
- ``NAME.job.json``: the machine-neutral job file;
- ``NAME.design.dxf``: the design drawing (``build`` only, when a pattern is given).

:func:`toolpath_streams` gives every file as a lazy iterator of text chunks: each
chunk of passes is built, safety-checked and formatted only when the file layer
pulls it, and then dropped, so a job of 10^6 passes is written in bounded memory.
Hand the dict to ``camtube.io.write_set`` (as :func:`write_toolpaths` does), which
stages every file and publishes the set only when every stream has finished
(a SafetyError in any chunk leaves nothing behind).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Iterable, Iterator, Sequence

from camtube.export.dialects import DIALECTS, Dialect
from camtube.io import write_set
from camtube.progress import NO_PROGRESS, Progress


def survey(job, progress: Progress = NO_PROGRESS):
    """Safety-check the job's neutral moves and estimate its time in one pass over the chunks.

    Both results are kept in the Job's :class:`~camtube.plan.job.JobCache` (where
    :func:`~camtube.plan.safety.check_job` and :func:`~camtube.plan.moves.estimate` keep them), so
    the writers that follow reuse them; a second call costs nothing. Returns the :class:`~camtube.plan.moves.Estimate`.

    Raises
    ------
    SafetyError
        From the first unsafe chunk.
    """
    from camtube.plan.moves import estimate, iter_moves
    from camtube.plan.safety import check_moves

    cache = job.cache
    if cache.estimate is not None and cache.checked:
        return cache.estimate
    with progress.task("safety check, estimate", total=len(job.passes)) as task:
        def checked():
            for mv in iter_moves(job):
                check_moves(job, mv)
                task.advance(len(mv.pass_rows()) - 1)
                yield mv

        est = estimate(job, checked())
    cache.checked = True
    if cache.estimate is None:
        cache.estimate = est
    return cache.estimate


def exporters(dialects: Sequence[Dialect] = tuple(DIALECTS.values())) -> dict[str, Callable[..., Iterator[str]]]:
    """The toolpath writers of a job, as a table: file suffix -> ``writer(job, progress)`` -> text chunks.

    One entry per output (as trimesh's ``exchange/export.py`` keeps its exporters): the
    toolpath DXF, the G-code of each dialect (by its suffix) and the job file, which records
    the machine of the first dialect. Every writer is pure (it yields text; the file layer
    writes it) and safety-checks what it writes.
    """
    from camtube.export.gcode import iter_gcode
    from camtube.export.jobfile import iter_job_json
    from camtube.export.toolpath_dxf import iter_toolpath_dxf

    table: dict[str, Callable[..., Iterator[str]]] = {
        ".toolpath.dxf": lambda job, progress=NO_PROGRESS: iter_toolpath_dxf(job, progress=progress)}
    for d in dialects:
        table[d.suffix] = lambda job, progress=NO_PROGRESS, d=d: iter_gcode(job, d, progress=progress)
    first = dialects[0] if dialects else None
    table[".job.json"] = lambda job, progress=NO_PROGRESS: iter_job_json(job, progress=progress, dialect=first)
    return table


def toolpath_streams(job, dialects: Sequence[Dialect] = tuple(DIALECTS.values()),
                     progress: Progress = NO_PROGRESS) -> dict[str, Iterator[str]]:
    """File name -> lazy iterator of text chunks of the job's toolpath outputs (:func:`exporters`, walked).

    Nothing is computed until a stream is iterated; the first one iterated runs
    :func:`survey` (check + estimate, shared by all), and each stream safety-checks what
    it writes (raising :class:`~camtube.errors.SafetyError` before yielding unsafe text).
    """
    def surveyed(writer):
        survey(job, progress)
        yield from writer(job, progress)

    return {f"{job.name}{suffix}": surveyed(writer) for suffix, writer in exporters(dialects).items()}


def toolpath_texts(job, dialects: Sequence[Dialect] = tuple(DIALECTS.values())) -> dict[str, str]:
    """File name -> whole text of the job's toolpath outputs (small jobs, tests, golden files)."""
    return {name: "".join(chunks) for name, chunks in toolpath_streams(job, dialects).items()}


def write_toolpaths(job, outdir: str | os.PathLike, dialects: Sequence[Dialect] = tuple(DIALECTS.values()),
                    pattern=None, progress: Progress | None = None) -> list[Path]:
    """Check and write the job's toolpath DXF, G-code (each dialect) and job file (+ design DXF if ``pattern``).

    Streams every file (bounded memory) and publishes them together.

    Raises
    ------
    SafetyError
        The job is unsafe; no file has been written.
    """
    progress = NO_PROGRESS if progress is None else progress
    streams: dict[str, str | Iterable[str]] = {}
    if pattern is not None:
        from camtube.export.dxf import design_dxf

        streams[f"{job.name}.design.dxf"] = design_dxf(pattern)
    streams.update(toolpath_streams(job, dialects, progress))
    return write_set(outdir, streams, job=job.name)
