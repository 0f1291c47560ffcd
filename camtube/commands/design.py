"""CLI of the design stage: ``camtube design`` and ``camtube dxf``."""
from __future__ import annotations

import argparse
import math
from pathlib import Path

from camtube.commands.common import add_pattern_argument, load_from_args, path_value, refuse_output_over_input
from camtube.errors import CamtubeError


def register(sub) -> None:
    p = sub.add_parser("design", help="print the derived geometry of a pattern",
                       description="Print phi, ybar, moment arm, closure angle, tube length, backbone "
                                   "area and second moment of area (mm, rad and deg).")
    add_pattern_argument(p)
    p.add_argument("--stroke", type=float, metavar="MM",
                   help="also print the notch-by-notch forward model at this tendon stroke (mm): per-notch angles "
                        "and strain, tendon force, tip position and direction, one tendon pulled at a time")
    p.add_argument("--calibration", type=path_value, metavar="FIT.json",
                   help="with --stroke: use the parameters of a 'camtube model fit/diagnose --json' file")
    p.add_argument("--hinge", choices=("fe_row", "beam", "fe_fit"), default="fe_row",
                   help="with --stroke: notch stiffness: E I over h plus a root length that shrinks with the webs "
                        "to the neighbours (fe_row, default, fitted to FE runs of notches in rows), E I / h (beam, "
                        "the paper's) or with a lone notch's root length (fe_fit); see docs/design.md")
    p.add_argument("--overcut", type=float, metavar="MM",
                   help="with --stroke: how much wider than drawn each notch is cut, mm (default: 0 with kerf "
                        "compensation, else the calibration's kerf or the 0.02 mm the CAD verification assumes; "
                        "the value 'camtube synthesize' designs with)")
    p.set_defaults(func=cmd_design)

    p = sub.add_parser("dxf", help="write the unrolled design DXF",
                       description="Write the unrolled drawing: x along the tube from the tip, y arc length "
                                   "on the outer surface (mm, R2013, $INSUNITS=4).")
    add_pattern_argument(p)
    p.add_argument("-o", "--output", required=True, metavar="OUT.dxf", help="output DXF file")
    p.set_defaults(func=cmd_dxf)

    p = sub.add_parser("schema", help="print every pattern YAML key with units, range and default (Markdown)")
    p.set_defaults(func=cmd_schema)

    p = sub.add_parser("preview", help="write an SVG picture of the unrolled pattern",
                       description="Write an SVG of the unrolled sheet (x from the tip, y arc length, mm) "
                                   "with notches in red and holes in blue.")
    add_pattern_argument(p)
    p.add_argument("-o", "--output", required=True, metavar="OUT.svg", help="output SVG file")
    p.set_defaults(func=cmd_preview)


def design_report(pattern) -> str:
    """Text table of a pattern's derived geometry, then notes on the bend at ``rules.max_stroke``."""
    from camtube.design.geometry import beam_depth_mm, pattern_geometry
    from camtube.design.rules import stroke_notes

    t = pattern.tube
    rows = [
        ("pattern", pattern.name, ""),
        ("notches / holes", f"{len(pattern.notches)} / {len(pattern.holes)}", ""),
        ("tube r_o / r_i / wall", f"{t.outer_radius_mm:.3f} / {t.inner_radius_mm:.3f} / {t.wall_mm:.3f}", "mm"),
        ("tube length", f"{t.length_mm:.3f}", "mm"),
    ]
    if not pattern.notches:
        rows.append(("note", "no notches: the tube does not bend (phi, ybar and the moment arm are undefined)", ""))
        return _table(rows)
    geo = pattern_geometry(pattern)
    g = geo.first
    rows += [
        ("notched length (sum of h)", f"{geo.notched_length_mm:.3f}", "mm"),
        ("backbone angle phi", f"{g.phi_rad:.3f}", f"rad ({math.degrees(g.phi_rad):.1f} deg)"),
        ("centroid ybar", f"{g.ybar_mm:.3f}", "mm"),
        ("moment arm ybar + r_i - r_t", f"{g.moment_arm_mm:.3f}", "mm"),
        ("backbone area", f"{g.area_mm2:.4f}", "mm^2"),
        ("backbone second moment", f"{g.second_moment_mm4:.5f}", "mm^4"),
        ("closure angle per notch", f"{math.degrees(g.closure_angle_rad):.2f}", "deg"),
    ]
    for angle_deg, closure_rad, count in _closure_by_direction(pattern, geo):
        rows.append((f"closure angle, {count} notches at {angle_deg:g} deg", f"{math.degrees(closure_rad):.1f}", "deg"))
    rows += [
        ("backbone strain at closure", f"{g.closure_strain:.3f}", ""),
        ("beam depth r_o (1 - cos(s / 2 r_o))", f"{beam_depth_mm(t.outer_radius_mm, g.arc_mm):.3f}", "mm"),
    ]
    if not geo.uniform:
        rows.append(("note", "notches differ: values are for the first notch", ""))
    notes = stroke_notes(pattern)
    return _table(rows) + ("".join(f"\nnote: {n}" for n in notes))


def _closure_by_direction(pattern, geo) -> list[tuple[float, float, int]]:
    """(direction deg, closure angle of its notches rad, notch count) per bending direction."""
    from camtube.design.geometry import notches_by_direction

    closure = {id(n): g.closure_angle_rad for n, g in zip(pattern.notches, geo.notches)}
    return [(a, sum(closure[id(n)] for n in ns), len(ns)) for a, ns in notches_by_direction(pattern)]


def _table(rows) -> str:
    w = max(len(r[0]) for r in rows)
    return "\n".join(f"{a:<{w}}  {b} {c}".rstrip() for a, b, c in rows)


def cmd_design(args: argparse.Namespace) -> int:
    if args.stroke is not None and not (0.0 <= args.stroke < 1e3):
        raise CamtubeError(f"--stroke {args.stroke:g}: the tendon stroke must be >= 0 and < 1000 mm; fix: give a "
                           "stroke in mm, e.g. --stroke 1.5")
    if args.calibration and args.stroke is None:
        raise CamtubeError("--calibration is used by the forward model; fix: add --stroke MM")
    if args.overcut is not None and args.stroke is None:   # (it was ignored without a word)
        raise CamtubeError(f"--overcut {args.overcut:g} is used by the forward model; fix: add --stroke MM")
    loaded = load_from_args(args)
    mech = None
    if args.stroke is not None:
        from camtube.joint.forward import Mechanics

        from dataclasses import replace

        from camtube.synthesis.solve import expected_overcut_mm

        calib = Mechanics.from_fit_json(args.calibration) if args.calibration else None
        mech = calib or Mechanics()
        overcut = args.overcut if args.overcut is not None else expected_overcut_mm(loaded.pattern.process, calib)
        if not 0.0 <= overcut < 0.5:
            if args.overcut is None:  # from the calibration's kerf.kerf_mm
                raise CamtubeError(f"{args.calibration}: kerf.kerf_mm = {overcut:g} mm, the overcut it gives, must be "
                                   ">= 0 and < 0.5 mm; fix: pass --overcut MM, or a calibration with a physical kerf")
            raise CamtubeError(f"--overcut {overcut:g}: must be >= 0 and < 0.5 mm; fix: give the laser's overcut in mm")
        mech = replace(mech, kerf_mm=overcut, hinge=args.hinge)
    print(design_report(loaded.pattern))
    extra = _design_extras(loaded.pattern)
    if extra:
        print(extra)
    if mech is not None and loaded.pattern.notches:
        from camtube.joint.forward import stroke_table

        print(stroke_table(loaded.pattern, args.stroke, mech))
    return 0


def _design_extras(pattern) -> str:
    """Sections later stages add to ``camtube design`` (gathered by the orchestration, not by this stage)."""
    from camtube.pipeline import design_extras

    return design_extras(pattern)


def cmd_dxf(args: argparse.Namespace) -> int:
    from camtube.export.dxf import design_dxf
    from camtube.io import write_atomic

    if Path(args.output).suffix.lower() != ".dxf":
        raise CamtubeError(f"{args.output}: dxf writes a DXF drawing; fix: name the output OUT.dxf")
    refuse_output_over_input(args.output, "-o", [("PATTERN", args.pattern)])
    loaded = load_from_args(args)
    text = design_dxf(loaded.pattern)
    path = write_atomic(args.output, text)
    p = loaded.pattern
    print(f"wrote {path}: {len(p.notches)} notches, {len(p.holes)} holes, "
          f"sheet {p.tube.length_mm:g} x {p.tube.circumference_mm:.4f} mm")
    return 0


def cmd_preview(args: argparse.Namespace) -> int:
    from camtube.export.svg import unrolled_svg
    from camtube.io import write_atomic

    if Path(args.output).suffix.lower() != ".svg":
        raise CamtubeError(f"{args.output}: preview writes SVG, not {Path(args.output).suffix or 'a file without a suffix'}; "
                           "fix: name the output OUT.svg (convert it to PNG with any SVG tool if needed)")
    loaded = load_from_args(args)
    path = write_atomic(args.output, unrolled_svg(loaded.pattern))
    print(f"wrote {path}")
    return 0


def cmd_schema(args: argparse.Namespace) -> int:
    from camtube.design.schema import markdown

    print(markdown())
    return 0
