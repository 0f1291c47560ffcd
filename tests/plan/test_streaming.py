"""Chunked moves and the streaming G-code emitter: chunk boundaries change nothing; LEAD moves are emitted gated off."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.errors import SafetyError
from camtube.export.dialects import GRBL, LINUXCNC
from camtube.export.gcode import gcode, iter_gcode
from camtube.plan import estimate, job_moves, plan_job
from camtube.plan.moves import CUT, LEAD, RAPID, Moves, iter_moves
from camtube.plan.safety import check_job, check_moves
from tests.conftest import PATTERNS
from tests.export.test_gcode_rs274 import canonical, replay


@pytest.fixture(scope="module")
def job():
    return plan_job(load_pattern(PATTERNS / "tube1-bidirectional.yaml"))


def test_chunks_concatenate_to_the_whole_move_list(job):
    whole = job_moves(job)
    for size in (1, 7, 100, 10_000):
        chunks = list(iter_moves(job, size))
        assert len(chunks) == math.ceil(len(job.passes) / size)
        for a, b in zip(chunks, chunks[1:]):
            assert b.start == a.end and b.first_pass == int(a.pass_index[-1]) + 1
        cat = Moves.concat(chunks)
        for f in ("x", "y", "z", "kind", "laser", "pass_index", "vertex", "speed"):
            assert np.array_equal(getattr(cat, f), getattr(whole, f)), f
        starts = [np.concatenate(c) for c in zip(*(ch.starts() for ch in chunks))]
        for s, w in zip(starts, whole.starts()):
            assert np.array_equal(s, w)


@pytest.mark.parametrize("dialect", [LINUXCNC, GRBL], ids=lambda d: d.name)
def test_gcode_in_small_chunks_is_byte_identical(job, dialect):
    whole = gcode(job, dialect)
    chunked = gcode(job, dialect, moves=list(iter_moves(job, 13)))  # row by row, every boundary exercised
    assert chunked == whole
    assert "".join(iter_gcode(job, dialect)) == whole
    e = estimate(job, list(iter_moves(job, 5)))
    assert e.total_s == pytest.approx(estimate(job).total_s, rel=1e-12)


def test_an_unsafe_chunk_is_never_yielded(job):
    mv = job_moves(job)
    x = mv.x.copy()
    bad_row = int(np.flatnonzero(mv.pass_index == 300)[3])  # a cut move of pass 300
    x[bad_row] += 0.7  # out of its notch (0.3 mm wide), still on the tube
    from dataclasses import replace

    edited = replace(mv, x=x)
    cut = int(mv.pass_rows()[290])  # chunks hold whole passes: 0..289, 290..
    chunks = [edited.rows(0, cut), edited.rows(cut, len(mv))]
    it = iter_gcode(job, LINUXCNC, moves=chunks)
    next(it)  # the header
    first = next(it)
    assert "pass 0:" in first and "pass 300:" not in first
    with pytest.raises(SafetyError, match="pass 300 "):
        next(it)


def with_leads(job, n_pass: int = 6, reach_mm: float = 0.05) -> Moves:
    """The job's moves with a lead-in (from outside the cut) and an over-travel LEAD move around each of
    the first ``n_pass`` passes, laser off, at the scan speed (what a corner strategy adds)."""
    mv = job_moves(job)
    cols = {f: getattr(mv, f).tolist() for f in ("x", "y", "z", "kind", "laser", "pass_index", "vertex", "speed")}
    rows = mv.pass_rows().tolist()
    out = {f: [] for f in cols}
    sp = job.process.scan_speed_mm_s

    def add(i=None, **v):
        for f in out:
            out[f].append(v[f] if f in v else cols[f][i])

    for p in range(len(rows) - 1):
        r0, r1 = rows[p], rows[p + 1]
        for i in range(r0, r1):
            if p < n_pass and cols["kind"][i] == CUT and cols["kind"][i - 1] != CUT:
                # rapid to a point reach_mm before the start (in -x), then a LEAD move to the start
                j = len(out["x"]) - 1 - (1 if cols["kind"][i - 1] != RAPID else 0)
                sx, sy = out["x"][j], out["y"][j]
                out["x"][j] = sx - reach_mm
                if j != len(out["x"]) - 1:
                    out["x"][-1] = sx - reach_mm
                add(i - 1, x=sx, y=sy, kind=LEAD, laser=False, speed=sp, vertex=-1)
            add(i)
        if p < n_pass:  # over-travel past the end of the pass
            add(r1 - 1, x=cols["x"][r1 - 1] + reach_mm, kind=LEAD, laser=False, speed=sp, vertex=-1)
    arr = {f: np.asarray(v) for f, v in out.items()}
    arr["kind"] = arr["kind"].astype(np.int8)
    arr["laser"] = arr["laser"].astype(bool)
    return Moves(**arr)


def test_lead_moves_are_safe_gated_off_and_fed(job, tmp_path):
    mv = with_leads(job)
    check_moves(job, mv)  # LEAD moves leave the cut region with the gate closed: allowed
    text = gcode(job, LINUXCNC, moves=mv)
    lines = text.splitlines()
    gate, leads = False, 0
    for line in lines:
        if line == "M62 P0":
            gate = True
        elif line in ("M63 P0", "M65 P0"):
            gate = False
        elif line.startswith("G0"):
            assert not gate
        elif line.startswith("G1") and not gate:
            leads += 1
    assert leads == 2 * 6
    assert lines.count("M62 P0") == len(job.passes)
    e = estimate(job, mv)
    assert e.lead_s == pytest.approx(2 * 6 * 0.05 / job.process.scan_speed_mm_s, rel=1e-6)
    # LinuxCNC's interpreter: the lead moves are feeds at the scan speed with the gate closed
    path = tmp_path / "lead.ngc"
    path.write_text(text)
    segs, gates = replay(canonical(path), LINUXCNC, job.outer_radius_mm)
    closed_feeds = [s for s in segs if s[0] == "STRAIGHT_FEED" and not s[3] and abs(s[1][2] - s[2][2]) < 1e-9]
    assert len(closed_feeds) == 12 and gates == len(job.passes)
    for _, a, b, _, surf, secs in closed_feeds:
        assert surf == pytest.approx(0.05, abs=2e-4) and surf / secs == pytest.approx(25.0, rel=0.01)


def test_lead_moves_with_the_laser_on_or_beyond_the_tube_are_refused(job):
    mv = with_leads(job)
    lead = np.flatnonzero(mv.kind == LEAD)
    from dataclasses import replace

    laser = mv.laser.copy()
    laser[lead[1]] = True
    with pytest.raises(SafetyError, match="laser is on during a lead move"):
        check_moves(job, replace(mv, laser=laser))
    x = mv.x.copy()
    x[lead[0]] = job.length_mm + 0.5
    with pytest.raises(SafetyError, match="leaves the tube"):
        check_moves(job, replace(mv, x=x))
    z = mv.z.copy()
    z[lead[2]] += 0.05
    with pytest.raises(SafetyError, match="lead move changes the focus"):
        check_moves(job, replace(mv, z=z))


def test_check_job_is_chunked_and_remembered(job):
    from dataclasses import replace

    fresh = replace(job)
    assert fresh.cache.checked is False  # the cache is the Job's own: a new Job starts empty
    check_job(fresh)
    assert fresh.cache.checked is True
    short = replace(job, length_mm=1.0)
    with pytest.raises(SafetyError, match=r"unsafe move\(s\)"):
        check_job(short)
    assert short.cache.checked is False


def test_survey_checks_and_estimates_once_for_every_writer(job):
    from dataclasses import replace

    from camtube.export.outputs import survey, toolpath_streams

    fresh = replace(job)
    est = survey(fresh)
    assert fresh.cache.checked is True and estimate(fresh) is est is fresh.cache.estimate
    assert est == estimate(replace(job))  # the same figures as the estimate alone
    bad = replace(job, length_mm=1.0)
    streams = toolpath_streams(bad)
    with pytest.raises(SafetyError, match="leaves the tube"):
        next(iter(streams[f"{job.name}.toolpath.dxf"]))


def test_writers_stream_in_bounded_chunks_without_pass_objects():
    from camtube.design.contour import rectangle
    from camtube.design.pattern import Process
    from camtube.plan.moves import CHUNK_PASSES
    from camtube.export.outputs import toolpath_streams

    n = 1000  # 32,000 passes: 8 chunks of passes
    job = plan_job([rectangle(1.5 + i, 0.5, 1.8 + i, 2.5, "notch") for i in range(n)], Process(),
                   outer_radius_mm=0.75, length_mm=n + 3.0)
    assert len(job.passes) == 32 * n
    for name, stream in toolpath_streams(job).items():
        sizes = [len(c) for c in stream]
        total = sum(sizes)
        if name.endswith(".job.json"):  # one line per cut: small anyway
            assert total < 200 * n
            continue
        assert len(sizes) >= len(job.passes) // CHUNK_PASSES, name
        assert max(sizes) < 0.2 * total and max(sizes) < 3e6, (name, max(sizes), total)
    # the writers worked from the arrays: no Pass or Contour object was made per pass
    assert job.passes._contours == {}


@pytest.mark.parametrize("dialect", [LINUXCNC, GRBL], ids=lambda d: d.name)
def test_gate_reopens_after_a_lead_move_inside_a_pass(job, dialect):
    """A corner strategy's over-travel between two cuts: gate off, lead out and back, gate on again
    (with the dialect's formatted gate-on line, e.g. GRBL's ``M4 S200``)."""
    mv = job_moves(job)
    rows = mv.pass_rows()
    i = int(rows[0]) + 3  # after the second cutting move of pass 0
    assert mv.kind[i] == CUT and mv.kind[i + 1] == CUT
    x, y = mv.x[i], mv.y[i]
    ins = {"x": [x + 0.02, x], "y": [y, y], "z": [mv.z[i]] * 2, "kind": [LEAD] * 2, "laser": [False] * 2,
           "pass_index": [0, 0], "vertex": [-1, -1], "speed": [job.process.scan_speed_mm_s] * 2}
    edited = Moves(**{f: np.insert(getattr(mv, f), i + 1, np.asarray(v, dtype=getattr(mv, f).dtype))
                      for f, v in ins.items()})
    check_moves(job, edited)
    text = gcode(job, dialect, moves=edited)
    assert "\x00" not in text and "{" not in text
    first = text.split("pass 0:")[1].split("pass 1:")[0]
    on, off = dialect.laser_on.format(**dialect.fields(2.0, 60.0)), dialect.laser_off
    assert first.count(on) == 2 and first.count(off) == 2
    lines = first.splitlines()
    k = lines.index(off)  # the first gate-off is followed by the two lead moves, then the gate opens again
    assert lines[k + 1].startswith("G1") and lines[k + 2].startswith("G1") and lines[k + 3] == on
    # the rest of the job is unchanged
    assert text.split("pass 1:")[1] == gcode(job, dialect).split("pass 1:")[1]
