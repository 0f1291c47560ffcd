"""Per-pass toolpath DXF: every pass as a closed polyline, one layer per (focus, drill) class.

For laser software that maps layers to settings. Layer ``F{f}-D{d}`` holds
the passes of focus level ``f`` (0 on the surface, 1 defocused) and drill cut
``d`` (offset ``kerf/2 + d * drill_offset`` inward); its description states the
settings, and each layer has its own colour. Polylines are in execution order
and start at the pass's start point; seam-crossing paths are unwrapped (``y``
may leave ``[0, 2 pi r_o]``, as the rotary stage cuts them). The design
regions and the tube surface are on construction layers (not plotted).
"""
from __future__ import annotations

import math

from camtube.design.contour import rectangle
from camtube.export.dxf import add_contour, new_document, to_string
from camtube.plan.safety import check_job

#: ACI colours of the (focus, drill) layers, in class order; cycles if there are more classes.
COLOURS = (1, 3, 5, 6, 2, 4, 30, 200, 140, 210, 40, 170)


def layer_name(focus_level: int, drill_index: int) -> str:
    return f"F{focus_level}-D{drill_index}"


def toolpath_document(job):
    """ezdxf document of the job's passes (safety-checked first)."""
    check_job(job)
    doc = new_document()
    pr = job.process
    classes = sorted({(p.focus_level, p.drill_index, p.focus_offset_mm, p.offset_mm) for p in job.passes})
    for k, (f, d, z, off) in enumerate(classes):
        layer = doc.layers.add(layer_name(f, d), color=COLOURS[k % len(COLOURS)])
        layer.description = (f"focus {z:g} mm into the material, inward offset {off:.4f} mm, {pr.power_w:g} W, "
                             f"{pr.frequency_khz:g} kHz, {pr.scan_speed_mm_s:g} mm/s, {job.repeats} repeats")
    for name, color, desc in (("CONSTRUCTION-DESIGN", 8, "design cut regions (the finished edges)"),
                              ("CONSTRUCTION-OUTLINE", 9, "unrolled outer surface; never cut")):
        layer = doc.layers.add(name, color=color)
        layer.description = desc
        layer.dxf.plot = 0
    msp = doc.modelspace()
    circ = 2.0 * math.pi * job.outer_radius_mm
    for c in job.design:
        add_contour(msp, c, "CONSTRUCTION-DESIGN")
    add_contour(msp, rectangle(0.0, 0.0, job.length_mm, circ), "CONSTRUCTION-OUTLINE")  # last: read_contours' size
    for p in job.passes:
        add_contour(msp, p.contour, layer_name(p.focus_level, p.drill_index))
    return doc


def iter_toolpath_dxf(job, progress=None):
    yield toolpath_dxf(job)


def toolpath_dxf(job) -> str:
    """DXF text of :func:`toolpath_document` (deterministic)."""
    return to_string(toolpath_document(job))
