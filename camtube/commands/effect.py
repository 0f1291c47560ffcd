"""``camtube model effect new NAME --from DIAG.json``: write a starter effect file (thin CLI over :mod:`.starter`).

Hook (in :func:`camtube.commands.model.register`, with the ``model`` sub-parsers)::

    from camtube.commands.effect import register_effect_commands; register_effect_commands(model_sub)
"""
from __future__ import annotations

import argparse

from camtube.commands.common import no_subcommand, path_value
from camtube.model.unexplained.analysis import VARIABLES


def register_effect_commands(subparsers) -> None:
    """Add ``effect`` (with ``new``) to the ``model`` group's sub-parsers."""
    e = subparsers.add_parser("effect", help="write your own effect: a starter file from a diagnosis",
                              description="Tools for user effects (the effect API: docs/diagnose.md).")
    e.set_defaults(func=lambda args: no_subcommand(e, "camtube model effect"))
    esub = e.add_subparsers(dest="effect_command", metavar="SUBCOMMAND")
    n = esub.add_parser(
        "new", help="write a starter effect file from a diagnosis's 'unexplained' section",
        description="Write NAME.py: an Effect on the stage the diagnosis suggests, reading the variable the "
                    "residual follows, with a term of the shape found (periodic, step, linear, quadratic, "
                    "saturating) whose parameters start from and are bounded around the period and size "
                    "found. It runs as written with --effect-file; edit the physics in _apply.")
    n.add_argument("name", metavar="NAME", help="effect name (a Python identifier), e.g. drive_error")
    n.add_argument("--from", dest="diag", metavar="DIAG.json",
                   help="diagnosis JSON (camtube model diagnose ... --json DIAG.json)")
    n.add_argument("--stage", choices=("force", "stroke", "elongation", "kinematics", "angle"),
                   help="stage to act on (default: the one the diagnosis suggests)")
    n.add_argument("--follows", choices=VARIABLES, help="variable the effect follows (default: the diagnosis's lead)")
    n.add_argument("-o", "--output", type=path_value, metavar="OUT.py", help="file to write (default NAME.py)")
    n.add_argument("--overwrite", action="store_true", help="replace an existing file")
    n.set_defaults(func=cmd_effect_new)


def cmd_effect_new(args: argparse.Namespace) -> int:
    from pathlib import Path

    from camtube.errors import DataError
    from camtube.io import write_atomic
    from camtube.model.unexplained.starter import starter_from_json, starter_source

    if args.diag:
        text = starter_from_json(args.name, args.diag, stage=args.stage, follows=args.follows)
    elif args.follows:
        text = starter_source(args.name, None, stage=args.stage, follows=args.follows)
    else:
        raise DataError("model effect new: nothing to start from; fix: give --from DIAG.json, or --follows VARIABLE "
                        "(and optionally --stage)")
    out = Path(args.output or f"{args.name}.py")
    if out.suffix != ".py" and not out.is_dir():  # --effect-file imports it: Python needs the .py suffix
        example = out.with_suffix(".py").name if out.name not in ("", ".", "..") else "effect.py"
        raise DataError(f"-o {out}: --effect-file loads the effect as a Python module, which must end in .py; "
                        f"fix: e.g. -o {example}")
    if out.exists() and not args.overwrite:
        raise DataError(f"{out}: exists; fix: add --overwrite to replace it, or -o OTHER.py")
    print(f"wrote {write_atomic(out, text)}")
    print(f"use it: camtube model diagnose DATA.csv --pattern PATTERN --effect-file {out}")
    return 0
