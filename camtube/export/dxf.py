"""Design DXF: the unrolled drawing a CAD user would make, and reading DXF contours back.

Frame: x along the tube from the tip, y arc length on the outer surface,
``0 <= y <= 2 pi r_o`` (mm, ``$INSUNITS = 4``). Every cut is a closed
LWPOLYLINE on its kind's layer; a cut crossing the seam ``y = 0`` is split into
closed pieces there. The unrolled outer surface is drawn on a construction
layer that is switched off for plotting and never cut.
"""
from __future__ import annotations

import io
from dataclasses import dataclass

import ezdxf
from ezdxf.document import Drawing

from camtube import __version__
from camtube.design.contour import Contour, merge_seam_pieces, outline, sheet_contours
from camtube.design.pattern import Pattern

DXF_VERSION = "R2013"
LAYERS = {
    # name: (ACI colour, meaning)
    "NOTCHES": (1, "notch cut contours"),
    "HOLES": (5, "tendon hole cut contours"),
    "CUTS": (3, "cut contours of other kinds"),
    "CONSTRUCTION-OUTLINE": (8, "unrolled outer surface, 0<=x<=L, 0<=y<=2 pi r_o; never cut"),
}
KIND_LAYER = {"notch": "NOTCHES", "hole": "HOLES"}
CUT_LAYERS = ("NOTCHES", "HOLES", "CUTS")


def new_document() -> Drawing:
    """An empty R2013 drawing in mm with deterministic header values."""
    doc = ezdxf.new(DXF_VERSION, setup=False, units=4)
    doc.header["$INSUNITS"] = 4
    doc.header["$MEASUREMENT"] = 1
    doc.header["$LUNITS"] = 2
    return doc


def add_contour(msp, contour: Contour, layer: str) -> None:
    msp.add_lwpolyline([(float(x), float(y)) for x, y in contour.points], close=True,
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


@dataclass(frozen=True)
class DxfContours:
    """Closed contours read from a DXF.

    Attributes
    ----------
    contours : tuple[Contour, ...]
        Cut contours (seam pieces joined when ``circumference_mm`` is known).
    circumference_mm : float | None
        Height of the construction outline, if the drawing has one.
    length_mm : float | None
        Width of the construction outline.
    """

    contours: tuple[Contour, ...]
    circumference_mm: float | None
    length_mm: float | None


def _layer_kind(layer: str) -> str:
    up = layer.upper()
    if up.startswith("NOTCH"):
        return "notch"
    if up.startswith("HOLE"):
        return "hole"
    return "cut"


def read_contours(source, circumference_mm: float | None = None, merge_seam: bool = True) -> DxfContours:
    """Closed contours of a DXF (a camtube drawing or one drawn by hand).

    Closed LWPOLYLINEs and POLYLINEs on any layer not starting with
    ``CONSTRUCTION`` are cuts; their layer name gives the kind (``NOTCH*``,
    ``HOLE*``, else ``cut``). The construction outline gives the sheet size.

    Parameters
    ----------
    source : str | os.PathLike | ezdxf Drawing
        A file path or a loaded document.
    circumference_mm : float, optional
        Sheet height used to join seam pieces; defaults to the outline's height.
    """
    doc = source if isinstance(source, Drawing) else ezdxf.readfile(str(source))
    msp = doc.modelspace()
    cuts: list[Contour] = []
    circ, length = None, None
    for e in msp.query("LWPOLYLINE POLYLINE"):
        layer = e.dxf.layer
        if e.dxftype() == "LWPOLYLINE":
            closed = e.closed
            pts = [(float(p[0]), float(p[1])) for p in e.get_points("xy")]
        else:
            closed = e.is_closed
            pts = [(float(v.dxf.location.x), float(v.dxf.location.y)) for v in e.vertices]
        if len(pts) > 1 and pts[0] == pts[-1]:
            pts = pts[:-1]
            closed = True
        if layer.upper().startswith("CONSTRUCTION"):
            xs = [p[0] for p in pts]
            ys = [p[1] for p in pts]
            length, circ = max(xs) - min(xs), max(ys) - min(ys)
            continue
        if not closed or len(pts) < 3:
            continue
        c = Contour(tuple(pts), _layer_kind(layer), -1)
        if c.area_mm2 < 0:  # normalise to counter-clockwise
            c = Contour(tuple(reversed(pts)), c.kind, -1)
        cuts.append(c)
    circ_used = circumference_mm if circumference_mm is not None else circ
    if merge_seam and circ_used:
        cuts = merge_seam_pieces(cuts, circ_used)
    cuts.sort(key=lambda c: (c.bounds[0], c.bounds[1], c.kind))
    return DxfContours(tuple(cuts), circ, length)
