"""Per-pass toolpath DXF: every pass as a polyline, one layer per (focus, drill) class, streamed.

For laser software that maps layers to settings. Layer ``F{f}-D{d}`` holds
the passes of focus level ``f`` (0 on the surface, 1 defocused) and drill cut
``d`` (offset ``kerf/2 + d * drill_offset`` inward); its description states the
settings, and each layer has its own colour. Polylines are in execution order
and start at the pass's start point (closed for cut regions, open for slits);
seam-crossing paths are unwrapped (``y`` may leave ``[0, 2 pi r_o]``, as the rotary
stage cuts them). The design regions and the tube surface are on construction
layers (not plotted).

Streaming: ezdxf builds the document without entities (header, tables, objects,
with handles reserved for the entities), and :func:`iter_toolpath_dxf` writes
each LWPOLYLINE (design regions, outline, passes) as DXF text into its ENTITIES
section, chunk by chunk, exactly as ezdxf would (a test compares the
bytes with :func:`toolpath_document` and reads the result with ezdxf's
``readfile`` + ``audit``).
"""
from __future__ import annotations

import math
from typing import Iterator

import numpy as np

from camtube.design.contour import rectangle
from camtube.export.dxf import new_document, to_string
from camtube.plan.moves import CHUNK_PASSES
from camtube.plan.safety import check_job
from camtube.progress import NO_PROGRESS, Progress

#: ACI colours of the (focus, drill) layers, in class order; cycles if there are more classes.
COLOURS = (1, 3, 5, 6, 2, 4, 30, 200, 140, 210, 40, 170)
#: Distinct paths whose vertex text is kept for reuse (bounds the memo's memory).
MEMO_MAX = 500_000


def layer_name(focus_level: int, drill_index: int) -> str:
    return f"F{focus_level}-D{drill_index}"


def _classes(job) -> list[tuple[int, int, float, float]]:
    """(focus level, drill index, focus offset, inward offset) of each layer, sorted.

    A slit's passes (offset 0) share the layer of their class; its offset is the largest.
    """
    pk = job.packed
    if pk.n_pass == 0:
        return []
    key = pk.pass_focus.astype(np.int64) * (int(pk.pass_drill.max()) + 1) + pk.pass_drill
    uniq, first, inv = np.unique(key, return_index=True, return_inverse=True)
    off = np.full(len(uniq), -np.inf)
    np.maximum.at(off, inv, pk.pass_offset)
    return [(int(pk.pass_focus[i]), int(pk.pass_drill[i]), float(pk.pass_z[i]), float(o))
            for i, o in zip(first.tolist(), off.tolist())]


def _skeleton(job, n_reserved: int):
    """The document without entities, ``n_reserved`` handles kept free for them. Returns (doc, first handle)."""
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
    handles = doc.entitydb.handles
    first = int(str(handles), 16)
    handles.reset("%X" % (first + n_reserved))
    return doc, first


def _add(msp, contour, layer: str) -> None:
    msp.add_lwpolyline([(float(x), float(y)) for x, y in contour.points], close=contour.closed,
                       dxfattribs={"layer": layer})


def _outline(job):
    return rectangle(0.0, 0.0, job.length_mm, 2.0 * math.pi * job.outer_radius_mm)


def toolpath_document(job):
    """ezdxf document of the job's passes (safety-checked first; small jobs: one entity object per pass)."""
    check_job(job)
    doc, first = _skeleton(job, 0)
    msp = doc.modelspace()
    for c in job.design:
        _add(msp, c, "CONSTRUCTION-DESIGN")
    _add(msp, _outline(job), "CONSTRUCTION-OUTLINE")  # last construction entity: the sheet size
    for p in job.passes:
        _add(msp, p.contour, layer_name(p.focus_level, p.drill_index))
    return doc


def iter_toolpath_dxf(job, progress: Progress = NO_PROGRESS) -> Iterator[str]:
    """DXF text of the job's toolpath in chunks, in bounded memory (deterministic).

    The whole neutral move list is safety-checked (chunk by chunk) before the first chunk.
    """
    check_job(job)
    n_design = len(job.design)
    doc, first = _skeleton(job, n_design + 1 + job.packed.n_pass)
    text = to_string(doc)
    owner = doc.modelspace().block_record_handle
    start = text.index("\n  2\nENTITIES\n")
    cut = text.index("  0\nENDSEC\n", start)
    head, tail = text[:cut], text[cut:]
    del text
    yield head
    for lo in range(0, n_design, CHUNK_PASSES):
        hi = min(n_design, lo + CHUNK_PASSES)
        yield "".join([_polyline(first + i, owner, "CONSTRUCTION-DESIGN", job.design[i].points, job.design[i].closed)
                       for i in range(lo, hi)])
    yield _polyline(first + n_design, owner, "CONSTRUCTION-OUTLINE", _outline(job).points, True)
    yield from _entities(job, first + n_design + 1, owner, progress)
    yield tail


def _polyline(handle: int, owner: str, layer: str, points, closed: bool) -> str:
    """One LWPOLYLINE as ezdxf writes it (R2013): handle, owner, layer, count, closed flag, vertices."""
    return (f"  0\nLWPOLYLINE\n  5\n{handle:X}\n330\n{owner}\n100\nAcDbEntity\n  8\n{layer}\n100\nAcDbPolyline\n"
            f" 90\n{len(points)}\n 70\n{1 if closed else 0}\n"
            + "".join([" 10\n%r\n 20\n%r\n" % (float(x), float(y)) for x, y in points]))


def _entities(job, first: int, owner: str, progress: Progress) -> Iterator[str]:
    """LWPOLYLINE text of every pass, chunk by chunk.

    An entity's text is its handle, a part that depends on its layer and vertex count,
    and its vertices; the vertex text is formatted once per path and reused (up to
    :data:`MEMO_MAX` paths), so a pass costs one string join.
    """
    pk = job.packed
    n = pk.n_pass
    lead = "  0\nLWPOLYLINE\n  5\n"
    rest = "\n330\n" + owner + "\n100\nAcDbEntity\n  8\n%s\n100\nAcDbPolyline\n 90\n%d\n 70\n%d\n"
    memo: dict[int, str] = {}
    heads: dict[tuple[int, int, int, bool], str] = {}
    off, closed, verts = pk.geom_offset, pk.geom_closed, pk.vertices
    size = pk.geom_size

    with progress.task("toolpath DXF", total=n) as task:
        for lo in range(0, n, CHUNK_PASSES):
            hi = min(n, lo + CHUNK_PASSES)
            geoms = pk.pass_geom[lo:hi]
            keys = list(zip(pk.pass_focus[lo:hi].tolist(), pk.pass_drill[lo:hi].tolist(), size[geoms].tolist(),
                            closed[geoms].tolist()))
            for k in set(keys) - heads.keys():
                heads[k] = rest % (layer_name(k[0], k[1]), k[2], 1 if k[3] else 0)
            gl = geoms.tolist()
            local = {}
            for g in set(gl):
                t = memo.get(g)
                if t is None:
                    a, b = int(off[g]), int(off[g + 1])
                    t = "".join([" 10\n%r\n 20\n%r\n" % (x, y) for x, y in verts[a:b].tolist()])
                    if len(memo) < MEMO_MAX:
                        memo[g] = t
                local[g] = t
            yield "".join([lead + ("%X" % h) + heads[k] + local[g]
                           for h, k, g in zip(range(first + lo, first + hi), keys, gl)])
            task.advance(hi - lo)


def toolpath_dxf(job) -> str:
    """DXF text of the job's toolpath (deterministic; :func:`iter_toolpath_dxf` joined)."""
    return "".join(iter_toolpath_dxf(job))
