"""Pass paths as paths, not segments: curves cut as few chords within the path tolerance.

A drawing's curves (arcs, fillets, ellipses, splines, bulges) arrive flattened to
chords 25 nm from the curve (``TOL.chord``): thousands of vertices a millimetre,
each of which a machine would treat as a move of its own. A pass path is cut
within ``TOL.path`` (1 um) instead: :func:`simplify_closed` keeps only the
vertices needed for every dropped vertex to lie within the tolerance of the chord
that replaces it, and only on the side of the chord *outside* the cut region,
so the chords never leave the region (the region lies on the left of a
counter-clockwise path). A true corner always stays a vertex (it lies farther
than the tolerance from any chord across it). Rectangles and polygons come out
unchanged; open paths (slits) are never simplified, since the safety check
allows a slit's beam only ``TOL.safety`` off its path.

:func:`turn_angles_deg` gives the turn at each vertex of a path; vertices that
turn by more than ``TOL.corner_deg`` are its true corners.
"""
from __future__ import annotations

import numpy as np

from camtube.tol import TOL


def signed_area_mm2(points: np.ndarray) -> float:
    """Shoelace area of a closed ring (mm^2): positive when counter-clockwise."""
    x, y = points[:, 0], points[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def simplify_closed(points, tol_mm: float = TOL.path, inside_mm: float = 0.0) -> np.ndarray:
    """The vertices of a closed path that keep it within ``tol_mm`` of the given one, chords inside.

    Parameters
    ----------
    points : (n, 2) float
        Vertices of a closed path (mm), without the closing repeat of the first; the first
        vertex is kept (the pass starts there).
    tol_mm : float
        Largest distance (mm) of a dropped vertex from its chord on the outside of the chord.
    inside_mm : float
        Largest distance (mm) a dropped vertex may lie on the inside (the chord then passes
        outside the given path by that much): 0 for a path on the design line; a pass offset
        into the removed region may give up to half its offset.

    Returns
    -------
    (k, 2) float
        The kept vertices in order, ``k <= n``.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    n = len(pts)
    if n < 4:
        return pts
    sgn = 1.0 if signed_area_mm2(pts) >= 0 else -1.0  # +: the region is on the left of each chord
    ring = np.vstack([pts, pts[:1]])
    keep = np.zeros(n + 1, dtype=bool)
    keep[0] = keep[-1] = True
    left = max(float(inside_mm), 1e-9)
    stack = [(0, n)]
    while stack:
        i, j = stack.pop()
        if j - i < 2:
            continue
        a, b = ring[i], ring[j]
        q = ring[i + 1:j]
        d = b - a
        L2 = float(d @ d)
        if L2 < 1e-24:  # the closing chord of the whole ring: split at the vertex farthest from its start
            k = i + 1 + int(np.argmax(np.hypot(*(q - a).T)))
        else:
            L = L2 ** 0.5
            rel = q - a
            cross = sgn * (d[0] * rel[:, 1] - d[1] * rel[:, 0]) / L  # > 0: the vertex lies inside the chord
            t = (rel @ d) / L2
            # distance to the chord as a segment (beyond an end: to that end), by side
            tc = np.clip(t, 0.0, 1.0)
            dist = np.hypot(rel[:, 0] - tc * d[0], rel[:, 1] - tc * d[1])
            viol = np.where(cross > 0, dist / left, dist / tol_mm)
            m = int(np.argmax(viol))
            if viol[m] <= 1.0:
                continue
            k = i + 1 + m
        keep[k] = True
        stack.append((i, k))
        stack.append((k, j))
    return ring[keep][:-1]


def turn_angles_deg(points, closed: bool = True) -> np.ndarray:
    """(n,) float: how far the path turns at each vertex (deg, 0..180); 0 at the ends of an open path."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    n = len(p)
    if n < 3:
        return np.zeros(n)
    d_in = p - np.roll(p, 1, axis=0)
    d_out = np.roll(p, -1, axis=0) - p
    a = np.degrees(np.abs(np.arctan2(d_in[:, 0] * d_out[:, 1] - d_in[:, 1] * d_out[:, 0],
                                     np.einsum("ij,ij->i", d_in, d_out))))
    if not closed:
        a[0] = a[-1] = 0.0
    return a
