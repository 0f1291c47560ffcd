"""The ingest report: a one-page HTML with three PNG figures (alignment, angle from poses, dropouts).

Writers return text and bytes; :func:`report_files` gives the ``{name: payload}`` set that
:func:`camtube.io.write_set` puts on disk at once.
"""
from __future__ import annotations

import html
import io

import numpy as np

from camtube.model.ingest.merge import Ingested


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110, metadata={"Software": None})
    import matplotlib.pyplot as plt

    plt.close(fig)
    return buf.getvalue()


def _norm(y: np.ndarray) -> np.ndarray:
    lo, hi = np.nanpercentile(y, 1), np.nanpercentile(y, 99)
    return (y - lo) / (hi - lo if hi > lo else 1.0)


def alignment_png(ing: Ingested) -> bytes:
    """Top: the three signals (normalised) over one cycle in the middle, on the tracker clock after alignment.
    Bottom: each window's lag minus the fitted offset + drift line (ms), with the line's standard error."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    b, tr = ing.bend, ing.traces
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8.5, 6.2), constrained_layout=True)
    cyc = ing.data.cycle
    mid = int(np.median(cyc))
    rows = ing.data.time_s[cyc == mid] + tr["row_t"][0]
    a, z = (rows.min() - 1.0, rows.max() + 1.0) if rows.size else (b.time_s[0], b.time_s[-1])
    for t, y, lab, st in ((b.time_s, b.angle_deg, "angle (tracker)", "o"), (tr["motor_t"], tr["motor_stroke"],
                          "stroke (motor)", "-"), (tr["daq_t"], tr["daq_force"], "force (DAQ)", "-")):
        m = (t >= a) & (t <= z)
        ax1.plot(t[m], _norm(y)[m], st, ms=2.5, lw=1.0, label=lab)
    ax1.set_xlabel("tracker clock (s from its first frame)")
    ax1.set_ylabel("normalised")
    ax1.set_title(f"cycle {mid} after alignment")
    ax1.legend(loc="upper right", fontsize=8)
    for name, c in ing.clocks.items():
        if c.window_t_s.size:
            fit = c.offset_s + c.drift_ppm * 1e-6 * (c.window_t_s - c.t_mid_s)
            ax2.plot(c.to_ref(c.window_t_s), (c.window_lag_s - fit) * 1e3, "o-", ms=4,
                     label=f"{name} ({c.method}): offset {c.offset_s * 1e3:.2f} +- {c.offset_err_s * 1e3:.2f} ms, "
                           f"drift {c.drift_ppm:.1f} +- {c.drift_err_ppm:.1f} ppm")
    ax2.axhline(0, color="k", lw=0.8)
    ax2.set_xlabel("tracker clock (s)")
    ax2.set_ylabel("window lag - fit (ms)")
    ax2.legend(fontsize=8)
    return _png(fig)


def angle_png(ing: Ingested) -> bytes:
    """Bend angle and out-of-plane rotation per tracker frame; frames without a pose marked below."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    b = ing.bend
    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8.5, 5.6), sharex=True, constrained_layout=True,
                                   gridspec_kw={"height_ratios": [3, 1.3]})
    ax1.plot(b.time_s, b.angle_deg, lw=0.7, label="bend angle")
    lost = ~b.valid
    if lost.any():
        ax1.plot(b.time_s[lost], np.full(lost.sum(), np.nanmin(b.angle_deg) - 1.0), "|", color="C3", ms=8,
                 label=f"no pose ({lost.sum()} frames)")
    ax1.set_ylabel("angle (deg)")
    ax1.legend(loc="upper right", fontsize=8)
    ax1.set_title(f"bend axis (base coil frame) {np.array2string(b.axis, precision=3)}; rest: {b.n_rest} frames")
    ax2.plot(b.time_s, b.out_of_plane_deg, lw=0.6, color="C2")
    ax2.set_ylabel("out of plane (deg)")
    ax2.set_xlabel("tracker clock (s from its first frame)")
    return _png(fig)


def dropouts_png(ing: Ingested) -> bytes:
    """Timeline: per coil the frames not tracked (by state), the export's absent frames, the logs' gaps."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    b, tr = ing.bend, ing.traces
    fig, ax = plt.subplots(figsize=(8.5, 2.8), constrained_layout=True)
    lanes = []
    for role in ("tip", "base"):
        st = tr.get(f"{role}_state")
        if st is None:
            continue
        y = len(lanes)
        lanes.append(f"{role} coil")
        for k, state in enumerate(sorted({str(s) for s in st if str(s).lower() != "ok"})):
            m = np.array([str(s) == state for s in st])
            ax.plot(b.time_s[m], np.full(m.sum(), y), "|", ms=14, color=f"C{k + 3}", label=f"{role}: {state} ({m.sum()})")
    dt = np.diff(b.time_s)
    med = float(np.median(dt))
    y = len(lanes)
    lanes.append("tracker export")
    for k in np.flatnonzero(dt > 1.5 * med):
        ax.plot([b.time_s[k], b.time_s[k + 1]], [y, y], lw=6, color="C1")
    for name in ("daq", "motor"):
        t = tr[f"{name}_t"]
        d = np.diff(t)
        y = len(lanes)
        lanes.append(f"{name} log")
        ax.plot([t[0], t[-1]], [y, y], lw=1, color="0.7")
        for k in np.flatnonzero(d > 1.5 * float(np.median(d))):
            ax.plot([t[k], t[k + 1]], [y, y], lw=6, color="C1")
    ax.set_yticks(range(len(lanes)), lanes)
    ax.set_ylim(-0.7, len(lanes) + 0.9)
    ax.set_xlabel("tracker clock (s from its first frame); orange: gaps in a log")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="upper right", ncol=2)
    return _png(fig)


def summary_lines(ing: Ingested) -> list[str]:
    """The report's numbers as text lines (also printed by the command)."""
    d = ing.data
    out = [f"rows: {len(d)} (sample {d.sample[0]}, cycles 1-{int(d.cycle.max())}, "
           f"stroke {d.stroke_mm.min():.3f} to {d.stroke_mm.max():.3f} mm, force {d.force_N.min():.3f} to "
           f"{d.force_N.max():.3f} N, angle {np.nanmin(d.angle_deg):.2f} to {np.nanmax(d.angle_deg):.2f} deg)"]
    for name, c in ing.clocks.items():
        line = (f"{name} clock ({c.method}): offset {c.offset_s:+.4f} s +- {c.offset_err_s * 1e3:.2f} ms, "
                f"drift {c.drift_ppm:+.1f} +- {c.drift_err_ppm:.1f} ppm (at {name} time {c.t_mid_s:.1f} s)")
        if np.isfinite(c.runner_up):
            line += f"; next best offset {c.runner_up_lag_s:+.2f} s scores {100 * c.runner_up:.0f} %"
        out.append(line)
    fl = ", ".join(f"{r} {s}: {n}" for (r, s), n in sorted(ing.flagged.items())) or "none"
    out.append(f"tracker dropouts: {ing.dropouts} frames (flagged: {fl}; absent from the export: {ing.absent_frames})")
    out.append("frames without a row: " + ", ".join(f"{k} {v}" for k, v in ing.dropped.items()))
    out.append(f"gaps: " + ", ".join(f"{k} {v}" for k, v in ing.gaps.items()))
    for k, lines in ing.set_aside.items():
        shown = ", ".join(str(int(x)) for x in lines[:3]) + (", ..." if lines.size > 3 else "")
        out.append(f"set aside: {ing.sources.get(k, k)}: {lines.size} line(s) whose time stamp repeats the line "
                   f"before (lines {shown}; the first at each stamp kept)")
    oop = ing.bend.out_of_plane_deg[ing.bend.valid]
    if np.isfinite(oop).any():
        out.append(f"out-of-plane rotation: RMS {ing.bend.out_of_plane_rms_deg:.3f} deg, max {np.nanmax(oop):.3f} deg")
    return out


def report_html(ing: Ingested, title: str) -> str:
    """The one-page HTML (figures by file name: alignment.png, angle.png, dropouts.png)."""
    esc = html.escape
    items = "".join(f"<li>{esc(s)}</li>" for s in summary_lines(ing))
    src = "".join(f"<li>{esc(k)}: <code>{esc(v)}</code></li>" for k, v in ing.sources.items())
    return (f"<!doctype html>\n<html><head><meta charset='utf-8'><title>{esc(title)}</title>"
            "<style>body{font-family:sans-serif;max-width:60em;margin:1em auto}img{max-width:100%}</style>"
            f"</head><body>\n<h1>{esc(title)}</h1>\n<ul>{src}</ul>\n<ul>{items}</ul>\n"
            "<h2>Clock alignment</h2><img src='alignment.png' alt='alignment'>\n"
            "<h2>Angle from poses</h2><img src='angle.png' alt='angle from poses'>\n"
            "<h2>Dropouts and gaps</h2><img src='dropouts.png' alt='dropouts'>\n</body></html>\n")


def report_files(ing: Ingested, title: str) -> dict[str, bytes | str]:
    """``{file name: payload}`` of the report directory."""
    return {"index.html": report_html(ing, title), "alignment.png": alignment_png(ing),
            "angle.png": angle_png(ing), "dropouts.png": dropouts_png(ing)}
