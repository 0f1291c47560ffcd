"""Machine-neutral job file: JSON, schema ``camtube.job/1`` (documented in ``docs/plan.md``).

Every pass with its settings and geometry (unrolled frame, mm), the design cut
regions, the process and the summary figures. Deterministic: keys in a fixed
order, every float written with 6 fixed decimals, one pass per line.
"""
from __future__ import annotations

import json
import math

from camtube import __version__
from camtube.plan.safety import check_job

SCHEMA = "camtube.job/1"


def _enc(v) -> str:
    if isinstance(v, bool) or v is None:
        return json.dumps(v)
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if not math.isfinite(v):
            raise ValueError(f"non-finite number {v!r} in a job file")
        s = f"{v:.6f}"
        return "0.000000" if s == "-0.000000" else s
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)}: {_enc(x)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_enc(x) for x in v) + "]"
    raise TypeError(f"cannot encode {type(v).__name__} in a job file")


def _points(contour) -> list:
    return [[float(x), float(y)] for x, y in contour.points]


def job_dict(job, dialect=None) -> dict:
    """The job file content as plain data (fixed key order).

    ``dialect``: the G-code dialect (and so the machine profile) the job is made for; its
    profile is recorded under ``machine`` and its motion-aware time is ``summary.total_time_s``
    (default: the default LinuxCNC profile).
    """
    from camtube.export.dialects import LINUXCNC
    from camtube.plan.motion_time import job_estimate

    check_job(job)
    dialect = LINUXCNC if dialect is None else dialect
    est = job_estimate(job, dialect)
    pr = job.process
    process = {
        "power_w": float(pr.power_w), "frequency_khz": float(pr.frequency_khz),
        "scan_speed_mm_s": float(pr.scan_speed_mm_s), "wavelength_nm": float(pr.wavelength_nm),
        "drill_offset_mm": float(pr.drill_offset_mm), "drill_passes": int(pr.drill_passes),
        "defocus_mm": float(pr.defocus_mm), "repeats": None if pr.repeats is None else int(pr.repeats),
        "repeat_rule": [{"max_depth_mm": float(r.max_depth_mm), "repeats": int(r.repeats)} for r in pr.repeat_rule],
        "kerf_mm": float(pr.kerf_mm), "rapid_speed_mm_s": float(pr.rapid_speed_mm_s),
        "focus_speed_mm_s": float(pr.focus_speed_mm_s),
    }
    summary = {
        "cuts": est.cuts, "passes": est.passes, "cut_length_mm": est.cut_length_mm, "cut_time_s": est.cut_s,
        "rapid_time_s": est.rapid_s, "focus_time_s": est.focus_s, "total_time_s": est.total_s,
        "lower_bound_s": est.lower_bound_s, "ratio": est.ratio,
        "constant_speed_time_s": est.constant_speed_s,
    }
    design = [{"index": i, "kind": c.kind, "points": _points(c)} for i, c in enumerate(job.design)]
    passes = [{
        "index": k, "cut_index": p.cut_index, "kind": p.kind, "repeat": p.repeat, "focus_level": p.focus_level,
        "focus_offset_mm": float(p.focus_offset_mm), "drill_index": p.drill_index, "offset_mm": float(p.offset_mm),
        "power_w": float(p.power_w), "frequency_khz": float(p.frequency_khz), "speed_mm_s": float(p.speed_mm_s),
        "length_mm": p.length_mm, "points": _points(p.contour),
    } for k, p in enumerate(job.passes)]
    return {
        "schema": SCHEMA, "generator": f"camtube {__version__}", "name": job.name,
        "units": {"length": "mm", "time": "s", "speed": "mm/s", "power": "W", "frequency": "kHz"},
        "frame": "x along the tube from the tip; y arc length on the outer surface (unwrapped); "
                 "rotary angle = y / outer_radius_mm rad",
        "outer_radius_mm": float(job.outer_radius_mm), "length_mm": float(job.length_mm),
        "ordering": job.ordering, "repeats": int(job.repeats), "process": process,
        "machine": dialect.profile.record() if dialect.profile is not None else None, "summary": summary,
        "design": design, "passes": passes,
    }


def iter_job_json(job, progress=None, dialect=None):
    yield job_json(job, dialect)


def job_json(job, dialect=None) -> str:
    """Safety-checked job file text (raises :class:`~camtube.errors.SafetyError`)."""
    d = job_dict(job, dialect)
    lines = ["{"]
    items = list(d.items())
    for n, (k, v) in enumerate(items):
        comma = "," if n < len(items) - 1 else ""
        if k in ("design", "passes"):
            inner = ",\n".join("  " + _enc(x) for x in v)
            lines.append(f' {json.dumps(k)}: [\n{inner}\n ]{comma}')
        else:
            lines.append(f" {json.dumps(k)}: {_enc(v)}{comma}")
    lines.append("}")
    return "\n".join(lines) + "\n"
