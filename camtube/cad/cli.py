"""CLI of the CAD stage: ``camtube cad PATTERN -o DIR``."""
from __future__ import annotations

import argparse

from camtube.cliutil import add_pattern_argument, load_from_args


def register(sub) -> None:
    p = sub.add_parser(
        "cad", help="write the 3-D model of the cut tube (STEP, STL), its as-cut simulation and a verification report",
        description="Build the tube with its cuts (axis X, x = 0 at the tip, rotary angle 0 on +Y): STEP (mm) and "
                    "STL of the design, STL of the tube as the planned job cuts it (kerf simulation), PNG pictures "
                    "and a verification report (text + JSON).")
    add_pattern_argument(p)
    p.add_argument("-o", "--output", required=True, metavar="DIR", help="output directory")
    p.add_argument("--no-step", action="store_true", help="skip the build123d B-rep and STEP (fast preview)")
    p.add_argument("--no-pictures", action="store_true", help="skip the PNG pictures")
    p.add_argument("--kerf", type=float, default=None, metavar="MM",
                   help="beam kerf for the simulation, mm (default: process.kerf, or 0.02 if that is 0)")
    p.add_argument("--segments", type=int, default=None, metavar="N",
                   help="sides of the meshes' polygonal circles (default 256; 128 above 64 cuts)")
    p.add_argument("--strict", action="store_true", help="exit with status 1 if a verification check fails")
    p.set_defaults(func=cmd_cad)


def cmd_cad(args: argparse.Namespace) -> int:
    from camtube.cad.outputs import build_outputs
    from camtube.plan import plan_job

    pattern = load_from_args(args).pattern
    job = plan_job(pattern)
    lines: list[str] = []
    paths = build_outputs(pattern, job, args.output, step=not args.no_step, pictures=not args.no_pictures,
                          segments=args.segments, kerf_mm=args.kerf, log=lines.append)
    for p in paths:
        print(f"wrote {p}")
    for line in lines:
        print(line)
    failed = any(line.startswith("verification: FAIL") for line in lines)
    return 1 if (failed and args.strict) else 0
