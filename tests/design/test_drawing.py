"""Drawings in common CAD styles (examples/dxf) import to the cuts the generator's own truth says, or are refused.

The truth in ``examples/dxf/expected.yaml`` comes from ``make_examples.py``:
shapely shapes, exact areas and scipy's B-spline, built in the tube frame
independently of camtube's reader.
"""
from __future__ import annotations

import math
from pathlib import Path

import ezdxf
import pytest
import yaml
from ezdxf.disassemble import recursive_decompose
from shapely.geometry import LineString, Polygon

from camtube.design.contour import cut_contour
from camtube.design.drawing import load_drawing
from camtube.design.source import DrawingOptions, load_source
from camtube.errors import PatternError
from tests.conftest import PATTERNS

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "dxf"
EXPECTED = yaml.safe_load((EXAMPLES / "expected.yaml").read_text())
RO = EXPECTED["outer_radius_mm"]
C = 2 * math.pi * RO
AREA_RTOL = 5e-4        # 0.05 %
CENTROID_TOL_MM = 0.01


def options(o: dict) -> DrawingOptions:
    return DrawingOptions(outer_radius_mm=o.get("outer_radius_mm"), length_mm=o.get("length_mm"), units=o.get("units"),
                          layers=tuple(tuple(x) for x in o.get("layers", ())))


def _dy(a: float, b: float) -> float:
    """Distance of two y positions on the wrapped sheet."""
    d = (a - b) % C
    return min(d, C - d)


def _dangle(a: float, b: float) -> float:
    d = (a - b) % 360.0
    return min(d, 360.0 - d)


def measured(cut) -> dict:
    con = cut_contour(cut, RO)
    if cut.kind == "slit":
        g = LineString(con.points)
        m = g.interpolate(0.5, normalized=True)
        return {"kind": "slit", "length_mm": g.length, "point": (m.x, m.y), "angle_deg": cut.angle_deg,
                "x_mm": (cut.x_start_mm, cut.x_end_mm)}
    g = Polygon(con.points)
    assert g.is_valid
    return {"kind": cut.kind, "area_mm2": g.area, "point": (g.centroid.x, g.centroid.y), "angle_deg": cut.angle_deg,
            "x_mm": (cut.x_start_mm, cut.x_end_mm)}


ACCEPTED = [n for n, c in EXPECTED["cases"].items() if "cuts" in c]
REFUSED = [n for n, c in EXPECTED["cases"].items() if "refused" in c]


def test_every_construct_of_the_issue_has_an_example():
    names = set(EXPECTED["cases"])
    for need in ("outline_layer0", "inches", "blocks", "four_lines", "gap_1e-4", "spline", "circle_hole", "bulges",
                 "offset_outline", "duplicate", "backbone_thin", "wrong_radius", "slits", "slits_unmapped",
                 "seam_split", "unitless_refused", "open_outline"):
        assert need in names


@pytest.mark.parametrize("name", ACCEPTED)
def test_drawing_imports_the_drawn_cuts(name):
    case = EXPECTED["cases"][name]
    loaded = load_drawing(EXAMPLES / case["file"], [], options(case["options"]))
    want = case["cuts"]
    got = [measured(c) for c in loaded.pattern.cuts]
    assert sorted(g["kind"] for g in got) == sorted(w["kind"] for w in want)
    assert loaded.pattern.tube.outer_radius_mm == pytest.approx(RO, abs=1e-6)
    for w in want:
        wp = w.get("centroid_mm") or w["midpoint_mm"]
        same_kind = [g for g in got if g["kind"] == w["kind"]]
        g = min(same_kind, key=lambda g: math.hypot(g["point"][0] - wp[0], _dy(g["point"][1], wp[1])))
        got.remove(g)
        where = f"{name}: {w['kind']} near x = {wp[0]:.3f}"
        assert math.hypot(g["point"][0] - wp[0], _dy(g["point"][1], wp[1])) <= CENTROID_TOL_MM, where
        if w["kind"] == "slit":
            assert g["length_mm"] == pytest.approx(w["length_mm"], rel=AREA_RTOL), where
        else:
            assert g["area_mm2"] == pytest.approx(w["area_mm2"], rel=AREA_RTOL), where
        # position on the tube: angle of the cut's centre and its axial extent
        assert _dangle(g["angle_deg"], w["angle_deg"]) <= math.degrees(CENTROID_TOL_MM / RO), where
        assert g["x_mm"] == pytest.approx(w["x_mm"], abs=1e-3), where
    for phrase in case.get("summary", []):
        assert phrase in loaded.summary, (phrase, loaded.summary)


@pytest.mark.parametrize("name", ACCEPTED)
def test_every_entity_is_accounted_for(name):
    """The summary counts every drawn entity (blocks expanded by ezdxf's own recursive_decompose)."""
    case = EXPECTED["cases"][name]
    loaded = load_drawing(EXAMPLES / case["file"], [], options(case["options"]))
    doc = ezdxf.readfile(EXAMPLES / case["file"])
    n = sum(1 for _ in recursive_decompose(doc.modelspace()))
    assert f"from {n} entities" in loaded.summary or f"from {n} entity" in loaded.summary


@pytest.mark.parametrize("name", REFUSED)
def test_drawing_is_refused_naming_the_entity(name):
    case = EXPECTED["cases"][name]
    with pytest.raises(PatternError) as err:
        load_drawing(EXAMPLES / case["file"], [], options(case["options"]))
    text = str(err.value)
    for phrase in case["refused"]:
        assert phrase in text, (phrase, text)
    for issue in err.value.issues:
        assert issue.file and issue.fix  # one line naming the file, the entity and the fix


def test_inches_equal_mm():
    mm = load_drawing(EXAMPLES / "outline_layer0.dxf", [], DrawingOptions()).pattern
    inch = load_drawing(EXAMPLES / "inches.dxf", [], DrawingOptions()).pattern
    for a, b in zip(mm.cuts, inch.cuts):
        assert (a.kind, a.x_mm, a.width_mm, a.arc_mm, a.angle_deg) == pytest.approx(
            (b.kind, b.x_mm, b.width_mm, b.arc_mm, b.angle_deg), abs=1e-9)


def test_drawn_rectangles_stay_rectangles_and_curves_keep_their_outline():
    p = load_drawing(EXAMPLES / "circle_hole.dxf", [], DrawingOptions()).pattern
    assert [c.is_drawn for c in p.cuts] == [True, False, False]  # the CIRCLE hole, then two rectangles
    hole = p.holes[0]
    # chords of the flattened circle lie within TOL.chord of it
    from camtube.tol import TOL

    r = [math.hypot(x - 1.0, y - C / 2) for x, y in hole.outline]
    assert max(r) == pytest.approx(0.15, abs=1e-7) and min(r) >= 0.15 - TOL.chord
    assert len(hole.outline) >= math.pi / math.acos(1 - TOL.chord / 0.15) - 1


def test_units_option_and_conflicts():
    with pytest.raises(PatternError, match="unknown unit"):
        load_drawing(EXAMPLES / "unitless.dxf", [], DrawingOptions(units="furlong"))
    with pytest.raises(PatternError, match="says its units are inch"):
        load_drawing(EXAMPLES / "inches.dxf", [], DrawingOptions(units="mm"))
    # (read in inches the cuts are 25 times larger: their beam depth, 23.6 mm, is beyond the process's repeat rule,
    # a design rule since the bad-input search; the repeats given, the drawing is read)
    with pytest.raises(PatternError, match="no row covers the beam depth 23.603 mm"):
        load_drawing(EXAMPLES / "unitless.dxf", [], DrawingOptions(units="inch"))
    p = load_drawing(EXAMPLES / "unitless.dxf", ["process.repeats=2"], DrawingOptions(units="inch")).pattern
    assert p.tube.length_mm == pytest.approx(254.0)


def test_layer_overrides():
    with pytest.raises(PatternError, match="no such layer.*did you mean 'KERF'"):
        load_drawing(EXAMPLES / "slits.dxf", [], DrawingOptions(layers=(("KERFS", "slit"),)))
    with pytest.raises(PatternError, match="unknown layer role"):
        load_drawing(EXAMPLES / "slits.dxf", [], DrawingOptions(layers=(("KERF", "cut"),)))
    # ignoring the notch layer leaves no cuts: refused, not an empty job
    with pytest.raises(PatternError, match="no cuts"):
        load_drawing(EXAMPLES / "slits.dxf", [], DrawingOptions(layers=(("KERF", "ignore"),)))


def test_slits_are_open_contours():
    p = load_drawing(EXAMPLES / "slits.dxf", [], DrawingOptions(layers=(("KERF", "slit"),))).pattern
    assert len(p.slits) == 9
    for c in p.slits:
        con = cut_contour(c, RO)
        assert con.closed is False and con.kind == "slit" and len(con.points) == 2


def test_settings_from_set_and_a_process_file(tmp_path):
    loaded = load_source(EXAMPLES / "outline_layer0.dxf",
                         [f"process={PATTERNS / 'femto-polyimide.yaml'}", "process.repeats=3",
                          "tube.inner_radius=0.7", "name=t"],
                         DrawingOptions())
    p = loaded.pattern
    assert p.name == "t" and p.tube.inner_radius_mm == 0.7 and p.process.repeats == 3
    assert not any(w.key == "tube.inner_radius" for w in loaded.warnings)
    with pytest.raises(PatternError, match="cuts come from the drawing"):
        load_source(EXAMPLES / "outline_layer0.dxf", ["notch.count=3"], DrawingOptions())
    with pytest.raises(PatternError, match="given twice"):
        load_source(EXAMPLES / "outline_layer0.dxf", ["tube.outer_radius=2"], DrawingOptions(outer_radius_mm=1.0))


def test_no_outline_needs_radius_and_length(tmp_path):
    doc = ezdxf.new("R2013", setup=False)
    doc.header["$INSUNITS"] = 4
    doc.modelspace().add_lwpolyline([(1, 1), (1.5, 1), (1.5, 3), (1, 3)], close=True, dxfattribs={"layer": "NOTCHES"})
    path = tmp_path / "bare.dxf"
    doc.saveas(path)
    with pytest.raises(PatternError, match="no tube outline found.*--outer-radius and --length"):
        load_drawing(path, [], DrawingOptions())
    p = load_drawing(path, [], DrawingOptions(outer_radius_mm=1.0, length_mm=5.0)).pattern
    assert (p.cuts[0].x_mm, p.cuts[0].width_mm, p.cuts[0].arc_mm) == pytest.approx((1.25, 0.5, 2.0))


def test_design_dxf_with_drawn_cuts_reads_back_the_same(tmp_path):
    """camtube's own design DXF of drawn cuts (bulges, spline, circle, slits, seam pieces) imports to the same cuts."""
    from camtube.export.dxf import design_dxf

    for name in ("bulges", "spline", "circle_hole", "seam_split", "slits", "blocks"):
        case = EXPECTED["cases"][name]
        first = load_drawing(EXAMPLES / case["file"], [], options(case["options"])).pattern
        path = tmp_path / f"{name}.design.dxf"
        path.write_text(design_dxf(first))
        if name == "slits":  # open polylines on their own layer
            msp = ezdxf.readfile(path).modelspace()
            assert len([e for e in msp.query("LWPOLYLINE[layer=='SLITS']") if not e.closed]) == len(first.cuts)
        again = load_drawing(path, [], DrawingOptions(layers=(("SLITS", "slit"),) if name == "slits" else ())).pattern
        assert len(again.cuts) == len(first.cuts)
        for a, b in zip(first.cuts, again.cuts):
            ga, gb = measured(a), measured(b)
            assert a.kind == b.kind
            assert ga["point"][0] == pytest.approx(gb["point"][0], abs=1e-6)
            assert _dy(ga["point"][1], gb["point"][1]) < 1e-6
            key = "length_mm" if a.kind == "slit" else "area_mm2"
            assert ga[key] == pytest.approx(gb[key], rel=1e-9)


@pytest.mark.parametrize("name", REFUSED)
def test_cli_refusal_writes_nothing(name, tmp_path, capsys):
    from camtube.commands import main

    case = EXPECTED["cases"][name]
    argv = ["toolpath", str(EXAMPLES / case["file"]), "-o", str(tmp_path / "o")]
    if "outer_radius_mm" in case["options"]:
        argv += ["--outer-radius", str(case["options"]["outer_radius_mm"])]
    assert set(case["options"]) <= {"outer_radius_mm"}
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert case["refused"][0] in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_committed_examples_are_what_the_generator_writes(tmp_path, monkeypatch, capsys):
    import examples.dxf.make_examples as gen

    monkeypatch.setattr(gen, "HERE", tmp_path)
    monkeypatch.setattr(gen, "CASES", {})
    assert gen.main() == 0
    for f in sorted(tmp_path.iterdir()):
        assert f.read_bytes() == (EXAMPLES / f.name).read_bytes(), f.name
