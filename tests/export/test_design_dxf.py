"""The unrolled design DXF, read back with ezdxf (an independent reader) and rendered by LibreCAD."""
from __future__ import annotations

import io
import math
import subprocess

import ezdxf
import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from camtube.design import cut_contours, load_pattern
from camtube.design.loader import build
from camtube.errors import PatternError
from camtube.design.drawing import load_drawing
from camtube.design.source import DrawingOptions
from camtube.export.dxf import design_dxf
from tests.conftest import PATTERNS, PRESETS, require_tool

ARC = {"tube1": 2.83, "tube2": 3.20, "tube3": 4.71}
RO = {"tube1": 0.75, "tube2": 0.85, "tube3": 1.25}


def doc_of(text: str):
    return ezdxf.read(io.StringIO(text))


def read_back(text: str, tmp_path, name: str = "design"):
    """The design DXF read back as a drawing (camtube's reader, see tests/design/test_drawing*.py)."""
    path = tmp_path / f"{name}.dxf"
    path.write_text(text)
    return load_drawing(path, [], DrawingOptions()).pattern


@pytest.mark.parametrize("name", PRESETS)
def test_preset_dxf_acceptance(name):
    pattern = load_pattern(PATTERNS / f"{name}.yaml")
    doc = doc_of(design_dxf(pattern))
    assert doc.dxfversion in ("AC1024", "AC1027")  # R2010 / R2013
    assert doc.header["$INSUNITS"] == 4
    auditor = doc.audit()
    assert not auditor.has_errors and not auditor.has_fixes
    msp = doc.modelspace()
    assert all(e.dxftype() == "LWPOLYLINE" and e.closed for e in msp)

    notches = [e for e in msp if e.dxf.layer == "NOTCHES"]
    holes = [e for e in msp if e.dxf.layer == "HOLES"]
    outline = [e for e in msp if e.dxf.layer.startswith("CONSTRUCTION")]
    assert len(notches) == 10 and len(holes) == 1 and len(outline) == 1

    boxes = []
    for e in notches:
        p = np.array(e.get_points("xy"))
        assert len(p) == 4
        w, h = np.ptp(p[:, 0]), np.ptp(p[:, 1])
        assert abs(w - 0.5) < 1e-6 and abs(h - ARC[name]) < 1e-6
        boxes.append((p[:, 0].min(), p[:, 0].max()))
    boxes.sort()
    gaps = [b[0] - a[1] for a, b in zip(boxes, boxes[1:])]
    assert np.allclose(gaps, 0.5, atol=1e-9)

    hp = np.array(holes[0].get_points("xy"))
    assert abs(np.ptp(hp[:, 0]) - 0.3) < 1e-6 and abs(np.ptp(hp[:, 1]) - 0.3) < 1e-6
    op = np.array(outline[0].get_points("xy"))
    assert abs(np.ptp(op[:, 1]) - 2 * math.pi * RO[name]) < 1e-9
    assert abs(np.ptp(op[:, 0]) - pattern.tube.length_mm) < 1e-9
    layer = doc.layers.get(outline[0].dxf.layer)
    assert layer.dxf.plot == 0  # construction: never plotted, never cut
    # every cut lies on the sheet 0 <= y <= 2 pi r_o
    for e in notches + holes:
        p = np.array(e.get_points("xy"))
        assert p[:, 1].min() >= -1e-12 and p[:, 1].max() <= 2 * math.pi * RO[name] + 1e-12


def test_seam_crossing_cut_is_split_and_joined_back(tmp_path):
    pattern = load_pattern(PATTERNS / "tube1-bidirectional.yaml")
    circ = pattern.tube.circumference_mm
    doc = doc_of(design_dxf(pattern))
    pieces = [e for e in doc.modelspace() if e.dxf.layer == "NOTCHES"]
    # 8 notches at 180 deg (whole) + 8 at 0 deg (two pieces each)
    assert len(pieces) == 8 + 16
    touching_seam = [e for e in pieces if min(p[1] for p in e.get_points("xy")) < 1e-9]
    assert len(touching_seam) == 8
    back = read_back(design_dxf(pattern), tmp_path)
    assert len(back.notches) == 16
    assert back.tube.circumference_mm == pytest.approx(circ)


def test_dxf_is_deterministic():
    p = load_pattern(PATTERNS / "tube2.yaml")
    assert design_dxf(p) == design_dxf(p)


def _normalised_boxes(contours, circ):
    out = []
    for c in contours:
        x0, y0, x1, y1 = c.bounds
        shift = math.floor(y0 / circ + 1e-9) * circ
        out.append((round(x0, 6), round(y0 - shift, 6), round(x1, 6), round(y1 - shift, 6), c.kind))
    return sorted(out)


# ---------------------------------------------------------------- property-based tests
@st.composite
def raw_patterns(draw):
    """Patterns that pass every design rule by construction (default rules: backbone arc >= 0.3 mm,
    web >= 0.1 mm), so a failure means the round trip is wrong, not that the input was invalid."""
    ro = draw(st.floats(0.3, 3.0))
    ri = ro * draw(st.floats(0.3, 0.9))
    circ = 2 * math.pi * ro
    n = draw(st.integers(1, 25))
    h = draw(st.floats(0.05, 1.5))
    c = draw(st.floats(0.1, 1.5))
    s = draw(st.floats(0.05 * circ, circ - 0.35))  # backbone arc 2 pi r_o - s >= 0.35 > rules.min_backbone_arc
    layout = draw(st.sampled_from(["uan", "bidirectional", "directions"]))
    angle = draw(st.floats(0, 359.99))
    first = draw(st.floats(0.0, 2.0))
    length = first + n * h + (n - 1) * c + draw(st.floats(0.0, 3.0))
    notch = {"layout": layout, "count": n, "width": h, "spacing": c, "arc": s, "first_offset": first,
             "angle_deg": angle}
    if layout == "directions":
        notch["directions_deg"] = draw(st.lists(st.floats(0, 359.99), min_size=1, max_size=4))
    raw = {"tube": {"outer_radius": ro, "inner_radius": ri, "length": length}, "notch": notch}
    if draw(st.booleans()):
        raw["tube"]["length"] = length + 1.0
        raw["holes"] = [{"x": length + 0.5, "size": min(0.3, ro), "angle_deg": draw(st.floats(0, 359.99))}]
    return raw


@settings(max_examples=60, deadline=None,
          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
@given(raw_patterns())
def test_dxf_round_trips(tmp_path, raw):
    try:
        pattern = build(raw).pattern
    except PatternError:
        assume(False)  # only valid patterns are drawn (e.g. backbone >= rules.min_backbone_arc)
    circ = pattern.tube.circumference_mm
    back = read_back(design_dxf(pattern), tmp_path)
    assert _normalised_boxes(cut_contours(back), circ) == _normalised_boxes(cut_contours(pattern), circ)
    assert back.tube.length_mm == pytest.approx(pattern.tube.length_mm)
    assert back.tube.outer_radius_mm == pytest.approx(pattern.tube.outer_radius_mm)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(raw_patterns(), st.floats(0.0, 0.5))
def test_valid_patterns_have_no_overlapping_cuts(raw, extra_arc):
    """Checked with shapely on the seam-split sheet, independently of the rule code."""
    raw["cuts"] = [{"x": raw["notch"]["first_offset"] + raw["notch"]["width"] / 2, "width": 0.1,
                    "arc": 0.1 + extra_arc, "angle_deg": 0.0}]
    try:
        pattern = build(raw).pattern
    except PatternError:
        return  # rejected patterns are the rule tests' business
    circ = pattern.tube.circumference_mm
    polys = []
    for con in cut_contours(pattern):
        x0, y0, x1, y1 = con.bounds
        rect = shapely.box(x0, y0, x1, y1)
        for k in (-1, 0, 1):  # the sheet wraps at the seam
            polys.append((con.cut_index, shapely.affinity.translate(rect, 0, k * circ)))
    for i, (ci, a) in enumerate(polys):
        for cj, b in polys[i + 1:]:
            if ci != cj:
                assert a.intersection(b).area < 1e-9


def test_librecad_renders_the_drawing(tmp_path):
    librecad = require_tool("librecad")
    xvfb = require_tool("xvfb-run")
    pattern = load_pattern(PATTERNS / "tube1-bidirectional.yaml")
    dxf = tmp_path / "tube.dxf"
    dxf.write_text(design_dxf(pattern))
    proc = subprocess.run([xvfb, "-a", librecad, "dxf2pdf", "-a", "-o", str(tmp_path / "tube.pdf"), str(dxf)],
                          capture_output=True, text=True, timeout=120)
    pdf = tmp_path / "tube.pdf"
    assert pdf.exists(), proc.stdout + proc.stderr
    data = pdf.read_bytes()
    assert data.startswith(b"%PDF")
    # rasterise the page and count drawn pixels: notches (red) and holes (blue) must be on it
    pdftoppm = require_tool("pdftoppm")
    subprocess.run([pdftoppm, "-r", "50", "-singlefile", str(pdf), str(tmp_path / "page")], check=True, timeout=60)
    img = _read_ppm(tmp_path / "page.ppm").astype(int)
    red = (img[..., 0] > 150) & (img[..., 1] < 100) & (img[..., 2] < 100)
    blue = (img[..., 2] > 150) & (img[..., 0] < 100) & (img[..., 1] < 100)
    assert red.sum() > 200 and blue.sum() > 10


def _read_ppm(path) -> np.ndarray:
    """Minimal binary PPM (P6) reader, shape (h, w, 3) uint8."""
    raw = path.read_bytes()
    fields, pos = [], 0
    while len(fields) < 4:
        while raw[pos:pos + 1].isspace():
            pos += 1
        if raw[pos:pos + 1] == b"#":
            pos = raw.index(b"\n", pos) + 1
            continue
        end = pos
        while not raw[end:end + 1].isspace():
            end += 1
        fields.append(raw[pos:end])
        pos = end
    assert fields[0] == b"P6"
    w, h = int(fields[1]), int(fields[2])
    return np.frombuffer(raw[pos + 1:pos + 1 + w * h * 3], dtype=np.uint8).reshape(h, w, 3)


def test_dxf_is_identical_across_processes():
    """ezdxf's class registration order depends on string hashing: the bytes must not."""
    import hashlib
    import sys

    code = ("import hashlib; from camtube.design import load_pattern; from camtube.export.dxf import design_dxf; "
            f"print(hashlib.sha256(design_dxf(load_pattern({str(PATTERNS / 'tube1.yaml')!r})).encode()).hexdigest())")
    digests = {subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                              env={**__import__("os").environ, "PYTHONHASHSEED": str(seed)}).stdout
               for seed in (1, 2, 3)}
    assert len(digests) == 1
    assert digests.pop().strip() == hashlib.sha256(design_dxf(load_pattern(PATTERNS / "tube1.yaml")).encode()).hexdigest()
