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


@pytest.mark.parametrize("name", ["circle_hole", "seam_split", "slits", "blocks", "bulges", "spline"])
def test_exact_solid_of_drawn_cuts(name):
    """The B-rep removes the drawing's area; fillets (bulges) and a spline walled by curves through their chords."""
    pytest.importorskip("build123d")
    from camtube.cad.solid import design_solid, volume_mm3

    pattern, cuts = load(name)
    solid = design_solid(pattern)
    assert solid.is_valid
    assert volume_mm3(solid) == pytest.approx(truth_volume(pattern, cuts), rel=1e-5)


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


def _tool_faces(tool) -> int:
    return len(tool.faces())


def test_a_drawn_circle_is_walled_by_curves_not_a_face_per_chord():
    """The CIRCLE hole (flattened to hundreds of chords) is a prism of four faces: two caps, two half walls; its
    volume is nearer the circle's area mapped radially than the chords' polygon is."""
    pytest.importorskip("build123d")
    from camtube.cad.mesh import design_regions
    from camtube.cad.solid import drawn_tool, smooth_runs, volume_mm3

    pattern, cuts = load("circle_hole")
    hole = design_regions(pattern)[[c.kind for c in pattern.cuts].index("hole")]
    pts = hole.points
    assert len(pts) > 100   # the reader's chords
    assert [len(r) for r in smooth_runs(pts)] == [len(pts) // 2 + 1, len(pts) - len(pts) // 2 + 1]
    r0, r1 = 0.6, 1.1
    want = cuts[2]["area_mm2"] / RO * (r1**2 - r0**2) / 2
    smooth, faceted = drawn_tool(pts, RO, r0, r1), drawn_tool(pts, RO, r0, r1, smooth=False)
    assert _tool_faces(smooth) == 4 and _tool_faces(faceted) == len(pts) + 2
    assert smooth.is_valid
    assert abs(volume_mm3(smooth) / want - 1) < 0.25 * abs(volume_mm3(faceted) / want - 1)   # 1.5e-5, 1e-4


def test_a_drawn_polygon_keeps_its_corners():
    """A 24-gon drawn as such (15 deg turns, edges alike) is not rounded: a curve through its vertices would leave
    its edges by far more than the pass tolerance, so each edge keeps its face and the volume is the polygon's."""
    pytest.importorskip("build123d")
    from shapely.geometry import Polygon

    from camtube.cad.solid import drawn_tool

    pts = [(3.0 + 0.3 * math.cos(2 * math.pi * k / 24), 2.0 + 0.3 * math.sin(2 * math.pi * k / 24)) for k in range(24)]
    r0, r1 = 0.6, 1.1
    tool = drawn_tool(pts, RO, r0, r1)
    assert _tool_faces(tool) == 24 + 2
    assert float(tool.volume) == pytest.approx(Polygon(pts).area / RO * (r1**2 - r0**2) / 2, rel=1e-7)


def test_a_rounded_rectangle_keeps_its_sides_as_lines():
    """Four sides and four fillets of chords: the sides stay one face each, each fillet one curved face."""
    from camtube.cad.solid import smooth_runs

    x0, y0, x1, y1, r = 2.0, 1.0, 2.5, 3.0, 0.1
    pts = []
    for cx, cy, a0 in ((x1 - r, y0 + r, -90), (x1 - r, y1 - r, 0), (x0 + r, y1 - r, 90), (x0 + r, y0 + r, 180)):
        pts += [(cx + r * math.cos(math.radians(a0 + 90 * k / 40)), cy + r * math.sin(math.radians(a0 + 90 * k / 40)))
                for k in range(41)]
    runs = smooth_runs(pts)
    assert sorted(len(r) for r in runs) == [2] * 4 + [41] * 4


def test_many_drawn_holes_cut_in_one_boolean(tmp_path):
    """Sixty round holes: each adds four faces to the solid (a face per chord took minutes and gigabytes for a
    hundred, scripts/bench_cad.py), and the volume is the drawing's."""
    pytest.importorskip("build123d")
    import ezdxf

    from camtube.cad.solid import design_solid, volume_mm3

    doc = ezdxf.new("R2010")
    doc.header["$INSUNITS"] = 4
    msp = doc.modelspace()
    circ, length, radius = 2 * math.pi * RO, 8.0, 0.1
    msp.add_lwpolyline([(0, 0), (length, 0), (length, circ), (0, circ)], close=True, dxfattribs={"layer": "OUTLINE"})
    for i in range(12):
        for j in range(5):
            msp.add_circle((0.6 + 0.6 * i, 0.5 + j * circ / 5), radius, dxfattribs={"layer": "HOLES"})
    path = tmp_path / "holes.dxf"
    doc.saveas(path)
    pattern = load_drawing(path, [f"tube.inner_radius={RI}"], DrawingOptions()).pattern
    assert len(pattern.cuts) == 60
    solid = design_solid(pattern)
    assert solid.is_valid
    assert len(solid.faces()) <= 4 + 4 * 60
    ring = RO**2 - RI**2
    want = math.pi * ring * length - 60 * math.pi * radius**2 / RO * ring / 2
    assert volume_mm3(solid) == pytest.approx(want, rel=1e-6)
