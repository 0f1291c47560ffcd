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
    """Run one command; return the exit status.

    0 success; 1 the command ran but its result failed a check (e.g. a CAD
    verification); 2 a user mistake or unsafe job, printed as one clear
    message (no traceback); 130 interrupted (Ctrl-C).
    """
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
        if not getattr(args, "func", None):
            parser.print_help()
            return 1
        return _run(args)
    except KeyboardInterrupt:
        print("camtube: interrupted; no output of this command was published", file=sys.stderr)
        return 130
    except BrokenPipeError:
        # the reader of our output went away (e.g. `camtube design ... | head -1`): stop quietly
        _silence_stdout()
        return 0


def _run(args: argparse.Namespace) -> int:
    try:
        return int(args.func(args) or 0)
    except CamtubeError as exc:
        print(f"camtube {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except MemoryError:
        print(f"camtube {args.command}: error: out of memory; fix: make the job smaller (fewer notches or "
              "repeats) or use a machine with more memory", file=sys.stderr)
        return 2
    except OSError as exc:
        if isinstance(exc, BrokenPipeError):
            raise
        where = exc.filename if exc.filename is not None else "input/output"
        print(f"camtube {args.command}: error: {where}: {exc.strerror or exc}; fix: check the path "
              "(it must exist, be readable, and be a file where a file is expected)", file=sys.stderr)
        return 2


def _silence_stdout() -> None:
    """Point stdout at /dev/null so the interpreter's final flush cannot raise again."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
