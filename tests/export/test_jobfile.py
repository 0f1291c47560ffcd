"""Job file camtube.job/2: valid JSON, one entry per cut, exact numbers, deterministic bytes, and a reader
whose expansion equals the planner's passes."""
from __future__ import annotations

import json
import re

import numpy as np
import pytest

from camtube.design.contour import Contour, rectangle
from camtube.design.loader import load_pattern
from camtube.design.pattern import Process
from camtube.errors import DataError
from camtube.export.dialects import LINUXCNC
from camtube.export.gcode import gcode
from camtube.export.jobfile import SCHEMA, iter_job_json, job_json, read_job
from camtube.plan import estimate, plan_job
from camtube.machine.motion_time import estimate_program
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def job():
    return plan_job(load_pattern(PATTERNS / "tube1-bidirectional.yaml"))


def test_schema_and_content(job):
    d = json.loads(job_json(job))
    assert d["schema"] == SCHEMA == "camtube.job/2"
    assert list(d)[:3] == ["schema", "generator", "name"]
    assert "passes" not in d  # not every point of every pass: one entry per cut
    assert len(d["cuts"]) == len(job.design) == 18
    assert sorted(d["tour"]) == list(range(18))
    e = estimate(job)
    s = d["summary"]
    assert s["passes"] == 576 and s["cuts"] == 18
    assert s["cut_length_mm"] == e.cut_length_mm  # exact round trip
    assert s["constant_speed_time_s"] == pytest.approx(e.total_s, rel=1e-12)
    assert s["constant_speed_time_s"] == pytest.approx(s["cut_time_s"] + s["rapid_time_s"] + s["focus_time_s"]
                                                       + s["lead_time_s"], rel=1e-12)
    # the total is motion-aware for the recorded machine: the same figure from the written G-code's text
    assert d["machine"]["name"] == LINUXCNC.profile.name
    assert d["machine"]["axes"]["X"]["max_acceleration"] == LINUXCNC.profile.axis("X").max_acceleration
    assert s["total_time_s"] == pytest.approx(estimate_program(gcode(job, LINUXCNC), LINUXCNC.profile).total_s,
                                              abs=2e-6)
    assert s["total_time_s"] > s["lower_bound_s"]
    assert s["ratio"] == pytest.approx(s["total_time_s"] / s["lower_bound_s"], abs=1e-6)
    for i, (c, design) in enumerate(zip(d["cuts"], job.design)):
        assert c["index"] == i and c["kind"] == design.kind and c["closed"] is True
        assert [tuple(p) for p in c["points"]] == list(design.points)
        assert len(c["start"]) == 2  # interleaved: one start vertex per tour direction
    # classes: 2 focus levels x 4 drill cuts with the paper's offsets
    assert [(k["focus_level"], k["drill_index"]) for k in d["classes"]] == [(f, i) for f in (0, 1) for i in range(4)]
    assert [k["offset_mm"] for k in d["classes"][:4]] == pytest.approx([0.0, 0.005, 0.01, 0.015])


@pytest.mark.parametrize("ordering", ["interleaved", "sequential", "chained"])
@pytest.mark.parametrize("name", ["tube1-bidirectional", "tube3"])
def test_reader_expands_to_the_planners_passes(tmp_path, name, ordering):
    job = plan_job(load_pattern(PATTERNS / f"{name}.yaml"), ordering=ordering)
    path = tmp_path / "j.job.json"
    path.write_text(job_json(job))
    back = read_job(path)
    assert back.name == job.name and back.repeats == job.repeats and back.ordering == ordering
    assert back.process == job.process and back.design == job.design
    assert len(back.passes) == len(job.passes)
    assert list(back.passes) == list(job.passes)  # geometry, provenance and settings, exactly
    assert gcode(back, LINUXCNC) == gcode(job, LINUXCNC)


def test_reader_expands_slits_and_general_polygons(tmp_path):
    hexagon = Contour(tuple((2 + 0.4 * np.cos(a), 3 + 0.8 * np.sin(a))
                            for a in np.linspace(0, 2 * np.pi, 6, endpoint=False)), "cut")
    slit = Contour(((4.0, 1.0), (4.5, 1.2), (5.0, 1.2)), "cut", closed=False)
    for ordering in ("interleaved", "sequential", "chained"):
        job = plan_job([hexagon, slit, rectangle(6, 1, 6.5, 2.5)], Process(kerf_mm=0.01), ordering=ordering,
                       outer_radius_mm=1.0, length_mm=8.0)
        back = read_job(json.loads(job_json(job)))
        assert list(back.passes) == list(job.passes)
        assert json.loads(job_json(job))["cuts"][1]["closed"] is False


def test_reader_refuses_other_schemas_and_contradictions(tmp_path, job):
    d = json.loads(job_json(job))
    with pytest.raises(DataError, match="schema 'camtube.job/1'"):
        read_job(dict(d, schema="camtube.job/1"))
    bad = json.loads(job_json(job))
    bad["classes"][2]["offset_mm"] = 0.5
    with pytest.raises(DataError, match="classes differ"):
        read_job(bad)
    bad = json.loads(job_json(job))
    bad["tour"] = bad["tour"][:-1]
    with pytest.raises(DataError, match="permutation"):
        read_job(bad)
    p = tmp_path / "x.json"
    p.write_text("{not json")
    with pytest.raises(DataError, match="not JSON"):
        read_job(p)
    p.write_text("[" * 100_000 + "]" * 100_000)  # valid JSON too deep for the parser: not a RecursionError
    with pytest.raises(DataError, match="not JSON .*nested too deeply"):
        read_job(p)


def test_deterministic_streamed_and_compact(job):
    a = job_json(job)
    b = job_json(plan_job(load_pattern(PATTERNS / "tube1-bidirectional.yaml")))
    assert a.encode() == b.encode()
    assert "".join(iter_job_json(job)) == a
    assert "-0.0," not in a and "-0.0]" not in a
    # one cut per line
    assert len(re.findall(r'^  \{"index": ', a, flags=re.M)) == len(job.design)
    # far smaller than one entry per pass with its points (schema 1 wrote ~150 bytes of points per pass)
    assert len(a) < 60 * len(job.passes)
