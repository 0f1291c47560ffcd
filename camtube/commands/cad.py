"""CLI of the CAD stage: ``camtube cad PATTERN -o DIR`` (the orchestration is :mod:`camtube.pipeline`)."""
from __future__ import annotations

import argparse

from camtube.commands.common import add_pattern_argument


def register(sub) -> None:
    from camtube.commands.common import add_cad_options

    p = sub.add_parser(
        "cad", help="write the 3-D model of the cut tube (STEP, STL), its as-cut simulation and a verification report",
        description="Build the tube with its cuts (axis X, x = 0 at the tip, rotary angle 0 on +Y): STEP (mm) and "
                    "STL of the design, STL of the tube as the planned job cuts it (kerf simulation), PNG pictures "
                    "and a verification report (text + JSON). PATTERN is a pattern YAML or a DXF drawing. "
                    "Exits 1 when a verification check fails.")
    add_pattern_argument(p)
    p.add_argument("-o", "--output", required=True, metavar="DIR",
                   help="output directory (created; this command's files are replaced all at once)")
    add_cad_options(p)
    p.set_defaults(func=cmd_cad)


def cmd_cad(args: argparse.Namespace) -> int:
    from camtube.commands.common import run_outputs

    return run_outputs(args, "cad")
