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
    fig.tight_layout(rect=(0, 0.07, 1, 0.97))
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()


def centerline_png(pattern: Pattern, strokes, mechanics: Mechanics = Mechanics(), target: np.ndarray | None = None,
                   title: str = "") -> bytes:
    """PNG of the tube's centre line in 3-D (perspective view and its three projections), one line per set of strokes.

    Parameters
    ----------
    strokes : sequence of {angle_deg: stroke_mm}
        Each entry pulls every named tendon to its stroke (mm) at once.
    target : (m, 3) float, optional
        A goal's centre line (mm, the frame of :class:`camtube.joint.forward.JointState`), drawn dashed.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(8.0, 7.6), dpi=120)
    ax3 = fig.add_subplot(2, 2, 1, projection="3d")
    views = [fig.add_subplot(2, 2, k) for k in (2, 3, 4)]
    names = (("x", 0), ("y", 1), ("z", 2))
    pairs = ((0, 2), (1, 2), (0, 1))
    colours = plt.cm.viridis(np.linspace(0.1, 0.85, len(strokes)))
    lines = []
    for s, col in zip(strokes, colours):
        st = simulate(pattern, s, mechanics)
        pts = st.centerline_mm
        label = "strokes " + ", ".join(f"{v:g} mm at {a:g} deg" for a, v in s.items()) + f": tip {st.tip_angle_deg:.1f} deg"
        lines.append((pts, col, "-", label))
    if target is not None:
        lines.append((np.asarray(target), "crimson", "--", "goal's centre line"))
    for pts, col, ls, label in lines:
        ax3.plot(pts[:, 0], pts[:, 1], pts[:, 2], color=col, ls=ls, lw=1.5, label=label)
        for ax, (i, j) in zip(views, pairs):
            ax.plot(pts[:, i], pts[:, j], color=col, ls=ls, lw=1.2)
    every = np.vstack([pts for pts, *_ in lines])
    mid, half = (every.max(axis=0) + every.min(axis=0)) / 2.0, max(float(np.ptp(every, axis=0).max()) / 2.0, 1e-3)
    ax3.set_xlim(mid[0] - half, mid[0] + half)  # a cube: equal scales on the three axes
    ax3.set_ylim(mid[1] - half, mid[1] + half)
    ax3.set_zlim(mid[2] - half, mid[2] + half)
    ax3.set_box_aspect((1, 1, 1))
    ax3.set_xlabel("x (mm)")
    ax3.set_ylabel("y (mm)")
    ax3.set_zlabel("z, from the base (mm)")
    fig.legend(*ax3.get_legend_handles_labels(), fontsize=7, loc="lower center", ncol=2)
    for ax, (i, j) in zip(views, pairs):
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlabel(f"{names[i][0]} (mm)", fontsize=7, labelpad=1)
        ax.set_ylabel(f"{names[j][0]} (mm)", fontsize=7, labelpad=1)
        ax.tick_params(labelsize=6)
        ax.grid(alpha=0.3)
    fig.suptitle(title or f"{pattern.name}: predicted centre line (notch-by-notch model)", fontsize=10)
    buf = io.BytesIO()
    fig.tight_layout(rect=(0, 0.07, 1, 0.97))
    fig.savefig(buf, format="png")
    plt.close(fig)
    return buf.getvalue()
