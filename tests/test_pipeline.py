"""camtube.pipeline: every valid pattern builds and verifies, whatever its directions (issue 9)."""
from __future__ import annotations

import json
import math

import pytest
import trimesh

from camtube.design.loader import load
from camtube.pipeline import BUILD, CAD, CadOptions, Request, run
from tests.conftest import PATTERNS


def _removed_volume(pattern) -> float:
    """Analytic volume removed by the cuts: annular sectors, area on the outer sheet x (r_o^2 - r_i^2) / (2 r_o)."""
    t = pattern.tube
    area = sum(c.width_mm * c.arc_mm for c in pattern.cuts)
    return area * (t.outer_radius_mm ** 2 - t.inner_radius_mm ** 2) / (2 * t.outer_radius_mm)


@pytest.mark.parametrize("overrides", [
    [],  # the shipped bidirectional preset: its notches together span 5.2 mm > one turn of 4.71 mm
    ["notch.layout=directions", "notch.directions_deg=[0, 120, 240]", "notch.arc=2.5", "tube.outer_radius=0.85",
     "tube.inner_radius=0.55"],  # three directions on tube 2 stock
])
def test_multi_direction_patterns_build_and_verify(tmp_path, overrides):
    loaded = load(PATTERNS / "tube1-bidirectional.yaml", overrides)
    p = loaded.pattern
    span = {round(c.angle_deg % 360, 6) for c in p.notches}
    assert len(span) >= 2
    res = run(loaded, tmp_path, Request(what=BUILD, cad=CadOptions(step=not overrides, pictures=False)))
    assert res.verified, "\n".join(res.cad.verdict_lines())
    names = {x.name for x in res.paths}
    assert {f"{p.name}.ngc", f"{p.name}.job.json", f"{p.name}.design.dxf", f"{p.name}.design.stl"} <= names
    mesh = trimesh.load(tmp_path / f"{p.name}.design.stl", force="mesh")
    t = p.tube
    full = math.pi * (t.outer_radius_mm ** 2 - t.inner_radius_mm ** 2) * t.length_mm
    assert mesh.is_watertight
    assert mesh.volume == pytest.approx(full - _removed_volume(p), rel=5e-3)
    assert json.loads((tmp_path / f"{p.name}.verify.json").read_text())["passed"] is True


def test_cad_request_writes_only_cad_files(tmp_path):
    loaded = load(PATTERNS / "tube1.yaml")
    res = run(loaded, tmp_path, Request(what=CAD, cad=CadOptions(step=False, pictures=False)))
    assert sorted(x.name for x in tmp_path.iterdir() if x.name != ".tube1.camtube-set") == sorted(
        x.name for x in res.paths) == ["tube1.ascut.stl", "tube1.design.stl", "tube1.verify.json", "tube1.verify.txt"]
    assert (tmp_path / ".tube1.camtube-set").read_text().split() == [x.name for x in res.paths]   # the set's list
    assert res.estimate is None and res.verified


def test_a_slit_drawing_builds_and_its_kerf_is_verified(tmp_path):
    """Slits (open paths mapped with --layer KERF=slit) go through plan, G-code and the CAD simulation."""
    from camtube.design.source import DrawingOptions, load_source
    from tests.conftest import ROOT

    loaded = load_source(ROOT / "examples" / "dxf" / "slits.dxf", (), DrawingOptions(layers=(("KERF", "slit"),)))
    assert {c.kind for c in loaded.pattern.cuts} == {"slit"}
    res = run(loaded, tmp_path, Request(what=BUILD, cad=CadOptions(step=False, pictures=False)))
    assert res.verified, "\n".join(res.cad.verdict_lines())
    # the as-cut region of each slit is the kerf band along it: area = length x kerf (+ round ends)
    from camtube.cad.ascut import design_region

    kerf = 0.02
    for c in res.job.design:
        assert not c.closed
        assert design_region(c, kerf).area == pytest.approx(c.length_mm * kerf + math.pi * (kerf / 2) ** 2, rel=1e-3)


def test_two_outputs_of_one_name_are_refused_not_one_silently_lost():
    from camtube.errors import CamtubeError
    from camtube.pipeline import _add_outputs

    files = {"t.job.json": b"job"}
    with pytest.raises(CamtubeError, match=r"t\.job\.json: two outputs .* fix: give the machine profile"):
        _add_outputs(files, {"t.job.json": iter(["G0"])})
    assert files == {"t.job.json": b"job"}
