"""CLI of the model stage: ``camtube model fit``, ``camtube model synth`` and ``camtube model ingest``.

``register(sub)`` adds the ``model`` command and its own sub-commands; other
modules add theirs to the same group: if :mod:`camtube.commands.diagnose`
exists, its ``register(model_sub)`` is called with the ``model`` sub-parsers.
Handlers import numpy/scipy/matplotlib lazily.
"""
from __future__ import annotations

import argparse
import importlib

from camtube.commands.common import lag_value, no_subcommand, path_value
from camtube.errors import CamtubeError
from camtube.model import EFFECT_NAMES


def check_suffix(path, suffixes, option):
    """See :func:`camtube.model.core.build.check_suffix`."""
    from camtube.model.core.build import check_suffix as check

    check(path, suffixes, option)


def register(sub) -> None:
    p = sub.add_parser("model", help="fit the joint model to measurements, make synthetic data",
                       description="Joint mechanics: tendon stroke (mm) and force (N) -> joint angle (deg).")
    p.set_defaults(func=lambda args: no_subcommand(p, "camtube model"))
    model_sub = p.add_subparsers(dest="model_command", metavar="SUBCOMMAND")

    f = model_sub.add_parser(
        "fit", help="fit the model to a measurement CSV and print the RMSE per sample",
        description="Compare the paper's model L_t = (ybar + r_i - r_t) theta + F L0 / (E_t pi r_t^2) with "
                    "measured stroke, force and angle. By default, like the paper: each sample's last "
                    "loading cycle, slack deadband removed, E_t fitted, L0 and E_t start from the pattern.")
    f.add_argument("data", type=path_value, metavar="DATA.csv",
                   help="columns sample, cycle, time_s, stroke_mm, force_N, angle_deg (extra columns kept)")
    _add_pattern_option(f)
    f.add_argument("--cycles", default="last", metavar="SPEC",
                   help="cycles to fit: last (default), last20, all, 5, 31-50, 2-, or a comma list")
    f.add_argument("--branch", default="loading", choices=("loading", "unloading", "both"),
                   help="stroke direction to fit (default: loading, as in the paper)")
    f.add_argument("--no-deadband", dest="deadband", action="store_false",
                   help="keep the slack deadband (default: remove it per cycle, as in the paper)")
    f.add_argument("--deadband-threshold", type=float, default=None, metavar="DEG",
                   help="smallest angle rise (deg) that counts as motion (default max(0.5, 4 x noise))")
    f.add_argument("--fit", dest="fit_params", default=None, metavar="P1,P2",
                   help="parameters to fit, full names (default: E_t and every parameter of the --effects; "
                        "e.g. E_t,arm_scale; 'none')")
    f.add_argument("--fix", action="append", default=[], metavar="NAME=VALUE",
                   help="hold a parameter at a value (units as listed: E_t GPa, L0 mm); repeatable")
    f.add_argument("--effects", default=None, metavar="A,B",
                   help="effects to add to the base model, by name: " + ", ".join(EFFECT_NAMES)
                        + " (or one of an --effect-file)")
    f.add_argument("--effect-file", action="append", default=[], metavar="F.py",
                   help="a .py file defining or registering Effect objects (loaded before --effects)")
    f.add_argument("--per-sample", default=None, metavar="P1,P2",
                   help="parameters (full names, or effect names for all their parameters) fitted with one "
                        "value per sample, e.g. slack,play; JSON names <name>@<sample>")
    f.add_argument("--init", action="append", default=[], metavar="NAME=VALUE",
                   help="start a fitted parameter at VALUE (also NAME@SAMPLE=VALUE); repeatable")
    f.add_argument("--starts", type=int, default=0, metavar="N",
                   help="multi-start: also start from the best points of an N-per-parameter grid over each "
                        "effect parameter's declared range (log-spaced for scales); default 0 (one start)")
    f.add_argument("--set-aside", action="store_true",
                   help="read the file as model diagnose does: drop rows with a missing value or a backward time "
                        "stamp, set aside spikes and repeated stamps, and correct the angle's lag (--lag-ms)")
    f.add_argument("--lag-ms", type=lag_value, default=0.0, metavar="MS",
                   help="with --set-aside: lag of the angle channel to correct (ms; default 0), or one per sample "
                        "(S1=76,S2=0)")
    f.add_argument("--rezero", action="store_true",
                   help="with --set-aside: re-zero the force at every rest where the load cell's zero drifts, as "
                        "model diagnose does")
    f.add_argument("--json", type=path_value, metavar="OUT.json", help="write the summary as JSON")
    f.add_argument("--plot", type=path_value, metavar="OUT.png", help="write angle and residual vs stroke (PNG)")
    f.set_defaults(func=cmd_fit)

    s = model_sub.add_parser(
        "synth", help="write a synthetic measurement CSV from the base model",
        description="Triangular stroke 0 -> rules.max_stroke -> 0 at a lead-screw speed, force from the "
                    "joint bending stiffness (E_pi 2.5 GPa), Gaussian EM-tracker and load-cell noise.")
    _add_pattern_option(s)
    s.add_argument("-o", "--output", required=True, type=path_value, metavar="DATA.csv", help="output CSV file")
    s.add_argument("--samples", type=int, default=2, help="number of samples (default 2)")
    s.add_argument("--cycles", type=int, default=50, help="cycles per sample (default 50)")
    s.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    s.add_argument("--noise-angle", type=float, default=0.25, metavar="DEG",
                   help="angle noise standard deviation, deg (default 0.25)")
    s.add_argument("--noise-force", type=float, default=0.005, metavar="N",
                   help="force noise standard deviation, N (default 0.005)")
    s.add_argument("--slack", type=float, default=0.05, metavar="MM", help="tendon slack, mm (default 0.05)")
    s.add_argument("--speed", type=float, default=0.5, metavar="MM_S", help="stroke speed, mm/s (default 0.5)")
    s.add_argument("--rate", type=float, default=40.0, metavar="HZ", help="sampling rate, Hz (default 40)")
    s.add_argument("--modulus", type=float, default=None, metavar="GPA",
                   help="tendon E_t used to generate, GPa (default: the pattern's)")
    s.set_defaults(func=cmd_synth)

    i = model_sub.add_parser(
        "ingest", help="turn a bench's raw logs (NDI tracker, load-cell DAQ, motor) into a measurement CSV",
        description="Read an NDI Aurora/Polaris tool-tracking CSV export, a DAQ log of the load cell and the motor's "
                    "log; compute the bend angle from the coils' poses, align the three clocks (offset and drift, "
                    "from a shared trigger or the shared motion), put stroke (mm) and force (N) on the tracker's "
                    "frames without bridging gaps, number the cycles, and write sample, cycle, time_s, stroke_mm, "
                    "force_N, angle_deg (deg). See docs/bench.md.")
    src = i.add_mutually_exclusive_group(required=True)
    src.add_argument("--tracker", metavar="TRACKER.csv", help="NDI Track CSV export (positions mm)")
    src.add_argument("--angle-log", metavar="ANGLE.csv",
                     help="instead of a tracker: a log of the joint angle (deg, or rad with --map angle.unit=rad)")
    i.add_argument("--daq", required=True, metavar="DAQ.csv", help="load cell log: a time column and a force column")
    i.add_argument("--motor", required=True, metavar="MOTOR.csv", help="motor log: a time column and a position column")
    i.add_argument("--bench", metavar="BENCH.yaml", help="bench map: tools, columns, units, calibrations (docs/bench.md)")
    i.add_argument("--map", dest="map_overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a bench map value, e.g. --map motor.gear_ratio=64 --map daq.N_per_V=2.2; repeatable")
    i.add_argument("--sample", default=None, metavar="NAME", help="sample name (default: the tracker file's stem)")
    i.add_argument("--max-lag", type=float, default=None, metavar="S",
                   help="largest clock offset between instruments to consider, s (default: any)")
    i.add_argument("-o", "--output", required=True, type=path_value, metavar="DATA.csv",
                   help="the measurement CSV to write")
    i.add_argument("--report", type=path_value, metavar="DIR",
                   help="write index.html and figures (alignment, angle, dropouts) here")
    i.set_defaults(func=cmd_ingest)

    from camtube.commands import diagnose, effect

    diagnose.register(model_sub)
    effect.register_effect_commands(model_sub)


def _add_pattern_option(p: argparse.ArgumentParser) -> None:
    p.add_argument("--pattern", required=True, type=path_value, metavar="PATTERN",
                   help="pattern YAML of the joint (see patterns/)")
    p.add_argument("--set", dest="overrides", action="append", default=[], metavar="KEY=VALUE",
                   help="override a pattern scalar, e.g. --set tendon.length=80")
    p.add_argument("-q", "--quiet", action="store_true", help="do not print design warnings")


def cmd_fit(args: argparse.Namespace) -> int:
    from camtube.commands.common import (
        check_output_file, check_outputs_apart, load_joint_pattern, refuse_output_over_input,
    )
    from camtube.io import write_together
    from camtube.model.core.build import (
        build_registry, check_fix_and_init, check_init_fitted, fitted_and_held, history_warning, parse_in_range,
        split_names,
    )
    from camtube.model.core.fit import FitError, fit
    from camtube.model.core.predict import model_for_pattern, pattern_values
    from camtube.model.data import check_fittable, check_row_count, find_slack, load_csv, prepare, remove_deadband, select_cycles
    from camtube.model.data.csvfile import check_sample_rows, check_signs, check_time_varies, check_zeros
    from camtube.model.diagnose.instruments import check_units, sampling_rates, slow_sampling_line
    from camtube.errors import DataError
    from camtube.model.report.fit import fit_json, fit_text

    check_suffix(args.json, (".json",), "--json")
    check_suffix(args.plot, (".png",), "--plot")
    inputs = [("DATA.csv", args.data), ("--pattern", args.pattern)] + [("--effect-file", f) for f in args.effect_file]
    for opt, path in (("--json", args.json), ("--plot", args.plot)):  # both written, or neither: checked first
        if path is not None:
            check_output_file(path, opt)
            refuse_output_over_input(path, opt, inputs)
    check_outputs_apart([("--json", args.json, True), ("--plot", args.plot, True)])
    if not 0 <= args.starts <= 50:
        raise DataError(f"--starts {args.starts}: allowed 0..50 grid points per parameter; fix: e.g. --starts 3 "
                        "(0: one start)")
    t = args.deadband_threshold
    if t is not None and not (0 < t < 360):
        raise DataError(f"--deadband-threshold {t}: the smallest angle rise that counts as motion must be > 0 and "
                        "< 360 deg; fix: e.g. --deadband-threshold 0.5, or leave it out for max(0.5, 4 x noise)")
    if t is not None and not args.deadband:   # (ignored without a word)
        raise DataError(f"--deadband-threshold {t:g} with --no-deadband: the threshold finds the slack deadband that "
                        "--no-deadband keeps, so it would not be used; fix: drop one of the two")
    pattern = load_joint_pattern(args)
    reg, _ = build_registry(args.effect_file)
    model = model_for_pattern(pattern, [reg.get_effect(n)
                                        for n in split_names(args.effects, "--effects")])
    if args.set_aside:
        from camtube.model.data import read_measurements
        from camtube.model.diagnose.instruments import check_instruments, zero_lines

        meas = read_measurements(args.data)
        check_time_varies(meas.data, args.data)
        if meas.summary():
            print(meas.summary())
        ins = check_instruments(select_cycles(meas.data, args.cycles), lag_ms=args.lag_ms or 0.0,
                                rezero=args.rezero)
        print("; ".join(ins.lines()[:1] + ins.lines()[-1:]))
        for line in zero_lines({smp: z for smp, z in ins.zeros.items() if z.applied}, True, "--rezero"):
            print(line)
        raw = ins.data
        rows = prepare(raw, "all", args.branch, args.deadband, args.deadband_threshold)
    else:
        if args.lag_ms:
            raise DataError("--lag-ms needs --set-aside (the instruments' check that corrects it); fix: add "
                            "--set-aside")
        if args.rezero:
            raise DataError("--rezero needs --set-aside (the instruments' check that re-zeroes the force); fix: add "
                            "--set-aside")
        raw = load_csv(args.data)
        check_time_varies(raw, args.data)
        _check_stroke_spikes(raw, args.data)
        rows = prepare(raw, args.cycles, args.branch, args.deadband, args.deadband_threshold)
    chosen = f"{args.data} (cycles {args.cycles}, {args.branch} branch)"
    # (the rows' count is checked once the parameters are known: as many rows as parameters or fewer is the fit's
    # own refusal, which names both)
    check_fittable(rows, chosen, min_rows=0)
    check_sample_rows(rows, args.data)
    check_signs(rows, args.data)
    check_zeros(raw, args.data,   # (every row: the slack deadband's removal shifts the stroke by its own zero)
                "" if args.rezero else " (or re-zero the force at the rests of the whole record: --set-aside "
                "--rezero --cycles all)")
    names, held = fitted_and_held(model, args.fit_params, args.fix)
    fixed = pattern_values(pattern)
    fixed.update(held)
    check_units(model_for_pattern(pattern), rows, fixed, names, args.data)
    init = parse_in_range(args.init, "--init", model.param_specs)
    check_fix_and_init(held, init)
    params = model.make_params(rows, names, fixed, initial=init,
                               per_sample=split_names(args.per_sample, "--per-sample"))
    check_init_fitted(init, params.varying)
    warn = history_warning(model, args.branch, min((len(set(rows.cycle[sl].tolist()))
                                                    for _, sl in rows.sample_slices()), default=0),
                           params.varying)
    if len(rows) > len(params.varying):
        check_row_count(len(rows), chosen)
    result = fit(model, rows, params=params, grid=args.starts)

    sel = (f"cycles {args.cycles}, {args.branch} branch, "
           + ("slack deadband removed" if args.deadband else "deadband kept"))
    title = (f"{pattern.name}: {args.data} ({len(raw)} rows; fitted {result.n_points}: {sel})"
             + (f"; effects: {', '.join(e.name for e in model.effects)}" if model.effects else ""))
    print(fit_text(result, title))
    if warn:
        print(warn)
    slow = slow_sampling_line(sampling_rates(raw)[0])   # (as model diagnose says it: a time column in ms)
    if slow:
        print(f"note: {slow}")
    if args.deadband:
        slack = find_slack(select_cycles(raw, args.cycles), args.deadband_threshold)
        for smp in rows.samples:
            vals = [v.stroke_mm for (s, _), v in slack.items() if s == smp]
            if vals:
                print(f"slack of sample {smp}: {min(vals):.3f}-{max(vals):.3f} mm over {len(vals)} cycle(s)")
    bad = result.unidentified
    if bad:  # refused before --json/--plot: no file holds values that are not estimates
        raise FitError(f"{args.data}: these rows cannot identify " + "; ".join(f"{k}: {v}" for k, v in bad.items())
                       + "; the values above are not estimates (no --json/--plot written); fix: hold them "
                       "(--fix NAME=VALUE), drop the effect, or select rows where they matter (e.g. --cycles all "
                       "--branch both --no-deadband)")
    meta = {"pattern": pattern.name, "data": str(args.data),
            "selection": {"cycles": args.cycles, "branch": args.branch, "deadband": bool(args.deadband)}}
    png = None
    if args.plot:  # made before anything is written, so that a failure leaves no --json without its --plot
        from camtube.model.report.plot import fit_png

        full = raw
        if args.deadband:
            full = remove_deadband(raw, args.deadband_threshold)
        png = fit_png(result, full, title=f"{pattern.name}: model vs measurement ({sel})")
    outputs = [(args.json, fit_json(result, meta))] if args.json else []
    if png is not None:
        outputs.append((args.plot, png))
    for path in write_together(outputs):  # both, or neither
        print(f"wrote {path}")
    return 0


def cmd_synth(args: argparse.Namespace) -> int:
    from camtube.commands.common import load_joint_pattern
    from camtube.model.sim.synth import noise_floor_deg, synthesize, write

    check_suffix(args.output, (".csv",), "-o/--output")
    pattern = load_joint_pattern(args)
    data = synthesize(pattern, args.samples, args.cycles, args.noise_angle, args.noise_force, args.seed,
                      modulus_gpa=args.modulus, speed_mm_s=args.speed, rate_hz=args.rate,
                      slack_mm=args.slack)
    path = write(data, args.output)
    floor = noise_floor_deg(pattern, args.noise_angle, args.noise_force, args.modulus)
    print(f"wrote {path}: {len(data)} rows, {args.samples} sample(s) x {args.cycles} cycles, "
          f"stroke 0-{pattern.rules.max_stroke_mm:g} mm; a perfect fit leaves RMSE ~{floor:.3f} deg")
    return 0


def _check_stroke_spikes(raw, source: str) -> None:
    """Refuse rows as read whose stroke jumps for one row (:func:`~camtube.model.diagnose.instruments.stroke_spikes`),
    naming the first: the fit would be made to a stroke the motor never had (one of 1e6 mm read as a stroke logged in
    um, and the fix said to divide it by 1000); ``--set-aside`` sets them aside instead."""
    import numpy as np

    from camtube.errors import DataError
    from camtube.model.diagnose.instruments import stroke_spikes

    bad = np.flatnonzero(stroke_spikes(np.asarray(raw.stroke_mm, float), raw.sample_slices()))
    if not bad.size:
        return
    k = int(bad[0])
    s = raw.stroke_mm
    more = f" (and {bad.size - 1} more such row(s))" if bad.size > 1 else ""
    raise DataError(f"{source}: sample {raw.sample[k]}, cycle {int(raw.cycle[k])}, t = {float(raw.time_s[k]):g} s: "
                    f"stroke_mm jumps to {float(s[k]):g} mm for one row, the rows either side read "
                    f"{float(s[k - 1]):g} and {float(s[k + 1]) if k + 1 < len(s) else float('nan'):g} mm{more}: a "
                    "glitch of the motor's log, not a motion; fix: correct or delete that line, or add --set-aside "
                    "(the instruments' check sets such rows aside and says so)")


def cmd_ingest(args: argparse.Namespace) -> int:
    from pathlib import Path

    from camtube.commands.common import check_output_dir, check_outputs_apart, refuse_output_over_input
    from camtube.io import check_writable_dir, write_together
    from camtube.model.data.csvfile import format_csv
    from camtube.model.ingest.merge import ingest_files
    from camtube.model.ingest.series import load_bench_map

    check_suffix(args.output, (".csv",), "-o/--output")
    if Path(args.output).is_dir():
        from camtube.errors import DataError

        raise DataError(f"-o {args.output}: is a directory; fix: name the measurement CSV to write")
    check_writable_dir(Path(args.output).absolute().parent)
    refuse_output_over_input(args.output, "-o", [("--tracker", args.tracker), ("--angle-log", args.angle_log),
                                                 ("--daq", args.daq), ("--motor", args.motor), ("--bench", args.bench)])
    if args.report:
        check_output_dir(args.report, "--report")
        if Path(args.report).resolve() == Path(args.output).resolve():
            raise CamtubeError(f"--report {args.report}: is also the -o file; fix: give the report a folder of its "
                               f"own, e.g. --report {Path(args.output).with_suffix('')}-report")
        check_outputs_apart([("-o", args.output, True), ("--report", args.report, False)])
    unused = [m for m in (args.map_overrides or []) if args.tracker and m.split("=", 1)[0].strip().startswith("angle.")]
    if unused:   # (the angle section is read with --angle-log only: it was ignored without a word)
        raise CamtubeError(f"--map {unused[0]}: the bench map's angle section is read with --angle-log only, and "
                           "--tracker was given (the tracker's export gives poses, in tracker.unit); fix: drop it, or "
                           "give the angle log with --angle-log")
    bench = load_bench_map(args.bench, args.map_overrides)
    first = args.tracker or args.angle_log
    ing = ingest_files(first, args.daq, args.motor, bench, args.sample, max_lag_s=args.max_lag,
                       angle_log=args.angle_log is not None)
    text = format_csv(ing.data)
    files = None
    if args.report:
        from camtube.model.ingest.report import report_files

        files = report_files(ing, f"ingest of {Path(first).name}")
    from camtube.model.ingest.report import summary_lines

    for line in summary_lines(ing):
        print(line)
    write_together([(args.output, text)] + ([(args.report, files)] if files is not None else []))  # all, or none
    print(f"wrote {Path(args.output)}")
    if files is not None:
        print(f"wrote {Path(args.report) / 'index.html'} (+ alignment.png, angle.png, dropouts.png)")
    return 0
