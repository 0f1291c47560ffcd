"""Toolpath DXF read back with ezdxf: one layer per (focus, drill) class with its own colour, every pass."""
from __future__ import annotations

import io
from collections import Counter

import ezdxf
import numpy as np
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


def test_streamed_text_is_ezdxfs_own_and_audits_clean(job, tmp_path):
    from camtube.export.dxf import to_string
    from camtube.export.toolpath_dxf import iter_toolpath_dxf, toolpath_document

    chunks = list(iter_toolpath_dxf(job))
    assert len(chunks) >= 3
    text = "".join(chunks)
    assert text == to_string(toolpath_document(job))  # byte for byte what ezdxf writes for the same entities
    path = tmp_path / "t.dxf"
    path.write_text(text)
    doc = ezdxf.readfile(path)
    auditor = doc.audit()
    assert not auditor.has_errors and not auditor.has_fixes, [str(e) for e in auditor.errors + auditor.fixes]
    handles = [e.dxf.handle for e in doc.modelspace()]
    assert len(handles) == len(set(handles)) == len(job.passes) + len(job.design) + 1
    assert int(doc.header["$HANDSEED"], 16) > max(int(h, 16) for h in handles)


def test_slits_are_open_polylines(tmp_path):
    from camtube.design.contour import Contour, rectangle
    from camtube.design.pattern import Process

    slit = Contour(((2.0, 1.0), (3.0, 1.5), (4.0, 1.5)), "cut", closed=False)
    job = plan_job([slit, rectangle(5, 1, 5.5, 2)], Process(), outer_radius_mm=1.0, length_mm=7.0)
    path = tmp_path / "s.dxf"
    path.write_text(toolpath_dxf(job))
    doc = ezdxf.readfile(path)
    assert not doc.audit().has_errors
    polys = [e for e in doc.modelspace().query("LWPOLYLINE") if not e.dxf.layer.startswith("CONSTRUCTION")]
    assert len(polys) == len(job.passes)
    for e, p in zip(polys, job.passes):
        assert e.closed == p.contour.closed
        drawn, planned = np.asarray(e.get_points("xy"), float), np.asarray(p.contour.points, float)
        assert drawn.shape == planned.shape
        np.testing.assert_allclose(drawn, planned, rtol=1e-9, atol=1e-9)
    assert sum(not e.closed for e in polys) == len(job.passes) // 2
