"""Helpers shared by the stage CLIs: pattern arguments and loading with warnings."""
from __future__ import annotations

import argparse
import sys

from camtube.design.loader import Loaded, load


def add_pattern_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``PATTERN`` and repeatable ``--set KEY=VALUE`` to a sub-command."""
    parser.add_argument("pattern", metavar="PATTERN", help="pattern YAML file (see patterns/)")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override any scalar of the pattern, e.g. --set notch.count=20 "
                             "--set process.repeats=6 (units as in the YAML: mm, deg)")
    parser.add_argument("-q", "--quiet", action="store_true", help="do not print design warnings")


def load_from_args(args: argparse.Namespace) -> Loaded:
    """Load the pattern named by ``args``; print design warnings to stderr."""
    loaded = load(args.pattern, args.overrides)
    if not getattr(args, "quiet", False):
        for w in loaded.warnings:
            print(f"warning: {w}", file=sys.stderr)
    return loaded
