"""``camtube model diagnose``: which physics is missing from the model (thin CLI over :mod:`camtube.model.diagnose`).

``register(model_sub)`` adds the sub-command to the ``model`` group that
:mod:`camtube.commands.model` creates.
"""
from __future__ import annotations

import argparse
import dataclasses
import shlex
from pathlib import Path

from camtube.commands.common import lag_value, path_value


def register(model_sub) -> None:
    from camtube.model import EFFECT_NAMES

    d = model_sub.add_parser(
        "diagnose", help="find the physical effects the model is missing, rank them, say how to add them",
        description="Fit the current model to every selected row (both directions of motion, slack deadband "
                    "kept), estimate the noise floor from the residual, try each candidate effect from several "
                    "starts (held-out error on alternating blocks of cycles, every cycle tested; BIC), and "
                    "recommend only effects whose gain beats the noise, whose parameters are identified and "
                    "resolvable, and whose refit on all rows lowers the RMSE; test per-sample values; print the "
                    "model fit command that reproduces the result. Angles deg, strokes mm, forces N.")
    d.add_argument("data", type=path_value, metavar="DATA.csv",
                   help="columns sample, cycle, time_s, stroke_mm, force_N, angle_deg")
    d.add_argument("--pattern", required=True, type=path_value, metavar="PATTERN",
                   help="pattern YAML of the joint (see patterns/)")
    d.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a pattern scalar, e.g. --set tendon.length=80")
    d.add_argument("-q", "--quiet", action="store_true", help="do not print design warnings")
    d.add_argument("--cycles", default="all", metavar="SPEC",
                   help="cycles to use: all (default), last20, 31-50, 2-, ... (comma lists allowed)")
    d.add_argument("--effects", default=None, metavar="A,B",
                   help="effects already in the model (default: none); built-in: " + ", ".join(EFFECT_NAMES))
    d.add_argument("--effect-file", action="append", default=[], metavar="F.py",
                   help="a .py file defining Effect objects; its effects become candidates too (repeatable)")
    d.add_argument("--candidates", default=None, metavar="A,B",
                   help="effects to try (default: every registered effect not in the model, i.e. the built-in "
                        + ", ".join(EFFECT_NAMES) + " and those of --effect-file)")
    d.add_argument("--fit", dest="fit_params", default=None, metavar="P1,P2",
                   help="base parameters fitted besides the effects' own (default E_t, unless held with --fix)")
    d.add_argument("--fix", action="append", default=[], metavar="NAME=VALUE",
                   help="hold a parameter at a value (E_t GPa, L0 mm); repeatable")
    d.add_argument("--max-rows", type=int, default=4000, metavar="N",
                   help="rows used by the candidate search, thinned evenly in time (default 4000, at least 100; "
                        "at least 25 per cycle, up to 4x this; 0 = all)")
    d.add_argument("--max-effects", type=int, default=4, metavar="N", help="most effects recommended (default 4)")
    d.add_argument("--modulus-range", default="1,300", metavar="LO,HI",
                   help="plausible tendon E_t in GPa; a fit outside is not trusted (default 1,300)")
    d.add_argument("--no-stop-rule", dest="stop_rule", action="store_false",
                   help="do not stop at 1.15 x the noise floor (the significance tests alone decide)")
    d.add_argument("--per-sample", dest="given_per_sample", default=None, metavar="P1,P2",
                   help="parameters of --effects (full names, or effect names for all their parameters) fitted with "
                        "one value per sample from the start, as model fit's --per-sample: an effect an earlier "
                        "diagnosis recommended per sample")
    d.add_argument("--no-per-sample", dest="per_sample", action="store_false",
                   help="do not test per-sample parameters of the recommended effects")
    d.add_argument("--init", action="append", default=[], metavar="NAME=VALUE",
                   help="also start a candidate's parameter at VALUE (e.g. a period), repeatable")
    d.add_argument("--no-baseline", dest="baseline", action="store_false",
                   help="do not take the joint's rest angle (friction in the joint) into the baseline when the "
                        "data show it; it is then an ordinary candidate")
    d.add_argument("--strict", action="store_true",
                   help="refuse rows with a missing value (nan, empty) or a time stamp that goes backwards, naming "
                        "the file and line (default: drop them and say how many)")
    d.add_argument("--lag-ms", type=lag_value, default=None, metavar="MS",
                   help="lag of the angle channel behind stroke and force (ms) to correct, or one per sample "
                        "(S1=76,S2=0) (default: estimated from the data, per sample where the samples differ, and "
                        "corrected when resolved; 0 = none)")
    d.add_argument("--no-rezero", dest="rezero", action="store_false",
                   help="keep the force as read where the load cell's zero drifts (default: re-zero it at every rest, "
                        "motor at zero and tendon slack, when the rests show a smooth drift from a zeroed cell)")
    d.add_argument("--json", type=path_value, metavar="OUT.json", help="write the diagnosis as JSON")
    d.add_argument("--report", type=path_value, metavar="DIR", help="write an HTML report with PNG plots into DIR")
    d.set_defaults(func=cmd_diagnose)


def _rows_left(args: argparse.Namespace, meas, ins) -> str:
    """The rows the diagnosis is left with, in words, and why the others were dropped or set aside (for an error
    about them: a reversed or constant time column leaves one row, which is then 'a stroke that never changes')."""
    why = []
    if meas.missing_lines.size:
        why.append(f"{meas.missing_lines.size} with a missing value")
    if meas.backward_lines.size:
        why.append(f"{meas.backward_lines.size} whose time_s goes backwards")
    why += [f"{len(idx)} with {'an' if reason[:1] in 'aeiou' else 'a'} {reason}" for reason, idx in ins.aside.items()
            if len(idx)]
    if not why:
        return f"{args.data} (cycles {args.cycles})"
    total = len(ins.data) + int(meas.missing_lines.size + meas.backward_lines.size) + int((~ins.kept).sum())
    return (f"{args.data} (cycles {args.cycles}; {len(ins.data)} of {total} rows left after dropping or setting "
            f"aside {', '.join(why)}: check the time_s column)")


def fit_command_prefix(args: argparse.Namespace, instruments=None) -> str:
    """The ``camtube model fit`` command selecting the same rows and files as this diagnosis (with the rows
    the instruments' check set aside, and its lag, when it found any)."""
    parts = ["camtube", "model", "fit", args.data, "--pattern", args.pattern]
    for o in args.overrides:
        parts += ["--set", o]
    parts += ["--cycles", args.cycles, "--branch", "both", "--no-deadband"]
    if instruments is not None and (instruments.n_aside or instruments.n_dropped or instruments.lag.corrected
                                    or instruments.rezeroed):
        parts += ["--set-aside", "--lag-ms", instruments.lag.as_option()]
        if instruments.rezeroed:
            parts += ["--rezero"]
    for f in args.effect_file:
        parts += ["--effect-file", f]
    for f in args.fix:
        parts += ["--fix", f]
    return shlex.join(parts)


def _check_init_names(init: dict, specs: dict, samples=None) -> None:
    """Refuse an ``--init`` start for no parameter of the model or a candidate (``specs``), or, once the data are
    read, for a sample they do not have (``NAME@S``): the search would drop it unseen."""
    import difflib

    from camtube.errors import DataError
    from camtube.model.core.params import split_name

    for name in init:
        base, smp = split_name(name)
        if base not in specs:
            near = difflib.get_close_matches(base, list(specs), n=1)
            raise DataError(f"--init {name}: unknown parameter {base!r}" + (f"; did you mean {near[0]!r}?" if near else "")
                            + f" (the model's and the candidates' parameters: {', '.join(specs)}); fix: use one of "
                            "these names (an effect's as EFFECT.param), or give the file of its effect with "
                            "--effect-file")
        if samples is not None and smp is not None and smp not in samples:
            raise DataError(f"--init {name}: the data have no sample {smp!r} (samples: {', '.join(samples)}); "
                            "fix: use NAME@SAMPLE with one of these samples, or NAME for all")


def cmd_diagnose(args: argparse.Namespace) -> int:
    from camtube.model.core.threads import one_blas_thread

    # speed: the instrument checks' regressions and the report's analyses are tall and thin too
    with one_blas_thread():
        return _diagnose(args)


def _diagnose(args: argparse.Namespace) -> int:
    from camtube.commands.common import (
        check_output_dir, check_output_file, check_outputs_apart, load_joint_pattern, refuse_output_over_input,
    )
    from camtube.errors import DataError
    from camtube.io import write_together
    from camtube.model.core.build import (build_registry, check_fix_and_init, check_suffix, fitted_and_held,
                                         parse_assignments, parse_in_range, split_names)
    from camtube.model.core.predict import model_for_pattern, pattern_values
    from camtube.model.data import check_fittable, read_measurements, select_cycles
    from camtube.model.data.csvfile import check_force_identifies, check_signs, check_zeros
    from camtube.model.diagnose import diagnose
    from camtube.model.diagnose.instruments import check_instruments, check_units, confirm_lag
    from camtube.model.diagnose.search import MIN_SEARCH_ROWS
    from camtube.model.report.diagnosis import diagnosis_json, diagnosis_text, report_files

    check_suffix(args.json, (".json",), "--json")
    if args.report is not None and Path(args.report).exists() and not Path(args.report).is_dir():
        raise DataError(f"--report {args.report}: is a file; the report is a directory (index.html and PNGs); "
                        "fix: name a directory (new or existing)")
    # --json and --report are written both or neither: where they go is checked before the work
    if args.json is not None:
        check_output_file(args.json, "--json")
        refuse_output_over_input(args.json, "--json", [("DATA.csv", args.data), ("--pattern", args.pattern)]
                                 + [("--effect-file", f) for f in args.effect_file])
    if args.report is not None:
        check_output_dir(args.report, "--report")
        if args.json is not None and Path(args.report).resolve() in (Path(args.json).resolve(),
                                                                     *Path(args.json).resolve().parents):
            raise DataError(f"--json {args.json}: is or lies in the --report folder {args.report}; fix: write the "
                            "JSON beside the report folder, not inside it")
    check_outputs_apart([("--json", args.json, True), ("--report", args.report, False)])
    if args.max_rows != 0 and not MIN_SEARCH_ROWS <= args.max_rows:
        raise DataError(f"--max-rows {args.max_rows}: too few rows for the candidate search (each candidate is fitted "
                        f"on half the cycles and tested on the others); allowed: 0 (all rows) or {MIN_SEARCH_ROWS} or "
                        "more; fix: e.g. --max-rows 4000 (the default), or 0 for all rows")
    if args.max_effects < 0:
        raise DataError(f"--max-effects {args.max_effects}: must be >= 0; fix: e.g. --max-effects 4")
    try:
        lo, hi = (float(v) for v in args.modulus_range.split(","))
    except ValueError:
        raise DataError(f"--modulus-range {args.modulus_range!r}: not LO,HI; fix: give two numbers in GPa, "
                        "e.g. --modulus-range 1,300") from None
    if not 0 < lo < hi < float("inf"):
        raise DataError(f"--modulus-range {args.modulus_range!r}: need finite 0 < LO < HI (GPa); fix: e.g. "
                        "--modulus-range 1,300")
    pattern = load_joint_pattern(args)
    reg, _ = build_registry(args.effect_file)
    model = model_for_pattern(pattern, [reg.get_effect(n)
                                        for n in split_names(args.effects, "--effects")])
    # every parameter the model or a candidate has (its range), checked before the data are read
    specs = {**{f"{e.name}.{q.name}": q for e in reg.values() for q in e.params}, **model.param_specs}
    init = parse_in_range(args.init, "--init", specs)
    _check_init_names(init, specs)
    check_fix_and_init(parse_assignments(args.fix, "--fix"), init)
    given_ps = list(dict.fromkeys(model.per_sample_names(split_names(args.given_per_sample, "--per-sample"))))
    meas = read_measurements(args.data, strict=args.strict)
    rows = select_cycles(meas.data, args.cycles)
    # (a column that never changes, or a handful of rows, is said as such before the instruments read a lag in it)
    check_fittable(rows, f"{args.data} (cycles {args.cycles})")
    ins = check_instruments(rows, lag_ms=args.lag_ms, dropped=meas.summary(),
                            n_dropped=int(meas.missing_lines.size + meas.backward_lines.size), rezero=args.rezero)
    check_fittable(ins.data, _rows_left(args, meas, ins))
    check_signs(ins.data, args.data)
    check_zeros(ins.data, args.data)
    _check_init_names(init, specs, ins.data.samples)
    fit_names, held = fitted_and_held(model, args.fit_params, args.fix, with_effects=False)
    check_force_identifies(ins.data, args.data, fit_names)
    fixed = pattern_values(pattern)
    fixed.update(held)
    check_units(model_for_pattern(pattern), ins.data, fixed, fit_names, args.data, (lo, hi))
    ins = confirm_lag(ins, model, fixed, fit_names)
    rows = ins.data
    cands = [reg.get_effect(c) for c in split_names(args.candidates, "--candidates", empty_ok=False)] or None
    d = diagnose(model, rows, fit_names, fixed, candidates=cands, given_per_sample=given_ps,
                 max_rows=args.max_rows, max_effects=args.max_effects, registry=reg,
                 stop_ratio=1.15 if args.stop_rule else None, modulus_range_gpa=(lo, hi),
                 per_sample=args.per_sample, init=init,
                 baseline=None if args.baseline else ())
    d = dataclasses.replace(d, instruments=ins)
    prefix = fit_command_prefix(args, ins)
    title = f"{pattern.name}: {args.data} ({len(rows)} rows, cycles {args.cycles}, both directions, deadband kept)"
    print(diagnosis_text(d, prefix, title))
    meta = {"pattern": pattern.name, "data": str(args.data), "cycles": args.cycles}
    files = report_files(d, prefix, title) if args.report else None  # made before anything is written
    outputs = [(args.json, diagnosis_json(d, prefix, meta))] if args.json else []
    if files is not None:
        outputs.append((args.report, files))
    write_together(outputs)  # the JSON and the report both, or neither
    if args.json:
        print(f"wrote {Path(args.json)}")
    if files is not None:
        print(f"wrote {Path(args.report) / 'index.html'}")
    return 0
