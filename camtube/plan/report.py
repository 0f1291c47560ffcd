"""What a command prints about a planned job: the summary table (durations as ``s (h:mm:ss)``).

The time warning itself is :func:`camtube.plan.moves.time_warning` (also written into
the G-code header); every duration goes through :func:`camtube.fmt.format_duration_s`.
"""
from __future__ import annotations

from camtube.fmt import format_duration_s


def summary_rows(job, est) -> list[tuple[str, str]]:
    """(label, value with unit) rows: job, ordering/repeats, cuts, passes, cut length, times, ratio."""
    parts = f"cut {format_duration_s(est.cut_s)}, rapid {format_duration_s(est.rapid_s)}, " \
            f"focus {format_duration_s(est.focus_s)}"
    if est.lead_s:
        parts += f", lead {format_duration_s(est.lead_s)}"
    machine = getattr(est, "machine", None)
    if machine:  # motion-aware total: the parts are at nominal speed
        parts = f"on machine {machine}, with its accelerations; at nominal speeds {parts}"
    return [
        ("job", job.name),
        ("ordering / repeats", f"{job.ordering} / {job.repeats}"),
        ("cuts", f"{est.cuts}"),
        ("passes", f"{est.passes}"),
        ("cut length", f"{est.cut_length_mm:.3f} mm"),
        ("estimated time", f"{format_duration_s(est.total_s)}: {parts}"),
        ("lower bound (length / speed)", format_duration_s(est.lower_bound_s)),
        ("ratio", f"{est.ratio:.4f}"),
    ]


def summary_table(job, est) -> str:
    """The summary rows as aligned text lines."""
    rows = summary_rows(job, est)
    w = max(len(a) for a, _ in rows)
    return "\n".join(f"{a:<{w}}  {b}".rstrip() for a, b in rows)
