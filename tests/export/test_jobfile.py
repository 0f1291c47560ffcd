"""Job file: valid JSON, schema camtube.job/1, every pass, deterministic bytes, fixed float format."""
from __future__ import annotations

import json
import math
import re

import pytest

from camtube.design.loader import load_pattern
from camtube.export.dialects import LINUXCNC
from camtube.export.gcode import gcode
from camtube.export.jobfile import SCHEMA, job_json
from camtube.plan import estimate, plan_job
from camtube.plan.motion_time import estimate_program
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def job():
    return plan_job(load_pattern(PATTERNS / "tube1-bidirectional.yaml"))


def test_schema_and_content(job):
    d = json.loads(job_json(job))
    assert d["schema"] == SCHEMA == "camtube.job/1"
    assert list(d)[:3] == ["schema", "generator", "name"]
    assert len(d["passes"]) == len(job.passes) == 576
    assert len(d["design"]) == len(job.design)
    e = estimate(job)
    s = d["summary"]
    assert s["passes"] == 576 and s["cuts"] == 18
    assert s["constant_speed_time_s"] == pytest.approx(e.total_s, abs=1e-6)
    assert s["constant_speed_time_s"] == pytest.approx(s["cut_time_s"] + s["rapid_time_s"] + s["focus_time_s"],
                                                       abs=3e-6)
    # the total is motion-aware for the recorded machine: the same figure from the written G-code's text
    assert d["machine"]["name"] == LINUXCNC.profile.name
    assert d["machine"]["axes"]["X"]["max_acceleration"] == LINUXCNC.profile.axis("X").max_acceleration
    assert s["total_time_s"] == pytest.approx(estimate_program(gcode(job, LINUXCNC), LINUXCNC.profile).total_s,
                                              abs=2e-6)
    assert s["total_time_s"] > s["lower_bound_s"]
    assert s["ratio"] == pytest.approx(s["total_time_s"] / s["lower_bound_s"], abs=1e-6)
    for k, (pd, ps) in enumerate(zip(d["passes"], job.passes)):
        assert pd["index"] == k and pd["cut_index"] == ps.cut_index and pd["drill_index"] == ps.drill_index
        assert [v for q in pd["points"] for v in q] == pytest.approx(
            [v for q in ps.contour.points for v in q], abs=1e-6)
        # geometry and settings suffice to recompute the length
        pts = pd["points"] + pd["points"][:1]
        length = sum(math.dist(a, b) for a, b in zip(pts, pts[1:]))
        assert length == pytest.approx(pd["length_mm"], abs=1e-5)


def test_deterministic_and_fixed_float_format(job):
    a = job_json(job)
    b = job_json(plan_job(load_pattern(PATTERNS / "tube1-bidirectional.yaml")))
    assert a.encode() == b.encode()
    numbers = re.findall(r"(?<![\w.])-?\d+\.\d+(?:[eE][-+]?\d+)?", re.sub(r'"[^"]*"', '""', a))
    assert numbers and all(re.fullmatch(r"-?\d+\.\d{6}", n) for n in numbers)
    assert "-0.000000" not in a
