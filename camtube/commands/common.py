"""Helpers shared by the commands: pattern arguments, loading with warnings, output checks."""
from __future__ import annotations

import argparse
import os
import sys

from camtube.design.loader import Loaded
from camtube.errors import CamtubeError
from camtube.io import PublishedInterrupt

#: Roles a drawing's layer can be given with ``--layer NAME=ROLE``.
LAYER_ROLES = ("notch", "hole", "slit", "ignore")


def no_subcommand(parser, name: str, kind: str = "subcommand") -> int:
    """``name`` given without its ``kind`` (``camtube``: a command): its help, one line saying so, exit 2 (a usage
    mistake)."""
    parser.print_help()
    print(f"{name}: error: no {kind} given; fix: give one of the {kind}s above", file=sys.stderr)
    return 2


def path_value(value: str) -> str:
    """argparse ``type`` of an option naming a file or folder: an empty value (``--json ''``, an unset
    shell variable) is refused, not taken as "option not given"."""
    if not value.strip():
        raise argparse.ArgumentTypeError(f"the path is empty ({value!r}): give a file or folder name")
    return value


def lag_value(value: str) -> float | dict[str, float]:
    """argparse ``type`` of ``--lag-ms``: one lag for every sample (``20``) or one per sample (``S1=76,S2=0``)."""
    text = value.strip()
    if "=" not in text:
        try:
            return float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{value!r} is not a number of ms: give e.g. 20, or S1=76,S2=0 for "
                                             "one lag per sample") from None
    out: dict[str, float] = {}
    for part in text.split(","):
        smp, eq, ms = part.partition("=")
        try:
            lag = float(ms)
        except ValueError:
            lag = None
        if not eq or not smp.strip() or lag is None:
            raise argparse.ArgumentTypeError(f"{part.strip()!r} in {value!r} is not SAMPLE=MS: give e.g. S1=76,S2=0 "
                                             "(one lag per sample), or one number for all")
        if smp.strip() in out:   # (the last one won without a word)
            raise argparse.ArgumentTypeError(f"sample {smp.strip()!r} is given twice in {value!r} ({out[smp.strip()]:g} "
                                             f"and {lag:g} ms): give each sample once")
        out[smp.strip()] = lag
    return out


def add_pattern_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``PATTERN``, repeatable ``--set KEY=VALUE``, ``-q`` and the drawing options to a sub-command."""
    parser.add_argument("pattern", type=path_value, metavar="PATTERN",
                        help="pattern YAML file, a preset name (tube1, tube2, tube3, tube1-bidirectional) "
                             "or a DXF drawing of the unrolled tube")
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
        same = [r for n, r in layers if n.upper() == name.upper()]
        if same:   # (the last one given won without a word)
            raise CamtubeError(f"--layer {item!r}: layer {name!r} is given a role twice ({same[0]} and {role}); fix: "
                               "give each layer one --layer NAME=ROLE")
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
    from camtube.design.loader import preset_names, resolve_preset
    from camtube.design.source import is_drawing, load_source

    path = str(resolve_preset(args.pattern))
    if not os.path.exists(path):
        raise CamtubeError(f"{args.pattern}: no such file or preset; fix: give the path of a pattern YAML or a DXF "
                           f"drawing, or a preset name ({', '.join(preset_names())})")
    if os.path.isdir(path):
        raise CamtubeError(f"{path}: is a directory; fix: give the path of a pattern YAML or a DXF drawing")
    options = drawing_options(args)
    if not is_drawing(path):
        _refuse_drawing_options(args, path)
    loaded = load_source(path, args.overrides, options)
    if not getattr(args, "quiet", False):
        summary = getattr(loaded, "summary", "")
        if summary:
            print(summary, file=sys.stderr)
        for w in loaded.warnings:
            print(f"warning: {w}", file=sys.stderr)
    return loaded


def load_joint_pattern(args: argparse.Namespace):
    """The pattern of a ``model`` command (``--pattern``): it must have notches, the joint the model describes."""
    pattern = load_from_args(args).pattern
    if not pattern.notches:
        raise CamtubeError(f"{args.pattern}: notch.count: the pattern has no notches, so there is no joint to model; "
                           "fix: give the pattern of the measured joint (notch.count >= 1, or cuts:)")
    return pattern


def _refuse_drawing_options(args: argparse.Namespace, path: str) -> None:
    """A drawing option given with a YAML pattern would be ignored: refuse it, saying what to write instead."""
    for opt, key in (("outer_radius", "tube.outer_radius"), ("length", "tube.length")):
        v = getattr(args, opt, None)
        if v is not None:
            raise CamtubeError(f"--{opt.replace('_', '-')} {v:g}: reads a DXF drawing, but {path} is a pattern YAML, "
                               f"whose {key} it would not change; fix: use --set {key}={v:g}")
    if getattr(args, "units", None) is not None:
        raise CamtubeError(f"--units {args.units}: reads a DXF drawing, but {path} is a pattern YAML (always mm); "
                           "fix: remove --units")
    if getattr(args, "layers", None):
        raise CamtubeError(f"--layer {args.layers[0]}: reads a DXF drawing, but {path} is a pattern YAML (no layers); "
                           "fix: remove --layer")


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


def refuse_output_over_input(output: str, option: str, inputs) -> None:
    """Refuse an output file that is one of the command's input files (``synthesize goal.yaml -o goal.yaml``,
    ``model ingest ... --daq daq.csv -o daq.csv``): writing it would destroy the input.

    ``inputs`` holds ``(option, path or None)`` pairs; the same file under another name (a link) counts too.
    """
    for opt, path in inputs:
        if not path or not os.path.exists(output) or not os.path.exists(path):
            continue
        try:
            same = os.path.samefile(output, path)
        except OSError:
            continue
        if same:
            raise CamtubeError(f"{option} {output}: is the input {opt} {path}, which writing would replace; "
                               "fix: name another output file")


def check_outputs_apart(outputs) -> None:
    """Refuse, before any work, an output of a command that is, or lies inside, another output written as a file
    (``--json a.json --plot a.json/p.png``): it could only be written by destroying the other.

    ``outputs`` holds ``(option, path or None, is_file)`` triples.
    """
    from pathlib import Path

    from camtube.io import output_clash

    given = [(opt, path, Path(path).resolve(), is_file) for opt, path, is_file in outputs if path]
    clash = output_clash([g[2] for g in given], [g[3] for g in given])
    if clash is not None:
        (opt, path, where, _), (other, other_path, other_where, _) = given[clash[0]], given[clash[1]]
        raise CamtubeError(f"{opt} {path}: {'is' if where == other_where else 'lies inside'} the {other} "
                           f"file {other_path}, so writing one would destroy the other; fix: give {opt} a "
                           f"path of its own, outside {other_path}")


def check_output_file(path: str, option: str) -> None:
    """Refuse, before any work, an output file that names a directory or lies where nothing can be written."""
    from camtube.io import OutputError, check_writable_dir

    if os.path.isdir(path):
        raise CamtubeError(f"{option} {path}: is a directory; fix: name a file")
    try:
        check_writable_dir(os.path.dirname(os.path.abspath(path)))
    except OutputError as exc:  # name the file the user gave, not its folder
        raise OutputError(f"{option} {path}", exc.reason, "give a file in a folder you can write to") from None


def check_output_dir(path: str, option: str = "-o") -> None:
    """Refuse, before any work, an output directory that names a file or cannot be written."""
    from camtube.io import check_writable_dir

    if os.path.exists(path) and not os.path.isdir(path):
        raise CamtubeError(f"{path}: is a file, but {option} names the output directory; fix: give a directory "
                           "(new or existing)")
    check_writable_dir(path)


def run_outputs(args: argparse.Namespace, what: str) -> int:
    """``camtube toolpath|build|cad``: load, build the outputs with :mod:`camtube.pipeline`, write them
    as one set, print the summary, the paths and the verification verdict; the exit status."""
    from camtube.export.dialects import DIALECTS
    from camtube.pipeline import Request, run
    from camtube.plan.report import summary_table
    from camtube.progress import make_progress

    check_output_dir(args.output)
    loaded = load_from_args(args)
    dialects = None if getattr(args, "dialect", "all") == "all" else (DIALECTS[args.dialect],)
    if getattr(args, "machine", None) is not None:
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
                     warn=None if args.quiet else (lambda w: print(f"warning: {w}", file=sys.stderr)),
                     inputs=[args.pattern])
    try:
        _report(args, result, summary_table)
    except KeyboardInterrupt:
        raise PublishedInterrupt(result.paths) from None
    if result.cad is not None and not result.verified:
        print(f"camtube {args.command}: the job failed its own verification (see the report above): "
              "do not cut it; exit status 1", file=sys.stderr)
        return 0 if args.allow_fail else 1
    return 0


def _report(args: argparse.Namespace, result, summary_table) -> None:
    """Print what a published run wrote: the summary, the paths and the verification verdict."""
    if result.estimate is not None:
        print(summary_table(result.job, result.estimate))
    for p in result.paths:
        print(f"wrote {p}")
    if result.cad is not None:
        for line in result.cad.verdict_lines():
            print(line)
