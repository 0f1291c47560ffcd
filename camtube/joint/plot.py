"""Picture of the bent tube at several tendon strokes (matplotlib, imported only here)."""
from __future__ import annotations

import io
import math

import numpy as np

from camtube.design.pattern import Pattern
from camtube.joint.forward import Mechanics, simulate


def _outline(points: np.ndarray, plane: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Both walls of the tube in the bending plane: the axis offset by +-radius along its in-plane normal."""
    xy = np.c_[points @ plane, points[:, 2]]  # (in-plane lateral, axial)
    d = np.gradient(xy, axis=0)
    d /= np.maximum(np.linalg.norm(d, axis=1, keepdims=True), 1e-12)
    nrm = np.c_[-d[:, 1], d[:, 0]]
    return xy + radius * nrm, xy - radius * nrm


def bend_png(pattern: Pattern, strokes_mm, angle_deg: float | None = None,
             mechanics: Mechanics = Mechanics(), title: str = "") -> bytes:
    """PNG of the tube's side view in one direction's bending plane, one outline per stroke.

    Parameters
    ----------
    strokes_mm : sequence of float
        Tendon strokes (mm) of the direction ``angle_deg`` (default: the first direction).
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    if angle_deg is None:
        angle_deg = pattern.notches[0].angle_deg
    a = math.radians(angle_deg)
    plane = np.array([math.cos(a), math.sin(a), 0.0])
    ro = pattern.tube.outer_radius_mm
    fig, ax = plt.subplots(figsize=(6.4, 5.2), dpi=120)
    colours = plt.cm.viridis(np.linspace(0.1, 0.85, len(strokes_mm)))
    for stroke, col in zip(strokes_mm, colours):
        st = simulate(pattern, {angle_deg: stroke}, mechanics)
        d = st.direction(angle_deg)
        left, right = _outline(st.centerline_mm, plane, ro)
        ax.fill(np.r_[left[:, 0], right[::-1, 0]], np.r_[left[:, 1], right[::-1, 1]], color=col, alpha=0.25, lw=0)
        ax.plot(left[:, 0], left[:, 1], color=col, lw=1)
        ax.plot(right[:, 0], right[:, 1], color=col, lw=1,
                label=f"stroke {stroke:g} mm: {d.bend_deg:.1f} deg, {d.force_N:.2f} N, strain {d.strain.max():.3f}")
        ax.plot(st.centerline_mm @ plane, st.centerline_mm[:, 2], color=col, lw=0.6, ls="--")
    ax.set_aspect("equal")
    ax.set_xlabel(f"lateral, towards the notches at {angle_deg:g} deg (mm)")
    ax.set_ylabel("along the straight tube from its base (mm)")
    ax.set_title(title or f"{pattern.name}: predicted shape (notch-by-notch model)", fontsize=10)
    ax.legend(fontsize=7, loc="lower left")
    ax.grid(alpha=0.3)
    buf = io.BytesIO()
    fig.tight_layout()
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()
