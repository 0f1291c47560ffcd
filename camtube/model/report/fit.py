"""Text and JSON reports of a :class:`~camtube.model.core.fit.FitResult` (pure: return strings).

``rmse_table(result)``: per-sample RMSE like the paper's Table III;
``param_table(result)``: values with standard errors, units and correlations;
``fit_text(result, title="")``: both; ``fit_dict(result, meta=None)`` and
``fit_json(result, meta=None)``: the machine-readable summary (schema
``camtube.fit/1``: ``rmse_deg``, ``per_sample`` {sample: rmse_deg},
``params`` {name: {value, stderr, unit, fitted}}, ``n_points``, ``n_params``,
``aic``, ``bic``, ``correlation`` {names, matrix}, ``success``, ``message``,
plus whatever ``meta`` holds). Non-finite numbers are written as ``null``.
"""
from __future__ import annotations

import json
import math

import numpy as np

from camtube.model.core.fit import FitResult


def _num(x: float) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def _fmt(x: float, digits: int = 4) -> str:
    if not math.isfinite(x):
        return "inf" if x > 0 else ("-inf" if x < 0 else "nan")
    return f"{x:.{digits}g}"


def _names(result: FitResult) -> list[str]:
    """Every parameter name of the fit (per-sample copies after their shared name), held ones included."""
    if result.parameters is not None:
        return list(result.parameters.names)
    return list(result.model.param_specs)


def rmse_table(result: FitResult) -> str:
    """Per-sample RMSE (deg) and point counts, then the overall RMSE."""
    rows = [("sample", "points", "RMSE deg")]
    for smp, sl in result.data.sample_slices():
        rows.append((smp, str(sl.stop - sl.start), f"{result.rmse_per_sample[smp]:.3f}"))
    rows.append(("all", str(result.n_points), f"{result.rmse:.3f}"))
    w = [max(len(r[i]) for r in rows) for i in range(3)]
    out = [f"{r[0]:<{w[0]}}  {r[1]:>{w[1]}}  {r[2]:>{w[2]}}" for r in rows]
    out.insert(1, "-" * len(out[0]))
    out.insert(len(out) - 1, "-" * len(out[0]))
    return "\n".join(out)


def param_table(result: FitResult) -> str:
    """Every parameter: value, +- standard error (fitted) or ``held``, unit; then correlations."""
    rows = [("parameter", "value", "+- stderr", "unit", "")]
    for name in _names(result):
        v = result.params[name]
        if name in result.fitted:
            se = _fmt(result.stderr[name], 3)
            note = "at bound" if name in result.at_bound else "fitted"
        elif result.parameters is not None and any(n.startswith(name + "@") for n in result.fitted):
            se, note = "", "per sample below"
        else:
            se, note = "", "held"
        rows.append((name, _fmt(v, 6), se, result.units.get(name, ""), note))
    w = [max(len(r[i]) for r in rows) for i in range(5)]
    out = [f"{r[0]:<{w[0]}}  {r[1]:>{w[1]}}  {r[2]:>{w[2]}}  {r[3]:<{w[3]}}  {r[4]}".rstrip() for r in rows]
    p = len(result.fitted)
    if p > 1:
        out.append("correlations:")
        for i in range(p):
            for j in range(i + 1, p):
                c = result.correlation[i, j]
                flag = "  (nearly inseparable)" if math.isfinite(c) and abs(c) > 0.95 else ""
                out.append(f"  {result.fitted[i]} ~ {result.fitted[j]}: {_fmt(c, 3)}{flag}")
    out.append(f"n = {result.n_points} points, p = {result.n_params} fitted; "
               f"AIC {result.aic:.1f}, BIC {result.bic:.1f}")
    if not result.success:
        out.append(f"warning: the optimiser did not converge: {result.message}")
    return "\n".join(out)


def fit_text(result: FitResult, title: str = "") -> str:
    """RMSE table and parameter table, under an optional title line."""
    parts = [title] if title else []
    parts += [rmse_table(result), "", param_table(result)]
    return "\n".join(parts)


def fit_dict(result: FitResult, meta: dict | None = None) -> dict:
    """The JSON-ready summary of ``result`` (see the module docstring)."""
    out: dict = {"schema": "camtube.fit/1"}
    out.update(meta or {})
    out["rmse_deg"] = _num(result.rmse)
    out["per_sample"] = {k: _num(v) for k, v in result.rmse_per_sample.items()}
    out["params"] = {
        name: {
            "value": _num(result.params[name]),
            "stderr": _num(result.stderr[name]) if name in result.fitted else None,
            "unit": result.units.get(name, ""),
            "fitted": name in result.fitted,
        }
        for name in _names(result)
    }
    out["n_points"] = int(result.n_points)
    out["n_params"] = int(result.n_params)
    out["aic"] = _num(result.aic)
    out["bic"] = _num(result.bic)
    corr = np.asarray(result.correlation, float)
    out["correlation"] = {"names": list(result.fitted),
                          "matrix": [[_num(c) for c in row] for row in corr.tolist()]}
    out["effects"] = [e.name for e in result.model.effects]
    out["success"] = bool(result.success)
    out["message"] = result.message
    return out


def fit_json(result: FitResult, meta: dict | None = None) -> str:
    """``fit_dict`` as indented JSON text with a final newline (deterministic)."""
    return json.dumps(fit_dict(result, meta), indent=2, allow_nan=False) + "\n"
