"""CLI of the synthesis stage: ``camtube synthesize GOAL.yaml -o PATTERN.yaml``."""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from camtube.commands.common import path_value, refuse_output_over_input
from camtube.errors import CamtubeError, PatternError


def register(sub) -> None:
    p = sub.add_parser(
        "synthesize", help="design the notch pattern that meets a goal (bend at a stroke, limits)",
        description="Read a goal YAML (stock, tendon, goal.bends: bend_deg at stroke_mm per direction, "
                    "distribution, a planar curve or a 3-D goal.centerline, limits), choose every notch's width and "
                    "arc with the notch-by-notch forward model, write a pattern YAML that camtube's rules accept, and "
                    "print target vs predicted, the active limit, the bend change per 10 um of notch depth and of "
                    "kerf, the bend under the other notch-stiffness model (beam vs fe_fit) and, for a 3-D goal, how "
                    "closely the centre line is followed. "
                    "An infeasible goal: one line naming the limit and the nearest feasible target, exit 2. "
                    "Lengths mm, angles deg, forces N.")
    p.add_argument("goal", type=path_value, metavar="GOAL.yaml", help="goal file (see examples/goals/ and docs/design.md)")
    p.add_argument("-o", "--output", required=True, metavar="PATTERN.yaml", help="pattern YAML to write")
    p.add_argument("--calibration", type=path_value, metavar="FIT.json",
                   help="parameters of an earlier tube's 'camtube model fit --json' or 'model diagnose --json' "
                        "(E_t, L0, slack, toe, kerf, friction, ...) to design with")
    p.set_defaults(func=cmd_synthesize)


def cmd_synthesize(args: argparse.Namespace) -> int:
    from camtube.design.loader import load_text
    from camtube.io import write_atomic
    from camtube.joint.forward import Mechanics
    from camtube.synthesis.goal import load_goal
    from camtube.synthesis.report import check_design, pattern_yaml, summary_text
    from camtube.synthesis.solve import synthesize

    out = Path(args.output)
    if out.suffix.lower() not in (".yaml", ".yml"):
        raise CamtubeError(f"{args.output}: synthesize writes a pattern YAML; fix: name the output PATTERN.yaml")
    if out.is_dir():
        raise CamtubeError(f"{args.output}: is a directory; fix: name the pattern file, e.g. {out / 'pattern.yaml'}")
    refuse_output_over_input(args.output, "-o", [("GOAL.yaml", args.goal), ("--calibration", args.calibration)])
    goal = load_goal(args.goal)
    calib = Mechanics.from_fit_json(args.calibration) if args.calibration else None
    t0 = time.perf_counter()
    design = synthesize(goal, calib)
    seconds = time.perf_counter() - t0
    text = pattern_yaml(design)
    try:
        loaded = load_text(text, out)  # camtube's own rules, before anything is written
    except PatternError as exc:  # (named after the output file, which is not written: the goal's problem)
        first = exc.issues[0]
        more = f" (and {len(exc.issues) - 1} more)" if len(exc.issues) > 1 else ""
        fix = f"relax the goal's lengths or limits behind {first.key}"
        if first.kind == "holes_collide":
            # (each direction's tendon is anchored in a hole at the same x: directions 10 deg apart collide there;
            # no length or limit fixes that)
            fix = ("set the bending directions (goal.bends[].angle_deg) further apart: each direction's tendon is "
                   "anchored in its own hole, and these holes collide")
        raise CamtubeError(f"{args.goal}: the pattern designed for this goal breaks camtube's pattern rules: "
                           f"{first.key}: {first.message}{more}; fix: {fix} (nothing was written)") from None
    checks = check_design(design, loaded.pattern)
    path = write_atomic(out, text)
    print(summary_text(design, checks, seconds, loaded.pattern))
    for w in loaded.warnings:
        print(f"warning: {w}", file=sys.stderr)
    print(f"wrote {path}")
    return 0
