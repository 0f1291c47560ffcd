"""Pictures (PNG bytes, matplotlib Agg, headless, deterministic).

- :func:`tube_png`: a shaded 3-D view of a tube mesh, turned so the notches face the viewer.
- :func:`unrolled_png`: the unrolled sheet with the design cuts and, if given, the simulated
  as-cut removed region, overcut (red) and undercut (blue).
"""
from __future__ import annotations

import io
import math

import numpy as np


def _figure(width_in: float, height_in: float):
    import matplotlib

    matplotlib.use("Agg", force=False)
    from matplotlib.figure import Figure

    return Figure(figsize=(width_in, height_in), dpi=110)


def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()


#: Largest mesh :func:`tube_png` draws (faces); a picture of a bigger one is unreadable anyway.
TUBE_PNG_MAX_FACES = 600_000


def picture_faces(mesh) -> tuple[np.ndarray, np.ndarray]:
    """Vertices and faces of ``mesh`` split for the painter's algorithm, which sorts whole triangles.

    Long triangles are split so the depth order holds: to a quarter of the diameter for a short
    tube; a long tube is drawn small, so to a sixtieth of its length at most -- splitting its
    sliver faces (the whole length long) to the diameter would multiply the faces by (L / D)^2
    (20 million faces at L = 300 mm).
    """
    from trimesh.remesh import subdivide_to_size

    t_lo, t_hi = np.asarray(mesh.bounds)
    edge = max(0.25 * float(min(t_hi[1] - t_lo[1], t_hi[2] - t_lo[2])), float(t_hi[0] - t_lo[0]) / 60.0)
    return subdivide_to_size(np.asarray(mesh.vertices, float), np.asarray(mesh.faces), max_edge=edge)


def tube_png(mesh, *, facing_angle_deg: float = 240.0, title: str = "", elevation_deg: float = 10.0,
             yaw_deg: float = 20.0, max_faces: int = TUBE_PNG_MAX_FACES) -> bytes:
    """Shaded orthographic picture of a tube mesh along X (painter's algorithm, flat shading).

    Parameters
    ----------
    mesh : trimesh.Trimesh
        Tube along X (mm), frame of :mod:`camtube.cad.frame`.
    facing_angle_deg : float
        Rotary angle turned towards the viewer (the notch side).
    title : str
    elevation_deg, yaw_deg : float
        The viewer looks from ``facing_angle_deg`` raised by ``elevation_deg`` towards the
        tube's axis, turned by ``yaw_deg`` towards the tip.
    max_faces : int
        Refuse bigger meshes (raises ValueError): a picture of them is unreadable anyway.
    """
    from matplotlib.collections import PolyCollection

    if len(mesh.faces) > max_faces:
        raise ValueError(f"mesh has {len(mesh.faces)} faces, more than max_faces={max_faces} for a picture")

    def rx(a):
        c, s = math.cos(a), math.sin(a)
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])

    def rz(a):
        c, s = math.cos(a), math.sin(a)
        return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])

    # facing angle -> -Y (towards the camera), then tilt and yaw; camera looks along +Y
    verts, faces = picture_faces(mesh)
    rot = rz(math.radians(yaw_deg)) @ rx(math.radians(elevation_deg)) @ rx(-math.pi / 2.0 - math.radians(facing_angle_deg))
    v = verts @ rot.T
    tri = v[faces]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.maximum(np.linalg.norm(n, axis=1, keepdims=True), 1e-300)
    visible = n[:, 1] < 0.0  # facing the camera (at -Y)
    tri, n = tri[visible], n[visible]
    light = np.array([-0.4, -0.8, 0.45])
    light /= np.linalg.norm(light)
    shade = 0.30 + 0.70 * np.clip(n @ light, 0.0, 1.0)
    order = np.argsort(-tri[:, :, 1].mean(axis=1), kind="stable")  # far first
    base = np.array([0.85, 0.58, 0.18])  # polyimide amber
    colours = np.column_stack([shade[order, None] * base, np.ones(len(order))])
    xy = tri[order][:, :, [0, 2]]

    lo, hi = v[:, [0, 2]].min(axis=0), v[:, [0, 2]].max(axis=0)
    span = np.maximum(hi - lo, 1e-6)
    width = min(2.0 + 10.0 * span[0] / max(span[0], 6.0 * span[1]), 14.0)
    height = max(width * span[1] / span[0] + (0.4 if title else 0.1), 1.2)
    fig = _figure(width, height)
    ax = fig.add_axes((0.01, 0.01, 0.98, 0.98 - (0.3 / height if title else 0.0)))
    ax.add_collection(PolyCollection(xy, facecolors=colours, edgecolors=colours, linewidths=0.15))
    pad = 0.02 * span[0]
    ax.set_xlim(lo[0] - pad, hi[0] + pad)
    ax.set_ylim(lo[1] - pad, hi[1] + pad)
    ax.set_aspect("equal")
    ax.set_axis_off()
    if title:
        fig.suptitle(title, fontsize=9, y=0.99, va="top")
    return _png(fig)


def _patch(poly, **kw):
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path
    from shapely.geometry.polygon import orient

    poly = orient(poly, 1.0)
    rings = [np.asarray(poly.exterior.coords)[:, :2]] + [np.asarray(r.coords)[:, :2] for r in poly.interiors]
    verts = np.concatenate(rings)
    codes = np.concatenate([[Path.MOVETO] + [Path.LINETO] * (len(r) - 2) + [Path.CLOSEPOLY] for r in rings])
    return PathPatch(Path(verts, codes), **kw)


def unrolled_png(design_contours, length_mm: float, outer_radius_mm: float, ascut=None, title: str = "") -> bytes:
    """The unrolled outer surface (x right, y up, mm) with the cuts.

    Parameters
    ----------
    design_contours : sequence of Contour
        Design cuts (unwrapped; folded onto the sheet for drawing).
    length_mm, outer_radius_mm : float
    ascut : camtube.cad.ascut.AsCut, optional
        Draws the removed region (grey), overcut (red) and undercut (blue).
    """
    import shapely
    from shapely.geometry import Polygon

    from camtube.cad.ascut import _polys, design_region, wrap_sheet

    circ = 2.0 * math.pi * outer_radius_mm
    aspect = length_mm / circ
    fig = _figure(min(3.0 + 2.2 * aspect, 16.0), 3.6)
    ax = fig.add_subplot(111)
    ax.add_patch(_patch(Polygon([(0, 0), (length_mm, 0), (length_mm, circ), (0, circ)]),
                        facecolor="#f4e3c8", edgecolor="#888888", linewidth=0.6))
    if ascut is not None:
        for p in _polys(wrap_sheet(ascut.removed, circ)):
            ax.add_patch(_patch(p, facecolor="#555555", edgecolor="none", alpha=0.55))
        over = shapely.difference(wrap_sheet(ascut.removed, circ), wrap_sheet(shapely.union_all(ascut.design), circ))
        under = shapely.difference(wrap_sheet(shapely.union_all(ascut.design), circ), wrap_sheet(ascut.removed, circ))
        for p in _polys(over):
            ax.add_patch(_patch(p, facecolor="#d62728", edgecolor="none"))
        for p in _polys(under):
            ax.add_patch(_patch(p, facecolor="#1f77b4", edgecolor="none"))
    for c in design_contours:
        region = Polygon(c.points) if getattr(c, "closed", True) else design_region(c, 0.02)
        for p in _polys(wrap_sheet(region, circ)):
            ax.add_patch(_patch(p, facecolor="none", edgecolor="black" if c.kind == "notch" else "#1f4fb4",
                                linewidth=0.7))
    ax.set_xlim(-0.02 * length_mm, 1.02 * length_mm)
    ax.set_ylim(-0.05 * circ, 1.05 * circ)
    ax.set_aspect("equal")
    ax.set_xlabel("x from the tip (mm)")
    ax.set_ylabel("y = r_o * angle (mm)")
    note = "design outlines; grey = removed as cut, red = overcut, blue = undercut" if ascut is not None else \
        "design outlines"
    ax.set_title((title + ": " if title else "") + note, fontsize=8)
    fig.tight_layout()
    return _png(fig)
