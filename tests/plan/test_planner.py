"""Planner: pass counts, offsets, kerf, repeats rule, orderings, DXF input."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from camtube.design.contour import Contour, cut_contours, rectangle
from camtube.design.geometry import beam_depth_mm
from camtube.design.loader import load_pattern
from camtube.design.pattern import Process, RepeatRule
from camtube.design.source import DrawingOptions, load_source
from camtube.errors import PatternError
from camtube.export.dxf import add_contour, design_dxf, new_document
from camtube.plan import estimate, job_moves, plan_job, repeats_for
from camtube.plan.packed import pack
from camtube.plan.planner import offset_contour
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def presets():
    return {n: load_pattern(PATTERNS / f"{n}.yaml") for n in ("tube1", "tube2", "tube3", "tube1-bidirectional")}


@pytest.mark.parametrize("name,notch_passes,repeats", [("tube1", 320, 4), ("tube2", 480, 6), ("tube3", 640, 8)])
def test_pass_counts_and_repeats(presets, name, notch_passes, repeats):
    job = plan_job(presets[name])
    assert job.repeats == repeats
    kinds = [p.kind for p in job.passes]
    assert kinds.count("notch") == notch_passes
    assert kinds.count("hole") == 4 * 2 * repeats
    # every (cut, repeat, focus, drill) exactly once
    keys = {(p.cut_index, p.repeat, p.focus_level, p.drill_index) for p in job.passes}
    assert len(keys) == len(job.passes)


@pytest.mark.parametrize("name,depth", [("tube1", 0.983), ("tube2", 1.111), ("tube3", 1.635)])
def test_repeats_rule_on_beam_depth(presets, name, depth):
    p = presets[name]
    arc = max(c.arc_mm for c in p.cuts)
    assert beam_depth_mm(p.tube.outer_radius_mm, arc) == pytest.approx(depth, abs=5e-4)
    assert repeats_for(p.process, depth) == {"tube1": 4, "tube2": 6, "tube3": 8}[name]


def test_explicit_repeats_override_and_rule_gap(presets):
    p = presets["tube3"]
    assert plan_job(p, replace(p.process, repeats=2)).repeats == 2
    with pytest.raises(PatternError, match="repeat_rule"):
        plan_job(p, replace(p.process, repeat_rule=(RepeatRule(1.0, 4),)))


def test_drill_offsets_step_into_the_removed_region(presets):
    p = presets["tube1"]
    job = plan_job(p)
    for ps in job.passes:
        design = job.design[ps.cut_index]
        dx0, dy0, dx1, dy1 = design.bounds
        x0, y0, x1, y1 = ps.contour.bounds
        o = ps.drill_index * p.process.drill_offset_mm
        assert ps.offset_mm == pytest.approx(o)
        assert (x0 - dx0, y0 - dy0, dx1 - x1, dy1 - y1) == pytest.approx((o, o, o, o), abs=1e-12)


def test_kerf_compensation_moves_the_first_cut_by_half_the_kerf(presets):
    p = presets["tube1"]
    kerf = 0.02
    job = plan_job(p, replace(p.process, kerf_mm=kerf))
    first = [ps for ps in job.passes if ps.drill_index == 0]
    for ps in first:
        dx0, dy0, _, _ = job.design[ps.cut_index].bounds
        x0, y0, _, _ = ps.contour.bounds
        # the kerf's outer edge (path - kerf/2) lies on the design line
        assert x0 - kerf / 2 == pytest.approx(dx0, abs=1e-12)
        assert y0 - kerf / 2 == pytest.approx(dy0, abs=1e-12)


def test_vanishing_contour_is_a_clear_error(presets):
    p = presets["tube1"]
    with pytest.raises(PatternError, match="vanishes"):
        plan_job(p, replace(p.process, drill_offset_mm=0.1))  # 3 x 0.1 > 0.3 mm hole / 2


def test_general_polygon_offset_uses_a_mitred_inward_buffer():
    tri = Contour(((0.0, 0.0), (1.0, 0.0), (0.0, 1.0)), "cut", 0)
    inner = offset_contour(tri, 0.05)
    assert inner.area_mm2 > 0 and len(inner.points) == 3
    import shapely

    outer = shapely.Polygon(tri.points)
    assert shapely.Polygon(inner.points).within(outer)
    # every edge of the offset triangle is 0.05 mm from the design triangle
    for x, y in inner.points:
        assert outer.exterior.distance(shapely.Point(x, y)) == pytest.approx(0.05, abs=1e-9)
    with pytest.raises(PatternError, match="vanishes"):
        offset_contour(tri, 0.5)


@pytest.mark.parametrize("ordering", ["interleaved", "sequential", "chained"])
def test_orderings(presets, ordering):
    job = plan_job(presets["tube1"], ordering=ordering)
    cuts = [p.cut_index for p in job.passes]
    n_cut = len(job.design)
    if ordering == "sequential":
        # all 32 passes of a cut are consecutive
        assert sum(1 for a, b in zip(cuts, cuts[1:]) if a != b) == n_cut - 1
    elif ordering == "chained":
        # a round of n_cut x drill passes visits every cut once with one (repeat, focus), its drill passes in a row
        n_drill = job.process.drill_passes
        per = n_cut * n_drill
        for k in range(0, len(cuts), per):
            rnd = job.passes[k:k + per]
            assert sorted(p.cut_index for p in rnd[::n_drill]) == list(range(n_cut))
            assert len({(p.repeat, p.focus_level) for p in rnd}) == 1
            for g in range(0, per, n_drill):
                assert [(p.cut_index, p.drill_index) for p in rnd[g:g + n_drill]] == \
                    [(rnd[g].cut_index, d) for d in range(n_drill)]
    else:
        # a round of n_cut passes visits every cut once with one (repeat, focus, drill)
        for k in range(0, len(cuts), n_cut):
            rnd = job.passes[k:k + n_cut]
            assert sorted(p.cut_index for p in rnd) == list(range(n_cut))
            assert len({(p.repeat, p.focus_level, p.drill_index) for p in rnd}) == 1


def test_default_ordering_meets_the_time_target(presets):
    for name in ("tube1", "tube2", "tube3"):
        e = estimate(plan_job(presets[name]))
        assert e.lower_bound_s == pytest.approx(e.cut_length_mm / 25.0)
        assert 1.0 <= e.ratio <= 1.10, (name, e.ratio)
        assert e.rapid_s > 0 and e.focus_s > 0


def test_start_point_is_the_corner_nearest_the_previous_end(presets):
    job = plan_job(presets["tube1-bidirectional"])
    prev = job.passes[0].contour.points[0]
    for ps in job.passes[1:80]:
        pts = np.asarray(ps.contour.points)
        d = np.hypot(pts[:, 0] - prev[0], pts[:, 1] - prev[1])
        assert d[0] <= d.min() + 0.02  # within the drill step of the nearest corner
        prev = ps.contour.points[0]


def test_seam_crossing_cuts_are_cut_continuously(presets):
    p = presets["tube1-bidirectional"]
    job = plan_job(p)
    seam = [c for c in job.design if c.bounds[1] < 0]
    assert seam, "the bidirectional preset has notches across the seam"
    assert all(len(c.points) == 4 for c in seam)
    assert set(c.points for c in job.design) == set(c.points for c in cut_contours(p))


def test_packed_cache_matches_the_passes(presets):
    job = plan_job(presets["tube1-bidirectional"])
    seeded = job_moves(job)
    # the same passes as Pass objects: Job.packed is then packed from the objects
    fresh = replace(job, passes=tuple(job.passes))
    assert fresh.cache.packed is None
    rebuilt = job_moves(fresh)
    for f in ("x", "y", "z", "kind", "laser", "pass_index", "speed"):
        assert np.array_equal(getattr(seeded, f), getattr(rebuilt, f)), f
    assert len(pack(job).geom_offset) - 1 == len({id(p.contour) for p in job.passes})
    for f in ("pass_cut", "pass_z", "pass_repeat", "pass_focus", "pass_drill", "pass_offset", "pass_power"):
        assert np.array_equal(getattr(job.packed, f), getattr(fresh.packed, f)), f
    # the planner keeps no Pass object per pass: the view builds them on demand
    assert type(job.passes).__name__ == "PassView" and job.passes[5] == fresh.passes[5]
    assert job.cut_length_mm == pytest.approx(sum(p.length_mm for p in fresh.passes))


def _dxf_of(contours, length, circ, tmp_path):
    doc = new_document()
    msp = doc.modelspace()
    doc.layers.add("CUTS")
    doc.layers.add("CONSTRUCTION-OUTLINE")
    add_contour(msp, rectangle(0, 0, length, circ), "CONSTRUCTION-OUTLINE")
    for c in contours:
        add_contour(msp, c, "CUTS")
    path = tmp_path / "hand.dxf"
    doc.saveas(path)
    return path


def test_dxf_input_plans_like_the_pattern(presets, tmp_path):
    p = presets["tube2"]
    path = tmp_path / "t2.dxf"
    path.write_text(design_dxf(p))
    drawn = load_source(path, [], DrawingOptions(outer_radius_mm=p.tube.outer_radius_mm)).pattern
    job = plan_job(drawn, p.process)
    ref = plan_job(p)
    assert job.repeats == 6 and len(job.passes) == len(ref.passes)
    assert job.length_mm == pytest.approx(p.tube.length_mm)
    assert estimate(job).cut_length_mm == pytest.approx(estimate(ref).cut_length_mm)
    with pytest.raises(PatternError, match="outer radius"):
        load_source(path, [], DrawingOptions(outer_radius_mm=0.5))  # the outline says 0.85
    with pytest.raises(PatternError, match="not a file"):
        plan_job(path, p.process)  # the planner takes patterns; drawings are design input


def test_dxf_of_general_contours(tmp_path):
    ro = 1.0
    circ = 2 * math.pi * ro
    hexagon = Contour(tuple((2 + 0.4 * math.cos(a), 3 + 0.8 * math.sin(a))
                            for a in np.linspace(0, 2 * math.pi, 6, endpoint=False)), "cut")
    path = _dxf_of([hexagon, rectangle(4, 1, 4.5, 2.5)], 8.0, circ, tmp_path)
    job = plan_job(load_source(path, [], DrawingOptions(outer_radius_mm=ro)).pattern, Process())
    arc = 1.6 * math.sin(math.pi / 3)  # the hexagon's y extent is the largest arc
    assert beam_depth_mm(ro, arc) < 1.0 and job.repeats == 4
    assert len(job.passes) == 2 * 4 * 2 * 4
    hexagon_passes = [p for p in job.passes if len(p.contour.points) == 6]
    assert len(hexagon_passes) == 32
    from camtube.export.gcode import gcode
    from camtube.plan.safety import check_job

    check_job(job)
    assert "M62 P0" in gcode(job)


@settings(max_examples=25, deadline=None)
@given(n=st.integers(1, 6), w=st.floats(0.2, 1.0), s=st.floats(0.5, 3.0), angle=st.floats(0, 359))
def test_every_planned_job_is_safe(n, w, s, angle):
    from camtube.plan.safety import check_job

    p = load_pattern(PATTERNS / "tube1.yaml", [f"notch.count={n}", f"notch.width={w:.3f}", f"notch.arc={s:.3f}",
                                               f"notch.angle_deg={angle:.3f}", f"tube.length={3 + 2 * n}"])
    for ordering in ("interleaved", "sequential", "chained"):
        check_job(plan_job(p, ordering=ordering))
