"""CAD of drawn cuts: the mesh and the exact B-rep remove what the drawing shows (volumes vs the generator's truth)."""
from __future__ import annotations

import math
from pathlib import Path

import pytest
import yaml

from camtube.design.drawing import load_drawing
from camtube.design.source import DrawingOptions

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "dxf"
EXPECTED = yaml.safe_load((EXAMPLES / "expected.yaml").read_text())
RO, RI = EXPECTED["outer_radius_mm"], 0.7


def load(name: str):
    case = EXPECTED["cases"][name]
    o = case["options"]
    opts = DrawingOptions(layers=tuple(tuple(x) for x in o.get("layers", ())))
    return load_drawing(EXAMPLES / case["file"], [f"tube.inner_radius={RI}"], opts).pattern, case["cuts"]


def truth_volume(pattern, cuts, kerf_mm: float = 0.02) -> float:
    """Tube minus every cut's true sheet area (slits: the kerf-wide band with round ends) mapped radially."""
    ring = RO**2 - RI**2
    area = 0.0
    for c in cuts:
        area += c["area_mm2"] if "area_mm2" in c else c["length_mm"] * kerf_mm + math.pi * (kerf_mm / 2) ** 2
    return math.pi * ring * pattern.tube.length_mm - area / RO * ring / 2.0


@pytest.mark.parametrize("name", ["bulges", "spline", "circle_hole", "seam_split", "blocks", "slits"])
def test_design_mesh_removes_the_drawn_area(name):
    pytest.importorskip("manifold3d")
    from camtube.cad.mesh import design_mesh
    from camtube.cad.verify import analytic_volume_mm3

    pattern, cuts = load(name)
    mesh = design_mesh(pattern, segments=256)
    want = truth_volume(pattern, cuts)
    assert mesh.is_watertight
    assert analytic_volume_mm3(pattern) == pytest.approx(want, rel=1e-5)  # chord flattening only
    assert float(mesh.volume) == pytest.approx(want, rel=2e-4)  # polygonal tube (256 sides): ~1e-4


@pytest.mark.parametrize("name", ["circle_hole", "seam_split", "slits", "blocks"])
def test_exact_solid_of_drawn_cuts(name):
    pytest.importorskip("build123d")
    from camtube.cad.solid import design_solid

    pattern, cuts = load(name)
    solid = design_solid(pattern)
    assert solid.is_valid
    assert float(solid.volume) == pytest.approx(truth_volume(pattern, cuts), rel=1e-5)


def test_drawn_tool_walls_are_radial():
    """A drawn prism's volume is its sheet area mapped radially: exact only if every wall is radial."""
    pytest.importorskip("build123d")
    from shapely.geometry import Polygon

    from camtube.cad.solid import drawn_tool

    pts = [(2.0, 2.0), (2.6, 2.0), (2.4, 4.5), (2.0, 4.0), (1.7, 3.0)]
    r0, r1 = 0.6, 1.1
    tool = drawn_tool(pts, RO, r0, r1)
    assert float(tool.volume) == pytest.approx(Polygon(pts).area / RO * (r1**2 - r0**2) / 2, rel=1e-7)


def test_verification_of_a_drawing_passes_and_says_what_it_skipped(tmp_path):
    pytest.importorskip("manifold3d")
    from camtube.cad.outputs import cad_models
    from camtube.cad.verify import report_text, verify
    from camtube.plan import plan_job

    pattern, _ = load("circle_hole")
    job = plan_job(pattern)
    m = cad_models(pattern, job, step=False)
    report = verify(pattern, design_mesh=m.design_mesh, ascut=m.ascut, ascut_mesh=m.ascut_mesh, segments=m.segments)
    assert report.passed, report_text(report)
    names = {c.name for c in report.checks}
    assert "notch[1].phi" in names and "notch[0].phi" not in names  # cut[0] is the CIRCLE hole; notches are rectangles
    pattern, _ = load("bulges")
    m = cad_models(pattern, plan_job(pattern), step=False)
    report = verify(pattern, design_mesh=m.design_mesh, ascut=m.ascut, ascut_mesh=m.ascut_mesh, segments=m.segments)
    assert report.passed, report_text(report)
    assert "are not rectangles" in report_text(report)
    assert not any(c.name.endswith(".phi") for c in report.checks)
