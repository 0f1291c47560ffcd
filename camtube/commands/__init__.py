"""camtube command line: parses arguments and calls the library.

This package sits above every stage: its modules import from the stages
(design, plan, export, machine, cad, model, motion) and :mod:`camtube.pipeline`,
and no stage imports it (``tests/test_layers.py`` holds that). One module per
group of sub-commands, each with ``register(subparsers)``; heavy libraries are
imported only inside the handlers that need them.
"""
from __future__ import annotations

import argparse
import importlib
import os
import re
import signal
import sys
import threading
from contextlib import contextmanager

from camtube import __version__
from camtube.errors import CamtubeError
from camtube.io import PublishedInterrupt, Terminated, raise_terminated

#: Command modules, each with ``register(subparsers)``, in the order ``--help`` lists them.
COMMAND_MODULES = (
    "camtube.commands.design", "camtube.commands.plan", "camtube.commands.cad", "camtube.commands.model", "camtube.commands.motion",
    "camtube.commands.synthesize",
)


#: The arguments :func:`main` parses (the parser's error reads the value after an option from them).
_ARGV: list[str] | None = None


class _Parser(argparse.ArgumentParser):
    """An argument parser whose mistakes are one line with a fix, like every other camtube error
    (argparse's own prints the whole usage first). Sub-command parsers are of this class too."""

    def error(self, message: str):
        m = re.match(r"argument (--[\w-]+)(?:/[\w-]+)?: expected one argument$", message)
        if m:
            # a negative value argparse takes for an option (-1e9, -1,5: its own test knows only -1 and -1.5)
            argv = _ARGV if _ARGV is not None else sys.argv[1:]
            at = [i for i, a in enumerate(argv) if a == m.group(1)]
            nxt = argv[at[0] + 1] if at and at[0] + 1 < len(argv) else ""
            if re.match(r"^-[\d.]", nxt):
                self.exit(2, f"{self.prog}: error: {m.group(1)} {nxt}: a value that starts with '-' is read as an "
                             f"option; fix: write {m.group(1)}={nxt}\n")
        self.exit(2, f"{self.prog}: error: {message}; fix: see `{self.prog} --help`\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="camtube",
        description="Design, plan, cut and explain laser-micromachined notched-tube joints. "
                    "Lengths are mm, angles deg unless an option says otherwise.",
    )
    parser.add_argument("--version", action="version", version=f"camtube {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run one command; return the exit status.

    0 success; 1 the command ran but its result failed a check (e.g. a CAD
    verification); 2 a user mistake or unsafe job, printed as one clear
    message (no traceback); 130 interrupted (Ctrl-C); 143 terminated (SIGTERM).
    """
    global _ARGV
    parser = build_parser()
    _ARGV = list(argv) if argv is not None else None
    try:
        with _sigterm_as_interrupt():
            args = parser.parse_args(argv)
            if not getattr(args, "func", None):   # no command: a usage mistake, as argparse's own (exit 2)
                from camtube.commands.common import no_subcommand

                return no_subcommand(parser, "camtube", "command")
            return _run(args)
    except PublishedInterrupt as exc:
        where = os.path.dirname(exc.paths[0]) if exc.paths else "the output folder"
        print(f"camtube: interrupted after the outputs were published: the set in {where} is complete and new",
              file=sys.stderr)
        return 0
    except KeyboardInterrupt as exc:
        return _stopped(exc)
    except BrokenPipeError:
        # the reader of our output went away (e.g. `camtube design ... | head -1`): stop quietly
        _silence_stdout()
        return 0
    except Exception as exc:  # noqa: BLE001: only to tell an interrupted import from a failure; re-raised
        interrupt = _interrupted(exc)
        if interrupt is None:
            raise
        return _stopped(interrupt)


@contextmanager
def _sigterm_as_interrupt():
    """While the command runs, SIGTERM raises :class:`~camtube.io.Terminated` (a ``KeyboardInterrupt``), so it
    cleans up as Ctrl-C does (the default action ends the process at once, leaving staging folders behind).
    Only in the main thread and over the default action (a handler someone else set is kept); put back after."""
    if (threading.current_thread() is not threading.main_thread()
            or signal.getsignal(signal.SIGTERM) != signal.SIG_DFL):
        yield
        return
    signal.signal(signal.SIGTERM, raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _stopped(exc: KeyboardInterrupt) -> int:
    """Say that the command was stopped before it published anything; 143 for SIGTERM, 130 for Ctrl-C."""
    if isinstance(exc, Terminated):
        print("camtube: terminated (SIGTERM); no output of this command was published", file=sys.stderr)
        return 143
    print("camtube: interrupted; no output of this command was published", file=sys.stderr)
    return 130


def _interrupted(exc: BaseException) -> KeyboardInterrupt | None:
    """The Ctrl-C (or SIGTERM) that caused ``exc``, or None (an extension module's import fails with an
    ``ImportError`` whose context is the ``KeyboardInterrupt`` that stopped it)."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, KeyboardInterrupt):
            return exc
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return None


@contextmanager
def _libraries_quiet(quiet: bool):
    """With ``-q``: no Python warning (numpy's RuntimeWarning, scipy's OptimizeWarning) and no library log record
    below ERROR (ezdxf's 'Found non-unique entity handle') reaches stderr while the command runs. What matters to the
    user camtube says itself, as a warning line (which ``-q`` drops too) or an error (which it never drops).

    Without ``-q`` numpy's arithmetic warnings (``RuntimeWarning``: an overflow in a value of 1e300, the mean of an
    empty slice in a log of one frame) are dropped too: they name a line of numpy or camtube, not of the input, and
    stood between the user and the one line that says what is wrong with it."""
    import warnings

    if not quiet:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            yield
        return
    import logging

    before = logging.root.manager.disable
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        logging.disable(logging.WARNING)
        try:
            yield
        finally:
            logging.disable(before)


def _run(args: argparse.Namespace) -> int:
    with _libraries_quiet(bool(getattr(args, "quiet", False))):
        return _run_command(args)


def _run_command(args: argparse.Namespace) -> int:
    try:
        return int(args.func(args) or 0)
    except CamtubeError as exc:
        msg = str(exc)
        data = getattr(args, "data", None)
        model = sys.modules.get("camtube.model.core.model")   # (loaded whenever a FitError was raised)
        if (model is not None and isinstance(exc, model.FitError) and isinstance(data, str)
                and os.path.basename(data) not in msg):
            msg = f"{data}: {msg}"   # a fit that cannot be made is about the measurement file: name it
        print(f"camtube {args.command}: error: {msg}", file=sys.stderr)
        return 2
    except MemoryError:
        smaller = ("give fewer rows (--cycles SPEC)" if args.command == "model" else
                   "make the job smaller (fewer notches or repeats)")
        print(f"camtube {args.command}: error: out of memory; fix: {smaller} or use a machine with more memory",
              file=sys.stderr)
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
    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)
    except (OSError, ValueError):
        pass


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
