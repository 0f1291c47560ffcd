"""CLI of the plan stage: ``camtube toolpath`` and ``camtube build``."""
from __future__ import annotations

import argparse
import sys

from camtube.cliutil import add_pattern_argument, load_from_args

PROGRESS_MIN_PASSES = 20000


def register(sub) -> None:
    from camtube.export.dialects import DIALECTS
    from camtube.plan.planner import DEFAULT_ORDERING, ORDERINGS

    def common(p):
        add_pattern_argument(p)
        p.add_argument("-o", "--output", required=True, metavar="DIR", help="output directory (created)")
        p.add_argument("--ordering", choices=ORDERINGS, default=DEFAULT_ORDERING,
                       help=f"pass ordering (default {DEFAULT_ORDERING}: one round per repeat/focus/drill "
                            "visits every cut; sequential: all passes of a cut, then the next)")
        p.add_argument("--dialect", choices=("all",) + tuple(DIALECTS), default="all",
                       help="G-code dialect(s) to write (default all: linuxcnc .ngc rotary X/A/Z, "
                            "grbl .nc flat X/Y/Z)")
        p.add_argument("--outer-radius", type=float, metavar="MM",
                       help="tube outer radius r_o in mm (needed when PATTERN is a .dxf)")
        p.add_argument("--length", type=float, metavar="MM",
                       help="tube length in mm for a .dxf without a CONSTRUCTION outline")

    p = sub.add_parser("toolpath", help="plan the laser passes; write toolpath DXF, G-code and job file",
                       description="Plan the multi-pass laser job (drill offsets 0.005 mm, focus + defocus, "
                                   "repeats by beam depth) of a pattern YAML or a DXF of closed contours and "
                                   "write NAME.toolpath.dxf, NAME.ngc, NAME.nc and NAME.job.json. Lengths mm, "
                                   "speeds mm/s, times s.")
    common(p)
    p.set_defaults(func=cmd_toolpath)
    p = sub.add_parser("build", help="write everything: design DXF, toolpaths, G-code, job file (+ CAD, report)",
                       description="Like toolpath, plus the design DXF and, when the CAD stage is installed, "
                                   "the CAD model and report.")
    common(p)
    p.set_defaults(func=cmd_build)


def _load(args):
    """(pattern or None, job)."""
    from camtube.plan.planner import plan_job

    if str(args.pattern).lower().endswith(".dxf"):
        from camtube.design.source import DrawingOptions, load_source

        loaded = load_source(args.pattern, args.overrides,
                             DrawingOptions(outer_radius_mm=args.outer_radius, length_mm=args.length))
        if not getattr(args, "quiet", False):
            print(loaded.summary, file=sys.stderr)
            for w in loaded.warnings:
                print(f"warning: {w}", file=sys.stderr)
        return loaded.pattern, plan_job(loaded.pattern, ordering=args.ordering)
    loaded = load_from_args(args)
    return loaded.pattern, plan_job(loaded.pattern, ordering=args.ordering)


def summary_table(job, est) -> str:
    """Text table: cuts, passes, cut length, estimated time, lower bound, ratio."""
    rows = [
        ("job", job.name, ""),
        ("ordering / repeats", f"{job.ordering} / {job.repeats}", ""),
        ("cuts", f"{est.cuts}", ""),
        ("passes", f"{est.passes}", ""),
        ("cut length", f"{est.cut_length_mm:.3f}", "mm"),
        ("estimated time", f"{est.total_s:.1f}", f"s (cut {est.cut_s:.1f}, rapid {est.rapid_s:.1f}, "
                                                  f"focus {est.focus_s:.1f})"),
        ("lower bound (length / speed)", f"{est.lower_bound_s:.1f}", "s"),
        ("ratio", f"{est.ratio:.4f}", ""),
    ]
    w = max(len(r[0]) for r in rows)
    return "\n".join(f"{a:<{w}}  {b} {c}".rstrip() for a, b, c in rows)


def _progress():
    if not sys.stderr.isatty():
        return None

    def show(done: int, total: int) -> None:
        n = 30 * done // total
        sys.stderr.write(f"\rposting [{'#' * n}{'.' * (30 - n)}] {done}/{total} passes")
        if done == total:
            sys.stderr.write("\n")
        sys.stderr.flush()

    return show


def _run(args, with_design: bool) -> int:
    from camtube.export.dialects import DIALECTS
    from camtube.plan.moves import estimate
    from camtube.plan.outputs import write_toolpaths

    pattern, job = _load(args)
    dialects = tuple(DIALECTS.values()) if args.dialect == "all" else (DIALECTS[args.dialect],)
    progress = _progress() if len(job.passes) >= PROGRESS_MIN_PASSES else None
    paths = write_toolpaths(job, args.output, dialects, pattern if with_design else None, progress)
    if with_design and pattern is not None:
        paths += _cad_outputs(pattern, job, args.output)
    print(summary_table(job, estimate(job)))
    for p in paths:
        print(f"wrote {p}")
    return 0


def _cad_outputs(pattern, job, outdir) -> list:
    try:
        from camtube.cad import build_outputs
    except ImportError:
        return []
    return list(build_outputs(pattern, job, outdir, log=print) or [])  # prints the verification verdict


def cmd_toolpath(args: argparse.Namespace) -> int:
    return _run(args, with_design=False)


def cmd_build(args: argparse.Namespace) -> int:
    return _run(args, with_design=True)
