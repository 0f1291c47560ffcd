"""The ``unexplained`` section of a diagnosis report (text, JSON, HTML), from a :class:`Diagnosis`.

The diagnosis report (:mod:`camtube.model.report.diagnosis`) calls these three hooks;
the analysis runs once per diagnosis (kept in the diagnosis's own cache).
"""
from __future__ import annotations

import html
import math

from camtube.model.unexplained.analysis import analyse, describe, variables_of

#: A name for the starter effect, by what the residual follows.
NAMES = {("stroke", True): "drive_error", ("time", True): "tendon_oscillation", ("angle", False): "arm_change",
         ("first_cycle", False): "first_cycle_set", ("cycle", False): "cycle_drift", ("time", False): "drift",
         ("stroke", False): "stroke_loss", ("force", False): "tendon_law", ("direction", False): "hysteresis",
         ("sample", False): "sample_offset"}


def of_diagnosis(d) -> dict | None:
    """``unexplained`` of the diagnosis's final (or partial) model (``None`` when within 1.15 x the noise floor)."""
    cache = getattr(d, "cache", None)
    if cache is not None and "unexplained" in cache:
        return cache.get("unexplained")
    # the misfit no fitted effect explains: after the partial effects when there are some (they are fitted,
    # but not recommended because the error stays above the floor), else after the recommended ones
    steps = getattr(d, "partial_steps", ())
    residual = steps[-1].residuals if getattr(d, "partial", ()) and steps else d.final.residuals
    # the bend angle it is read against: the model's the diagnosis starts from (with its baseline), noise-free and
    # smooth in the stroke and force; a partial chain's may be flattened by an effect of the wrong form (a hardstop
    # took the angle's lead to the stroke on the arm that changes with the angle)
    u = analyse(residual, variables_of(d.data, d.waterfall[0].residuals), d.noise_floor_deg)
    if cache is not None:
        cache.set("unexplained", u)
    return u


def _clean(x):
    if isinstance(x, float):
        return x if math.isfinite(x) else None
    if isinstance(x, dict):
        return {str(k): _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    return x


def json_section(d) -> dict | None:
    """JSON-ready ``unexplained``: {share, follows, periodic [{variable, period, unit, amplitude_deg, ...}],
    shape, samples, ...} or ``None``."""
    u = of_diagnosis(d)
    return None if u is None else _clean(u)


def suggested_name(u: dict) -> str:
    lead = u.get("leading", "")
    per = any(p["variable"] == lead for p in u.get("periodic", []))
    return NAMES.get((lead, per), NAMES.get((lead, False), "my_effect"))


def text_lines(d, json_path: str = "DIAG.json") -> list[str]:
    """Lines of the text report (empty when nothing is left)."""
    u = of_diagnosis(d)
    if u is None:
        return []
    lines = describe(u)
    if u.get("drift"):
        lines.append(f"  it is below what the diagnosis counts as a misfit (the error within {u['stop_ratio']:g} x the "
                     "floor), so "
                     + (f"the explanation with {', '.join(d.recommended)} stays complete" if d.recommended else
                        "nothing is recommended for it")
                     + "; a drift of an instrument is corrected at the instrument, not added to the joint model")
    elif d.recommended and getattr(d, "explanation", "") == "partial":
        lines.append(f"  this is what is left with the recommended effects ({', '.join(d.recommended)}): they explain "
                     f"most of the misfit, the error stays at {d.final.rmse_deg / d.noise_floor_deg:.2f} x the floor")
    elif d.recommended:  # not reached by the diagnosis (a recommended chain is within 1.15 x the floor)
        lines.append(f"  note: with {', '.join(d.recommended)} the error stays at "
                     f"{d.final.rmse_deg / d.noise_floor_deg:.2f} x the floor; the recommended effect(s) may stand in "
                     f"for the physics above: try the starter effect without them")
    if getattr(d, "partial", ()):
        lines.append(f"  this is the misfit left with the partial effects ({', '.join(d.partial)}), which lower the "
                     "error without explaining it: "
                     + ("write the effect (start below) and diagnose again with it" if u.get("leading") else
                        "look at the rows named above before writing an effect (set aside what the instruments' "
                        "check missed, and diagnose again)" if u.get("rows") else
                        "look at the residual plots before writing an effect"))
    if u.get("leading"):
        lines.append(f"  start an effect for it: camtube model effect new {suggested_name(u)} --from {json_path}"
                     f"  (the diagnosis's --json file)")
    return lines


def html_section(d) -> str:
    """An HTML ``<h2>`` section (empty string when nothing is left)."""
    lines = text_lines(d)
    if not lines:
        return ""
    return ("<h2>Unexplained</h2>\n<p>What the final model's residual still follows (cross-validated smoothing "
            "per variable; Lomb-Scargle periods against stroke and time).</p>\n<pre>"
            + html.escape("\n".join(lines)) + "</pre>\n")
