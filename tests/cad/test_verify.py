"""Verification report: passes on the presets, catches broken jobs by cut and place, renders deterministically."""
from __future__ import annotations

import dataclasses
import json

import numpy as np

from camtube.cad.ascut import simulate
from camtube.cad.mesh import tube_mesh
from camtube.cad.verify import analytic_volume_mm3, report_json, report_text, verify
from camtube.design.contour import Contour
from tests.cad.conftest import analytic_volume, job_of, mesh_of, preset


def _full(name, job=None, moves=None):
    p = preset(name)
    job = job or job_of(name)
    a = simulate(job, moves)
    t = p.tube
    am = tube_mesh(t.outer_radius_mm, t.inner_radius_mm, t.length_mm, [a.removed])
    return verify(p, design_mesh=mesh_of(name), ascut=a, ascut_mesh=am)


def test_presets_pass(preset_name):
    p = preset(preset_name)
    assert analytic_volume_mm3(p) == analytic_volume(p)
    r = _full(preset_name)
    assert r.passed, report_text(r)
    names = {c.name for c in r.checks}
    for i, c in enumerate(p.cuts):
        assert f"cut[{i}].slug" in names
        if c.kind == "notch":
            assert {f"notch[{i}].phi", f"notch[{i}].width", f"notch[{i}].phi.as_cut"} <= names
    assert {"design.stl.watertight", "design.stl.volume", "ascut.stl.watertight", "ascut.stl.volume",
            "min_web"} <= names
    phi = [c for c in r.checks if c.name.endswith("].phi")]
    assert all(abs(c.measured / c.expected - 1) < 1e-4 for c in phi)


def test_report_json_and_text_deterministic():
    a, b = _full("tube1"), _full("tube1")
    assert report_json(a) == report_json(b) and report_text(a) == report_text(b)
    doc = json.loads(report_json(a))
    assert doc["format"] == "camtube.cad-verify/1" and doc["passed"] is True and doc["failed"] == 0
    assert len(doc["checks"]) == len(a.checks)


def test_moved_pass_caught_with_cut_and_place():
    job = job_of("tube1")
    passes = list(job.passes)
    i = next(k for k, q in enumerate(passes) if q.cut_index == 5 and q.drill_index == 1)
    q = passes[i]
    passes[i] = dataclasses.replace(q, contour=Contour(tuple((x, y - 0.15) for x, y in q.contour.points),
                                                       q.contour.kind, q.contour.cut_index))
    bad = dataclasses.replace(job, passes=tuple(passes))
    bad.__dict__.pop("packed", None)
    r = _full("tube1", bad)
    assert not r.passed
    failed = {c.name for c in r.failures}
    assert "cut[5].overcut" in failed
    assert all(n.startswith("cut[5]") or n.startswith("notch[5]") for n in failed), failed
    text = report_text(r)
    assert "cut[5].overcut" in text and "x 5.490..6.010 mm" in text


def test_gap_caught_slug_not_freed():
    job = job_of("tube1")
    from camtube.plan import job_moves

    mv = job_moves(job)
    x0, y0, _ = mv.starts()
    cut = np.asarray(job.packed.pass_cut)[mv.pass_index]
    xmid = 0.5 * (job.design[7].bounds[0] + job.design[7].bounds[2])
    gap = mv.laser & (cut == 7) & (x0 == mv.x) & (mv.x > xmid)  # the far axial side, every pass
    r = _full("tube1", job, dataclasses.replace(mv, laser=mv.laser & ~gap))
    failed = {c.name: c for c in r.failures}
    assert "cut[7].slug" in failed and failed["cut[7].slug"].measured == "not freed"
    assert "cut[7].undercut" in failed
    assert "x 7.5" in failed["cut[7].slug"].detail  # names where the cut is
    assert not any(n.startswith("cut[") and not n.startswith("cut[7]") for n in failed)
