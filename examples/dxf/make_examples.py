"""Write the example drawings of ``examples/dxf/`` and ``expected.yaml``, the cuts each should give.

Every drawing is made with ezdxf the way CAD users (or scripts) draw a notch
pattern: outline on layer 0, inches, blocks and INSERT arrays, four LINEs, a
polyline open by 1e-4 mm, a closed SPLINE, a CIRCLE hole, bulge fillets and a
round-ended slot, an outline away from the origin, cuts split at the seam,
slits as LINE kerf paths -- and drawings camtube must refuse (duplicate notch,
backbone too thin, wrong radius, unitless, open outline).

The truth in ``expected.yaml`` is computed here, independently of camtube's
reader: shapes are built in the tube frame (x from the tip, y arc length on the
outer surface, mm) with shapely, exact formulas or scipy's B-spline, then moved
into the drawing's frame and units for drawing. Run::

    python examples/dxf/make_examples.py          # rewrites the .dxf files and expected.yaml

The drawing helpers (``draw_polygon`` ...) are reused by the property test
``tests/design/test_drawing_property.py``.
"""
from __future__ import annotations

import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

import ezdxf
import numpy as np
import shapely
import yaml
from shapely import affinity
from shapely.geometry import LineString, Polygon, box

HERE = Path(__file__).resolve().parent
RO = 1.0                       # outer radius of every example tube (mm)
C = 2.0 * math.pi * RO         # sheet height
L = 10.0                       # tube length (mm)
MID = C / 2.0                  # y of angle 180 deg
INSUNITS = {"mm": 4, "inch": 1, "unitless": 0}
MM_PER = {"mm": 1.0, "inch": 25.4, "unitless": 1.0}


# ---------------------------------------------------------------- drawing helpers
@dataclass
class Sheet:
    """A drawing being made: the document, its units, and where the tube frame's origin is drawn."""

    units: str = "mm"
    origin: tuple[float, float] = (0.0, 0.0)      # drawing position of the tube frame's (0, 0), in mm
    doc: object = field(default=None)

    def __post_init__(self):
        self.doc = ezdxf.new("R2013", setup=False)
        self.doc.header["$INSUNITS"] = INSUNITS[self.units]
        self.doc.header["$MEASUREMENT"] = 1
        for name in ("NOTCHES", "HOLES", "CONSTRUCTION", "KERF"):
            if name not in self.doc.layers:
                self.doc.layers.add(name)

    @property
    def msp(self):
        return self.doc.modelspace()

    def at(self, x_mm: float, y_mm: float) -> tuple[float, float]:
        """A tube-frame point (mm) in drawing coordinates (drawing units)."""
        k = MM_PER[self.units]
        return ((x_mm + self.origin[0]) / k, (y_mm + self.origin[1]) / k)

    def length(self, mm: float) -> float:
        return mm / MM_PER[self.units]


def draw_polygon(sheet: Sheet, pts, layer: str, style: str = "lwpolyline", layout=None) -> None:
    """A closed outline given in the tube frame: one closed LWPOLYLINE, an old-style POLYLINE, or LINEs."""
    msp = layout if layout is not None else sheet.msp
    d = [sheet.at(x, y) if layout is None else (sheet.length(x), sheet.length(y)) for x, y in pts]
    if style == "lwpolyline":
        msp.add_lwpolyline(d, close=True, dxfattribs={"layer": layer})
    elif style == "polyline":
        msp.add_polyline2d(d, close=True, dxfattribs={"layer": layer})
    elif style == "lines":
        for k in range(len(d)):
            a, b = d[k], d[(k + 1) % len(d)]
            if k % 2:  # CAD users draw lines in either direction
                a, b = b, a
            msp.add_line(a, b, dxfattribs={"layer": layer})
    else:
        raise ValueError(style)


def rect(x0, y0, x1, y1):
    return [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]


def draw_outline(sheet: Sheet, layer: str = "CONSTRUCTION", style: str = "lwpolyline", length=L, circ=C) -> None:
    draw_polygon(sheet, rect(0.0, 0.0, length, circ), layer, style)


def save(sheet: Sheet, name: str) -> None:
    from camtube.export.dxf import to_string  # fixed header stamps: the files are reproducible

    (HERE / name).write_text(to_string(sheet.doc))


# ---------------------------------------------------------------- truth
def truth(kind: str, geom, ro: float = RO) -> dict:
    """What camtube must import for one cut: area, centroid, angle of its centre, axial range (tube frame, mm)."""
    x0, y0, x1, y1 = geom.bounds
    out = {"kind": kind, "x_mm": [round(x0, 9), round(x1, 9)],
           "angle_deg": round(math.degrees(0.5 * (y0 + y1) / ro) % 360.0, 9)}
    if kind == "slit":
        out["length_mm"] = round(geom.length, 9)
        c = geom.interpolate(0.5, normalized=True)
        out["midpoint_mm"] = [round(c.x, 9), round(c.y, 9)]
    else:
        out["area_mm2"] = round(geom.area, 9)
        c = geom.centroid
        out["centroid_mm"] = [round(c.x, 9), round(c.y, 9)]
    return out


def rounded_rect(x0, y0, x1, y1, r, n=4000):
    """Exact rounded rectangle (corner radius r) as a fine polygon (error << 1e-8 mm^2)."""
    return box(x0 + r, y0 + r, x1 - r, y1 - r).buffer(r, quad_segs=n)


def bulge_rounded_rect(sheet: Sheet, x0, y0, x1, y1, r, layer):
    """The same shape drawn as one LWPOLYLINE with bulges (quarter arcs: bulge tan(90/4))."""
    b = math.tan(math.radians(90.0) / 4.0)
    pts = [(x0 + r, y0, 0), (x1 - r, y0, b), (x1, y0 + r, 0), (x1, y1 - r, b), (x1 - r, y1, 0), (x0 + r, y1, b),
           (x0, y1 - r, 0), (x0, y0 + r, b)]
    d = [(*sheet.at(x, y), 0.0, 0.0, bb) for x, y, bb in pts]
    sheet.msp.add_lwpolyline(d, format="xyseb", close=True, dxfattribs={"layer": layer})


CASES: dict[str, dict] = {}


def case(name: str, file: str, options: dict | None = None, cuts=None, refused=None, summary=None) -> None:
    entry: dict = {"file": file, "options": options or {}}
    if cuts is not None:
        entry["cuts"] = cuts
    if refused is not None:
        entry["refused"] = refused
    if summary is not None:
        entry["summary"] = summary
    CASES[name] = entry


def basic_cuts():
    """Four notches (0.5 x 3.0 mm at 180 deg) and a 0.3 mm square hole: the simplest pattern."""
    shapes = [("notch", box(x, MID - 1.5, x + 0.5, MID + 1.5)) for x in (2.0, 4.0, 6.0, 8.0)]
    shapes.append(("hole", box(0.85, MID - 0.15, 1.15, MID + 0.15)))
    return shapes


# ---------------------------------------------------------------- the examples
def outline_layer0():
    s = Sheet()
    draw_outline(s, layer="0")
    for kind, g in basic_cuts():
        draw_polygon(s, list(g.exterior.coords)[:-1], "0" if kind == "notch" else "HOLES")
    s.msp.add_text("tube1-like, r_o 1 mm", dxfattribs={"layer": "0", "insert": s.at(0.5, 0.5), "height": 0.2})
    save(s, "outline_layer0.dxf")
    case("outline_layer0", "outline_layer0.dxf", cuts=[truth(k, g) for k, g in basic_cuts()],
         summary=["imported 4 notches and 1 hole", "outline LWPOLYLINE", "on layer 0", "1 (annotation)"])


def inches():
    s = Sheet(units="inch")
    draw_outline(s)
    for kind, g in basic_cuts():
        draw_polygon(s, list(g.exterior.coords)[:-1], "NOTCHES" if kind == "notch" else "HOLES", "polyline")
    save(s, "inches.dxf")
    case("inches", "inches.dxf", cuts=[truth(k, g) for k, g in basic_cuts()], summary=["units inch"])


def unitless():
    s = Sheet(units="unitless")
    draw_outline(s)
    for kind, g in basic_cuts():
        draw_polygon(s, list(g.exterior.coords)[:-1], "NOTCHES" if kind == "notch" else "HOLES")
    save(s, "unitless.dxf")
    case("unitless_refused", "unitless.dxf", refused=["unitless", "--units"])
    case("unitless_mm", "unitless.dxf", options={"units": "mm"}, cuts=[truth(k, g) for k, g in basic_cuts()])


def blocks():
    s = Sheet()
    length = 11.0
    draw_outline(s, length=length)
    doc = s.doc
    n = doc.blocks.new("N")                      # a notch 0.4 x 2.5 mm centred on the block origin, layer 0
    draw_polygon(s, rect(-0.2, -1.25, 0.2, 1.25), "0", layout=n)
    pair = doc.blocks.new("PAIR")                # nested: two N, 0.8 mm apart
    pair.add_blockref("N", (0.0, 0.0))
    pair.add_blockref("N", (s.length(0.8), 0.0))
    trap = doc.blocks.new("T")                   # asymmetric: shows mirroring and rotation
    tpts = [(-0.2, -1.0), (0.2, -1.0), (0.1, 1.0), (-0.2, 1.0)]
    draw_polygon(s, tpts, "0", "lines", layout=trap)
    base = Polygon(rect(-0.2, -1.25, 0.2, 1.25))
    shapes = []
    s.msp.add_blockref("N", s.at(1.5, MID), dxfattribs={"layer": "NOTCHES"})
    shapes.append(affinity.translate(base, 1.5, MID))
    arr = s.msp.add_blockref("N", s.at(3.0, MID), dxfattribs={"layer": "NOTCHES"})
    arr.grid(size=(1, 4), spacing=(s.length(2.5), s.length(1.0)))  # MINSERT: 1 row, 4 columns, 1 mm apart
    shapes += [affinity.translate(base, 3.0 + k, MID) for k in range(4)]
    s.msp.add_blockref("PAIR", s.at(7.2, MID), dxfattribs={"layer": "NOTCHES"})
    shapes += [affinity.translate(base, 7.2 + d, MID) for d in (0.0, 0.8)]
    # mirrored (xscale -1) and turned 180 deg, and scaled 0.8
    s.msp.add_blockref("T", s.at(9.0, MID), dxfattribs={"layer": "NOTCHES", "xscale": -1.0, "rotation": 180.0})
    t = affinity.rotate(affinity.scale(Polygon(tpts), -1.0, 1.0, origin=(0, 0)), 180.0, origin=(0, 0))
    shapes.append(affinity.translate(t, 9.0, MID))
    s.msp.add_blockref("N", s.at(10.0, MID), dxfattribs={"layer": "NOTCHES", "xscale": 0.8, "yscale": 0.8})
    shapes.append(affinity.translate(affinity.scale(base, 0.8, 0.8, origin=(0, 0)), 10.0, MID))
    save(s, "blocks.dxf")
    case("blocks", "blocks.dxf", cuts=[truth("notch", g) for g in shapes],
         summary=["imported 9 notches", "INSERTs expanded"])


def four_lines():
    s = Sheet()
    draw_outline(s, layer="0", style="lines")
    shapes = [box(2.0, MID - 1.5, 2.5, MID + 1.5), box(4.0, MID - 1.0, 4.6, MID + 1.0)]
    for g in shapes:
        draw_polygon(s, list(g.exterior.coords)[:-1], "0", "lines")
    save(s, "four_lines.dxf")
    case("four_lines", "four_lines.dxf", cuts=[truth("notch", g) for g in shapes],
         summary=["8 loose entities joined into 2 loops"])


def gap():
    s = Sheet()
    draw_outline(s)
    g = box(3.0, MID - 1.2, 3.5, MID + 1.2)
    pts = [s.at(x, y) for x, y in list(g.exterior.coords)[:-1]]
    pts.append((pts[0][0] + 1e-4, pts[0][1]))    # "closed" by the eye: the end is 1e-4 mm from the start
    s.msp.add_lwpolyline(pts, close=False, dxfattribs={"layer": "NOTCHES"})
    save(s, "gap_1e-4.dxf")
    case("gap_1e-4", "gap_1e-4.dxf", cuts=[truth("notch", g)])
    s = Sheet()
    draw_outline(s)
    pts = [s.at(x, y) for x, y in list(g.exterior.coords)[:-1]]
    pts.append((pts[0][0] + 0.05, pts[0][1]))
    s.msp.add_lwpolyline(pts, close=False, dxfattribs={"layer": "NOTCHES"})
    save(s, "gap_0.05.dxf")
    case("gap_0.05", "gap_0.05.dxf", refused=["LWPOLYLINE #", "layer NOTCHES", "open path", "0.05 mm apart"])


def open_outline():
    s = Sheet()
    draw_outline(s)
    pts = rect(3.0, MID - 1.2, 3.5, MID + 1.2)
    for a, b in zip(pts, pts[1:]):              # three sides only
        s.msp.add_line(s.at(*a), s.at(*b), dxfattribs={"layer": "NOTCHES"})
    save(s, "open_outline.dxf")
    case("open_outline", "open_outline.dxf", refused=["3 LINEs", "layer NOTCHES", "open path", "(3, 1.94159) mm",
                                                      "(3, 4.34159) mm", "2.4 mm apart"])


def spline():
    """A closed clamped cubic B-spline (first control point = last); truth from scipy's B-spline."""
    from scipy.interpolate import BSpline

    s = Sheet()
    draw_outline(s)
    cx, cy = 5.0, MID
    ctrl = np.array([(cx + 0.4 * math.cos(a), cy + 1.6 * math.sin(a)) for a in np.linspace(0, 2 * math.pi, 9)])
    ctrl[-1] = ctrl[0]
    k = 3
    knots = np.concatenate([[0.0] * (k + 1), np.arange(1, len(ctrl) - k), [len(ctrl) - k] * (k + 1)]).astype(float)
    sp = s.msp.add_open_spline([s.at(x, y) for x, y in ctrl], degree=k, dxfattribs={"layer": "NOTCHES"})
    sp.knots = list(knots)
    curve = BSpline(knots, ctrl, k)(np.linspace(knots[0], knots[-1], 200001))
    g = Polygon(curve[:-1])
    save(s, "spline.dxf")
    case("spline", "spline.dxf", cuts=[truth("notch", g)])


def circle_hole():
    s = Sheet()
    draw_outline(s)
    shapes = [("notch", box(x, MID - 1.5, x + 0.5, MID + 1.5)) for x in (3.0, 5.0)]
    for _, g in shapes:
        draw_polygon(s, list(g.exterior.coords)[:-1], "NOTCHES")
    r = 0.15
    s.msp.add_circle(s.at(1.0, MID), s.length(r), dxfattribs={"layer": "HOLES"})
    cuts = [truth(k, g) for k, g in shapes]
    cuts.append({"kind": "hole", "x_mm": [1.0 - r, 1.0 + r], "angle_deg": 180.0, "area_mm2": round(math.pi * r * r, 12),
                 "centroid_mm": [1.0, MID]})
    save(s, "circle_hole.dxf")
    case("circle_hole", "circle_hole.dxf", cuts=cuts, summary=["imported 2 notches and 1 hole"])


def bulges():
    s = Sheet()
    draw_outline(s)
    bulge_rounded_rect(s, 2.0, MID - 1.5, 2.6, MID + 1.5, 0.1, "NOTCHES")
    g1 = rounded_rect(2.0, MID - 1.5, 2.6, MID + 1.5, 0.1)
    a1 = 0.6 * 3.0 - (4.0 - math.pi) * 0.1**2    # exact area of the filleted notch
    # a round-ended slot (stadium): 0.5 mm wide, 3.0 mm long around the tube, ends of radius 0.25
    r, x0, x1, y0, y1 = 0.25, 5.0, 5.5, MID - 1.5, MID + 1.5
    d = [(*s.at(x0, y0 + r), 0, 0, 0.0), (*s.at(x0, y1 - r), 0, 0, -1.0), (*s.at(x1, y1 - r), 0, 0, 0.0),
         (*s.at(x1, y0 + r), 0, 0, -1.0)]
    s.msp.add_lwpolyline(d, format="xyseb", close=True, dxfattribs={"layer": "NOTCHES"})
    a2 = 0.5 * (3.0 - 2 * r) + math.pi * r * r
    save(s, "bulges.dxf")
    t1 = truth("notch", g1)
    t1["area_mm2"] = round(a1, 12)
    t2 = {"kind": "notch", "x_mm": [x0, x1], "angle_deg": 180.0, "area_mm2": round(a2, 12),
          "centroid_mm": [0.5 * (x0 + x1), MID]}
    case("bulges", "bulges.dxf", cuts=[t1, t2])


def offset_outline():
    s = Sheet(origin=(23.5, -7.2))
    draw_outline(s)
    shapes = basic_cuts()
    for kind, g in shapes:
        draw_polygon(s, list(g.exterior.coords)[:-1], "NOTCHES" if kind == "notch" else "HOLES")
    # a notch at 30 deg, so a shift around the tube would show
    g = box(9.0, RO * math.radians(30) - 0.5, 9.5, RO * math.radians(30) + 0.5)
    draw_polygon(s, list(g.exterior.coords)[:-1], "NOTCHES")
    shapes.append(("notch", g))
    save(s, "offset_outline.dxf")
    case("offset_outline", "offset_outline.dxf", cuts=[truth(k, g) for k, g in shapes])


def seam_split():
    """A hexagonal notch and a rectangle crossing the seam, each drawn as two pieces on the sheet."""
    s = Sheet()
    draw_outline(s)
    hexagon = Polygon([(3.0 + 0.3 * math.cos(a), 0.3 + 0.9 * math.sin(a))
                       for a in np.linspace(0, 2 * math.pi, 6, endpoint=False)])
    hexagon = affinity.rotate(hexagon, 30.0, origin="centroid")
    rectangle = box(6.0, -1.0, 6.5, 0.5)
    for g in (hexagon, rectangle):
        for lo in (-C, 0.0):
            piece = shapely.intersection(affinity.translate(g, 0, -lo), box(0, 0, L, C))
            if piece.area > 0:
                draw_polygon(s, list(piece.exterior.coords)[:-1], "NOTCHES")
    save(s, "seam_split.dxf")
    cuts = [truth("notch", g) for g in (hexagon, rectangle)]
    case("seam_split", "seam_split.dxf", cuts=cuts, summary=["2 cuts rejoined at the seam"])


def duplicate():
    s = Sheet()
    draw_outline(s)
    for kind, g in basic_cuts():
        draw_polygon(s, list(g.exterior.coords)[:-1], "NOTCHES" if kind == "notch" else "HOLES")
    g = basic_cuts()[1][1]
    draw_polygon(s, list(g.exterior.coords)[:-1], "NOTCHES")     # pasted twice
    save(s, "duplicate.dxf")
    case("duplicate", "duplicate.dxf", refused=["duplicate", "LWPOLYLINE #", "layer NOTCHES"])


def backbone_thin():
    s = Sheet()
    draw_outline(s)
    g = box(4.0, MID - (C - 0.112) / 2, 4.5, MID + (C - 0.112) / 2)
    draw_polygon(s, list(g.exterior.coords)[:-1], "NOTCHES")
    save(s, "backbone_thin.dxf")
    case("backbone_thin", "backbone_thin.dxf", refused=["backbone arc", "0.1120 mm", "LWPOLYLINE #", "NOTCHES"])


def wrong_radius():
    s = Sheet()
    draw_outline(s, layer="0")
    for kind, g in basic_cuts():
        draw_polygon(s, list(g.exterior.coords)[:-1], "0" if kind == "notch" else "HOLES")
    save(s, "wrong_radius.dxf")
    case("wrong_radius", "wrong_radius.dxf", options={"outer_radius_mm": 0.5},
         refused=["6.2832 mm high", "2 pi x 1.0000 mm", "outer radius 0.5 mm needs 2 pi r_o = 3.1416 mm"])
    case("right_radius", "wrong_radius.dxf", options={"outer_radius_mm": 1.0},
         cuts=[truth(k, g) for k, g in basic_cuts()])


def slits():
    """Slits as single LINE kerf paths (the style of public tube-pattern generators), brick-laid."""
    s = Sheet()
    draw_outline(s)
    lines = []
    for i, x in enumerate(np.arange(1.0, 9.01, 1.0)):
        y0 = 0.5 if i % 2 == 0 else MID + 0.5
        lines.append(LineString([(x, y0), (x, y0 + 2.2)]))
    for g in lines:
        a, b = g.coords
        s.msp.add_line(s.at(*a), s.at(*b), dxfattribs={"layer": "KERF"})
    save(s, "slits.dxf")
    case("slits", "slits.dxf", options={"layers": [["KERF", "slit"]]}, cuts=[truth("slit", g) for g in lines],
         summary=["imported 9 slits"])
    case("slits_unmapped", "slits.dxf", refused=["LINE #", "layer KERF", "open path", "--layer KERF=slit"])


def main() -> int:
    for make in (outline_layer0, inches, unitless, blocks, four_lines, gap, open_outline, spline, circle_hole,
                 bulges, offset_outline, seam_split, duplicate, backbone_thin, wrong_radius, slits):
        make()
    doc = {"about": "Cuts each example drawing must give (tube frame: x from the tip, y arc length on the outer "
                    "surface, mm; angle of the cut's bounding-box centre, deg), or the phrases its refusal must "
                    "contain. Written by make_examples.py.",
           "outer_radius_mm": RO, "cases": CASES}
    (HERE / "expected.yaml").write_text(yaml.safe_dump(doc, sort_keys=False, width=120))
    print(f"wrote {len(CASES)} cases, {len(list(HERE.glob('*.dxf')))} drawings in {HERE}")
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(HERE.parents[1]))
    sys.exit(main())
