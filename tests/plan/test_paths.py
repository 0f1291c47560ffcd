"""Pass paths as paths: curves cut as few chords within TOL.path, never outside the region.

Independent truth: shapely's distances between the simplified and the given polygons,
and ezdxf's own reading of the curved example drawings.
"""
from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from camtube.design.source import DrawingOptions, load_source
from camtube.plan import plan_job
from camtube.plan.paths import simplify_closed, turn_angles_deg
from camtube.tol import TOL
from tests.conftest import ROOT


def ellipse(a_mm: float, b_mm: float, n: int = 4000, start_deg: float = 0.0) -> np.ndarray:
    t = np.radians(start_deg) + np.linspace(0.0, 2 * math.pi, n, endpoint=False)
    return np.column_stack([a_mm * np.cos(t), b_mm * np.sin(t)])


def check(points: np.ndarray, out: np.ndarray, tol: float, inside: float = 1e-9) -> None:
    given_ = shapely.Polygon(points)
    got = shapely.Polygon(out)
    assert np.array_equal(out[0], points[0])  # the pass still starts where it did
    # every kept vertex is a given one, in order
    idx = [int(np.flatnonzero(np.all(points == p, axis=1))[0]) for p in out]
    assert idx == sorted(idx)
    # chords never leave the region (beyond the allowance): points along every chord, 0 inside
    f = np.linspace(0.0, 1.0, 21)[:, None, None]
    along = (out[None, :, :] * (1 - f) + np.roll(out, -1, axis=0)[None, :, :] * f).reshape(-1, 2)
    assert shapely.distance(given_, shapely.points(along)).max() <= inside + 1e-9
    assert got.area <= given_.area + 1e-12
    # and every given vertex lies within tol of the chords
    ring = shapely.LinearRing(out)
    d = shapely.distance(shapely.points(points), ring)
    assert d.max() <= tol * (1 + 1e-9)


@settings(max_examples=40, deadline=None)
@given(a=st.floats(0.2, 3.0), b=st.floats(0.2, 3.0), start=st.floats(0.0, 360.0),
       tol=st.sampled_from([1e-4, 1e-3, 5e-3]))
def test_ellipses_become_few_chords_inside_within_tolerance(a, b, start, tol):
    pts = ellipse(a, b, 2000, start)
    out = simplify_closed(pts, tol)
    check(pts, out, tol)
    # few chords: a chord of a curve of radius R may span sqrt(8 R tol); halving (Douglas-Peucker)
    # keeps at most twice the fewest chords the tightest curvature needs
    r_min = min(a, b) ** 2 / max(a, b)
    perimeter = shapely.LinearRing(pts).length
    assert len(out) <= 2 * perimeter / math.sqrt(8 * r_min * tol) + 8


def test_clockwise_paths_keep_their_chords_inside():
    pts = ellipse(1.0, 0.3)[::-1]
    out = simplify_closed(pts, 1e-3)
    check(pts, out, 1e-3)


def test_corners_and_polygons_are_kept():
    square = np.array([[0, 0], [1, 0], [1, 1], [0, 1]], float)
    assert np.array_equal(simplify_closed(square), square)
    hexagon = np.column_stack([np.cos(np.arange(6) * math.pi / 3), np.sin(np.arange(6) * math.pi / 3)])
    assert np.array_equal(simplify_closed(hexagon), hexagon)
    # a filleted rectangle: its four straight edges become one chord each, the fillets a few
    fillet = shapely.box(0, 0, 0.4, 3.0).buffer(-0.1).buffer(0.1, quad_segs=64)
    pts = np.asarray(fillet.exterior.coords)[:-1][::-1]
    out = simplify_closed(pts, TOL.path)
    check(pts, out, TOL.path)
    assert len(out) < 60


def test_a_concave_run_keeps_its_vertices():
    """Chords across a concave curve would leave the region: those vertices stay."""
    t = np.linspace(0, math.pi, 400)
    # a square with a semicircular bite out of its bottom edge (concave), CCW
    bite = np.column_stack([1.5 - 0.3 * np.cos(t), 0.3 * np.sin(t)])
    pts = np.concatenate([[[0.0, 0.0]], bite, [[3.0, 0.0], [3.0, 2.0], [0.0, 2.0]]])
    out = simplify_closed(pts, 1e-3)
    check(pts, out, 1e-3)
    assert len(out) > 300


@pytest.mark.parametrize("name", ["filleted", "slotted", "elliptical"])
def test_curved_drawings_plan_to_few_chords_on_the_drawn_curve(name):
    loaded = load_source(ROOT / "examples" / "curved" / f"{name}.dxf", ["process.repeats=1"],
                         DrawingOptions(outer_radius_mm=0.8))
    job = plan_job(loaded.pattern)
    pk = job.packed
    design_vertices = sum(len(c.points) for c in job.design)
    first = [int(np.flatnonzero(pk.pass_cut == i)[0]) for i in range(len(job.design))]
    path_vertices = sum(int(pk.geom_size[pk.pass_geom[p]]) for p in first)
    assert path_vertices * 4 < design_vertices
    # the drill-0 paths lie on the drawn outline within the path tolerance, chords inside it
    for p in first:
        c = job.design[int(pk.pass_cut[p])]
        path = np.asarray(pk.path_points(int(pk.pass_geom[p])))
        region = shapely.Polygon(c.points)
        assert shapely.distance(shapely.points(np.asarray(c.points)), shapely.LinearRing(path)).max() <= TOL.path
        assert shapely.Polygon(path).difference(region.buffer(TOL.safety)).area == 0.0
    # the true corners of the drawing: none for slots and ellipses, none for fillets (all tangent)
    assert all((turn_angles_deg(c.points) > TOL.corner_deg).sum() == 0 for c in job.design)
