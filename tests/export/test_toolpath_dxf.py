"""Toolpath DXF read back with ezdxf: one layer per (focus, drill) class with its own colour, every pass."""
from __future__ import annotations

import io
from collections import Counter

import ezdxf
import pytest

from camtube.design.loader import load_pattern
from camtube.export.toolpath_dxf import toolpath_dxf
from camtube.plan import plan_job
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def job():
    return plan_job(load_pattern(PATTERNS / "tube3.yaml"))


def test_layers_and_passes(job):
    text = toolpath_dxf(job)
    doc = ezdxf.read(io.StringIO(text))
    classes = [f"F{f}-D{d}" for f in (0, 1) for d in range(4)]
    colours = {doc.layers.get(n).dxf.color for n in classes}
    assert len(colours) == 8
    msp = doc.modelspace()
    per_layer = Counter(e.dxf.layer for e in msp.query("LWPOLYLINE"))
    for n in classes:
        assert per_layer[n] == len(job.design) * job.repeats  # 11 cuts x 8 repeats
    assert doc.layers.get("F1-D2").description.startswith("focus 0.1 mm into the material, inward offset 0.0100 mm")
    # entities in execution order, starting at each pass's start point
    polys = [e for e in msp.query("LWPOLYLINE") if not e.dxf.layer.startswith("CONSTRUCTION")]
    assert len(polys) == len(job.passes)
    for e, p in zip(polys, job.passes):
        assert e.closed
        assert tuple(e.get_points("xy")[0]) == pytest.approx(p.contour.points[0])
    assert doc.layers.get("CONSTRUCTION-DESIGN").dxf.plot == 0


def test_deterministic_and_readable_by_ezdxf(job):
    text = toolpath_dxf(job)
    assert text == toolpath_dxf(plan_job(load_pattern(PATTERNS / "tube3.yaml")))
    msp = ezdxf.read(io.StringIO(text)).modelspace()
    passes = [e for e in msp.query("LWPOLYLINE") if not e.dxf.layer.startswith("CONSTRUCTION") and e.closed]
    assert len(passes) == len(job.passes)
    outline = [e for e in msp.query("LWPOLYLINE") if e.dxf.layer == "CONSTRUCTION-OUTLINE"]
    xs = [p[0] for p in outline[-1].get_points("xy")]
    assert max(xs) - min(xs) == pytest.approx(job.length_mm)
