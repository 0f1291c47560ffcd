"""Reports of a :class:`~camtube.model.diagnose.Diagnosis`: text, JSON, and an offline HTML page with PNG plots.

Pure writers return ``str``/``bytes``; :func:`write_report` puts the files on
disk through :mod:`camtube.io` (each file atomically; ``index.html`` last, so a
report directory with an index is complete).

``diagnosis_dict(d, command="")`` is the JSON-ready summary (schema
``camtube.diagnose/1``)::

    {"schema", "noise_floor_deg", "noise_floor_se_deg",
     "noise_floor_se_parts_deg": {"statistical", "systematic"},
     "noise_lag_rows",                          # 1: white noise; L: correlated, the floor read from rows L apart
     "noise_lags_rows": {sample: L},            # the same, each sample's (two trackers may filter differently)
     "base": {"effects", "rmse_deg", "heldout_rmse_deg", "per_sample", "params"},   # with the baseline
     "given": {"effects", "rmse_deg", "per_sample"},          # the model as given (before the baseline)
     "baseline": [{"effect", "meaning", "joined_chain", "rmse_before_deg", "rmse_deg", "params"}],  # rest_angle
     "candidates": [{"effect", "rmse_deg", "heldout_rmse_deg", "delta_bic", "params": {name: {value, stderr, unit}},
                     "equivalent", "confounded", "significant", "why", "meaning", "signature"}],
     "rounds": [[candidate, ...], ...],        # candidates of each greedy round (first = "candidates")
     "recommended": [effect, ...],             # in order; only a chain within 1.15 x the noise floor
     "replaced": [{"effects", "by"}], "dropped": [effect, ...],   # stepwise: swapped or dropped before the end
     "partial": [{"effect", "rmse_before_deg", "rmse_deg", "floor_ratio", "params"}],  # lower it, not a fix
     "waterfall": [{"effects", "rmse_deg", "per_sample"}],
     "per_sample": [name, ...], "held": {"name@S": value,   # per-sample copies held off (absent in S)
                                          "name": value},    # a baseline effect a stand-in holds off, or a
                                                             # parameter the rows kept barely depend on
     "final": {"effects", "rmse_deg", "params"}, "stop_reason", "command",
     "unexplained": null | {"share", "follows", "periodic": [{"variable", "period", "unit", "amplitude_deg"}],
                            "shape", "samples", "rows": null | {"share", "n", "fraction", "max_deg", "samples",
                            "time_s"}, ...}}   # camtube.model.unexplained

Non-finite numbers are written as ``null``.
"""
from __future__ import annotations

import html
import io
import json
import math
from pathlib import Path

import numpy as np

from camtube.model.diagnose.atlas import describe, residual_atlas
from camtube.model.diagnose.search import REACH_RATIO, Candidate, Diagnosis, baseline_stand_ins
from camtube.model.unexplained import report as unexplained_report


def _num(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def _times(value: float, floor: float) -> str:
    """``'1.07 x'`` (value over the noise floor), or a phrase when the floor is zero (noise-free data)."""
    if floor > 0 and math.isfinite(floor):
        return f"{value / floor:.2f} x"
    return "exact, no noise:" if value == 0 else "above zero; there is no"


def _pm(value: float, err: float, unit: str) -> str:
    e = f" +- {err:.2g}" if math.isfinite(err) else " +- inf"
    return f"{value:.4g}{e} {unit}".rstrip()


def fit_names(d: Diagnosis, effects) -> list[str]:
    """Full names of the parameters fitted with ``effects``: the base ones, then each effect's."""
    names = list(d.fit_params)
    for name in effects:
        names += [f"{name}.{p.name}" for p in d.catalog[name].params]
    return list(dict.fromkeys(names))


def partial_lines(d: Diagnosis) -> list[str]:
    """Text lines for the partial effects: they lower the error but leave a structured misfit (not a fix)."""
    if not d.partial:
        return []
    floor = d.noise_floor_deg
    steps = d.partial_steps
    out = [f"partial (they lower the error but the model stays above {REACH_RATIO:g} x the noise floor: a "
           "structured misfit remains that no built-in effect explains, see 'unexplained'; not recommended):"]
    prev = steps[0]
    for k, name in enumerate(d.partial, 1):
        step = steps[k] if k < len(steps) else steps[-1]
        own = [n for n in step.params if n.split("@")[0].startswith(name + ".")]
        own = [n for n in own if "@" in n or not any(m.startswith(n + "@") for m in own)]  # per-sample copies win
        params = ", ".join(f"{n} = {step.params[n]:.4g}" for n in own)
        out.append(f"  {name}: lowers {prev.rmse_deg:.3f} -> {step.rmse_deg:.3f} deg "
                   f"({_times(step.rmse_deg, floor)} the noise floor) but leaves a structured misfit"
                   + (f" ({params})" if params else ""))
        prev = step
    return out


def _partial_dicts(d: Diagnosis) -> list[dict]:
    out = []
    steps = d.partial_steps
    for k, name in enumerate(d.partial, 1):
        step = steps[k] if k < len(steps) else steps[-1]
        out.append({"effect": name, "rmse_before_deg": _num(steps[k - 1].rmse_deg), "rmse_deg": _num(step.rmse_deg),
                    "floor_ratio": _num(step.rmse_deg / d.noise_floor_deg) if d.noise_floor_deg > 0 else None,
                    "params": {n: {"value": _num(v), "stderr": _num(step.stderr[n]) if n in step.stderr else None,
                                   "unit": step.units.get(n, "")}
                               for n, v in step.params.items() if n.split("@")[0].startswith(name + ".")}})
    return out


def add_command(d: Diagnosis, prefix: str) -> str:
    """The ``camtube model fit`` command that reproduces the final model: same rows, same starts, same numbers."""
    import shlex

    effects = list(d.final.effects)
    if not (effects or d.final.per_sample) or not prefix:
        return ""
    # (no effects but E_t per sample, the samples' tendons differing: the paper's model with it)
    cmd = f"{prefix} --effects {','.join(effects)}" if effects else prefix
    if tuple(d.fit_params) != ("E_t",):  # model fit's default: E_t plus every effect parameter
        cmd += f" --fit {','.join(fit_names(d, effects)) or 'none'}"
    if d.final.per_sample:
        cmd += f" --per-sample {','.join(d.final.per_sample)}"
    for k, v in d.held.items():  # an effect held off in the samples that do not show it
        cmd += " --fix " + shlex.quote(f"{k}={v:.6g}")
    for k, v in d.final.init.items():
        cmd += " --init " + shlex.quote(f"{k}={v:.6g}")
    cmd += f" --starts {d.grid}"
    return cmd


def _candidate_dict(d: Diagnosis, c: Candidate) -> dict:
    e = d.catalog.get(c.effect)
    return {
        "effect": c.effect,
        "replaces": list(c.replaces),
        "rmse_deg": _num(c.rmse_deg),
        "heldout_rmse_deg": _num(c.heldout_rmse_deg),
        "delta_bic": _num(c.delta_bic),
        "params": {k: {"value": _num(v), "stderr": _num(s), "unit": u} for k, (v, s, u) in c.params.items()},
        "equivalent": list(c.equivalent),
        "confounded": list(c.confounded),
        "significant": bool(c.significant),
        "why": c.why,
        "meaning": e.meaning if e else "",
        "signature": e.signature if e else "",
    }


def diagnosis_dict(d: Diagnosis, command: str = "", meta: dict | None = None) -> dict:
    """JSON-ready summary of ``d`` (see the module docstring); ``command`` is the ``model fit`` prefix."""
    base, final = d.waterfall[0], d.final
    out: dict = {"schema": "camtube.diagnose/1"}
    out.update(meta or {})
    out["noise_floor_deg"] = _num(d.noise_floor_deg)
    out["base"] = {"effects": list(base.effects), "rmse_deg": _num(base.rmse_deg),
                   "heldout_rmse_deg": _num(d.base_heldout_rmse_deg),
                   "per_sample": {k: _num(v) for k, v in base.rmse_per_sample.items()},
                   "params": {k: {"value": _num(v), "stderr": _num(base.stderr[k]) if k in base.stderr else None,
                                  "unit": base.units.get(k, "")} for k, v in base.params.items()}}
    given = d.given or base
    out["given"] = {"effects": list(given.effects), "rmse_deg": _num(given.rmse_deg),
                    "per_sample": {k: _num(v) for k, v in given.rmse_per_sample.items()}}
    out["baseline"] = [{"effect": name, "meaning": d.catalog[name].meaning if name in d.catalog else "",
                        "joined_chain": list(d.baseline_gain.get(name, ((), 0, 0))[0]),
                        "rmse_before_deg": _num(d.baseline_gain.get(name, ((), math.nan, 0))[1]),
                        "rmse_deg": _num(d.baseline_gain.get(name, ((), 0, math.nan))[2]),
                        "params": {k: {"value": _num(v), "stderr": _num(final.stderr.get(k, math.inf)),
                                       "unit": final.units.get(k, "")}
                                   for k, v in final.params.items() if k.split("@")[0].startswith(name + ".")}}
                       for name in d.baseline]
    out["candidates"] = [_candidate_dict(d, c) for c in d.candidates]
    out["rounds"] = [[_candidate_dict(d, c) for c in r] for r in d.rounds]
    out["recommended"] = list(d.recommended)
    out["explanation"] = d.explanation or None
    out["nearest_on_bound"] = nearest_on_bound(d)
    ins = d.instruments
    if ins is not None:
        out["instruments"] = {
            "rows_read": len(ins.raw), "rows_dropped": int(ins.n_dropped), "dropped": ins.dropped or None,
            "rows_set_aside": {k: int(len(v)) for k, v in ins.aside.items()},
            "rates_hz": {k: _num(v) for k, v in ins.rates_hz.items()}, "rate_changes": list(ins.rate_changes),
            "lag_ms": _num(ins.lag.lag_ms), "lag_se_ms": _num(ins.lag.se_ms), "lag_given": bool(ins.lag.given),
            "lag_applied_ms": _num(ins.lag.applied_ms),
            "lag_per_sample": {smp: {"lag_ms": _num(ms), "se_ms": _num(se), "applied_ms": _num(applied)}
                               for smp, ms, se, _, applied in ins.lag.per_sample},
            "load_cell_zero": {smp: {"rests": z.n_rests, "start_N": _num(z.start_N), "end_N": _num(z.end_N),
                                     "change_N": _num(z.change_N), "change_se_N": _num(z.se_N),
                                     "scatter_N": _num(z.scatter_N), "rezeroed": bool(z.applied),
                                     "before_first_pull_N": _num(z.first_N) if z.first_rows else None,
                                     "first_cycle": int(z.first_cycle),
                                     "held_at_rest": bool(z.held_beside_offset)}
                               for smp, z in ins.zeros.items()},
            "load_cell_limit_N": {smp: {"reading_N": _num(v), "rows": int(k)} for smp, (v, k) in ins.limits.items()}}
    out["replaced"] = [{"effects": list(old), "by": new} for old, new in d.replaced]
    out["dropped"] = list(d.dropped)
    out["waterfall"] = [{"effects": list(s.effects), "rmse_deg": _num(s.rmse_deg),
                         "per_sample": {k: _num(v) for k, v in s.rmse_per_sample.items()}} for s in d.waterfall]
    out["final"] = {"effects": list(final.effects), "rmse_deg": _num(final.rmse_deg),
                    "params": {k: {"value": _num(v), "stderr": _num(final.stderr[k]) if k in final.stderr else None,
                                   "unit": final.units.get(k, "")} for k, v in final.params.items()}}
    out["noise_floor_se_deg"] = _num(d.noise_floor_se_deg)
    out["noise_lag_rows"] = int(d.noise_lag_rows)
    out["noise_lags_rows"] = {smp: int(v) for smp, v in d.noise_lags_rows.items()}
    if len(d.noise_floor_parts_deg) == 2:
        out["noise_floor_se_parts_deg"] = {"statistical": _num(d.noise_floor_parts_deg[0]),
                                           "systematic": _num(d.noise_floor_parts_deg[1])}
    out["partial"] = _partial_dicts(d)
    out["rejected"] = [{"effect": e, "why": w} for e, w in d.rejected]
    out["per_sample"] = list(d.per_sample)
    out["held"] = {k: _num(v) for k, v in d.held.items()}
    out["sample_notes"] = list(d.sample_notes)
    out["stiffness_note"] = d.stiffness_note or None
    out["alone"] = {smp: {"recommended": list(a["recommended"]), "explanation": a["explanation"] or None,
                          "partial": list(a["partial"]), "rmse_before_deg": _num(a["before_deg"]),
                          "rmse_after_deg": _num(a["after_deg"]), "noise_floor_deg": _num(a["floor_deg"])}
                    for smp, a in d.alone.items()}
    out["stop_reason"] = d.stop_reason
    out["command"] = add_command(d, command)
    out["unexplained"] = unexplained_report.json_section(d)
    return out


def baseline_lines(d: Diagnosis) -> list[str]:
    """The baseline effects that joined the model: what they mean, their values (the final chain's), the RMSE."""
    if not d.baseline or d.given is None:
        return []
    base = d.waterfall[0]
    out: list[str] = []
    for name in d.baseline:
        e = d.catalog.get(name)
        vals = "; ".join(_baseline_value(d, f"{name}.{p.name}", p.unit) for p in (e.params if e else ())
                         if f"{name}.{p.name}" in d.final.params
                         or any(k.startswith(f"{name}.{p.name}@") for k in d.final.params))
        out.append(f"baseline: {name} joins the model, as a property of this joint rather than missing physics: "
                   f"{e.meaning if e else name}; {vals}")
        chain, before, after = d.baseline_gain.get(name, ((), d.given.rmse_deg, base.rmse_deg))
        on = f"the model with {', '.join(chain)}" if chain else "the current model"
        out.append(f"  it lowers the RMSE of {on} from {before:.3f} to {after:.3f} deg"
                   + (f"; it sits in the {SIDES[name]}" if name in SIDES else ""))
    out.append("  the recommended steps below start from the model with it, and the command includes it "
               "(--no-baseline: try it as an ordinary candidate instead)")
    return out


def _baseline_value(d: Diagnosis, full: str, unit: str) -> str:
    """``name = value +- error`` of a baseline parameter in the final model; per sample when it is fitted so
    (a sample that does not show it: held at its off value)."""
    ps = [(k.split("@", 1)[1], k) for k in d.final.params if k.startswith(full + "@")]
    if not ps:
        return f"{full} = {_pm(d.final.params[full], d.final.stderr.get(full, math.inf), unit)}"
    return ", ".join(f"{k} = " + (f"{d.held[k]:g} (held: {smp} does not show it)" if k in d.held
                                  else _pm(d.final.params[k], d.final.stderr.get(k, math.inf), unit))
                     for smp, k in ps)


#: Where each built-in effect sits on the bench, and what the data cannot tell it from (with the measurement
#: that would).
SIDES = {
    "slack": "tendon or drive: the data cannot tell slack in the tendon from lost motion between the motor and "
             "the carriage (both take up stroke before the load cell sees tension); a displacement gauge on the "
             "carriage would (lost motion in the drive also opens only after an unloading, so the first pull "
             "differs)",
    "play": "drive (lost motion between the motor and the carriage) or a tendon that slips at the guide; a "
            "displacement gauge on the carriage would tell",
    "play_held": "drive (the nut's gap, with the carriage held by its rail: lost motion between the motor and the "
                 "carriage, not in the tendon); a displacement gauge on the carriage would measure it",
    "carriage_hold": "drive (the rail's friction holds the carriage within the nut's gap while the tendon's tension "
                     "is low: lost motion between the motor and the carriage, not in the tendon); a displacement "
                     "gauge on the carriage would measure it",
    "carriage_gap": "drive (the rail's friction holds the carriage while the tendon's tension is low, and the nut's "
                    "far flank, a gap away, pushes it down with the motor: lost motion between the motor and the "
                    "carriage, not in the tendon); a displacement gauge on the carriage would measure it",
    "toe": "tendon (its fibres straighten one after another)",
    "toe_shape": "tendon (its fibres straighten one after another)",
    "toe_soft": "tendon (part of it carries load from zero force, the crimped fibres straighten one after another)",
    "creep": "tendon (it lengthens under load); a drifting load-cell zero also grows with time: the rests at zero "
             "stroke show it (the instruments' line on the load cell's zero), and so does a re-zero with the tendon "
             "unloaded after the test",
    "creep_load": "tendon (it lengthens while it carries load, and does not recover at rest); a drifting "
                  "load-cell zero grows with time instead: the rests at zero stroke show it (the instruments' line "
                  "on the load cell's zero), and so does a re-zero with the tendon unloaded after the test",
    "viscoelastic": "tendon (delayed compliance); the joint's own relaxation does not show here (the measured "
                    "force carries it)",
    "friction": "tendon (friction at the guide or in a sheath)",
    "capstan": "tendon at the guide it wraps, between the load cell and the joint (the cell reads more than the "
               "joint pulls while pulling, less while releasing); a second load cell at the joint side would "
               "measure the ratio",
    "series": "tendon or sheath (a compliance in series: the same as a softer tendon)",
    "force_zero": "instruments (the load cell's zero)",
    "angle_bias": "instruments (the tracker's offset), or a joint that rests bent",
    "rest_angle": "joint (friction or a permanent set), or the drive: a carriage that its rail's friction holds "
                  "within the nut's gap keeps the tendon taut while the motor rests at zero (lost motion); a "
                  "displacement gauge on the carriage would tell",
    "relaxation": "joint (its polymer backbone relaxes; the tendon's own creep lengthens it under load instead, "
                  "and shows while it pulls: a dwell with the tendon slack, the joint filmed, tells)",
    "relaxation2": "joint (its polymer backbone relaxes on a fast and a slow time scale; the tendon's own creep "
                   "lengthens it under load instead, and shows while it pulls: a long dwell with the tendon slack, "
                   "the joint filmed, tells); or the instruments: a tracker whose zero drifts as it warms up reads "
                   "as a slow relaxation over 50 even cycles (a second sensor fixed to the base, or the tracker "
                   "logging the still joint for as long as the test, tells)",
    "hardstop": "joint (the notches close)",
    "kerf": "joint geometry", "flat_walls": "joint geometry", "chords": "joint geometry",
}


def unresolved_held(d: Diagnosis) -> dict:
    """The held values of the recommended effects' parameters that do not switch the effect off (not in its
    ``off`` values): held because the rows barely depend on them, not because a sample does not show it."""
    out = {}
    for k, v in d.held.items():
        (eff, _, pname), smp = k.split("@")[0].partition("."), k.partition("@")[2]
        e = d.catalog.get(eff)
        if eff not in d.recommended or e is None or pname in (e.off or {}):
            continue
        if smp and any(f"{eff}.{o}@{smp}" in d.held for o in (e.off or {})):
            continue   # the effect is held off in that sample: all its copies there are held with it
        out[k] = v
    return out


def _at_sharp_limit(d: Diagnosis, key: str, value: float) -> bool:
    """``key`` (``effect.param`` or ``effect.param@S``) is a parameter of kind ``sharp`` held at its lower bound."""
    eff, _, pname = key.split("@")[0].partition(".")
    e = d.catalog.get(eff)
    spec = next((p for p in (e.params if e is not None else ()) if p.name == pname), None)
    return spec is not None and spec.at_sharp_limit(value)


#: A candidate refused for a parameter on its bound is named as the nearest built-in when its held-out RMSE is at most
#: this share of what the effects listed partial leave (or of the model's, when none is).
NEAREST_SHARE = 0.5


def nearest_on_bound(d: Diagnosis) -> dict | None:
    """The built-in that lowers the error most where nothing is recommended, refused only because a parameter ended on
    its bound: ``{"effect", "heldout_rmse_deg", "left_rmse_deg", "bound", "side"}``, or None. Its family is what is
    missing, beyond the range of its law (``bench-shapes``: tube 3's backbone, its set ratcheting from 10 to 46 deg;
    ``relaxation2`` took the error from 14.1 to 1.9 deg with its slow arm's ratio on its bound, and the answer named
    ``angle_bias`` and ``slack``, partial at 26x the floor, alone). Only where its held-out RMSE is at most
    :data:`NEAREST_SHARE` of what the partial effects leave (of the model's where none is listed)."""
    if d.recommended or not d.rounds:
        return None
    left = d.partial_steps[-1].rmse_deg if d.partial else d.waterfall[0].rmse_deg
    best = None
    for rnd in d.rounds:
        for c in rnd:
            if c.significant or c.replaces or "is on its bound" not in c.why:
                continue
            if not math.isfinite(c.heldout_rmse_deg) or c.heldout_rmse_deg > NEAREST_SHARE * left:
                continue
            if best is None or c.heldout_rmse_deg < best.heldout_rmse_deg:
                best = c
    if best is None:
        return None
    bound = next(part.strip() for part in best.why.split(";") if "is on its bound" in part)
    return {"effect": best.effect, "heldout_rmse_deg": float(best.heldout_rmse_deg), "left_rmse_deg": float(left),
            "bound": bound, "side": SIDES.get(best.effect, "")}


def alone_lines(d: Diagnosis) -> list[str]:
    """The samples differ: each diagnosed alone, where some are explained and some are not (``Diagnosis.alone``)."""
    if not d.alone:
        return []
    out = ["  per sample (each diagnosed alone, as the samples differ):"]
    for smp, a in d.alone.items():
        ratio = a["after_deg"] / a["floor_deg"] if a["floor_deg"] > 0 else math.inf
        if a["recommended"]:
            label = f" ({a['explanation']} explanation)" if a["explanation"] else ""
            out.append(f"    {smp}: add {', then '.join(a['recommended'])}{label}: {a['before_deg']:.3f} -> "
                       f"{a['after_deg']:.3f} deg ({ratio:.2f} x its noise floor)")
        elif a["partial"]:
            out.append(f"    {smp}: nothing the library has explains it: {', '.join(a['partial'])} lower it from "
                       f"{a['before_deg']:.3f} to {a['after_deg']:.3f} deg, {ratio:.2f} x its noise floor (see "
                       "'unexplained')")
        else:
            out.append(f"    {smp}: nothing to add alone ({a['before_deg']:.3f} deg, {ratio:.2f} x its noise floor)")
    out.append("    (fit a sample alone from a file of its rows; what the others leave is in 'left' and 'unexplained')")
    return out


def answer_lines(d: Diagnosis) -> list[str]:
    """The answer first: what to add in order with the error before and after each step, what is left and what
    it follows, per sample, and the instruments' findings (rows set aside, lag)."""
    floor = d.noise_floor_deg
    steps = d.waterfall
    out = []
    unresolved = unresolved_held(d)
    if d.recommended:
        label = f" ({d.explanation} explanation)" if d.explanation else ""
        out.append(f"answer: add {', then '.join(d.recommended)}{label}")
        out.append(f"  current model: RMSE {steps[0].rmse_deg:.3f} deg ({_times(steps[0].rmse_deg, floor)} the noise "
                   f"floor {floor:.3f} deg)")
        stands = baseline_stand_ins(d.baseline, d.recommended)
        if stands:
            b, e = stands[0]
            out.append(f"  (as given {d.given.rmse_deg:.3f} deg ({_times(d.given.rmse_deg, floor)} the floor): the "
                       f"baseline's {b} takes it to {steps[0].rmse_deg:.3f}, but {e} can stand in for it, so that "
                       "share is counted with the steps below)")
        for k, name in enumerate(d.recommended, 1):
            side = SIDES.get(name)
            out.append(f"  {k}. + {name}: {steps[k - 1].rmse_deg:.3f} -> {steps[k].rmse_deg:.3f} deg "
                       f"({_times(steps[k].rmse_deg, floor)} the floor)" + (f"; sits in the {side}" if side else ""))
        if d.per_sample and len(steps) > len(d.recommended) + 1:
            out.append(f"  {len(d.recommended) + 1}. per sample ({', '.join(d.per_sample)}): "
                       f"{steps[-2].rmse_deg:.3f} -> {steps[-1].rmse_deg:.3f} deg")
        samples = list(steps[0].rmse_per_sample)
        if len(samples) > 1:
            for smp in samples:
                gains = [f"{name} {steps[k - 1].rmse_per_sample[smp]:.2f} -> {steps[k].rmse_per_sample[smp]:.2f}"
                         for k, name in enumerate(d.recommended, 1)]
                out.append(f"  sample {smp}: " + "; ".join(gains) + " deg")
            for name in d.recommended:
                off = sorted({k.split("@")[1] for k in d.held if "@" in k and k.split(".")[0] == name
                              and k not in unresolved})
                if off:
                    on = [smp for smp in samples if smp not in off]
                    out.append(f"  {name}: in sample(s) {', '.join(on)} only; held off in {', '.join(off)} "
                               "(that sample does not show it)")
        for k, v in d.held.items():   # a baseline effect a recommended one stands in for
            if "@" not in k and k.split(".")[0] in d.baseline:
                out.append(f"  {k.split('.')[0]} (the baseline) held at {k} = {v:g}: the recommended effects "
                           "explain the bent rest in its place")
        for k, v in unresolved.items():
            if _at_sharp_limit(d, k, v):
                out.append(f"  {k} held at {v:g}, its lower bound: the law at its sharp limit (a decade above it the "
                           "error moves by less than a candidate must gain, counted against what the effect does): "
                           "it switches within a row, a step, so the value is a limit, not an estimate")
                continue
            out.append(f"  {k} held at {v:g}: the rows kept barely depend on it (across its whole range the error "
                       "moves by less than a candidate must gain, counted against what the effect does), so it is not "
                       "an estimate; the rows where it acts were set aside (a load cell at its limit sets aside the "
                       "dwells at the top) or not measured")
    elif d.partial:
        out.append("answer: nothing the library has explains the misfit; the built-ins that lower it ("
                   + ", ".join(d.partial) + f") leave {_times(d.partial_steps[-1].rmse_deg, floor)} the noise floor "
                   "and are not recommended (see 'partial' and 'unexplained')")
    elif steps[0].rmse_deg > REACH_RATIO * floor and d.max_effects == 0:
        # (--max-effects 0: no candidate was tried, so the library is not to blame: it said "write an effect" where
        # slack explained the data)
        out.append(f"answer: no effect was searched for (--max-effects 0): the model stays at "
                   f"{_times(steps[0].rmse_deg, floor)} the noise floor ({steps[0].rmse_deg:.3f} vs {floor:.3f} deg); "
                   "run without --max-effects 0 to find what is missing")
    elif steps[0].rmse_deg > REACH_RATIO * floor:
        out.append(f"answer: nothing the library has explains the misfit: the model stays at "
                   f"{_times(steps[0].rmse_deg, floor)} the noise floor ({steps[0].rmse_deg:.3f} vs {floor:.3f} deg) "
                   "and no built-in effect lowers it reliably (see 'unexplained')")
    else:
        out.append(f"answer: nothing to add: the model is at {_times(steps[0].rmse_deg, floor)} the noise floor "
                   f"({steps[0].rmse_deg:.3f} vs {floor:.3f} deg)")
    if d.stiffness_note:
        out.append(f"  {d.stiffness_note}")
    out += alone_lines(d)
    near = nearest_on_bound(d)
    if near is not None:
        out.append(f"  nearest: {near['effect']} lowers the error most ({near['heldout_rmse_deg']:.3f} deg held out, "
                   f"against {near['left_rmse_deg']:.3f}{' with the effects listed partial' if d.partial else ''}), "
                   f"but {near['bound']}: what is missing is of its family"
                   + (f" (it sits in the {near['side']})" if near["side"] else "")
                   + ", beyond the range of its law; write an effect of that family with a wider law (see the "
                   "tutorial in docs/diagnose.md)")
    u = unexplained_report.of_diagnosis(d)
    if u is not None and u.get("drift"):
        out.append(f"  left: {u['sentence']}")
    elif u is not None and (d.recommended or d.partial or steps[0].rmse_deg > REACH_RATIO * floor):
        rows = u.get("rows")
        follows = ("it follows " + ", ".join(u["follows"][:2]) if u.get("follows") else
                   f"it follows no variable: {100 * rows['share']:.0f} % of it sits in {rows['n']} isolated rows"
                   if rows else "it follows nothing in particular (noise-like)")
        out.append(f"  left: {100 * u['share']:.0f} % of the final error is above the noise floor; {follows}; "
                   f"carried by sample(s) {', '.join(u.get('samples') or []) or 'alike'}")
    elif d.recommended:
        out.append("  left: nothing structured (the error is at the noise floor)")
    ins = d.instruments
    if ins is not None:
        from camtube.model.diagnose.instruments import with_aside

        out.append("instruments:")
        out += [f"  {line}" for line in ins.lines()]
        if ins.n_aside:
            r0, a0, _ = with_aside(ins, steps[0].predicted, floor)
            r1, a1, _ = with_aside(ins, steps[-1].predicted, floor)
            out.append(f"  with the {ins.n_aside} rows set aside counted: RMSE {r0:.3f} -> {r1:.3f} deg; the data allow "
                       f"{a1:.3f} deg (noise floor and artefacts): {r1 / a1:.2f} x; without them: "
                       f"{steps[0].rmse_deg:.3f} -> {steps[-1].rmse_deg:.3f} deg, floor {floor:.3f} deg: "
                       f"{steps[-1].rmse_deg / floor:.2f} x")
    return out


def diagnosis_json(d: Diagnosis, command: str = "", meta: dict | None = None) -> str:
    """:func:`diagnosis_dict` as indented JSON with a final newline (deterministic)."""
    return json.dumps(diagnosis_dict(d, command, meta), indent=2, allow_nan=False) + "\n"


def diagnosis_text(d: Diagnosis, command: str = "", title: str = "") -> str:
    """The diagnosis in words: floor, where the model fails, the ranking, what to add and how."""
    floor = d.noise_floor_deg
    base = d.waterfall[0]
    lines = [title] if title else []
    lines += answer_lines(d)
    lines.append("")
    given = d.given or base
    cur = ", ".join(given.effects) or "none"
    if given.per_sample:
        cur += f"; per sample: {', '.join(given.per_sample)}"
    parts = d.noise_floor_parts_deg
    what = ("white noise in the residual" if d.noise_lag_rows <= 1 else
            f"the noise in the residual, correlated from row to row: read from rows {d.noise_lag_rows} apart"
            if len(set(d.noise_lags_rows.values())) <= 1 else
            "the noise in the residual, correlated from row to row in some samples: read from rows "
            + ", ".join(f"{smp} {v}" for smp, v in d.noise_lags_rows.items()) + " apart")
    lines.append(f"noise floor ({what}): {floor:.3f} +- {d.noise_floor_se_deg:.3f} deg"
                 + (f" (statistical {parts[0]:.3f}, systematic {parts[1]:.3f})" if len(parts) == 2 else ""))
    lines.append(f"current model (effects: {cur}): RMSE {given.rmse_deg:.3f} deg = "
                 f"{_times(given.rmse_deg, floor)} the noise floor; held-out {d.base_heldout_rmse_deg:.3f} deg")
    lines += baseline_lines(d)
    where = describe(residual_atlas(d.data, base.residuals), floor)
    if where:
        lines.append("where it fails:")
        lines += [f"  - {w}" for w in where]
    if d.candidates:
        lines.append("")
        lines.append("candidates (each effect added to the current model, ranked by held-out RMSE):")
        w = max(len(c.label) for c in d.candidates)
        lines.append(f"  {'#':>2}  {'effect':<{w}}  {'held-out':>8}  {'RMSE':>7}  {'dBIC':>9}  verdict")
        for k, c in enumerate(d.candidates, 1):
            verdict = "significant" if c.significant else c.why
            if c.equivalent:
                verdict += f"; cannot be told apart from {', '.join(c.equivalent)}"
            lines.append(f"  {k:>2}  {c.label:<{w}}  {c.heldout_rmse_deg:8.3f}  {c.rmse_deg:7.3f}  "
                         f"{c.delta_bic:9.1f}  {verdict}")
    lines.append("")
    if d.recommended:
        lines.append("recommended, in order" + (f" ({d.explanation} explanation)" if d.explanation else "") + ":")
        prev = base
        # the values are those of the whole chain (what the command below gives before any per-sample step):
        # a step's own refit can differ a lot (play alone takes up a toe's slack)
        chain = d.waterfall[len(d.recommended)]
        for k, name in enumerate(d.recommended, 1):
            e = d.catalog[name]
            step = d.waterfall[k]
            lines.append(f"  {k}. {name}: {e.signature}: {e.meaning}.")
            for p in e.params:
                full = f"{name}.{p.name}"
                if full in chain.per_sample:
                    lines.append(f"       {full}, per sample ({p.doc}):")
                    for smp in chain.rmse_per_sample:
                        key = f"{full}@{smp}"
                        lines.append(f"         {key} = {_pm(chain.params[key], chain.stderr.get(key, math.inf), p.unit)}")
                    continue
                lines.append(f"       {full} = {_pm(chain.params[full], chain.stderr.get(full, math.inf), p.unit)}"
                             f"  ({p.doc})")
            i = d.chosen_round.get(name, k - 1)
            rnd = d.rounds[i] if i < len(d.rounds) else ()
            c = next((c for c in rnd if c.effect == name and c.significant),
                     next((c for c in rnd if c.effect == name), None))
            if c is not None and c.equivalent:
                lines.append(f"       the data cannot tell it apart from: {', '.join(c.equivalent)}")
            if c is not None and c.confounded:
                lines.append(f"       strongly correlated with: {', '.join(c.confounded)}")
            lines.append(f"       RMSE {prev.rmse_deg:.3f} -> {step.rmse_deg:.3f} deg "
                         f"({_times(step.rmse_deg, floor)} the noise floor)")
            prev = step
        if d.per_sample and len(d.waterfall) > len(d.recommended) + 1:
            step = d.final
            lines.append(f"  per sample: {', '.join(d.per_sample)} (significantly better on held-out cycles)")
            for full in d.per_sample:
                for smp in step.rmse_per_sample:
                    key = f"{full}@{smp}"
                    unit = step.units.get(key, "")
                    if key in step.params:
                        lines.append(f"       {key} = {_pm(step.params[key], step.stderr.get(key, math.inf), unit)}")
            lines.append(f"       RMSE {prev.rmse_deg:.3f} -> {step.rmse_deg:.3f} deg "
                         f"({_times(step.rmse_deg, floor)} the noise floor)")
        cmd = add_command(d, command)
        if cmd:
            lines.append("add them:")
            lines.append(f"  {cmd}")
    else:
        lines.append("recommended: nothing")
        cmd = add_command(d, command) if d.baseline or d.stiffness_note else ""
        if cmd:
            lines.append("the model with its baseline:" if d.baseline else "the model with E_t per sample:")
            lines.append(f"  {cmd}")
    lines += partial_lines(d)
    for old, new in d.replaced:
        lines.append(f"replaced: {', '.join(old)} (chosen in an earlier round) by {new}: with {new} in the model "
                     f"the parameters of {', '.join(old)} went to a bound (it explains what they did), so "
                     f"{'they were' if len(old) > 1 else 'it was'} dropped")
    for name in d.dropped:
        lines.append(f"dropped: {name} (chosen in an earlier round): without it the held-out error is not "
                     "significantly worse, so a later effect explains what it did")
    for note in d.sample_notes:
        lines.append(f"note: {note}")
    for name, why in d.rejected:
        lines.append(f"not recommended: {name}: {why}")
    lines.append(f"stop: {d.stop_reason}")
    lines += unexplained_report.text_lines(d)
    return "\n".join(lines)


# ----------------------------------------------------------------------------- figures

def _png(fig) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", metadata={"Software": None})
    return buf.getvalue()


def _figure(w: float, h: float):
    import matplotlib

    matplotlib.use("Agg")
    from matplotlib.figure import Figure

    return Figure(figsize=(w, h), dpi=100)


def model_png(d: Diagnosis, max_samples: int = 4) -> bytes:
    """Angle vs stroke: measured, current model and the model with the recommended effects, per sample."""
    sl = d.data.sample_slices()[:max_samples]
    fig = _figure(4.2 * len(sl), 4.0)
    axes = np.atleast_1d(fig.subplots(1, len(sl), squeeze=False)[0])
    base, final = d.waterfall[0], d.final
    for ax, (smp, s) in zip(axes, sl):
        st = d.data.stroke_mm[s]
        ax.plot(st, d.data.angle_deg[s], ".", ms=1.5, color="0.6", label="measured", rasterized=True)
        ax.plot(st, base.predicted[s], "-", lw=0.7, color="tab:red",
                label="current model" + (f" + {', '.join(d.baseline)} (baseline)" if d.baseline else ""))
        if final is not base:
            ax.plot(st, final.predicted[s], "-", lw=0.7, color="black",
                    label="+ " + ", ".join(d.recommended) + (f" ({d.explanation})" if d.explanation else ""))
        elif d.partial and d.partial_steps:
            ax.plot(st, d.partial_steps[-1].predicted[s], "--", lw=0.7, color="tab:blue",
                    label="+ " + ", ".join(d.partial) + " (partial, not recommended)")
        ax.set_title(f"sample {smp}: RMSE {base.rmse_per_sample[smp]:.2f} -> {final.rmse_per_sample[smp]:.2f} deg",
                     fontsize=9)
        ax.set_xlabel("stroke (mm)")
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("joint angle (deg)")
    axes[0].legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return _png(fig)


def artefacts_png(d: Diagnosis, max_samples: int = 4) -> bytes | None:
    """Angle against time per sample as read, with the rows the instruments' check set aside marked (``None``
    without an instruments' check)."""
    ins = d.instruments
    if ins is None:
        return None
    raw = ins.raw
    sl = raw.sample_slices()[:max_samples]
    fig = _figure(13.0, 2.4 * len(sl) + 0.6)
    axes = np.atleast_1d(fig.subplots(len(sl), 1, squeeze=False)[:, 0])
    marks = {"angle spike": ("x", "tab:red"), "force spike": ("+", "tab:purple"),
             "repeated time stamp": ("|", "tab:orange"), "angle burst row": ("x", "tab:brown"),
             "force burst row": ("+", "tab:pink"), "frozen angle row": ("s", "tab:cyan"),
             "load cell limit row": (".", "tab:olive"), "force ahead of the stroke row": ("D", "tab:blue")}
    for ax, (smp, s) in zip(axes, sl):
        t = raw.elapsed_s[s]
        ax.plot(t, raw.angle_deg[s], "-", lw=0.4, color="0.55", label="angle as read", rasterized=True)
        for why, rows in ins.aside.items():
            r = rows[(rows >= s.start) & (rows < s.stop)]
            if r.size:
                m, c = marks.get(why, ("o", "black"))
                ax.plot(raw.elapsed_s[r], raw.angle_deg[r], m, ms=6, color=c, label=f"{why} ({r.size}), set aside")
        ax.set_ylabel(f"{smp}: angle (deg)")
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, loc="upper right")
    axes[-1].set_xlabel("time since the sample's first row (s)")
    lag = ins.lag
    axes[0].set_title(f"rows read {len(raw)}; set aside {ins.n_aside}; dropped before (missing values, backward "
                      f"stamps) {ins.n_dropped}; angle lag corrected "
                      + (", ".join(f"{smp} {a:.3g} ms" for smp, _, _, _, a in lag.per_sample) if lag.per_sample
                         else f"{lag.applied_ms:.3g} ms"), fontsize=9)
    fig.tight_layout()
    return _png(fig)


def atlas_png(d: Diagnosis) -> bytes:
    """The residual atlas of the current model (grey points, red trend) and of the final model (black trend)."""
    base = residual_atlas(d.data, d.waterfall[0].residuals)
    final = residual_atlas(d.data, d.final.residuals) if d.recommended else None
    fig = _figure(13.0, 7.0)
    axes = fig.subplots(2, 3).ravel()
    from camtube.model.diagnose.atlas import variable

    rng = np.random.default_rng(0)
    n = len(d.data)
    pick = np.sort(rng.choice(n, size=min(n, 4000), replace=False)) if n else np.zeros(0, int)
    for ax, p in zip(axes, base.panels):
        x = variable(d.data, p.key)[pick]
        jitter = rng.uniform(-0.3, 0.3, x.size) if p.key == "direction" else 0.0
        ax.plot(x + jitter, d.waterfall[0].residuals[pick], ".", ms=1, color="0.7", rasterized=True)
        ax.axhline(0.0, color="0.4", lw=0.7)
        ax.fill_between(p.centre, np.nan_to_num(p.q25), np.nan_to_num(p.q75), color="tab:red", alpha=0.15, lw=0)
        ax.plot(p.centre, p.median, "o-", ms=3, color="tab:red", label="current model (median)")
        for sgn, style in ((1, "--"), (-1, ":")):
            if sgn in p.by_direction:
                c, m = p.by_direction[sgn]
                ax.plot(c, m, style, color="tab:red", lw=1,
                        label="loading" if sgn > 0 else "unloading")
        if final is not None:
            q = final.panel(p.key)
            ax.plot(q.centre, q.median, "s-", ms=3, color="black", label="with " + ", ".join(d.recommended))
        ax.set_xlabel(f"{p.label} ({p.unit})" if p.unit else p.label)
        ax.set_title(f"explains {100 * p.explained:.0f}% of the residual", fontsize=9)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("residual (deg)")
    axes[3].set_ylabel("residual (deg)")
    axes[0].legend(fontsize=7)
    fig.tight_layout()
    return _png(fig)


def ranking_png(d: Diagnosis) -> bytes:
    """Held-out RMSE of each first-round candidate, with the current model and the noise floor."""
    cands = list(d.candidates)
    fig = _figure(7.0, 0.35 * max(len(cands), 3) + 1.2)
    ax = fig.subplots()
    y = np.arange(len(cands))[::-1]
    ax.barh(y, [c.heldout_rmse_deg for c in cands],
            color=["tab:green" if c.significant else "0.6" for c in cands])
    ax.set_yticks(y, [c.label for c in cands])
    ax.axvline(d.base_heldout_rmse_deg, color="tab:red", lw=1, label="current model")
    ax.axvline(d.noise_floor_deg, color="black", ls="--", lw=1, label="noise floor")
    ax.set_xlabel("held-out RMSE (deg); green: significant")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return _png(fig)


def waterfall_png(d: Diagnosis) -> bytes:
    """RMSE overall and per sample as the recommended effects are added."""
    steps = d.waterfall
    samples = list(steps[0].rmse_per_sample)
    groups = ["all"] + samples
    fig = _figure(1.6 + 1.1 * len(steps) * len(groups) / 2, 3.6)
    ax = fig.subplots()
    width = 0.8 / len(steps)
    x = np.arange(len(groups))
    for k, s in enumerate(steps):
        vals = [s.rmse_deg] + [s.rmse_per_sample[g] for g in samples]
        label = (("current model" + (f" + {', '.join(d.baseline)}" if d.baseline else "")) if k == 0
                 else "+ " + d.recommended[k - 1] if k <= len(d.recommended)
                 else "per-sample " + ", ".join(d.per_sample))
        ax.bar(x + (k - (len(steps) - 1) / 2) * width, vals, width, label=label)
    ax.axhline(d.noise_floor_deg, color="black", ls="--", lw=1, label="noise floor")
    ax.set_xticks(x, ["all"] + [f"sample {g}" for g in samples])
    ax.set_ylabel("RMSE (deg)")
    ax.legend(fontsize=7)
    fig.tight_layout()
    return _png(fig)


def report_files(d: Diagnosis, command: str = "", title: str = "camtube diagnosis") -> dict[str, bytes]:
    """``{file name: bytes}`` of the report: four PNGs and ``index.html`` (self-contained, offline)."""
    files = {"model.png": model_png(d), "atlas.png": atlas_png(d), "ranking.png": ranking_png(d),
             "waterfall.png": waterfall_png(d)}
    art = artefacts_png(d)
    if art is not None:
        files["artefacts.png"] = art
    esc = html.escape
    rows = []
    for k, c in enumerate(d.candidates, 1):
        params = "; ".join(f"{n} = {_pm(v, s, u)}" for n, (v, s, u) in c.params.items())
        note = "significant" if c.significant else c.why
        if c.equivalent:
            note += f"; cannot be told apart from {', '.join(c.equivalent)}"
        rows.append(f"<tr><td>{k}</td><td>{esc(c.label)}</td><td>{c.heldout_rmse_deg:.3f}</td>"
                    f"<td>{c.rmse_deg:.3f}</td><td>{c.delta_bic:.1f}</td><td>{esc(params)}</td>"
                    f"<td>{esc(note)}</td></tr>")
    page = f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>{esc(title)}</title>
<style>body{{font-family:sans-serif;max-width:1300px;margin:1em auto}}pre{{background:#f4f4f4;padding:.6em;
white-space:pre-wrap}}table{{border-collapse:collapse;font-size:90%}}td,th{{border:1px solid #ccc;padding:2px 6px}}
img{{max-width:100%}}</style></head><body>
<h1>{esc(title)}</h1>
<h2>Answer</h2>
<pre>{esc(chr(10).join(answer_lines(d)))}</pre>
{("<p>Add them: <code>" + esc(add_command(d, command)) + "</code></p>") if d.recommended and add_command(d, command) else ""}
<h2>Model vs measurement</h2><p>Measured angle, the current model and the model with the recommended effects
(or, when nothing is recommended, the partial effects, dashed).</p><img src="model.png" alt="angle vs stroke">
<h2>Waterfall</h2><p>RMSE as the recommended effects are added, refitted on all rows.</p>
<img src="waterfall.png" alt="waterfall">
{'<h2>Instruments</h2><p>The angle as read; the rows set aside before fitting are marked.</p><img src="artefacts.png" alt="artefacts">' if art is not None else ""}
{unexplained_report.html_section(d)}<h2>Candidates</h2><img src="ranking.png" alt="ranking">
<table><tr><th>#</th><th>effect</th><th>held-out RMSE deg</th><th>RMSE deg</th><th>delta BIC</th>
<th>parameters</th><th>verdict</th></tr>
{chr(10).join(rows)}
</table>
<h2>Residual atlas</h2>
<p>Residual (measured - model) against each variable; lines are binned medians, the band the quartiles of the
current model; dashed/dotted: loading/unloading.</p><img src="atlas.png" alt="residual atlas">
<h2>The diagnosis in full</h2>
<pre>{esc(diagnosis_text(d, command))}</pre>
</body></html>
"""
    files["index.html"] = page.encode("utf-8")
    return files


def write_report(d: Diagnosis, directory: str | Path, command: str = "", title: str = "camtube diagnosis") -> Path:
    """Write :func:`report_files` into ``directory`` (PNGs first, ``index.html`` last); returns the index path."""
    from camtube.io import write_atomic

    files = report_files(d, command, title)
    directory = Path(directory)
    for name, payload in files.items():
        if name != "index.html":
            write_atomic(directory / name, payload)
    return write_atomic(directory / "index.html", files["index.html"])
