"""CLI of the motion stage: ``camtube motion JOB.ngc`` and ``camtube machines``."""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from camtube.commands.common import path_value


def register(sub) -> None:
    p = sub.add_parser(
        "motion", help="run a job on LinuxCNC's motion controller (real time) and measure what it did",
        description="Run JOB.ngc headless in LinuxCNC's motion controller and trajectory planner with the "
                    "machine profile's limits, in real time (a job of N s takes N s), recording the commanded "
                    "axes and the laser gate every servo cycle. Reports the run time against the estimate, the "
                    "beam-on path length against the job's cut length (mm), the share of the beam-on path within "
                    "+-5 % of the scan speed, the farthest beam-on position outside the cut regions (um) and the "
                    "largest distance by which the beam misses a drawn corner (um). Needs linuxcnc-uspace; "
                    "exits 2 with one line when it is missing.")
    p.add_argument("program", metavar="JOB.ngc", help="G-code written by camtube toolpath (LinuxCNC dialect)")
    p.add_argument("--job", metavar="JOB.job.json",
                   help="the job file written with it (default: JOB.job.json next to the program)")
    p.add_argument("--machine", type=path_value, metavar="NAME|FILE", default=None,
                   help="machine profile (default linuxcnc-rotary; `camtube machines` lists them)")
    p.add_argument("--json", action="store_true", help="print the figures as JSON instead of a table")
    p.add_argument("--keep", metavar="DIR", help="keep the LinuxCNC configuration, log and recording in DIR")
    p.set_defaults(func=cmd_motion)
    q = sub.add_parser("machines", help="list the machine profiles (machines/*.yaml)",
                       description="List the shipped machine profiles with their dialect, axis limits "
                                   "(mm/s, mm/s^2; deg/s, deg/s^2 for a rotary axis), blending and corner strategy.")
    q.set_defaults(func=cmd_machines)


def _job_path(program: Path, given: str | None) -> Path:
    if given:
        return Path(given)
    name = program.name[: -len(program.suffix)] if program.suffix else program.name
    return program.with_name(name + ".job.json")


def cmd_motion(args: argparse.Namespace) -> int:
    from camtube.errors import CamtubeError
    from camtube.machine import load_profile
    from camtube.motion.analysis import JobGeometry, analyse
    from camtube.motion.linuxcnc import check_program, run_program, unavailable_reason
    from camtube.machine.motion_time import estimate_program

    why = unavailable_reason()
    if why:
        print(f"camtube motion: {why}; nothing was run", file=sys.stderr)
        return 2
    profile = load_profile(args.machine)
    program = Path(args.program)
    if not program.is_file():
        why = "not a G-code file (a directory or a device)" if program.exists() else "no such G-code file"
        raise CamtubeError(f"{program}: {why}; fix: give the .ngc that `camtube toolpath` wrote")
    text = check_program(program, profile)  # one line and exit 2 for a file LinuxCNC cannot run, before it starts
    geom = JobGeometry.from_job_file(_job_path(program, args.job))
    est = estimate_program(text, profile)
    rec = run_program(program, profile, workdir=args.keep)
    report = analyse(rec, geom, profile, estimate_s=est.total_s)
    if args.json:
        print(json.dumps(report.as_dict(), indent=1))
    else:
        print(report.table())
    return 0


def cmd_machines(args: argparse.Namespace) -> int:
    from camtube.machine import DEFAULT_MACHINE, load_profile, profile_names

    for name in profile_names():
        p = load_profile(name)
        lim = ", ".join(f"{k} {v.max_velocity:g}/{v.max_acceleration:g}" for k, v in p.limits)
        blend = p.blending if isinstance(p.blending, str) else f"G64 P{p.blending:g}"
        mark = " (default)" if name == DEFAULT_MACHINE else ""
        print(f"{name}{mark}: {p.dialect} {p.suffix}, axes {''.join(p.axes)}, max vel/acc {lim}, "
              f"blending {blend}, corners {p.corner_strategy}"
              + (f", laser gated by {p.gating}" if p.dialect == "linuxcnc" else ""))
        print(f"    {p.description}")
    return 0
