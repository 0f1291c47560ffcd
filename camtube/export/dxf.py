"""Design DXF: the unrolled drawing a CAD user would make (reading drawings is :mod:`camtube.design.drawing`).

Frame: x along the tube from the tip, y arc length on the outer surface,
``0 <= y <= 2 pi r_o`` (mm, ``$INSUNITS = 4``). Every cut is a closed
LWPOLYLINE on its kind's layer (a drawn cut keeps its outline's vertices), a
slit an open LWPOLYLINE on ``SLITS``; a cut crossing the seam ``y = 0`` is split
into pieces there. The unrolled outer surface is drawn on a construction layer
that is switched off for plotting and never cut. Read back with
:func:`camtube.design.drawing.load_drawing`, the drawing gives the same cuts.
"""
from __future__ import annotations

import io

import ezdxf
from ezdxf.document import Drawing

from camtube import __version__
from camtube.design.contour import Contour, outline, sheet_contours
from camtube.design.pattern import Pattern

DXF_VERSION = "R2013"
LAYERS = {
    # name: (ACI colour, meaning)
    "NOTCHES": (1, "notch cut contours"),
    "HOLES": (5, "tendon hole cut contours"),
    "SLITS": (6, "slits: open paths the beam follows"),
    "CUTS": (3, "cut contours of other kinds"),
    "CONSTRUCTION-OUTLINE": (8, "unrolled outer surface, 0<=x<=L, 0<=y<=2 pi r_o; never cut"),
}
KIND_LAYER = {"notch": "NOTCHES", "hole": "HOLES", "slit": "SLITS"}
CUT_LAYERS = ("NOTCHES", "HOLES", "SLITS", "CUTS")


def new_document() -> Drawing:
    """An empty R2013 drawing in mm with deterministic header values."""
    doc = ezdxf.new(DXF_VERSION, setup=False, units=4)
    doc.header["$INSUNITS"] = 4
    doc.header["$MEASUREMENT"] = 1
    doc.header["$LUNITS"] = 2
    return doc


def add_contour(msp, contour: Contour, layer: str) -> None:
    """A closed LWPOLYLINE of the contour (an open one for an open path) on ``layer``."""
    msp.add_lwpolyline([(float(x), float(y)) for x, y in contour.points], close=contour.closed,
                       dxfattribs={"layer": layer})


def design_document(pattern: Pattern) -> Drawing:
    """The unrolled design drawing of ``pattern`` as an ezdxf document."""
    doc = new_document()
    for name, (color, desc) in LAYERS.items():
        layer = doc.layers.add(name, color=color)
        layer.description = desc
        if name.startswith("CONSTRUCTION"):
            layer.dxf.plot = 0
    msp = doc.modelspace()
    add_contour(msp, outline(pattern), "CONSTRUCTION-OUTLINE")
    for con in sheet_contours(pattern):
        add_contour(msp, con, KIND_LAYER.get(con.kind, "CUTS"))
    t = pattern.tube
    doc.header["$EXTMIN"] = (0.0, 0.0, 0.0)
    doc.header["$EXTMAX"] = (t.length_mm, t.circumference_mm, 0.0)
    return doc


def to_string(doc: Drawing) -> str:
    """Serialise a document to DXF text, byte-identical for the same drawing.

    ezdxf stamps dates and random GUIDs into the header on write; camtube
    writes fixed ones instead (ezdxf's own switch for reproducible output), so
    users can diff drawings.
    """
    _fix_class_order(doc)
    stream = io.StringIO()
    saved = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True
    meta = doc.ezdxf_metadata()
    stamp = f"ezdxf {ezdxf.__version__} for camtube {__version__}"
    meta["CREATED_BY_EZDXF"] = stamp
    doc._update_ezdxf_metadata = lambda: meta.__setitem__("WRITTEN_BY_EZDXF", stamp)  # no wall-clock stamp
    try:
        doc.write(stream)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = saved
    return stream.getvalue()


def _fix_class_order(doc: Drawing) -> None:
    """Register the CLASSES entries now, in sorted order.

    ezdxf 1.x registers some classes (LAYOUT, ACDBPLACEHOLDER for R2013) in an
    order that varies between processes (string hashing); sorting them before
    writing fixes the bytes. ``write`` only appends classes still missing.
    """
    from collections import OrderedDict

    doc.classes.add_required_classes(doc.dxfversion)
    doc.classes.classes = OrderedDict(sorted(doc.classes.classes.items()))


def design_dxf(pattern: Pattern) -> str:
    """DXF text of the unrolled design of ``pattern``."""
    return to_string(design_document(pattern))
