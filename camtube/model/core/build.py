"""Setting up a model from user input: effect names and files, ``--fix``/``--init`` lists, fitted names.

These used to live in the CLI modules; the CLI and the Python API share them.
"""
from __future__ import annotations

import math

from typing import Iterable, Mapping, Sequence

from camtube.model.core.model import FitError, JointModel
from camtube.model.core.registry import Registry, registry_with_files


#: An example value per option, for the fix of a malformed name list.
_LIST_EXAMPLES = {"--fit": "E_t,arm_scale (or --fit none: fit nothing)", "--effects": "slack,play",
                  "--candidates": "slack,play", "--per-sample": "slack,play"}


def split_names(text: str | None, option: str | None = None, *, empty_ok: bool = True) -> list[str]:
    """``'a, b,none'`` -> ``['a', 'b']`` (comma list; 'none' means nothing).

    With ``option`` (the command-line option the list came from) the list is checked: an empty name
    (``'a,,b'``, ``','``), a name given twice, or, unless ``empty_ok``, an empty list raise
    :class:`FitError` naming the option.
    """
    items = [t.strip() for t in (text or "").split(",")]
    if option is not None and text is not None:
        fix = f"fix: e.g. {option} {_LIST_EXAMPLES.get(option, 'NAME1,NAME2')}"
        if not text.strip():
            if not empty_ok:
                raise FitError(f"{option} {text!r}: an empty list of names; {fix}")
        elif not all(items):
            raise FitError(f"{option} {text!r}: an empty name (a comma too many); {fix}")
        twice = sorted({t for t in items if items.count(t) > 1})
        if twice:
            raise FitError(f"{option} {text!r}: names {', '.join(twice)} twice; fix: name each once, {fix[5:]}")
    return [t for t in items if t and t.lower() != "none"]


def fit_param_names(model: JointModel, text: str | None = None, base: Sequence[str] = ("E_t",)) -> list[str]:
    """Parameters to fit: the ``--fit`` list, or by default ``base`` and every parameter of the model's effects."""
    if text is not None:
        return split_names(text, "--fit", empty_ok=False)
    return list(dict.fromkeys(list(base) + [n for e in model.effects for n in e.full_names()]))


def parse_assignments(items: Iterable[str], option: str = "--fix") -> dict[str, float]:
    """``['L0=70', 'E_t = 30']`` -> ``{'L0': 70.0, 'E_t': 30.0}``; a bad item raises naming ``option``."""
    out = {}
    for it in items:
        name, sep, val = it.partition("=")
        key = name.strip()
        try:
            value = float(val)
        except ValueError:
            sep = ""
        if not sep or not key:
            raise FitError(f"{option} {it!r}: use NAME=VALUE with a number; fix: e.g. {option} L0=70")
        if key in out:   # (the last one won without a word)
            raise FitError(f"{option} names {key} twice ({out[key]:g} and {value:g}); fix: give it once")
        out[key] = value
    return out


def check_fix_and_init(held: Mapping[str, float], init: Mapping[str, float]) -> None:
    """Refuse a parameter both held (``--fix``) and given a start (``--init``): the start took the held value's place
    (``--fix E_t=28 --init E_t=40`` held E_t at 40 and wrote it so)."""
    both = [n for n in init if n in held]
    if both:
        n = both[0]
        raise FitError(f"--fix {n}={held[n]:g} and --init {n}={init[n]:g} both name {n}: a held parameter has no "
                       f"start; fix: drop --init {n}=... to hold it at {held[n]:g}, or drop --fix {n}=... to fit it "
                       f"from {init[n]:g}")


def parse_fix(items: Iterable[str], model: JointModel | None = None) -> dict[str, float]:
    """``--fix NAME=VALUE`` items -> ``{name: value}``; with ``model``, each value within its parameter's bounds.

    Raises
    ------
    FitError
        A malformed item, or a value outside the bounds the parameter declares (named with its unit).
    """
    return parse_in_range(items, "--fix", model.param_specs if model is not None else None)


def parse_in_range(items: Iterable[str], option: str, specs: Mapping | None = None) -> dict[str, float]:
    """``NAME=VALUE`` items of ``option`` (``--fix``, ``--init``) -> ``{name: value}``: every value a finite number,
    and within the bounds of its parameter where ``specs`` (full name -> :class:`Param`) knows it.

    Raises
    ------
    FitError
        A malformed item, a value that is not finite, or one outside its parameter's bounds (named with its unit).
    """
    out = parse_assignments(items, option)
    for name, value in out.items():
        sp = (specs or {}).get(name.split("@")[0])
        if sp is not None and not (sp.lo <= value <= sp.hi and math.isfinite(value)):
            unit = f" {sp.unit}" if sp.unit else ""
            raise FitError(f"{option} {name}={value:g}: outside the range {name} can take, {sp.lo:g}..{sp.hi:g}{unit}; "
                           "fix: give a value in that range")
        if not math.isfinite(value):
            raise FitError(f"{option} {name}={value:g}: not a finite number; fix: give a number, e.g. {option} "
                           f"{name}=1")
    return out


def fitted_and_held(model: JointModel, fit_text: str | None, fix_items: Iterable[str],
                    base: Sequence[str] = ("E_t",), with_effects: bool = True) -> tuple[list[str], dict[str, float]]:
    """The parameters to fit and the ``--fix`` values to hold, consistent with each other.

    A parameter held with ``--fix`` leaves the default fitted set (``base``, and every effect
    parameter when ``with_effects``); naming it in an explicit ``--fit`` as well is a
    contradiction and refused.

    Returns
    -------
    (list of str, dict)
        Full names to fit; ``{name: value}`` held.
    """
    held = parse_fix(fix_items, model)
    if fit_text is None:
        default = fit_param_names(model, None, base) if with_effects else list(base)
        names = [n for n in default if n not in held]
    else:
        names = fit_param_names(model, fit_text)
        both = [n for n in names if n in held]
        if both:
            raise FitError(f"--fit and --fix both name {', '.join(both)}: a parameter is either fitted or held; "
                           f"fix: drop it from --fit to hold it, or drop --fix {both[0]}=... to fit it")
        if {"E_t", "L0"} <= set(names) and not any(e.source for e in model.effects):
            # (fitted together: E_t +- 9e5 GPa, correlation 1, exit 0 and a JSON a synthesis took as a calibration)
            raise FitError("--fit names both E_t and L0, which enter the model only as L0 / E_t (the tendon's "
                           "compliance): together neither is determined; fix: fit one of them and hold the other at its "
                           "measured value (the pattern's tendon length, or --fix L0=VALUE)")
    return names, held


def check_init_fitted(init: Mapping[str, float], varying: Sequence[str]) -> None:
    """Refuse an ``--init`` for a parameter that is not fitted: the start of a held parameter became its held value
    (``--init L0=50`` held L0 at 50 and moved E_t by 29 %), and a sample's copy of a parameter not fitted per sample was
    ignored."""
    for name in init:
        if name in varying:
            continue
        base, _, smp = name.partition("@")
        if smp and base in varying:
            raise FitError(f"--init {name}: {base} is not fitted per sample, so it has no copy for sample {smp}; fix: "
                           f"add --per-sample {base.split('.')[0] if '.' in base else base}, or give --init "
                           f"{base}=VALUE")
        raise FitError(f"--init {name}: {base} is not fitted (--init starts a fitted parameter); fix: add it to "
                       f"--fit to fit it from that value, or hold it there with --fix {name}=VALUE")


def build_registry(effect_files: Iterable[str] = ()) -> tuple[Registry, tuple]:
    """The built-in registry plus the effects of ``effect_files``; also the files' effects."""
    return registry_with_files(effect_files)


def build_model(pattern, effects: str | Sequence[str] = "", effect_files: Iterable[str] = (),
                registry: Registry | None = None) -> JointModel:
    """JointModel of ``pattern`` with ``effects`` (comma list or names) from the built-ins plus ``effect_files``."""
    from camtube.model.core.predict import model_for_pattern

    if registry is None:
        registry, _ = build_registry(effect_files)
    names = split_names(effects) if isinstance(effects, str) else list(effects)
    return model_for_pattern(pattern, [registry.get_effect(n) for n in names])


def history_warning(model: JointModel, branch: str, n_cycles: int, fitted: Sequence[str]) -> str:
    """A warning when a history effect is fitted on rows that cannot identify it (one branch or one cycle).

    Returns an empty string when the selection is fine.
    """
    hist = [e for e in model.effects if e.history and any(n in fitted for n in e.full_names())]
    if not hist:
        return ""
    why = []
    if branch != "both":
        why.append(f"only the {branch} branch")
    if n_cycles < 2:
        why.append("a single cycle")
    if not why:
        return ""
    return (f"warning: {', '.join(e.name for e in hist)} depend(s) on the history of the motion, but the fit uses "
            f"{' and '.join(why)}: the parameters may be unidentifiable (infinite standard errors); "
            "use --cycles all --branch both --no-deadband (the rows camtube model diagnose uses)")


def check_suffix(path: str | None, suffixes: tuple[str, ...], option: str) -> None:
    """Refuse an output file whose suffix does not match the format written to it.

    Raises
    ------
    DataError
        Naming the option, the path and the suffix to use.
    """
    from pathlib import Path

    from camtube.errors import DataError

    if path is None:
        return
    p = Path(path)
    if p.is_dir():  # also '.', '/' and '..', whose file name is empty
        raise DataError(f"{option} {path}: is a directory; fix: name a file, e.g. {option.split('/')[-1]} "
                        f"{p / ('out' + suffixes[0])}")
    if p.suffix.lower() not in suffixes:
        stem = p.stem if p.stem not in ("", ".", "..") else "out"
        raise DataError(f"{option} {path}: writes {suffixes[0][1:].upper()}, so the file must end in "
                        f"{' or '.join(suffixes)} (got {p.suffix or 'no suffix'!r}); "
                        f"fix: e.g. {option.split('/')[-1]} {stem}{suffixes[0]}")
    # a folder on the way that is a file: found before the fit or the diagnosis runs, not once it has printed its
    # whole report (--json base.csv/x.json)
    for parent in p.parents:
        if parent.exists() or parent.is_symlink():
            if not parent.is_dir():
                raise DataError(f"{option} {path}: {parent} is a file, not a folder; fix: write the output elsewhere, "
                                "or rename that file")
            break
