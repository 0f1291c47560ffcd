"""What ``camtube synthesize`` prints and writes: the pattern YAML, target vs predicted, the
active limit and the laser tolerance (bend change per 10 um of notch depth and of kerf).

Writers return text; the command writes files.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace

import numpy as np

from camtube.design.pattern import Pattern
from camtube.joint.forward import simulate
from camtube.synthesis.solve import Design

#: Step of the tolerance figures (mm): 10 um.
TOL_STEP_MM = 0.010


def _num(v: float) -> str:
    return f"{v:.6g}"


def _list(vals) -> str:
    return "[" + ", ".join(_num(v) for v in vals) + "]"


def _other_strokes(goal) -> str:
    """The check line's note for directions whose target stroke is not the first's (each direction's bend is read at
    its own stroke: the 0 deg direction of a two-direction goal, 30 deg at 1.2 mm, was checked at the first's 1.5 mm,
    37.5 deg), "" when every direction has the first's."""
    first = goal.bends[0]
    others = [b for b in goal.bends[1:] if b.stroke_mm != first.stroke_mm]
    if not others:
        return ""
    return (f" (for the {first.angle_deg:g} deg direction; "
            + "; ".join(f"--stroke {b.stroke_mm:g} for the {b.angle_deg:g} deg direction" for b in others) + ")")


def pattern_yaml(design: Design, process: object | None = None) -> str:
    """The pattern YAML of ``design`` (per-notch lists from the tip; one anchor hole per direction)."""
    g = design.goal
    p = design.pattern
    t, td, r = p.tube, p.tendon, p.rules
    sec = design.notch_section
    proc = g.process if process is None else process
    lines = [
        f"# Written by camtube synthesize from {g.source or 'a goal'}: per-notch values from the tip.",
        "# Targets (bend at the tendon stroke, per direction): "
        + "; ".join(f"{b.bend_deg:g} deg at {b.stroke_mm:g} mm towards {b.angle_deg:g} deg" for b in g.bends),
        f"# Check: camtube design THIS.yaml --stroke {g.bends[0].stroke_mm:g} --overcut {design.mechanics.kerf_mm:g}"
        + (f" --hinge {design.mechanics.hinge}" if design.mechanics.hinge != "fe_row" else "")
        + (" --calibration FIT.json (the same fit)" if design.mechanics.source != "defaults" else "")
        + _other_strokes(g),
        f"name: {json.dumps(p.name)}",   # quoted: a name YAML would read as a date or a number stays text
        f"tube: {{outer_radius: {_num(t.outer_radius_mm)}, inner_radius: {_num(t.inner_radius_mm)}, "
        f"length: {_num(t.length_mm)}, material: {t.material}}}",
        "notch:",
        "  layout: uan",
        f"  count: {sec['count']}",
        f"  first_offset: {_num(sec['first_offset'])}",
        f"  widths: {_list(sec['widths'])}",
        f"  arcs: {_list(sec['arcs'])}",
    ]
    if sec["count"] > 1:
        lines.append(f"  spacings: {_list(sec['spacings'])}")
    else:
        lines.append("  spacing: 0.5")
    lines.append(f"  angles_deg: {_list(sec['angles_deg'])}")
    lines.append("holes:")
    for h in p.holes:
        lines.append(f"  - {{x: {_num(h.x_mm)}, size: {_num(h.width_mm)}, angle_deg: {_num(h.angle_deg)}}}")
    lines.append(f"tendon: {{radius: {_num(td.radius_mm)}, length: {_num(td.length_mm)}, modulus_gpa: "
                 f"{_num(td.modulus_gpa)}, material: {td.material}, friction: {_num(td.friction)}}}")
    if isinstance(proc, dict):
        import yaml

        lines.append("process: " + yaml.safe_dump(proc, default_flow_style=True, sort_keys=False, width=10**6).strip())
    else:
        lines.append(f"process: {proc}")
    lines.append(f"rules: {{min_backbone_arc: {_num(r.min_backbone_arc_mm)}, min_web: {_num(r.min_web_mm)}, "
                 f"max_strain: {_num(r.max_strain)}, max_stroke: {_num(r.max_stroke_mm)}}}")
    return "\n".join(lines) + "\n"


@dataclass(frozen=True)
class DirectionCheck:
    """Forward-model figures of one direction of a pattern at its design stroke.

    Attributes
    ----------
    angle_deg, target_deg, stroke_mm : float
    predicted_deg : float
        Bend the forward model predicts at ``stroke_mm``.
    force_N, max_strain : float
    share_error : float
        Largest relative difference between a notch's share and its target share.
    per_10um_depth_deg, per_10um_kerf_deg : float
        Change of the bend at ``stroke_mm`` when every notch is cut 10 um deeper, or with 10 um more kerf
        (arc and width each 10 um larger).
    other_hinge : str
        The notch-stiffness model compared with (:func:`other_hinge`: ``beam``, or ``fe_row`` for a beam design).
    other_hinge_deg : float
        Bend at ``stroke_mm`` of the same pattern under ``other_hinge``: what the choice of stiffness model means
        for this pattern (docs/design.md compares the hinges with the FE of a notch in its row).
    """

    angle_deg: float
    target_deg: float
    stroke_mm: float
    predicted_deg: float
    force_N: float
    max_strain: float
    share_error: float
    per_10um_depth_deg: float
    per_10um_kerf_deg: float
    other_hinge: str = ""
    other_hinge_deg: float = math.nan


def other_hinge(hinge: str) -> str:
    """The hinge the stiffness line compares with: the paper's ``beam``, or ``fe_row`` for a beam design."""
    return "fe_row" if hinge == "beam" else "beam"


def _deeper_arc(s: float, ro: float, dd: float) -> float:
    """Arc of a notch cut ``dd`` deeper (beam depth ``r_o (1 - cos(s / 2 r_o))``)."""
    depth = ro * (1.0 - math.cos(s / (2.0 * ro))) + dd
    return 2.0 * ro * math.acos(max(-1.0, 1.0 - depth / ro))


def _perturbed(pattern: Pattern, arc, width) -> Pattern:
    cuts = [replace(c, arc_mm=arc(c.arc_mm), width_mm=width(c.width_mm)) if c.kind == "notch" else c
            for c in pattern.cuts]
    return pattern.with_cuts(cuts)


def check_design(design: Design, pattern: Pattern | None = None) -> tuple[DirectionCheck, ...]:
    """Target vs forward model for each direction of ``pattern`` (default: the design's), with tolerances."""
    p = pattern or design.pattern
    mech = design.mechanics
    ro = p.tube.outer_radius_mm
    deeper = _perturbed(p, lambda s: _deeper_arc(s, ro, TOL_STEP_MM), lambda h: h)
    kerfed = _perturbed(p, lambda s: s + TOL_STEP_MM, lambda h: h + TOL_STEP_MM)
    other = other_hinge(mech.hinge)
    mech_other = replace(mech, hinge=other)
    out = []
    for d in design.directions:
        b = d.target
        st = simulate(p, {b.angle_deg: b.stroke_mm}, mech).direction(b.angle_deg)
        bo = simulate(p, {b.angle_deg: b.stroke_mm}, mech_other).direction(b.angle_deg).bend_deg
        target_shares = list(d.shares[::-1])  # base to tip, like the state
        err = max(abs(a - t) / t for a, t in zip(st.shares, target_shares))
        bd = simulate(deeper, {b.angle_deg: b.stroke_mm}, mech).direction(b.angle_deg).bend_deg
        bk = simulate(kerfed, {b.angle_deg: b.stroke_mm}, mech).direction(b.angle_deg).bend_deg
        out.append(DirectionCheck(b.angle_deg, b.bend_deg, b.stroke_mm, st.bend_deg, st.force_N,
                                  float(st.strain.max()), float(err), bd - st.bend_deg, bk - st.bend_deg, other, bo))
    return tuple(out)


def active_limits(design: Design, checks) -> list[tuple[str, float]]:
    """``(limit key, margin)`` per limit, smallest margin first (margin: fraction of the limit still free)."""
    g = design.goal
    lim = g.limits
    p = design.pattern
    circ = p.tube.circumference_mm
    notches = p.notches
    first, last = notches[0], notches[-1]
    length = last.x_end_mm - first.x_start_mm
    out = [
        ("limits.max_strain", 1.0 - max(c.max_strain for c in checks) / lim.max_strain),
        ("limits.max_force_N", 1.0 - max(c.force_N for c in checks) / lim.max_force_N),
        ("limits.max_length", 1.0 - length / lim.max_length_mm),
        ("limits.min_backbone_arc", (circ - max(n.arc_mm for n in notches)) / lim.min_backbone_arc_mm - 1.0
         if lim.min_backbone_arc_mm > 0 else math.inf),
        ("limits.min_feature", min(n.width_mm for n in notches) / lim.min_feature_mm - 1.0),
    ]
    return sorted(out, key=lambda kv: kv[1])


def summary_text(design: Design, checks, seconds: float | None = None, pattern: Pattern | None = None) -> str:
    """Target against predicted per direction, the active limit, the laser tolerance and the stiffness spread."""
    p = pattern or design.pattern
    m = design.mechanics
    lines = [f"{p.name}: {len(p.notches)} notches, joint {p.notches[-1].x_end_mm - p.notches[0].x_start_mm:.2f} mm, "
             f"tube {p.tube.length_mm:g} mm; mechanics: {m.source}"
             + (f" (not used: {', '.join(m.ignored)})" if m.ignored else "")
             + (f"; solved in {seconds:.2f} s" if seconds is not None else "")]
    if m.kerf_mm:
        lines.append(f"notches drawn {1000 * m.kerf_mm:.0f} um narrower (arc and width) than they are to be cut: the "
                     "expected overcut of a process without kerf compensation")
    lines.append("direction  notches  stroke mm  target deg  predicted deg  force N  strain   shares err  "
                 "deg/10um depth  deg/10um kerf")
    for d, c in zip(design.directions, checks):
        lines.append(f"{c.angle_deg:9g}  {d.count:7d}  {c.stroke_mm:9.3f}  {c.target_deg:10.2f}  {c.predicted_deg:13.2f}  "
                     f"{c.force_N:7.3f}  {c.max_strain:.4f}  {100 * c.share_error:8.2f} %  {c.per_10um_depth_deg:+14.2f}  "
                     f"{c.per_10um_kerf_deg:+13.2f}")
    lim = active_limits(design, checks)
    key, margin = lim[0]
    lines.append(f"active limit: {key} ({100 * margin:.1f} % to spare); next: "
                 + ", ".join(f"{k} {100 * v:.0f} %" for k, v in lim[1:3]))
    lines.append("tolerance: a notch cut 10 um deeper, or 10 um more kerf (arc and width), changes the bend at the "
                 "design stroke by the degrees shown")
    lines.append(stiffness_line(design, checks, pattern))
    if design.goal.centerline:
        from camtube.synthesis.centerline import follow

        f = follow(design.goal, p, m)
        lines.append(f"centre line (every tendon at its stroke): tip at ({f.model_tip_mm[0]:.3f}, {f.model_tip_mm[1]:.3f}, "
                     f"{f.model_tip_mm[2]:.3f}) mm, target ({f.target_tip_mm[0]:.3f}, {f.target_tip_mm[1]:.3f}, "
                     f"{f.target_tip_mm[2]:.3f}) mm; farthest from the target's centre line {1000 * f.max_deviation_mm:.0f} um "
                     f"over {f.length_mm:.2f} mm; tip direction off by {f.tip_direction_error_deg:.2f} deg")
    return "\n".join(lines)


def stiffness_line(design: Design, checks, pattern: Pattern | None = None) -> str:
    """The bend at the design stroke under the other notch-stiffness model, per direction (one line)."""
    from camtube.joint.forward import direction_notches

    p = pattern or design.pattern
    m = design.mechanics
    other = checks[0].other_hinge
    k_own = np.concatenate([ns.stiffness_nmm_per_rad for ns in direction_notches(p, m)])
    k_other = np.concatenate([ns.stiffness_nmm_per_rad for ns in direction_notches(p, replace(m, hinge=other))])
    ratio = k_other / k_own
    lo, hi = float(ratio.min()), float(ratio.max())
    span = f"{lo:.2f}" if abs(hi - lo) < 0.005 else f"{lo:.2f} to {hi:.2f}"
    parts = [f"{c.other_hinge_deg:.2f} deg ({c.other_hinge_deg - c.predicted_deg:+.2f}) towards {c.angle_deg:g} deg"
             for c in checks]
    return (f"stiffness: designed with the {m.hinge} hinge; with the {other} hinge (this pattern's notches {span} x as "
            f"stiff) the bend at the design stroke would be " + "; ".join(parts)
            + " (fe_row is within 7 % of the FE of a notch in its row, beam 1.3 to 4.6 x too stiff: docs/design.md)")
