"""Helpers shared by the stage CLIs: pattern arguments and loading with warnings."""
from __future__ import annotations

import argparse
import os
import sys

from camtube.design.loader import Loaded
from camtube.errors import CamtubeError

#: Roles a drawing's layer can be given with ``--layer NAME=ROLE``.
LAYER_ROLES = ("notch", "hole", "slit", "ignore")


def add_pattern_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``PATTERN``, repeatable ``--set KEY=VALUE``, ``-q`` and the drawing options to a sub-command."""
    parser.add_argument("pattern", metavar="PATTERN",
                        help="pattern YAML file (see patterns/) or a DXF drawing of the unrolled tube")
    parser.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                        help="override any scalar of the pattern, e.g. --set notch.count=20 "
                             "--set process.repeats=6 (units as in the YAML: mm, deg)")
    parser.add_argument("-q", "--quiet", action="store_true", help="do not print design warnings or progress")
    g = parser.add_argument_group("drawing input (PATTERN is a .dxf)")
    g.add_argument("--outer-radius", type=float, metavar="MM",
                   help="tube outer radius r_o, mm (default: from the drawing's tube outline, whose height is 2 pi r_o)")
    g.add_argument("--length", type=float, metavar="MM",
                   help="tube length, mm (default: from the drawing's tube outline)")
    g.add_argument("--units", metavar="UNIT",
                   help="units of a drawing whose $INSUNITS is unset: mm, cm, m, um, inch, foot")
    g.add_argument("--layer", dest="layers", action="append", default=[], metavar="NAME=ROLE",
                   help=f"what to do with a layer: {', '.join(LAYER_ROLES)} (repeatable; defaults by name: "
                        "NOTCH* notch, HOLE* hole, SLIT* slit, CONSTRUCTION* ignore)")


def drawing_options(args: argparse.Namespace):
    """The :class:`~camtube.design.source.DrawingOptions` given on the command line."""
    from camtube.design.source import DrawingOptions

    layers = []
    for item in getattr(args, "layers", []) or []:
        name, sep, role = item.partition("=")
        if not sep or not name or role not in LAYER_ROLES:
            raise CamtubeError(f"--layer {item!r}: expected NAME=ROLE with ROLE one of {', '.join(LAYER_ROLES)}; "
                               "fix: e.g. --layer CUTS=notch")
        layers.append((name, role))
    for opt in ("outer_radius", "length"):
        v = getattr(args, opt, None)
        if v is not None and not (v > 0 and v < float("inf")):
            raise CamtubeError(f"--{opt.replace('_', '-')} {v}: must be a finite length > 0 mm; fix: give the tube's "
                               f"{opt.replace('_', ' ')} in mm")
    return DrawingOptions(outer_radius_mm=getattr(args, "outer_radius", None), length_mm=getattr(args, "length", None),
                          units=getattr(args, "units", None), layers=tuple(layers))


def load_from_args(args: argparse.Namespace) -> Loaded:
    """Load the pattern or drawing named by ``args``; print the import summary and design warnings to stderr."""
    from camtube.design.source import load_source

    path = args.pattern
    if not os.path.exists(path):
        raise CamtubeError(f"{path}: no such file; fix: give the path of a pattern YAML or a DXF drawing")
    if os.path.isdir(path):
        raise CamtubeError(f"{path}: is a directory; fix: give the path of a pattern YAML or a DXF drawing")
    loaded = load_source(path, args.overrides, drawing_options(args))
    if not getattr(args, "quiet", False):
        summary = getattr(loaded, "summary", "")
        if summary:
            print(summary, file=sys.stderr)
        for w in loaded.warnings:
            print(f"warning: {w}", file=sys.stderr)
    return loaded
