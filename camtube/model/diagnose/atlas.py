"""Residual atlas: where the model fails, against every variable a missing effect could hide in.

``residual_atlas(data, residual_deg, n_bins=16) -> Atlas`` bins the residual
(measured - model, deg) against stroke, force, angle, direction of motion,
cycle number and time, and gives the median and quartiles per bin (a smoothed
trend robust to outliers). Against stroke it also gives one trend per
direction of motion (loading / unloading), the view in which play, friction
and viscoelasticity differ.

Each :class:`Panel` also carries ``explained``: the fraction of the residual's
variance that its binned median explains (0 = the residual does not depend on
this variable, 1 = it is a function of it). The diagnosis uses these numbers
to describe the residual in words.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from camtube.model.data.dataset import Dataset

#: (key, label, unit) of the atlas panels, in display order.
VARIABLES = (
    ("stroke_mm", "stroke", "mm"),
    ("force_N", "force", "N"),
    ("angle_deg", "angle", "deg"),
    ("direction", "direction of motion", ""),
    ("cycle", "cycle", ""),
    ("time_s", "time", "s"),
)


@dataclass(frozen=True, eq=False)
class Panel:
    """Binned residual against one variable.

    Attributes
    ----------
    key, label, unit : str
    centre : (b,) float
        Bin centres (for ``direction``: -1, +1; for ``cycle``: the cycle numbers when few).
    median, q25, q75 : (b,) float
        Residual statistics per bin, deg (NaN for empty bins).
    count : (b,) int
    explained : float
        Variance fraction of the residual explained by the binned median.
    by_direction : dict[int, tuple[(b,) float, (b,) float]]
        For ``stroke_mm`` only: direction (+1/-1) -> (centres, medians).
    """

    key: str
    label: str
    unit: str
    centre: np.ndarray
    median: np.ndarray
    q25: np.ndarray
    q75: np.ndarray
    count: np.ndarray
    explained: float
    by_direction: dict


@dataclass(frozen=True, eq=False)
class Atlas:
    """All panels plus the residual's RMSE (deg)."""

    panels: tuple[Panel, ...]
    rmse_deg: float

    def panel(self, key: str) -> Panel:
        for p in self.panels:
            if p.key == key:
                return p
        raise KeyError(key)


def variable(data: Dataset, key: str) -> np.ndarray:
    """(n,) float values of one atlas variable of ``data``."""
    if key == "direction":
        return data.direction.astype(float)
    return np.asarray(getattr(data, key), float)


def binned(x: np.ndarray, r: np.ndarray, edges: np.ndarray) -> tuple[np.ndarray, ...]:
    """Median, 25 and 75 % quantiles and count of ``r`` in bins of ``x`` with ``edges`` (b+1,).

    Returns arrays of shape ``(b,)`` and the (n,) bin index of each row.
    """
    b = edges.size - 1
    idx = np.clip(np.searchsorted(edges, x, side="right") - 1, 0, b - 1)
    order = np.argsort(idx, kind="stable")
    si, sr = idx[order], r[order]
    bounds = np.searchsorted(si, np.arange(b + 1))
    med = np.full(b, np.nan)
    q25 = np.full(b, np.nan)
    q75 = np.full(b, np.nan)
    cnt = np.diff(bounds)
    for k in range(b):
        seg = sr[bounds[k]:bounds[k + 1]]
        if seg.size:
            q25[k], med[k], q75[k] = np.percentile(seg, [25, 50, 75])
    return med, q25, q75, cnt, idx


def _explained(r: np.ndarray, med: np.ndarray, idx: np.ndarray) -> float:
    var = float(np.mean((r - r.mean()) ** 2))
    if var <= 0:
        return 0.0
    fit = np.where(np.isfinite(med[idx]), med[idx], 0.0)
    return float(max(0.0, 1.0 - np.mean((r - fit) ** 2) / var))


def residual_atlas(data: Dataset, residual_deg: np.ndarray, n_bins: int = 16) -> Atlas:
    """The residual atlas of ``residual_deg`` (n,) over the rows of ``data`` (see the module docstring)."""
    r = np.asarray(residual_deg, float)
    panels = []
    for key, label, unit in VARIABLES:
        x = variable(data, key)
        if key == "direction":
            edges = np.array([-1.5, 0.0, 1.5])
        elif key == "cycle":
            cycles = np.unique(x)
            if cycles.size <= 60:
                edges = np.concatenate((cycles - 0.5, [cycles[-1] + 0.5]))
            else:
                edges = np.linspace(cycles[0] - 0.5, cycles[-1] + 0.5, n_bins + 1)
        else:
            lo, hi = (float(np.min(x)), float(np.max(x))) if x.size else (0.0, 1.0)
            edges = np.linspace(lo, hi if hi > lo else lo + 1.0, n_bins + 1)
        med, q25, q75, cnt, idx = binned(x, r, edges)
        by_dir: dict = {}
        if key == "stroke_mm":
            d = data.direction
            for sgn in (1, -1):
                m = d == sgn
                if m.any():
                    md, *_ = binned(x[m], r[m], edges)
                    by_dir[sgn] = (0.5 * (edges[1:] + edges[:-1]), md)
        centre = np.array([-1.0, 1.0]) if key == "direction" else 0.5 * (edges[1:] + edges[:-1])
        panels.append(Panel(key, label, unit, centre, med, q25, q75, cnt, _explained(r, med, idx), by_dir))
    return Atlas(tuple(panels), float(np.sqrt(np.mean(r**2))) if r.size else 0.0)


def describe(atlas: Atlas, floor_deg: float) -> list[str]:
    """Sentences on where the residual lives (variables explaining >= 20 % of it), strongest first."""
    out = []
    for p in sorted(atlas.panels, key=lambda q: -q.explained):
        if p.explained < 0.2 or atlas.rmse_deg <= 1.05 * floor_deg:
            continue
        span = float(np.nanmax(p.median) - np.nanmin(p.median))
        out.append(f"the residual depends on {p.label}: its binned median spans {span:.2f} deg and "
                   f"explains {100 * p.explained:.0f}% of the residual variance")
    return out
