"""A starter effect file from what the diagnosis found unexplained.

``starter_source(name, unexplained=None, *, stage=None, follows=None) -> str`` returns the text of a
``.py`` file that runs as written with ``--effect-file`` (the effect API of ``docs/diagnose.md``):
an :class:`~camtube.model.api.Effect` on the right stage, reading the signal it follows, with a
term of the shape that was found (periodic, step, linear, quadratic, saturating) whose parameters
start from, and are bounded around, what the analysis measured (the period, the amplitude, the
size). The user then replaces the term by the physics; the plumbing is done.

``starter_from_json(name, path, stage=None, follows=None)`` reads a diagnosis JSON written with
``camtube model diagnose --json`` and uses its ``unexplained`` section.

Units of the term, per stage (``residual = measured - model``, so a positive term raises the model):
``stroke`` mm (deg -> mm: x arm), ``elongation`` mm (opposite sign), ``kinematics`` rad,
``angle`` deg, ``force`` N (via the tendon compliance).
"""
from __future__ import annotations

import json
import keyword
import math
import re
from pathlib import Path

from camtube.errors import DataError
from camtube.inputfile import parse_json, read_input_text
from camtube.model import EFFECT_NAMES
from camtube.model.unexplained.analysis import HINTS, LABELS, VARIABLES

STAGES = ("force", "stroke", "elongation", "kinematics", "angle")
#: The signal each stage transforms, its name in ``apply`` and its unit.
SIGNAL = {"force": ("force_N", "N"), "stroke": ("stroke_mm", "mm"), "elongation": ("elongation_mm", "mm"),
          "kinematics": ("theta_rad", "rad"), "angle": ("angle_deg", "deg")}
#: Default stage per variable (when the diagnosis does not say).
DEFAULT_STAGE = {"stroke": "stroke", "time": "stroke", "cycle": "stroke", "first_cycle": "stroke",
                 "direction": "stroke", "force": "elongation", "angle": "kinematics", "sample": "angle"}

# how each variable is read inside apply(ctx, signal, p)
_READ = {
    "stroke": "x = np.asarray(ctx.data.stroke_mm, float)       # motor stroke, mm",
    "time": "x = np.asarray(ctx.data.time_s, float)          # s since the sample's start",
    "cycle": "x = np.asarray(ctx.data.cycle, float)           # cycle number",
    "first_cycle": "x = ctx.first_cycle.astype(float)               # 1 in each sample's first cycle, else 0",
    "direction": "x = np.asarray(ctx.direction, float)           # +1 loading, -1 unloading",
    "force": "x = np.asarray(ctx.force_N, float)             # tendon force after the force stage, N",
    "sample": "x = np.isin(ctx.data.sample, SAMPLES).astype(float)  # 1 in the samples that carry it",
}
_X_UNIT = {"stroke": "mm", "time": "s", "cycle": "", "first_cycle": "", "direction": "", "force": "N",
           "angle": "rad", "sample": ""}


def _to_stage(stage: str) -> str:
    """Body of ``_to_stage(ctx, deg)``: a size in degrees of bend -> the stage's unit (residual = measured - model)."""
    return {"stroke": "return np.radians(deg) * ctx.geometry.moment_arm_mm       # mm of stroke",
            "elongation": "return -np.radians(deg) * ctx.geometry.moment_arm_mm      # mm less elongation",
            "kinematics": "return np.radians(deg)                                    # rad",
            "angle": "return deg                                               # deg",
            "force": "return -np.radians(deg) * ctx.geometry.moment_arm_mm / ctx.compliance_mm_per_N  # N"}[stage]


def _ident(name: str) -> str:
    """``name`` if it can name a new effect: a Python identifier that is not a built-in effect's name (which
    ``--effect-file`` refuses: 'two different effects are named ...')."""
    if not re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name or "") or keyword.iskeyword(name):
        raise DataError(f"effect name {name!r}: not a Python identifier (letters, digits and _, not starting "
                        "with a digit); fix: e.g. drive_error")
    if name in EFFECT_NAMES:
        raise DataError(f"effect name {name!r}: {name} is a built-in effect, and --effect-file refuses a file "
                        f"defining another effect of that name; fix: choose another name, e.g. my_{name}")
    return name


def _num(x: float) -> str:
    return repr(float(f"{x:.6g}"))


def starter_source(name: str, unexplained: dict | None = None, *, stage: str | None = None,
                   follows: str | None = None) -> str:
    """Text of a runnable effect file for effect ``name`` (see the module docstring).

    Parameters
    ----------
    name : str
        Effect name (a Python identifier).
    unexplained : dict, optional
        A diagnosis's ``unexplained`` section (:func:`camtube.model.unexplained.analyse`).
    stage : str, optional
        Stage to act on (default: what the section suggests, else by the variable).
    follows : str, optional
        Variable the effect follows (default: the section's leading variable).
    """
    _ident(name)
    u = dict(unexplained or {})
    var = follows or u.get("leading") or (u.get("follows") or [None])[0]
    if var is None:
        raise DataError("no variable to follow; fix: give --follows VARIABLE (one of " + ", ".join(VARIABLES)
                        + ") or a diagnosis JSON whose 'unexplained' section names one")
    if var not in VARIABLES:
        raise DataError(f"--follows {var!r}: not a variable; fix: use one of {', '.join(VARIABLES)}")
    per = next((p for p in u.get("periodic") or [] if p.get("variable") == var), None)
    stage = stage or (u.get("stage") if u.get("leading") == var and u.get("stage") else None) \
        or DEFAULT_STAGE[var]
    if stage not in STAGES:
        raise DataError(f"--stage {stage!r}: not a stage; fix: use one of {', '.join(STAGES)}")
    if var == "angle" and stage not in ("kinematics", "angle"):
        raise DataError(f"--stage {stage} with --follows angle: the angle is known only from the kinematics stage "
                        "on; fix: use --stage kinematics (or angle)")
    shape = "periodic" if per else (u.get("shape") if u.get("leading") == var and u.get("shape") else
                                    ("step" if var in ("first_cycle", "direction", "sample") else "linear"))
    sig, _ = SIGNAL[stage]
    size_deg = float(u.get("size_deg") or (2 * per["amplitude_deg"] if per else 1.0))
    size_deg = max(abs(size_deg), 1e-3)
    physics, _ = HINTS.get((var, per is not None), HINTS.get((var, False), ("", "")))
    lo, hi = (u.get("range") or [None, None]) if u.get("leading") == var else (None, None)
    if var == "angle" and lo is not None:
        lo, hi = math.radians(lo), math.radians(hi)
    span = (hi - lo) if lo is not None and hi > lo else 1.0
    x0 = lo if lo is not None else 0.0

    params: list[str] = []
    read = _READ.get(var, "")
    if var == "angle":
        read = ("x = theta_rad                                    # bend angle, rad" if stage == "kinematics"
                else "x = np.radians(angle_deg)                        # bend angle, rad")
    xu = _X_UNIT[var]
    b4 = _num(4 * size_deg)
    if per:
        period, amp, phase = float(per["period"]), float(per["amplitude_deg"]), float(per.get("phase_rad", 0.0))
        pu = per.get("unit", xu)
        pname = f"period_{pu}" if pu else "period"
        body = (f'w = 2.0 * np.pi * x / p["{pname}"]\n'
                f'    term_deg = p["sin_deg"] * np.sin(w) + p["cos_deg"] * np.cos(w)')
        bound = _num(3.0 * amp + 0.05)
        params += [
            f'Param("sin_deg", "deg", -{bound}, {bound}, {_num(amp * math.cos(phase))}, '
            f'"sine part (found: {amp:.3g} deg in all, phase {phase:.2f} rad)")',
            f'Param("cos_deg", "deg", -{bound}, {bound}, {_num(amp * math.sin(phase))}, "cosine part")',
            f'Param("{pname}", "{pu}", {_num(0.9 * period)}, {_num(1.1 * period)}, {_num(period)},\n'
            f'              "period against {LABELS[var]} (found: {period:.4g} {pu}; the fit is multimodal in the '
            f'period: keep its bounds near the value found)",\n'
            f'              starts=({_num(0.97 * period)}, {_num(period)}, {_num(1.03 * period)}))',
        ]
    elif shape == "step" or var in ("first_cycle", "direction", "sample"):
        body = 'term_deg = p["step_deg"] * x'
        if var == "first_cycle":
            body = 'term_deg = p["step_deg"] * (1.0 - x)      # from the end of the first cycle on'
        params.append(f'Param("step_deg", "deg", -{b4}, {b4}, 0.0, "size of the step (found: about {size_deg:.3g} deg)")')
    elif shape == "saturating":
        body = f'term_deg = p["size_deg"] * -np.expm1(-(x - {_num(x0)}) / p["scale"])'
        params += [f'Param("size_deg", "deg", -{b4}, {b4}, 0.0, "size reached (found: about {size_deg:.3g} deg)")',
                   f'Param("scale", "{xu}", {_num(0.01 * span)}, {_num(3 * span)}, {_num(0.2 * span)},\n'
                   f'              "over how much of {LABELS[var]} it saturates")']
    else:  # linear or quadratic in the variable, over the range found
        body = (f'u = (x - {_num(x0)}) / {_num(span)}            # 0 .. 1 over the range found\n'
                f'    term_deg = p["k1_deg"] * u')
        b20 = _num(20 * size_deg)  # the linear part trades with the fitted base parameters: wide bounds
        params.append(f'Param("k1_deg", "deg", -{b20}, {b20}, 0.0, "linear part over the range of {LABELS[var]}")')
        if shape == "quadratic":
            body += ' + p["k2_deg"] * u * u'
            params.append(f'Param("k2_deg", "deg", -{b20}, {b20}, 0.0, '
                          f'"quadratic part (found: about {size_deg:.3g} deg)")')

    if stage == "stroke":
        ret = "return np.maximum(stroke_mm + _to_stage(ctx, term_deg), 0.0)   # a tendon cannot push"
    else:
        ret = f"return {sig} + _to_stage(ctx, term_deg)"
    helpers = ""
    samples_line = ""
    if var == "sample":
        # a step between samples: every sample but the first (a shared offset is the built-in angle_bias)
        names = list(u.get("per_sample_rmse_deg") or {}) or list(u.get("samples") or [])
        samples_line = (f"\n#: samples offset against the first one ({names[0] if names else '?'}); "
                        f"the diagnosis found it carried by {list(u.get('samples') or [])!r}\n"
                        f"SAMPLES = {names[1:]!r}\n")
    found = u.get("sentence") or f"the residual follows {LABELS[var]}"
    stage_doc = {"stroke": "the stroke that reaches the tendon (mm), from the motor stroke",
                 "elongation": "the tendon's elongation (mm); ctx.force_N is the force",
                 "kinematics": "the bend angle (rad) from the tendon length; ctx.l_kin_mm, ctx.arm_mm are set",
                 "angle": "the measured angle (deg)", "force": "the force (N) before it is used"}[stage]
    plist = ",\n        ".join(params)
    return f'''"""Starter effect {name!r}, written by `camtube model effect new` from a diagnosis.

Found: {found}.
Stage: {stage}: apply(ctx, {sig}, p) returns {stage_doc}.
Shape: {shape} in {LABELS[var]}; the parameters start from, and are bounded around, what was found.
Sizes are in degrees of bend (what the residual showed); _to_stage turns them into this stage's unit.

Replace the term in _apply by the physics (keep the signature), then

    camtube model diagnose DATA.csv --pattern PATTERN --effect-file {name}.py

Signals in apply: ctx.data (rows per sample in time order: ctx.data.sample_slices()),
ctx.data.stroke_mm / time_s / cycle / sample, ctx.force_N, ctx.direction (+1 loading), ctx.first_cycle,
ctx.peak_force_N (largest force so far), ctx.time_since_reversal_s, ctx.compliance_mm_per_N,
ctx.geometry (moment_arm_mm, ...); at kinematics also ctx.l_kin_mm, ctx.arm_mm (theta = l_kin / arm).
"""
from __future__ import annotations

import numpy as np

from camtube.model.api import Effect, Param
{samples_line}

def _to_stage(ctx, deg):
    {_to_stage(stage)}
{helpers}

def _apply(ctx, {sig}: np.ndarray, p: dict) -> np.ndarray:
    {read}
    {body}
    {ret}


{name.upper()} = Effect(
    name={name!r},
    stage={stage!r},
    params=(
        {plist},
    ),
    apply=_apply,
    meaning={(physics or "a physical effect the library does not ship")!r},
    signature={("the residual " + ("is periodic in " if per else "follows ") + LABELS[var])!r},
)
'''


def starter_from_json(name: str, path: str | Path, *, stage: str | None = None,
                      follows: str | None = None) -> str:
    """:func:`starter_source` from a diagnosis JSON file's ``unexplained`` section."""
    _ident(name)  # a name that cannot be used is refused before the file is read
    path = Path(path)
    try:
        doc = parse_json(read_input_text(path))
    except FileNotFoundError:
        raise DataError(f"{path}: no such diagnosis file; fix: write one with camtube model diagnose ... --json "
                        f"{path.name}") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise DataError(f"{path}: not a diagnosis JSON ({exc}); fix: give the file camtube model diagnose "
                        "... --json wrote") from None
    if not isinstance(doc, dict) or "unexplained" not in doc:
        raise DataError(f"{path}: no 'unexplained' section; fix: write it with this version of camtube model "
                        f"diagnose --json, or give --stage and --follows")
    u = doc["unexplained"]
    if u is None and follows is None:
        raise DataError(f"{path}: the diagnosis left nothing unexplained (unexplained: null); fix: give --follows to "
                        f"start an effect anyway")
    redo = ("fix: write it again with camtube model diagnose ... --json, or give --stage and --follows instead of "
            "--from")
    if u is not None and not isinstance(u, dict):
        raise DataError(f"{path}: the 'unexplained' section is {type(u).__name__} {u!r:.40}, not the mapping camtube "
                        f"model diagnose writes; {redo}")
    try:
        return starter_source(name, u, stage=stage, follows=follows)
    except (TypeError, ValueError, KeyError, AttributeError, IndexError) as exc:  # an edited section's values
        raise DataError(f"{path}: the 'unexplained' section does not read as camtube model diagnose writes it "
                        f"({type(exc).__name__}: {exc}); {redo}") from None
