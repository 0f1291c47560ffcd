"""camtube command line: parses arguments and calls the library.

Each stage contributes its sub-commands through a light ``register``
function in its own ``cli`` module; heavy libraries are imported only inside
the handlers that need them.
"""
from __future__ import annotations

import argparse
import importlib
import sys

from camtube import __version__
from camtube.errors import CamtubeError

#: Stage CLI modules, each with ``register(subparsers)``; missing ones are skipped.
COMMAND_MODULES = (
    "camtube.design.cli", "camtube.plan.cli", "camtube.cad.cli", "camtube.model.cli", "camtube.motion.cli",
)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="camtube",
        description="Design, plan, cut and explain laser-micromachined notched-tube joints. "
                    "Lengths are mm, angles deg unless an option says otherwise.",
    )
    parser.add_argument("--version", action="version", version=f"camtube {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        try:
            mod = importlib.import_module(name)
        except ModuleNotFoundError as exc:
            if exc.name and name.startswith(exc.name):
                continue
            raise
        mod.register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 1
    try:
        return int(args.func(args) or 0)
    except CamtubeError as exc:
        print(f"camtube {args.command}: error:\n{exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
