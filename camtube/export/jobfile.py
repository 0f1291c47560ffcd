"""Machine-neutral job file: JSON, schema ``camtube.job/2`` (documented in ``docs/plan.md``), and its reader.

One entry per cut with its geometry (its start vertex per tour direction), the
visiting order of the cuts, the pass classes (focus level, drill offset,
settings), the process and the summary figures: everything needed to regenerate
every pass (:func:`read_job` does, with the planner's own rules), not every point
of every pass. A 100,000-notch job is about 20 MB instead of 1.2 GB (schema 1).

Deterministic: keys in a fixed order, one cut per line, every float written as
its shortest round-trip form (``repr``), so a reader recovers the planner's exact
numbers. :func:`iter_job_json` streams the text in chunks of cuts.
"""
from __future__ import annotations

import json
import math
import os
from typing import Iterator

import numpy as np

from camtube import __version__
from camtube.errors import DataError
from camtube.inputfile import parse_json, read_input_text
from camtube.plan.safety import check_job
from camtube.progress import NO_PROGRESS, Progress

SCHEMA = "camtube.job/2"
CHUNK_CUTS = 4096


def _enc(v) -> str:
    if isinstance(v, bool) or v is None:
        return json.dumps(v)
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if isinstance(v, (float, np.floating)):
        v = float(v)
        if not math.isfinite(v):
            raise ValueError(f"non-finite number {v!r} in a job file")
        return repr(v + 0.0)  # + 0.0: no "-0.0"
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)}: {_enc(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_enc(x) for x in v) + "]"
    raise TypeError(f"cannot encode {type(v).__name__} in a job file")


def _recipe(job):
    from camtube.plan.packed import PassView

    view = job.passes
    if not isinstance(view, PassView) or view.tour is None:
        raise ValueError(f"{job.name}: the job file describes planned jobs (plan_job); this job's passes were "
                         "made by hand")
    return view.tour, view.starts


def _process_dict(pr) -> dict:
    return {
        "power_w": float(pr.power_w), "frequency_khz": float(pr.frequency_khz),
        "scan_speed_mm_s": float(pr.scan_speed_mm_s), "wavelength_nm": float(pr.wavelength_nm),
        "drill_offset_mm": float(pr.drill_offset_mm), "drill_passes": int(pr.drill_passes),
        "defocus_mm": float(pr.defocus_mm), "repeats": None if pr.repeats is None else int(pr.repeats),
        "repeat_rule": [{"max_depth_mm": float(r.max_depth_mm), "repeats": int(r.repeats)} for r in pr.repeat_rule],
        "kerf_mm": float(pr.kerf_mm), "rapid_speed_mm_s": float(pr.rapid_speed_mm_s),
        "focus_speed_mm_s": float(pr.focus_speed_mm_s), "max_time_h": float(pr.max_time_h),
    }


def _classes(job) -> list[dict]:
    from camtube.plan.planner import pass_offsets_mm

    pr = job.process
    return [{"focus_level": f, "focus_offset_mm": (0.0, float(pr.defocus_mm))[f], "drill_index": d,
             "offset_mm": float(o), "power_w": float(pr.power_w), "frequency_khz": float(pr.frequency_khz),
             "speed_mm_s": float(pr.scan_speed_mm_s)}
            for f in (0, 1) for d, o in enumerate(pass_offsets_mm(pr))]


def _head(job, dialect=None) -> dict:
    """Everything but the cuts (fixed key order).

    ``dialect``: the G-code dialect (and so the machine profile) the job is made for
    (default: the default LinuxCNC profile). Its profile is recorded under ``machine``, and
    ``summary.total_time_s`` is the motion-aware time on it (``constant_speed_time_s``: every
    move at its nominal speed).
    """
    from camtube.export.dialects import LINUXCNC
    from camtube.machine.motion_time import job_estimate

    dialect = LINUXCNC if dialect is None else dialect
    est = job_estimate(job, dialect)
    tour, _ = _recipe(job)
    summary = {
        "cuts": est.cuts, "passes": est.passes, "cut_length_mm": est.cut_length_mm, "cut_time_s": est.cut_s,
        "rapid_time_s": est.rapid_s, "focus_time_s": est.focus_s, "lead_time_s": est.lead_s,
        "total_time_s": est.total_s, "lower_bound_s": est.lower_bound_s, "ratio": est.ratio,
        "constant_speed_time_s": est.constant_speed_s,
    }
    if est.link_length_mm > 0:  # chained passes: the beam is on along the cut length plus the links
        summary["link_length_mm"] = est.link_length_mm
    machine = dialect.profile.record() if getattr(dialect, "profile", None) is not None else None
    return {
        "schema": SCHEMA, "generator": f"camtube {__version__}", "name": job.name,
        "units": {"length": "mm", "time": "s", "speed": "mm/s", "power": "W", "frequency": "kHz"},
        "frame": "x along the tube from the tip; y arc length on the outer surface (unwrapped); "
                 "rotary angle = y / outer_radius_mm rad",
        "outer_radius_mm": float(job.outer_radius_mm), "length_mm": float(job.length_mm),
        "ordering": job.ordering, "repeats": int(job.repeats), "process": _process_dict(job.process),
        "machine": machine, "summary": summary, "classes": _classes(job), "tour": tour.tolist(),
    }


def _cut_line(i: int, c, start: list[int]) -> str:
    return "  " + _enc({"index": i, "kind": c.kind, "closed": bool(c.closed), "start": start,
                        "points": [[float(x), float(y)] for x, y in c.points]})


def iter_job_json(job, progress: Progress = NO_PROGRESS, dialect=None) -> Iterator[str]:
    """Safety-checked job file text of a planned job, in chunks (raises :class:`~camtube.errors.SafetyError`).

    The whole neutral move list is checked (chunk by chunk) before the first chunk of text.
    ``dialect``: the machine the job is made for (see :func:`_head`).
    """
    check_job(job)
    head = _head(job, dialect)
    _, starts = _recipe(job)
    lines = ["{"]
    for k, v in head.items():
        if k == "classes":
            inner = ",\n".join("  " + _enc(x) for x in v)
            lines.append(f' {json.dumps(k)}: [\n{inner}\n ],')
        else:
            lines.append(f" {json.dumps(k)}: {_enc(v)},")
    lines.append(' "cuts": [')
    yield "\n".join(lines) + "\n"
    design = job.design
    n = len(design)
    st = starts.T.tolist()  # per cut: its start per tour direction
    with progress.task("job file", total=len(job.passes)) as task:
        for lo in range(0, n, CHUNK_CUTS):
            hi = min(n, lo + CHUNK_CUTS)
            text = ",\n".join(_cut_line(i, design[i], st[i]) for i in range(lo, hi))
            yield text + (",\n" if hi < n else "\n")
            task.advance(len(job.passes) * (hi - lo) // max(n, 1))
    yield " ]\n}\n"


def job_json(job, dialect=None) -> str:
    """Safety-checked job file text (raises :class:`~camtube.errors.SafetyError`)."""
    return "".join(iter_job_json(job, dialect=dialect))


def job_dict(job, dialect=None) -> dict:
    """The job file content as plain data (fixed key order)."""
    return json.loads(job_json(job, dialect))


# ---------------------------------------------------------------- reading
def _bad(where: str, what: str) -> DataError:
    return DataError(f"{where}: {what}")


def read_job(source) -> "camtube.plan.Job":  # noqa: F821
    """Expand a ``camtube.job/2`` file back into its :class:`~camtube.plan.Job` (every pass).

    Parameters
    ----------
    source : str | os.PathLike | dict
        A path to a job file, or its parsed content.

    The passes are regenerated with the planner's own rules
    (:func:`camtube.plan.planner.assemble`) from the cuts, their start vertices, the
    tour, the ordering, the repeats and the process; the result has the same passes
    as the job that was written. The file's classes and pass count are checked
    against that expansion.

    Raises
    ------
    DataError
        Not a camtube.job/2 file, or one whose content contradicts itself.
    """
    from camtube.design.contour import Contour
    from camtube.design.pattern import Process, RepeatRule
    from camtube.plan.job import Job
    from camtube.plan.packed import PassView
    from camtube.plan.planner import ORDERINGS, assemble

    where = "job file"
    if isinstance(source, dict):
        d = source
    else:
        where = os.fspath(source)
        try:
            d = parse_json(read_input_text(source))
        except json.JSONDecodeError as e:
            raise _bad(where, f"not JSON (line {e.lineno}: {e.msg})") from None
    if not isinstance(d, dict) or d.get("schema") != SCHEMA:
        found = d.get("schema") if isinstance(d, dict) else None
        raise _bad(where, f"schema {found!r} is not {SCHEMA!r}; re-run camtube toolpath to write a current job file")
    try:
        p = dict(d["process"])
        p["repeat_rule"] = tuple(RepeatRule(float(r["max_depth_mm"]), int(r["repeats"])) for r in p["repeat_rule"])
        process = Process(**p)
        design = tuple(Contour(tuple((float(x), float(y)) for x, y in c["points"]), c["kind"], i, bool(c["closed"]))
                       for i, c in enumerate(d["cuts"]))
        starts = np.array([c["start"] for c in d["cuts"]], dtype=np.int64).reshape(len(design), -1).T
        tour = np.asarray(d["tour"], dtype=np.int64)
        ordering, repeats = d["ordering"], int(d["repeats"])
    except (KeyError, TypeError, ValueError) as e:
        raise _bad(where, f"malformed ({type(e).__name__}: {e})") from None
    if ordering not in ORDERINGS:
        raise _bad(where, f"ordering {ordering!r} is not one of {', '.join(ORDERINGS)}")
    if sorted(tour.tolist()) != list(range(len(design))):
        raise _bad(where, "tour is not a permutation of the cut indices")
    n_dir = 2 if ordering in ("interleaved", "chained") else 1
    if starts.shape != (n_dir, len(design)) or (starts < 0).any() or any(
            int(k) >= len(c.points) for row in starts for k, c in zip(row, design)):
        raise _bad(where, f"each cut needs {n_dir} start vertex index(es) within its points")
    packed = assemble(design, tour, starts, repeats, ordering, process)
    job = Job(str(d["name"]), float(d["outer_radius_mm"]), float(d["length_mm"]), design,
              PassView(packed, design, tour, starts), process, repeats, ordering)
    if d.get("classes") != json.loads(_enc(_classes(job))):
        raise _bad(where, "classes differ from what the process gives (edit the process, not the classes)")
    if int(d.get("summary", {}).get("passes", -1)) != len(job.passes):
        raise _bad(where, f"summary.passes is not the {len(job.passes)} passes the cuts and process give")
    return job
