"""Design-rule checks on a built :class:`~camtube.design.pattern.Pattern`.

Errors make a pattern unusable (nothing is written); warnings are what a
designer must act on: at ``rules.max_stroke`` a notch closes (the tendon then
pulls against a hard stop), or the backbone strain passes twice the material's
elastic limit (a large permanent set, risk of cracking). A strain between the
limit and twice it is what the source paper's joints see (their first cycle
differs, later cycles repeat): ``camtube design`` says so in a note
(:func:`stroke_notes`), and no warning is printed.
"""
from __future__ import annotations

import math
import re
from typing import Sequence

import numpy as np

from camtube.design.geometry import DirectionBend, beam_depth_mm, bends_at_stroke
from camtube.design.pattern import ASSUMED_KERF_MM, Cut, Pattern
from camtube.errors import Issue
from camtube.tol import TOL


def _circular_gap(a0: float, a1: float, b0: float, b1: float, c: float) -> float:
    """Gap between arcs [a0, a1] and [b0, b1] on a circle of length c (0 if they overlap)."""
    best = math.inf
    for k in (-1.0, 0.0, 1.0):
        lo, hi = b0 + k * c, b1 + k * c
        best = min(best, max(0.0, lo - a1, a0 - hi))
    return best


_YAML_ORIGIN = re.compile(r"^(notch|cuts\[\d+\]|holes\[\d+\])$")


def _is_key(origin: str) -> bool:
    """True for a YAML origin (``notch``, ``cuts[2]``, ``holes[0]``, a bare kind); False for a drawn entity."""
    return bool(_YAML_ORIGIN.match(origin)) or origin in ("hole", "slit")


def _shape(cut: Cut, outer_radius_mm: float):
    """The cut's region on the unwrapped sheet as a shapely geometry (polygon, or line for a slit)."""
    from shapely.geometry import LineString, Polygon, box

    if cut.outline is None:
        y0, y1 = cut.y_range_mm(outer_radius_mm)
        return box(cut.x_start_mm, y0, cut.x_end_mm, y1)
    return LineString(cut.outline) if cut.kind == "slit" else Polygon(cut.outline)


def _shifted_pairs(a: Cut, b: Cut, outer_radius_mm: float):
    import shapely

    c = 2.0 * math.pi * outer_radius_mm
    ga, gb = _shape(a, outer_radius_mm), _shape(b, outer_radius_mm)
    for k in (-1.0, 0.0, 1.0):
        yield ga, shapely.affinity.translate(gb, 0.0, k * c)


def cut_distance_mm(a: Cut, b: Cut, outer_radius_mm: float) -> float:
    """Shortest distance between two cuts on the unrolled surface (0 if they touch or overlap).

    Negative-overlap is not measured: overlapping cuts report 0 and
    :func:`cuts_overlap` tells them apart from touching ones. Drawn cuts are
    measured on their outlines (shapely), the sheet wrapping at the seam.
    """
    if a.outline is not None or b.outline is not None:
        return min(float(ga.distance(gb)) for ga, gb in _shifted_pairs(a, b, outer_radius_mm))
    c = 2.0 * math.pi * outer_radius_mm
    dx = max(0.0, b.x_start_mm - a.x_end_mm, a.x_start_mm - b.x_end_mm)
    ay, by = a.y_range_mm(outer_radius_mm), b.y_range_mm(outer_radius_mm)
    dy = _circular_gap(ay[0], ay[1], by[0], by[1], c)
    return math.hypot(dx, dy)


def cuts_overlap(a: Cut, b: Cut, outer_radius_mm: float, tol: float = 1e-9) -> bool:
    """True if the two cut regions share area (not only an edge); a slit overlaps what it crosses."""
    if a.outline is not None or b.outline is not None:
        for ga, gb in _shifted_pairs(a, b, outer_radius_mm):
            if "slit" in (a.kind, b.kind):
                if ga.intersects(gb) and ga.distance(gb) <= tol:
                    return True
            elif ga.intersection(gb).area > tol * max(1.0, ga.length):
                return True
        return False
    c = 2.0 * math.pi * outer_radius_mm
    ox = min(a.x_end_mm, b.x_end_mm) - max(a.x_start_mm, b.x_start_mm)
    if ox <= tol:
        return False
    ay, by = a.y_range_mm(outer_radius_mm), b.y_range_mm(outer_radius_mm)
    for k in (-1.0, 0.0, 1.0):
        oy = min(ay[1], by[1] + k * c) - max(ay[0], by[0] + k * c)
        if oy > tol:
            return True
    return False


def _pair_key(origin_a: str, origin_b: str, a: Cut, b: Cut) -> str:
    """The YAML key to blame for a clash: the hole, else a hand-placed cut, else the notch spacing.

    Drawn cuts: both entities.
    """
    if not _is_key(origin_a):
        return f"{origin_b} and {origin_a}"
    for o, c in ((origin_b, b), (origin_a, a)):
        if c.kind == "hole":
            return o
    for o in (origin_b, origin_a):
        if o != "notch":
            return o
    return "notch.spacing"


def _row_too_long(pattern: Pattern, origins: list, err) -> None:
    """The generated row of notches ends past the tube's end: name the count and the length, with both fixes."""
    row = [c for c, o in zip(pattern.cuts, origins) if o == "notch"]
    length = pattern.tube.length_mm
    start = min(c.x_start_mm for c in row)
    end = max(c.x_end_mm for c in row)
    pitch = (row[1].x_mm - row[0].x_mm) if len(row) > 1 else row[0].width_mm
    fit = sum(1 for c in row if c.x_end_mm <= length + 1e-12)
    err("notch.count", f"{len(row)} notches from x = {start:.4g} mm end at x = {end:.4g} mm, past the tube's end "
        f"(tube.length = {length:g} mm)", len(row), f"at most {fit} notches in this tube at pitch "
        f"h + c = {pitch:.4g} mm", f"lower notch.count to {fit}, lengthen tube.length to at least {end:.4g} mm, "
        "or shorten notch.spacing / notch.first_offset")


def _report_crossing_slits(pairs: list[tuple[int, int]], cuts, origins, err, overlap) -> None:
    """Drawn slits that overlap: a pair as any two overlapping cuts (``overlap(i, j)``), and one line for each group of
    three or more that overlap one another (a T or a star of slits from one point: one mistake, not one line per
    pair)."""
    parent: dict[int, int] = {}

    def root(k: int) -> int:
        while parent.setdefault(k, k) != k:
            k = parent[k]
        return k

    for i, j in pairs:
        parent[root(i)] = root(j)
    groups: dict[int, list[int]] = {}
    for k in sorted(parent):
        groups.setdefault(root(k), []).append(k)
    for members in sorted(groups.values()):
        if len(members) == 2:
            overlap(*next(pair for pair in pairs if set(pair) == set(members)))   # (in the sweep's order)
            continue
        names = [origins[k] for k in members]
        err(", ".join(names[:-1]) + f" and {names[-1]}",
            f"{len(members)} slits meet or cross (a T or a star drawn as separate slits): "
            + ", ".join(_describe(cuts[k]) for k in members) + " overlap one another", None,
            "cuts must not overlap",
            "draw each slit as one path that ends short of the others by the minimum web, or delete the extra ones")


def _describe(cut: Cut) -> str:
    return f"{cut.kind} at x={cut.x_mm:.4g} mm, angle {cut.angle_deg:.4g} deg"


def _same(a: Cut, b: Cut, outer_radius_mm: float, tol: float = 1e-6) -> bool:
    """True if two cuts are the same cut (a copy drawn or listed twice)."""
    if a.kind != b.kind or abs(a.x_mm - b.x_mm) > tol or abs(a.width_mm - b.width_mm) > tol \
            or abs(a.arc_mm - b.arc_mm) > tol:
        return False
    c = 2.0 * math.pi * outer_radius_mm
    dy = (a.y_center_mm(outer_radius_mm) - b.y_center_mm(outer_radius_mm)) % c
    if min(dy, c - dy) > tol:
        return False
    if a.outline is None and b.outline is None:
        return True
    ga, gb = _shape(a, outer_radius_mm), _shape(b, outer_radius_mm)
    return float(ga.hausdorff_distance(gb)) <= max(tol, 2e-4)


def section_arc_mm(cut: Cut) -> float:
    """Largest circumferential extent (mm) of the cut in any section ``x = const``.

    For a rectangle this is ``arc_mm``; for a drawn outline the span of its
    intersection with the lines ``x = const`` through its vertices (where the
    span is largest for a polygon), so a slanted or rounded notch is judged
    by its widest section, not its bounding box.
    """
    if cut.outline is None or cut.kind == "slit":
        return cut.arc_mm
    a = np.asarray(cut.outline, dtype=float)
    b = np.roll(a, -1, axis=0)
    xs = np.unique(a[:, 0])
    probes = np.concatenate([xs - 1e-9, xs + 1e-9, 0.5 * (xs[1:] + xs[:-1])])
    lo, hi = np.minimum(a[:, 0], b[:, 0]), np.maximum(a[:, 0], b[:, 0])
    dx = np.where(b[:, 0] != a[:, 0], b[:, 0] - a[:, 0], 1.0)
    best = 0.0
    for k in range(0, len(probes), 256):  # (probes x edges) in chunks
        x = probes[k:k + 256, None]
        crossing = (lo <= x) & (x <= hi) & (b[:, 0] != a[:, 0])
        y = np.where(crossing, a[:, 1] + (x - a[:, 0]) / dx * (b[:, 1] - a[:, 1]), np.nan)
        has = crossing.any(axis=1)
        if has.any():
            best = max(best, float(np.nanmax(np.nanmax(y[has], axis=1) - np.nanmin(y[has], axis=1))))
    return best


def check(pattern: Pattern, origins: Sequence[str] | None = None, file: str | None = None,
          lines: dict[str, int] | None = None) -> tuple[list[Issue], list[Issue]]:
    """Run every design rule. Returns ``(errors, warnings)``.

    Parameters
    ----------
    origins : sequence of str, optional
        For each cut of ``pattern.cuts``, the YAML key it came from
        (``notch``, ``cuts[2]``, ``holes[0]``), so messages name the key.
    lines : dict, optional
        Dotted key -> line number in ``file``.
    """
    t = pattern.tube
    ro, ri = t.outer_radius_mm, t.inner_radius_mm
    circ = t.circumference_mm
    rules = pattern.rules
    origins = list(origins) if origins is not None else [c.kind for c in pattern.cuts]
    lines = lines or {}
    errors: list[Issue] = []
    warnings: list[Issue] = []

    def err(key, msg, value=None, allowed="", fix="", kind=""):
        errors.append(Issue(key, msg, value, allowed, fix, file, lines.get(key), kind))

    def warn(key, msg, value=None, allowed="", fix=""):
        warnings.append(Issue(key, msg, value, allowed, fix, file, lines.get(key)))

    if not ri < ro:
        err("tube.inner_radius", "inner radius must be smaller than the outer radius",
            ri, f"< tube.outer_radius = {ro:g} mm", "check r_i and r_o (radii, not diameters)")
        return errors, warnings  # everything below depends on a valid section
    defocus = pattern.process.defocus_mm
    if defocus > 2.0 * ro:  # Z = -defocus: a focus beyond the far side of the tube cuts nothing of it
        err("process.defocus", f"puts the second focus {defocus:g} mm into the material, beyond the far side of the "
            f"tube (outer diameter 2 r_o = {2.0 * ro:g} mm), where it cuts nothing", defocus,
            f">= 0 and <= 2 r_o = {2.0 * ro:g} mm", "set process.defocus to the depth of the second focus level "
            "(0.1 mm in the paper's process)")
    proc = pattern.process
    if proc.repeats is None and pattern.cuts:
        # the repeats by the beam depth of the deepest cut (as the planner reads them): a rule that covers no depth
        # this pattern has was refused only by toolpath, naming no file or line, after design had passed it
        from camtube.design.contour import cut_contours, deepest_arc_mm

        arc = deepest_arc_mm(ro, cut_contours(pattern))
        depth = beam_depth_mm(ro, arc)
        deepest = max((r.max_depth_mm for r in proc.repeat_rule), default=None)
        if deepest is None or depth > deepest:
            err("process.repeat_rule", f"no row covers the beam depth {depth:.3f} mm of the deepest cut (arc "
                f"{arc:.3f} mm)" + ("" if deepest is not None else ": the rule is empty"),
                [] if deepest is None else deepest, f"a row with max_depth >= {depth:.3f} mm",
                "add a repeat_rule row with a larger max_depth, or set process.repeats")
    rt = pattern.tendon.radius_mm
    if not rt < ri:
        err("tendon.radius", "the tendon is thicker than the tube's lumen (it runs inside the tube)", rt,
            f"< tube.inner_radius = {ri:g} mm", "check r_t (a radius, not a diameter) and r_i")

    seen_keys: set[str] = set()
    for cut, origin in zip(pattern.cuts, origins):
        if _is_key(origin):
            key_arc = "notch.arc" if origin == "notch" else (
                f"{origin}.arc" if cut.kind == "notch" else f"{origin}.size")
            key_x = "notch.first_offset" if origin == "notch" else f"{origin}.x"
            fix_arc = "reduce the arc s"
        else:  # a drawn entity: the message names it
            key_arc = key_x = origin
            fix_arc = "draw the notch shorter around the tube"
        if cut.kind == "notch" and (origin != "notch" or "arc" not in seen_keys):
            arc = section_arc_mm(cut)
            if arc >= circ:
                err(key_arc, "notch arc must be shorter than the outer circumference",
                    round(arc, 9), f"< 2 pi r_o = {circ:.4f} mm", fix_arc)
            elif circ - arc < rules.min_backbone_arc_mm:
                err(key_arc, f"backbone arc 2 pi r_o - s = {circ - arc:.4f} mm is thinner than "
                    f"rules.min_backbone_arc = {rules.min_backbone_arc_mm:g} mm", round(arc, 9),
                    f"<= {circ - rules.min_backbone_arc_mm:.4f} mm", fix_arc + " or lower rules.min_backbone_arc")
            if origin == "notch" and circ - arc < rules.min_backbone_arc_mm:
                seen_keys.add("arc")  # per-notch arcs: every notch is checked, the key is reported once
        if cut.kind == "slit":
            if cut.outline:
                xs = [p[0] for p in cut.outline]
                ys = [p[1] for p in cut.outline]
                span = max(ys) - min(ys)
                if span > circ + TOL.rule and max(xs) - min(xs) >= rules.min_web_mm:
                    # (a helix of three turns was refused only by the G-code's safety check, naming no entity)
                    err(key_arc, f"{_describe(cut)} winds {span / circ:.2f} turns around the tube, more than the "
                        "rotary job cuts in one slit (its G-code would wind the axis up)", round(span, 9),
                        f"<= 2 pi r_o = {circ:.4f} mm around the tube", "draw it to less than one turn around the tube"
                        if not _is_key(origin) else "shorten the slit")
                elif max(xs) - min(xs) < rules.min_web_mm and span > circ - rules.min_backbone_arc_mm - TOL.rule:
                    # (a ring: a notch of that arc is refused; the slit cut the tube in two, or over itself, exit 0)
                    what = ("runs all the way round the tube (and over itself)" if span > circ + TOL.rule else
                            "runs all the way round the tube: it cuts it in two" if span >= circ - TOL.rule else
                            f"leaves a backbone of {circ - span:.4f} mm around the tube")
                    err(key_arc, f"{_describe(cut)} spans {span:.4f} mm around the tube at one place along it: it "
                        f"{what}", round(span, 9), f"<= 2 pi r_o - rules.min_backbone_arc = "
                        f"{circ - rules.min_backbone_arc_mm:.4f} mm", "draw the slit shorter around the tube"
                        if not _is_key(origin) else "shorten the slit")
        elif cut.kind == "hole" and cut.arc_mm >= circ / 2.0:
            err(key_arc, "hole is wider than half the circumference", cut.arc_mm, f"< {circ / 2:.4f} mm",
                "use a smaller hole")
        slack = 1e-12 if cut.outline is None else 1e-9
        if origin == "notch" and cut.x_end_mm > t.length_mm + slack and cut.x_start_mm >= -slack:
            if "row" not in seen_keys:  # the row of notches is longer than the tube: one line for the row
                seen_keys.add("row")
                _row_too_long(pattern, origins, err)
        elif cut.x_start_mm < -slack or cut.x_end_mm > t.length_mm + slack:
            err(key_x, f"{_describe(cut)} spans x = [{cut.x_start_mm:.4g}, {cut.x_end_mm:.4g}] mm, outside the tube",
                round(cut.x_mm, 9), f"the cut inside 0 <= x <= tube.length = {t.length_mm:g} mm",
                "move the cut or lengthen tube.length")

    # pairwise overlap / web: sweep in x so long patterns stay near-linear
    order = sorted(range(len(pattern.cuts)), key=lambda i: pattern.cuts[i].x_start_mm)
    thinned_by_kerf = not pattern.process.kerf_mm > 0
    cuts = pattern.cuts
    crossing: list[tuple[int, int]] = []   # drawn slits that overlap, (i, j) by index

    def overlap(i: int, j: int) -> None:
        """The line for cut ``j`` overlapping cut ``i`` (``i`` first in the sweep)."""
        a, b = cuts[i], cuts[j]
        hole_pair = "hole" in (a.kind, b.kind)
        drawn = not (_is_key(origins[i]) and _is_key(origins[j]))
        what = "collides with" if hole_pair else "overlaps"
        err(_pair_key(origins[i], origins[j], a, b), f"{_describe(b)} {what} {_describe(a)}", None,
            "cuts must not overlap", "move the two cuts apart in the drawing, or delete one" if drawn else
            "move the hole along x or around the tube" if hole_pair else "increase notch.spacing or move the cut",
            kind="holes_collide" if a.kind == b.kind == "hole" else "")

    for a_pos, i in enumerate(order):
        a = cuts[i]
        for j in order[a_pos + 1:]:
            b = cuts[j]
            if b.x_start_mm > a.x_end_mm + rules.min_web_mm + (ASSUMED_KERF_MM if thinned_by_kerf else 0.0):
                break
            hole_pair = "hole" in (a.kind, b.kind)
            key = _pair_key(origins[i], origins[j], a, b)
            # (a drawing's cuts were told to "increase notch.spacing", a YAML key a drawing does not have)
            drawn = not (_is_key(origins[i]) and _is_key(origins[j]))
            if _same(a, b, ro):
                err(key, f"{_describe(b)} is a duplicate of {_describe(a)} (drawn or listed twice)", None,
                    "each cut once", "delete one of the two")
            elif cuts_overlap(a, b, ro):
                if drawn and a.kind == b.kind == "slit":
                    crossing.append((i, j))   # reported below: three slits from one point are one mistake
                else:
                    overlap(i, j)
            else:
                d = cut_distance_mm(a, b, ro)
                widen = ("move the two cuts apart in the drawing" if drawn else
                         "move the hole away from the notches" if hole_pair else "increase notch.spacing")
                if d < rules.min_web_mm - TOL.rule:  # (the CAD verification's min_web: the same slack)
                    what = "is too close to" if not hole_pair else "collides with (web too thin)"
                    err(key, f"{_describe(b)} {what} {_describe(a)}: web {d:.4g} mm", round(d, 9),
                        f">= rules.min_web = {rules.min_web_mm:g} mm", widen,
                        kind="holes_collide" if a.kind == b.kind == "hole" else "")
                elif thinned_by_kerf and d < rules.min_web_mm + ASSUMED_KERF_MM - TOL.rule:
                    # without kerf compensation each side of the web is cut half a kerf wider than drawn: as cut it is
                    # thinner than the limit, and the CAD verification (which cuts it so) fails it
                    left = (f"{d - ASSUMED_KERF_MM:.4g} mm as cut" if d > ASSUMED_KERF_MM
                            else "none: the two cuts merge as cut")
                    warn(key, f"the web between {_describe(a)} and {_describe(b)} is {d:.4g} mm as drawn; with "
                         f"process.kerf = 0 (no kerf compensation) a {ASSUMED_KERF_MM:g} mm kerf leaves {left}",
                         round(d, 9),
                         f">= rules.min_web + kerf = {rules.min_web_mm + ASSUMED_KERF_MM:g} mm as drawn",
                         f"set process.kerf to the beam's kerf (kerf compensation), or {widen}")
        if len(errors) > 50:
            break
    _report_crossing_slits(crossing, cuts, origins, err, overlap)

    if pattern.notches and not errors:
        for d in bends_at_stroke(pattern):
            for w in stroke_warnings(d, t.material):
                warn(w.key, w.message, w.value, w.allowed, w.fix)
    return errors, warnings


#: A strain above this multiple of ``rules.max_strain`` at ``rules.max_stroke`` is a warning.
STRAIN_WARNING_FACTOR = 2.0


def stroke_warnings(d: DirectionBend, material: str) -> list[Issue]:
    """Warnings for one bending direction at ``rules.max_stroke`` (empty when the design is fine for it)."""
    out = []
    where = f"notches at {d.angle_deg:g} deg"
    if d.closes:
        out.append(Issue("rules.max_stroke", f"{where}: a notch closes at a tendon stroke of "
                         f"{d.closing_stroke_mm:.2f} mm, before rules.max_stroke = {d.stroke_mm:g} mm; beyond it the "
                         "tendon pulls against closed notches (a hard stop) and the joint angle stops following the "
                         "model", round(d.stroke_mm, 6), f"<= {d.closing_stroke_mm:.3f} mm",
                         "lower rules.max_stroke, or widen the notches (notch.width) or add notches"))
    if d.strain > STRAIN_WARNING_FACTOR * d.strain_limit:
        out.append(Issue("rules.max_strain", f"{where}: at rules.max_stroke = {d.stroke_mm:g} mm the joint bends "
                         f"{math.degrees(d.bend_rad):.1f} deg with a backbone strain of {d.strain:.3f}, more than "
                         f"{STRAIN_WARNING_FACTOR:g}x the {material} elastic limit {d.strain_limit:g} (largest elastic "
                         f"bend {math.degrees(d.elastic_bend_rad):.1f} deg at {d.elastic_stroke_mm:.2f} mm): expect a "
                         "large permanent set in the first cycles and a risk of cracking the backbone",
                         round(d.strain, 6), f"<= {STRAIN_WARNING_FACTOR * d.strain_limit:g}",
                         f"lower rules.max_stroke towards {d.elastic_stroke_mm:.2f} mm, or use more or wider notches"))
    return out


def stroke_notes(pattern: Pattern) -> list[str]:
    """Plain-language notes on the bend at ``rules.max_stroke``, per direction (for ``camtube design``)."""
    notes = []
    for d in bends_at_stroke(pattern):
        head = (f"notches at {d.angle_deg:g} deg ({d.notches}): at rules.max_stroke {d.stroke_mm:g} mm the joint "
                f"bends {math.degrees(d.bend_rad):.1f} deg (base model, stroke only), backbone strain {d.strain:.3f}; "
                f"largest elastic bend {math.degrees(d.elastic_bend_rad):.1f} deg at {d.elastic_stroke_mm:.2f} mm; "
                f"all notches closed at {math.degrees(d.closure_rad):.1f} deg")
        if d.strain > d.strain_limit:
            head += (f". Above the elastic limit {d.strain_limit:g}: expect a permanent set in the first cycles "
                     "(the source paper's first cycle differs; later cycles repeat)")
        notes.append(head)
    return notes
