"""Per-pass toolpath DXF: every pass as a polyline, one layer per (focus, drill) class, streamed.

For laser software that maps layers to settings. Layer ``F{f}-D{d}`` holds
the passes of focus level ``f`` (0 on the surface, 1 defocused) and drill cut
``d`` (offset ``kerf/2 + d * drill_offset`` inward); its description states the
settings, and each layer has its own colour. Polylines are in execution order
and start at the pass's start point (closed for cut regions, open for slits);
seam-crossing paths are unwrapped (``y`` may leave ``[0, 2 pi r_o]``, as the rotary
stage cuts them). The design regions and the tube surface are on construction
layers (not plotted).

Streaming: ezdxf builds the document without the passes (header, tables, the
construction entities, with handles reserved for the passes), and
:func:`iter_toolpath_dxf` writes each pass's LWPOLYLINE as DXF text into its
ENTITIES section, chunk by chunk, exactly as ezdxf would (a test compares the
bytes with :func:`toolpath_document` and reads the result with ezdxf's
``readfile`` + ``audit``).
"""
from __future__ import annotations

import math
from typing import Iterator

import numpy as np

from camtube.design.contour import rectangle
from camtube.export.dxf import add_contour, new_document, to_string
from camtube.plan.moves import CHUNK_PASSES
from camtube.plan.safety import check_job
from camtube.progress import NO_PROGRESS, Progress

#: ACI colours of the (focus, drill) layers, in class order; cycles if there are more classes.
COLOURS = (1, 3, 5, 6, 2, 4, 30, 200, 140, 210, 40, 170)
#: Distinct paths whose vertex text is kept for reuse (bounds the memo's memory).
MEMO_MAX = 200_000


def layer_name(focus_level: int, drill_index: int) -> str:
    return f"F{focus_level}-D{drill_index}"


def _classes(job) -> list[tuple[int, int, float, float]]:
    """(focus level, drill index, focus offset, inward offset) of each layer, sorted."""
    pk = job.packed
    if pk.n_pass == 0:
        return []
    key = np.stack([pk.pass_focus.astype(float), pk.pass_drill.astype(float), pk.pass_z, pk.pass_offset], 1)
    rows = np.unique(key, axis=0)
    out: dict[tuple[int, int], tuple[float, float]] = {}
    for f, d, z, o in rows.tolist():  # a slit's passes (offset 0) share the layer of their class
        k = (int(f), int(d))
        out[k] = (z, max(o, out[k][1])) if k in out else (z, o)
    return [(f, d, z, o) for (f, d), (z, o) in sorted(out.items())]


def _skeleton(job, n_reserved: int):
    """The document without the passes; ``n_reserved`` handles kept free for them. Returns (doc, first handle)."""
    doc = new_document()
    pr = job.process
    for k, (f, d, z, off) in enumerate(_classes(job)):
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
        _add(msp, c, "CONSTRUCTION-DESIGN")
    add_contour(msp, rectangle(0.0, 0.0, job.length_mm, circ), "CONSTRUCTION-OUTLINE")  # last: read_contours' size
    handles = doc.entitydb.handles
    first = int(str(handles), 16)
    handles.reset("%X" % (first + n_reserved))
    return doc, first


def _add(msp, contour, layer: str) -> None:
    msp.add_lwpolyline([(float(x), float(y)) for x, y in contour.points], close=contour.closed,
                       dxfattribs={"layer": layer})


def toolpath_document(job):
    """ezdxf document of the job's passes (safety-checked first; small jobs: one entity object per pass)."""
    check_job(job)
    doc, first = _skeleton(job, 0)
    msp = doc.modelspace()
    for p in job.passes:
        _add(msp, p.contour, layer_name(p.focus_level, p.drill_index))
    return doc


def iter_toolpath_dxf(job, progress: Progress = NO_PROGRESS) -> Iterator[str]:
    """DXF text of the job's toolpath in chunks, in bounded memory (deterministic).

    The whole neutral move list is safety-checked (chunk by chunk) before the first chunk.
    """
    check_job(job)
    pk = job.packed
    n = pk.n_pass
    doc, first = _skeleton(job, n)
    text = to_string(doc)
    owner = doc.modelspace().block_record_handle
    start = text.index("\n  2\nENTITIES\n")
    cut = text.index("  0\nENDSEC\n", start)
    head, tail = text[:cut], text[cut:]
    del text
    yield head
    yield from _entities(job, first, owner, progress)
    yield tail


def _entities(job, first: int, owner: str, progress: Progress) -> Iterator[str]:
    pk = job.packed
    n = pk.n_pass
    head = ("  0\nLWPOLYLINE\n  5\n%X\n330\n" + owner + "\n100\nAcDbEntity\n  8\n%s\n100\nAcDbPolyline\n"
            " 90\n%d\n 70\n%d\n")
    memo: dict[int, str] = {}
    off, closed, verts = pk.geom_offset, pk.geom_closed, pk.vertices
    layers: dict[tuple[int, int], str] = {}
    with progress.task("toolpath DXF", total=n) as task:
        for lo in range(0, n, CHUNK_PASSES):
            hi = min(n, lo + CHUNK_PASSES)
            parts = []
            for k, (g, f, d) in enumerate(zip(pk.pass_geom[lo:hi].tolist(), pk.pass_focus[lo:hi].tolist(),
                                               pk.pass_drill[lo:hi].tolist())):
                body = memo.get(g)
                if body is None:
                    a, b = int(off[g]), int(off[g + 1])
                    body = "".join(" 10\n%r\n 20\n%r\n" % (x, y) for x, y in verts[a:b].tolist())
                    if len(memo) < MEMO_MAX:
                        memo[g] = body
                layer = layers.get((f, d))
                if layer is None:
                    layer = layers[(f, d)] = layer_name(f, d)
                parts.append(head % (first + lo + k, layer, int(off[g + 1] - off[g]), 1 if closed[g] else 0))
                parts.append(body)
            task.advance(hi - lo)
            yield "".join(parts)


def toolpath_dxf(job) -> str:
    """DXF text of the job's toolpath (deterministic; :func:`iter_toolpath_dxf` joined)."""
    return "".join(iter_toolpath_dxf(job))
