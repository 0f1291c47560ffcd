"""CLI of the plan stage: ``camtube toolpath`` and ``camtube build`` (the orchestration is :mod:`camtube.pipeline`)."""
from __future__ import annotations

import argparse
import os
import sys

from camtube.cliutil import add_pattern_argument, load_from_args
from camtube.errors import CamtubeError

def register(sub) -> None:
    from camtube.export.dialects import DIALECTS
    from camtube.plan.planner import DEFAULT_ORDERING, ORDERINGS

    def common(p):
        add_pattern_argument(p)
        p.add_argument("-o", "--output", required=True, metavar="DIR",
                       help="output directory (created; files of this command are replaced all at once, "
                            "other files in it are kept)")
        p.add_argument("--ordering", choices=ORDERINGS, default=DEFAULT_ORDERING,
                       help=f"pass ordering (default {DEFAULT_ORDERING}: one round per repeat/focus/drill "
                            "visits every cut; sequential: all passes of a cut, then the next)")
        p.add_argument("--dialect", choices=("all",) + tuple(DIALECTS), default="all",
                       help="G-code dialect(s) to write (default all: linuxcnc .ngc rotary X/A/Z, "
                            "grbl .nc flat X/Y/Z)")
        p.add_argument("--machine", metavar="NAME|FILE",
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


def add_cad_options(p: argparse.ArgumentParser) -> None:
    """The CAD stage's options (shared by ``camtube cad`` and ``camtube build``)."""
    g = p.add_argument_group("CAD model and verification")
    g.add_argument("--no-step", action="store_true", help="skip the build123d B-rep and STEP (fast preview)")
    g.add_argument("--no-pictures", action="store_true", help="skip the PNG pictures")
    g.add_argument("--kerf", type=float, default=None, metavar="MM",
                   help="beam kerf for the simulation, mm (default: process.kerf, or 0.02 if that is 0)")
    g.add_argument("--segments", type=int, default=None, metavar="N",
                   help="sides of the meshes' polygonal circles (default 256; 128 above 64 cuts)")
    g.add_argument("--allow-fail", action="store_true",
                   help="exit 0 even when a verification check fails (default: exit 1)")


def cad_options(args: argparse.Namespace):
    """:class:`camtube.pipeline.CadOptions` from the parsed CAD options (values checked)."""
    from camtube.pipeline import CadOptions

    if args.kerf is not None and not (0 < args.kerf < 1.0):
        raise CamtubeError(f"--kerf {args.kerf}: the simulated kerf must be > 0 and < 1 mm; fix: give the beam's "
                           "kerf width in mm, e.g. --kerf 0.02")
    if args.segments is not None and not (8 <= args.segments <= 4096):
        raise CamtubeError(f"--segments {args.segments}: allowed 8..4096; fix: e.g. --segments 256")
    return CadOptions(step=not args.no_step, pictures=not args.no_pictures, segments=args.segments,
                      kerf_mm=args.kerf)


def check_output_dir(path: str) -> None:
    """Refuse an output directory that names an existing file."""
    if os.path.exists(path) and not os.path.isdir(path):
        raise CamtubeError(f"{path}: is a file, but -o names the output directory; fix: give a directory "
                           "(new or existing)")


def _run(args, what: str) -> int:
    from camtube.export.dialects import DIALECTS
    from camtube.pipeline import Request, run
    from camtube.plan.report import summary_table
    from camtube.progress import make_progress

    check_output_dir(args.output)
    loaded = load_from_args(args)
    dialects = None if getattr(args, "dialect", "all") == "all" else (DIALECTS[args.dialect],)
    if getattr(args, "machine", None):
        from camtube.export.dialects import dialect_from_profile
        from camtube.machine import load_profile

        if args.dialect != "all":
            raise CamtubeError("--machine and --dialect both choose the G-code; fix: give one of them")
        dialects = (dialect_from_profile(load_profile(args.machine)),)
    cad = cad_options(args) if what != "toolpath" else None
    request = Request(what=what, dialects=dialects, ordering=getattr(args, "ordering", None),
                      **({"cad": cad} if cad is not None else {}))
    with make_progress(quiet=args.quiet) as progress:
        result = run(loaded, args.output, request, progress,
                     warn=None if args.quiet else (lambda w: print(f"warning: {w}", file=sys.stderr)))
    if result.estimate is not None:
        print(summary_table(result.job, result.estimate))
    for p in result.paths:
        print(f"wrote {p}")
    if result.cad is not None:
        for line in result.cad.verdict_lines():
            print(line)
        if not result.verified:
            print(f"camtube {args.command}: the job failed its own verification (see the report above): "
                  "do not cut it; exit status 1", file=sys.stderr)
            return 0 if args.allow_fail else 1
    return 0


def cmd_toolpath(args: argparse.Namespace) -> int:
    return _run(args, "toolpath")


def cmd_build(args: argparse.Namespace) -> int:
    return _run(args, "build")
