"""The ``chained`` ordering: a cut's drill passes as one beam-on path, joined by beam-on links (issue 21).

Checked against independent truth where there is one: the drawing's own geometry (shapely) for where the
links lie, LinuxCNC's interpreter (rs274) for what the G-code asks, and the written program's own estimate.
"""
from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.design.source import DrawingOptions, load_source
from camtube.errors import SafetyError
from camtube.export.dialects import dialect_from_profile
from camtube.export.gcode import gcode
from camtube.export.jobfile import job_json, read_job
from camtube.machine import load_profile
from camtube.machine.bound import time_optimal
from camtube.machine.motion_time import estimate_program, job_estimate
from camtube.plan import estimate, job_moves, plan_job
from camtube.plan.moves import LINK, RAPID, Moves
from camtube.plan.paths import turn_angles_deg
from camtube.plan.safety import check_job, check_moves
from camtube.tol import TOL
from tests.conftest import PATTERNS, ROOT, require_tool


def drawing(name: str, overrides=("process.repeats=1",)):
    loaded = load_source(ROOT / "examples" / "curved" / f"{name}.dxf", list(overrides),
                         DrawingOptions(outer_radius_mm=0.8))
    return loaded.pattern


@pytest.fixture(scope="module", params=["filleted", "slotted", "elliptical", "tube1"])
def pair(request):
    """(interleaved job, chained job) of one drawing or preset."""
    if request.param == "tube1":
        pattern = load_pattern(PATTERNS / "tube1.yaml", ["process.repeats=1"])
    else:
        pattern = drawing(request.param)
    return plan_job(pattern, ordering="interleaved"), plan_job(pattern, ordering="chained")


def test_chained_cuts_the_same_passes_in_groups(pair):
    inter, chain = pair
    pk = chain.packed
    # the same passes (cut, repeat, focus, drill) and so the same cut length, in another order
    key = lambda pk: sorted(zip(pk.pass_cut.tolist(), pk.pass_repeat.tolist(), pk.pass_focus.tolist(),  # noqa: E731
                                pk.pass_drill.tolist()))
    assert key(pk) == key(inter.packed)
    # (a curve's chords depend on where its ring starts, each within TOL.path of the drawing: a few ppm)
    assert chain.cut_length_mm == pytest.approx(inter.cut_length_mm, rel=1e-5)
    n_drill = chain.process.drill_passes
    # a round per (repeat, focus) visits every cut; inside it a cut's drill passes follow each other
    assert pk.pass_drill.tolist() == [d for _ in range(len(pk.pass_drill) // n_drill) for d in range(n_drill)]
    # every pass but a group's first is linked to the one before; focus changes once per round
    assert pk.pass_link.tolist() == [d > 0 for d in pk.pass_drill.tolist()]
    assert int(np.count_nonzero(np.diff(pk.pass_z))) == 2 * chain.repeats - 1


def test_links_are_short_beam_on_moves_inside_the_cut(pair):
    _, job = pair
    check_job(job)  # the safety check passes on every move, links included
    mv = job_moves(job)
    x0, y0, _ = mv.starts()
    link = mv.kind == LINK
    pk = job.packed
    assert int(link.sum()) == int(pk.pass_link.sum()) and mv.laser[link].all()
    assert not ((mv.kind == RAPID) & np.isin(mv.pass_index, np.flatnonzero(pk.pass_link))).any()
    L = np.hypot(mv.x - x0, mv.y - y0)[link]
    d = job.process.drill_offset_mm
    # across the strip between two drill offsets: d on a smooth part, d sqrt(2) at a rectangle's corner
    assert L.min() >= d * (1 - 1e-6) and L.max() <= d * math.sqrt(2) * (1 + 1e-6)
    # each link lies inside its cut's region (shapely, independent of the safety check's own test)
    import shapely

    for i in np.flatnonzero(link).tolist():
        region = shapely.Polygon(job.design[int(pk.pass_cut[mv.pass_index[i]])].points)
        seg = shapely.LineString([(x0[i], y0[i]), (mv.x[i], mv.y[i])])
        assert region.buffer(TOL.safety).covers(seg)
    # counted honestly: beside the cut length, not in it
    est = estimate(job)
    assert est.cut_length_mm == pytest.approx(job.cut_length_mm, rel=1e-12)
    assert est.link_length_mm == pytest.approx(job.link_length_mm, rel=1e-9) == pytest.approx(L.sum(), rel=1e-9)
    assert est.lower_bound_s == pytest.approx(job.cut_length_mm / job.process.scan_speed_mm_s)
    assert job.link_length_mm < 0.001 * job.cut_length_mm  # the beam-on path within 0.1 % of the cut length


@pytest.mark.parametrize("name", ["filleted", "slotted", "elliptical"])
def test_links_of_a_curved_drawing_lie_where_it_is_smooth_and_slow(name):
    """No link at a drawn corner: a group starts (and its links lie) where the drawing turns by less than
    TOL.corner_deg, read on the design contour (flattened to 25 nm); and where it is most curved (the
    machine is slow there anyway): on a fillet or a slot's end, at an ellipse's tip (radius of curvature
    b^2 / a = 0.027 mm there, 7.5 mm on its flanks)."""
    job = plan_job(drawing(name), ordering="chained")
    for starts in job.passes.starts:
        for i, k in enumerate(starts.tolist()):
            c = job.design[i]
            turn = turn_angles_deg(c.points, True)
            n = len(c.points)
            assert max(turn[(k - 1) % n], turn[k], turn[(k + 1) % n]) <= TOL.corner_deg
            x0, y0, x1, y1 = c.bounds
            x, y = c.points[k]
            if name == "elliptical":  # within 0.1 mm of the top or bottom tip
                assert min(abs(y - y0), abs(y1 - y)) < 0.1 and abs(x - 0.5 * (x0 + x1)) < 0.1
            else:  # on a fillet or a slot's half circle: within the radius of the top or bottom
                r = 0.1 if name == "filleted" else 0.2
                assert min(abs(y - y0), abs(y1 - y)) <= r + 1e-9


def test_a_polygon_with_corners_starts_its_links_on_a_smooth_part():
    """A D-shaped cut (a half-disc: two corners, one straight side, one arc): its groups start on the arc."""
    from camtube.design.contour import Contour

    a = np.linspace(-math.pi / 2, math.pi / 2, 181)
    d_shape = Contour(tuple((2.0 + 0.3 * math.cos(t), 1.5 + 0.3 * math.sin(t)) for t in a), "cut")
    job = plan_job([d_shape], ordering="chained", outer_radius_mm=1.0, length_mm=4.0)
    check_job(job)
    pts = np.asarray(d_shape.points)
    for k in job.passes.starts.ravel().tolist():
        assert 0 < k < len(pts) - 1  # not one of the two corners (the first and last points)
    plain = plan_job([d_shape], ordering="interleaved", outer_radius_mm=1.0, length_mm=4.0)
    assert plain.passes.starts[0, 0] == 0  # without chaining: the corner nearest the origin


def test_the_safety_check_refuses_a_bad_link(pair):
    _, job = pair
    mv = job_moves(job)
    i = int(np.flatnonzero(mv.kind == LINK)[0])

    def edited(**cols):
        f = {k: getattr(mv, k).copy() for k in ("x", "y", "z", "kind", "laser", "pass_index", "vertex", "speed")}
        for k, (row, v) in cols.items():
            f[k][row] = v
        return Moves(**f, start=mv.start)

    with pytest.raises(SafetyError, match="link between chained passes runs with the laser off"):
        check_moves(job, edited(laser=(i, False)))
    # a link that leaves the cut: its end moved 0.1 mm out of the region (and the next cut move with it)
    x_out = float(job.design[int(job.packed.pass_cut[mv.pass_index[i]])].bounds[2]) + 0.1
    with pytest.raises(SafetyError, match="leaves the cut region"):
        check_moves(job, edited(x=(i, x_out)))
    # a link into a pass of another cut
    first_rapid = int(np.flatnonzero((mv.kind == RAPID) & (mv.pass_index > 0))[0])
    other = edited(kind=(first_rapid, LINK), laser=(first_rapid, True))
    with pytest.raises(SafetyError, match="link joins passes of different cuts|leaves the cut region"):
        check_moves(job, other)


def test_the_job_file_round_trips_a_chained_job(tmp_path, pair):
    _, job = pair
    back = read_job(tmp_path.joinpath("j.job.json").write_text(job_json(job)) and tmp_path / "j.job.json")
    assert back.ordering == "chained" and list(back.passes) == list(job.passes)
    assert back.packed.pass_link.tolist() == job.packed.pass_link.tolist()
    d = dialect_from_profile(load_profile("linuxcnc-path"))
    assert gcode(back, d) == gcode(job, d)


@pytest.mark.parametrize("machine", ["linuxcnc-path", "linuxcnc-path-airbearing", "linuxcnc-rotary"])
def test_a_chain_opens_the_gate_once(machine, pair):
    """rs274 (LinuxCNC's interpreter) reads the program: one gate-on and one rapid per group of drill passes,
    every feed move with the gate on, the gate switched only at rest (after G61 on the blended profiles)."""
    _, job = pair
    dialect = dialect_from_profile(load_profile(machine))
    text = gcode(job, dialect)
    groups = int(np.count_nonzero(~job.packed.pass_link))
    lines = text.splitlines()
    assert lines.count(f"M62 P{dialect.profile.gate_output}") == groups
    assert sum(ln.startswith("G0 X") for ln in lines) == groups
    if dialect.profile.corner_strategy == "blend":
        for k, ln in enumerate(lines):
            if ln.startswith("M63"):
                assert lines[k - 2] == "G61"
    # the estimate of the written program is the job's (the writers and the estimate see the same moves)
    est = job_estimate(job, dialect)
    assert estimate_program(text, dialect.profile).total_s == pytest.approx(est.total_s, rel=1e-9)
    exe = require_tool("rs274")
    path = ROOT / "build" / f"test_chained_{machine}_{job.name}.ngc"
    path.parent.mkdir(exist_ok=True)
    path.write_text(text)
    try:
        r = subprocess.run([exe, "-g", str(path)], capture_output=True, text=True, timeout=120)
    finally:
        path.unlink()
    assert r.returncode == 0 and "error" not in r.stderr.lower()
    gate, feeds, on_feeds, sets = False, 0, 0, 0
    for line in r.stdout.splitlines():
        if "SET_MOTION_OUTPUT_BIT(0)" in line:
            gate, sets = True, sets + 1
        elif "CLEAR_MOTION_OUTPUT_BIT(0)" in line:
            gate = False
        elif "STRAIGHT_FEED(" in line:
            feeds += 1
            on_feeds += gate
        elif "STRAIGHT_TRAVERSE(" in line:
            assert not gate, "the gate is open on a rapid"
    assert sets == groups and feeds == on_feeds > 0


def test_chaining_saves_the_rapids_and_stops_on_the_blended_profile(pair):
    inter, chain = pair
    p = load_profile("linuxcnc-path")
    d = dialect_from_profile(p)
    assert job_estimate(chain, d).total_s < job_estimate(inter, d).total_s
    a, b = time_optimal(inter, p), time_optimal(chain, p)
    assert b.free_s < a.free_s and b.total_s < a.total_s
    # on a curved drawing the estimate never beats the bound (a relaxed problem: stops only at run ends); a
    # rectangle's corners are blended within 1 um by LinuxCNC, not stopped at, slightly faster than the bound
    if chain.name != "tube1":
        assert b.total_s <= job_estimate(chain, d).total_s * (1 + 1e-9)


def test_the_path_profiles_plan_chained_and_the_rotary_profile_does_not(tmp_path):
    from camtube.commands import main

    assert load_profile("linuxcnc-path").ordering == "chained"
    assert load_profile("linuxcnc-path-airbearing").ordering == "chained"
    assert load_profile("linuxcnc-rotary").ordering == "interleaved"
    dxf = ROOT / "examples" / "curved" / "slotted.dxf"
    for machine, ordering in (("linuxcnc-path", "chained"), ("linuxcnc-rotary", "interleaved")):
        out = tmp_path / machine
        assert main(["toolpath", str(dxf), "--outer-radius", "0.8", "--machine", machine, "-q",
                     "--set", "process.repeats=1", "-o", str(out)]) == 0
        assert read_job(out / "slotted.job.json").ordering == ordering
    out = tmp_path / "asked"
    assert main(["toolpath", str(dxf), "--outer-radius", "0.8", "--machine", "linuxcnc-path", "-q",
                 "--ordering", "interleaved", "--set", "process.repeats=1", "-o", str(out)]) == 0
    assert read_job(out / "slotted.job.json").ordering == "interleaved"


def test_a_chained_job_on_the_overtravel_profile_gets_its_leads_and_no_links(pair):
    """Over-travel gives every edge its own beam-off leads: a chained job's links become rapids there (the gate
    never stays open between passes), and the program is what the estimate timed."""
    _, job = pair
    dialect = dialect_from_profile(load_profile("linuxcnc-surface"))
    text = gcode(job, dialect)  # safety-checked while written
    est = job_estimate(job, dialect)
    assert est.link_length_mm == 0.0
    assert estimate_program(text, dialect.profile).total_s == pytest.approx(est.total_s, rel=1e-9)
    lines = text.splitlines()
    for k, ln in enumerate(lines):
        if ln.startswith("(pass "):  # every pass is entered with the gate closed
            assert lines[k + 1].startswith("G0 ")
