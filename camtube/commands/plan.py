"""CLI of the plan stage: ``camtube toolpath`` and ``camtube build`` (the orchestration is :mod:`camtube.pipeline`)."""
from __future__ import annotations

import argparse

from camtube.commands.common import add_cad_options, add_pattern_argument, path_value, run_outputs

def register(sub) -> None:
    from camtube.export.dialects import DIALECTS
    from camtube.plan.planner import DEFAULT_ORDERING, ORDERINGS

    def common(p):
        add_pattern_argument(p)
        p.add_argument("-o", "--output", required=True, metavar="DIR",
                       help="output directory (created; files of this command are replaced all at once, "
                            "other files in it are kept)")
        p.add_argument("--ordering", choices=ORDERINGS, default=None,
                       help=f"pass ordering (default: the machine profile's, {DEFAULT_ORDERING} unless it says "
                            f"otherwise; {DEFAULT_ORDERING}: one round per repeat/focus/drill visits every cut; "
                            "sequential: all passes of a cut, then the next; chained: one round per "
                            "repeat/focus visits every cut and cuts its drill passes as one beam-on path, "
                            "each joined to the next by a beam-on link inside the cut)")
        p.add_argument("--dialect", choices=("all",) + tuple(DIALECTS), default="all",
                       help="G-code dialect(s) to write (default all: linuxcnc .ngc rotary X/A/Z, "
                            "grbl .nc flat X/Y/Z)")
        p.add_argument("--machine", type=path_value, metavar="NAME|FILE",
                       help="machine profile to write the G-code for (see `camtube machines`; a YAML file of "
                            "your own): axes, limits, blending, laser I/O, corner strategy. Replaces --dialect; "
                            "the estimate and the job file follow its limits")

    p = sub.add_parser("toolpath", help="plan the laser passes; write toolpath DXF, G-code and job file",
                       description="Plan the multi-pass laser job (drill offsets 0.005 mm, focus + defocus, "
                                   "repeats by beam depth) of a pattern YAML or a DXF drawing and write "
                                   "NAME.toolpath.dxf, NAME.ngc, NAME.nc and NAME.job.json. Lengths mm, "
                                   "speeds mm/s, times s.")
    common(p)
    p.set_defaults(func=cmd_toolpath)
    p = sub.add_parser("build", help="write everything: design DXF, toolpaths, G-code, job file, CAD model, report",
                       description="Like toolpath, plus the design DXF, the CAD model (STEP, STL), the as-cut "
                                   "simulation, pictures and the verification report. Exits 1 when a "
                                   "verification check fails.")
    common(p)
    add_cad_options(p)
    p.set_defaults(func=cmd_build)


def cmd_toolpath(args: argparse.Namespace) -> int:
    return run_outputs(args, "toolpath")


def cmd_build(args: argparse.Namespace) -> int:
    return run_outputs(args, "build")
