"""Write the curved notch drawings of ``examples/curved/`` (issue 21), as designers draw them.

Notches drawn the way designers draw them to lower the stress at the notch ends, on a tube
of outer radius 0.8 mm (circumference 5.027 mm), 12 mm long, 8 notches 1.2 mm apart:

- ``filleted.dxf``: rectangles 0.4 x 3.0 mm with 0.1 mm fillets, drawn as LINEs and ARCs;
- ``slotted.dxf``: slots (stadiums) 0.4 x 3.0 mm, two LINEs and two half-circle ARCs;
- ``elliptical.dxf``: ELLIPSE entities, 0.4 x 3.0 mm.

Tube frame: x along the tube from the tip, y arc length on the outer surface (mm); the
outline is a rectangle 12 x 2 pi 0.8 mm on layer CONSTRUCTION, notches on layer NOTCHES.
Run ``python examples/curved/make_curved.py`` to rewrite them; cut them with
``camtube toolpath examples/curved/filleted.dxf --outer-radius 0.8 -o out``.
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import ezdxf

HERE = Path(__file__).resolve().parent
RO = 0.8                      # outer radius (mm)
C = 2.0 * math.pi * RO        # circumference (mm)
LENGTH = 12.0                 # tube length (mm)
COUNT, PITCH, FIRST = 8, 1.2, 1.8   # notches, axial pitch and first centre (mm)
W, H = 0.4, 3.0               # notch width along the tube, height around it (mm)
FILLET = 0.1                  # fillet radius (mm)


def _doc():
    doc = ezdxf.new("R2013", setup=False)
    doc.header["$INSUNITS"] = 4
    doc.header["$MEASUREMENT"] = 1
    for name in ("NOTCHES", "CONSTRUCTION"):
        doc.layers.add(name)
    msp = doc.modelspace()
    msp.add_lwpolyline([(0, 0), (LENGTH, 0), (LENGTH, C), (0, C)], close=True, dxfattribs={"layer": "CONSTRUCTION"})
    return doc, msp


def _centres():
    return [(FIRST + k * PITCH, C / 2.0) for k in range(COUNT)]


def _rounded(msp, cx, cy, w, h, r):
    """A w x h rectangle centred at (cx, cy) with corner radius r: LINEs and ARCs (CCW arcs, degrees)."""
    x0, x1, y0, y1 = cx - w / 2, cx + w / 2, cy - h / 2, cy + h / 2
    a = {"layer": "NOTCHES"}
    if w / 2 - r > 1e-12:
        msp.add_line((x0 + r, y0), (x1 - r, y0), dxfattribs=a)
        msp.add_line((x1 - r, y1), (x0 + r, y1), dxfattribs=a)
    msp.add_line((x1, y0 + r), (x1, y1 - r), dxfattribs=a)
    msp.add_line((x0, y1 - r), (x0, y0 + r), dxfattribs=a)
    msp.add_arc((x1 - r, y0 + r), r, 270, 360, dxfattribs=a)
    msp.add_arc((x1 - r, y1 - r), r, 0, 90, dxfattribs=a)
    msp.add_arc((x0 + r, y1 - r), r, 90, 180, dxfattribs=a)
    msp.add_arc((x0 + r, y0 + r), r, 180, 270, dxfattribs=a)


def main() -> int:
    sys.path.insert(0, str(HERE.parents[1]))
    from camtube.export.dxf import to_string  # fixed header stamps: reproducible files

    for name in ("filleted", "slotted", "elliptical"):
        doc, msp = _doc()
        for cx, cy in _centres():
            if name == "filleted":
                _rounded(msp, cx, cy, W, H, FILLET)
            elif name == "slotted":
                _rounded(msp, cx, cy, W, H, W / 2)
            else:
                msp.add_ellipse((cx, cy), major_axis=(0, H / 2), ratio=W / H, dxfattribs={"layer": "NOTCHES"})
        (HERE / f"{name}.dxf").write_text(to_string(doc))
    return 0


if __name__ == "__main__":
    sys.exit(main())
