"""Write a job's files: every text is produced (and safety-checked) before any file is written.

File names in the output directory, for a job called ``NAME``:

- ``NAME.toolpath.dxf``: per-pass toolpath DXF;
- ``NAME<suffix>`` per dialect: ``NAME.ngc`` (LinuxCNC rotary), ``NAME.nc`` (GRBL flat bed);
- ``NAME.job.json``: the machine-neutral job file;
- ``NAME.design.dxf``: the design drawing (``build`` only, when a pattern is given).
"""
from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Sequence

from camtube.export.dialects import DIALECTS, Dialect
from camtube.io import write_atomic


def toolpath_texts(job, dialects: Sequence[Dialect] = tuple(DIALECTS.values()),
                   progress: Callable[[int, int], None] | None = None) -> dict[str, str]:
    """File name -> text of the job's toolpath outputs (raises SafetyError before returning anything)."""
    from camtube.export.gcode import gcode
    from camtube.export.jobfile import job_json
    from camtube.export.toolpath_dxf import toolpath_dxf

    texts = {f"{job.name}.toolpath.dxf": toolpath_dxf(job)}
    for d in dialects:
        texts[f"{job.name}{d.suffix}"] = gcode(job, d, progress=progress)
    texts[f"{job.name}.job.json"] = job_json(job)
    return texts


def write_texts(texts: dict[str, str], outdir: str | os.PathLike) -> list[Path]:
    """Write every text atomically into ``outdir``; return the paths in order."""
    return [write_atomic(Path(outdir) / name, text) for name, text in texts.items()]


def write_toolpaths(job, outdir: str | os.PathLike, dialects: Sequence[Dialect] = tuple(DIALECTS.values()),
                    pattern=None, progress: Callable[[int, int], None] | None = None) -> list[Path]:
    """Check and write the job's toolpath DXF, G-code (each dialect) and job file (+ design DXF if ``pattern``).

    Raises
    ------
    SafetyError
        The job is unsafe; no file has been written.
    """
    texts = {}
    if pattern is not None:
        from camtube.export.dxf import design_dxf

        texts[f"{job.name}.design.dxf"] = design_dxf(pattern)
    texts.update(toolpath_texts(job, dialects, progress))
    return write_texts(texts, outdir)
