"""Figures of a fit (matplotlib is imported here only, with the Agg backend).

``fit_figure(result, all_data=None)`` returns a matplotlib Figure: one column
per sample; top, angle vs stroke of every cycle in ``all_data`` coloured like
the paper's Fig. 1d (first cycle red, the middle cycles blue, the last 20
green), the fitted rows' model angle on top (black); bottom, residual
(measured - model, deg) vs stroke of the fitted rows. ``fit_png(...) -> bytes``
renders it; write the bytes with :func:`camtube.io.write_atomic`.
"""
from __future__ import annotations

import io

import numpy as np

from camtube.model.data.dataset import Dataset
from camtube.model.core.fit import FitResult

#: The last this many cycles are drawn green (the paper's cycles 31-50).
LAST_CYCLES = 20


def _cycle_groups(cycles: np.ndarray) -> list[tuple[str, str, np.ndarray]]:
    """(label, colour, mask) of the first, middle and last cycles of one sample."""
    c0, c1 = int(cycles.min()), int(cycles.max())
    first = cycles == c0
    last_lo = max(c0 + 1, c1 - LAST_CYCLES + 1)
    last = (cycles >= last_lo) & ~first
    mid = ~first & ~last
    groups = [(f"cycle {c0}", "tab:red", first)]
    if mid.any():
        groups.append((f"cycles {c0 + 1}-{last_lo - 1}", "tab:blue", mid))
    if last.any():
        groups.append((f"cycles {last_lo}-{c1}" if c1 > last_lo else f"cycle {c1}", "tab:green", last))
    return groups


def fit_figure(result: FitResult, all_data: Dataset | None = None, title: str = ""):
    """The angle-stroke and residual-stroke figure of ``result`` (see the module docstring)."""
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    data = result.data
    full = all_data if all_data is not None else data
    samples = data.samples
    fig = Figure(figsize=(4.2 * len(samples), 6.0), dpi=110)
    axes = fig.subplots(2, len(samples), squeeze=False, sharex="col",
                        gridspec_kw={"height_ratios": [3, 1.3]})
    full_slices = dict(full.sample_slices())
    for j, (smp, sl) in enumerate(data.sample_slices()):
        ax, axr = axes[0, j], axes[1, j]
        if smp in full_slices:
            fs = full_slices[smp]
            s, a, c = full.stroke_mm[fs], full.angle_deg[fs], np.asarray(full.cycle[fs])
            for label, colour, m in _cycle_groups(c):
                ax.plot(s[m], a[m], ".", ms=1.5, color=colour, alpha=0.5, label=label, rasterized=True)
        st = data.stroke_mm[sl]
        order = np.argsort(st, kind="stable")
        ax.plot(st[order], result.predicted[sl][order], "-", color="black", lw=1.4, label="model (fitted rows)")
        ax.set_title(f"sample {smp}: RMSE {result.rmse_per_sample[smp]:.2f} deg", fontsize=10)
        ax.grid(alpha=0.3)
        axr.axhline(0.0, color="0.5", lw=0.8)
        axr.plot(st, result.residuals[sl], ".", ms=2, color="black", rasterized=True)
        axr.set_xlabel("tendon stroke (mm)")
        axr.grid(alpha=0.3)
        if j == 0:
            ax.set_ylabel("joint angle (deg)")
            axr.set_ylabel("residual (deg)")
            ax.legend(fontsize=7, loc="upper left", markerscale=4)
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def fit_png(result: FitResult, all_data: Dataset | None = None, title: str = "") -> bytes:
    """PNG bytes of :func:`fit_figure` (no timestamp in the metadata)."""
    fig = fit_figure(result, all_data, title)
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()
