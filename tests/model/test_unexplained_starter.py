"""Starter effect files from the ``unexplained`` section: they run as written, start where the analysis
found the effect, and (for a periodic drive error from the independent simulator) bring the error to the
noise floor and lead the diagnosis's ranking without start values given by hand.
"""
from __future__ import annotations

import argparse
import importlib.util
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from camtube.errors import DataError
from camtube.model.data.dataset import Dataset
from camtube.model.unexplained import analyse, variables_of
from camtube.commands.effect import register_effect_commands
from camtube.model.unexplained.starter import starter_from_json, starter_source

ROOT = Path(__file__).resolve().parents[2]


def _module(path: Path, name: str):
    spec = importlib.util.spec_from_file_location(name, path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    spec.loader.exec_module(mod)
    return mod


GEN = _module(ROOT / "examples/foreign_effects/generate.py", "foreign_generate_starter")


def _effect_from(text: str, tmp_path: Path, name: str):
    """Import a written starter file without touching the process-wide effect registry."""
    from camtube.model.api import Effect

    f = tmp_path / f"{name}.py"
    f.write_text(text, encoding="utf-8")
    mod = _module(f, f"starter_{name}")
    effs = [v for v in vars(mod).values() if isinstance(v, Effect)]
    assert len(effs) == 1
    return effs[0]


def _setup(effect: str, params: dict | None, seed: int):
    from camtube.design.loader import load_pattern
    from camtube.model.diagnose import noise_floor
    from camtube.model.core.fit import fit
    from camtube.model.core.predict import model_for_pattern, pattern_values

    rows, truth = GEN.simulate(effect, params, cycles=20, seed=seed, joint=GEN.Joint(rate_hz=20.0))
    data = Dataset(rows["sample"], rows["cycle"].astype(int), rows["time"], rows["stroke"], rows["force"],
                   rows["angle"])
    pattern = load_pattern(ROOT / "patterns" / "tube2.yaml")
    base = fit(model_for_pattern(pattern), data, ("E_t",), pattern_values(pattern))
    floor = noise_floor(data, base.residuals)
    return data, pattern, floor, analyse(base.residuals, variables_of(data), floor), truth


@pytest.mark.parametrize("effect,params,seed,key", [
    ("drive", {"period_mm": 0.7, "amp_mm": 0.018, "phase_rad": 2.0}, 21, "period_mm"),
    ("oscillation", {"period_s": 29.0}, 22, "period_s"),
])
def test_periodic_starter_reaches_the_floor_and_leads(effect, params, seed, key, tmp_path):
    from camtube.model.api import registry
    from camtube.model.diagnose import diagnose
    from camtube.model.core.fit import fit
    from camtube.model.core.predict import model_for_pattern, pattern_values

    data, pattern, floor, u, truth = _setup(effect, params, seed)
    assert u is not None
    eff = _effect_from(starter_source("found", u), tmp_path, f"found_{effect}")
    assert eff.stage == "stroke"
    model = model_for_pattern(pattern, [eff])
    names = ("E_t",) + tuple(n for n in model.param_specs if n.startswith("found."))
    r = fit(model, data, names, pattern_values(pattern))
    assert r.rmse <= 1.15 * truth.sensor_floor_deg
    true_period = params[key]
    fitted_period = next(v for n, v in r.params.items() if n.startswith("found.period"))
    assert abs(fitted_period / true_period - 1.0) < 0.01
    amp = math.hypot(r.params["found.sin_deg"], r.params["found.cos_deg"])
    amp_true = math.degrees(params.get("amp_mm", GEN.DEFAULTS[effect]["amp_mm"]) / GEN.Joint().arm_mm)
    assert abs(amp / amp_true - 1.0) < 0.1
    # the diagnosis, with every built-in and the starter as candidates, starts from the file's values
    d = diagnose(model_for_pattern(pattern), data, ("E_t",), pattern_values(pattern),
                 candidates=list(registry().values()) + [eff])
    assert d.recommended[:1] == ("found",)
    assert d.final.rmse_deg <= 1.15 * d.noise_floor_deg


def test_starter_for_each_variable_runs(tmp_path):
    from camtube.design.loader import load_pattern
    from camtube.model.core.predict import model_for_pattern, pattern_values

    rows, _ = GEN.simulate("none", cycles=3, seed=1, joint=GEN.Joint(rate_hz=10.0))
    data = Dataset(rows["sample"], rows["cycle"].astype(int), rows["time"], rows["stroke"], rows["force"],
                   rows["angle"])
    pattern = load_pattern(ROOT / "patterns" / "tube2.yaml")
    for var in ("stroke", "angle", "force", "direction", "cycle", "first_cycle", "time", "sample"):
        for shape in ("linear", "quadratic", "step", "saturating"):
            u = {"leading": var, "follows": [var], "periodic": [], "shape": shape, "size_deg": 0.8,
                 "range": [0.0, 2.0], "samples": ["S1"]}
            eff = _effect_from(starter_source(f"e_{var}_{shape}", u), tmp_path, f"e_{var}_{shape}")
            m = model_for_pattern(pattern, [eff])
            vals = m.initial_values(data, pattern_values(pattern))
            for name, spec in m.param_specs.items():   # a term of every parameter's upper bound still predicts
                if name.startswith("e_"):
                    vals[name] = spec.hi
            out = m.predict(data, vals)
            assert out.shape == (len(data),) and np.all(np.isfinite(out)), (var, shape)


def test_cli_writes_a_starter_from_a_diagnosis_json(tmp_path, capsys):
    u = {"leading": "stroke", "follows": ["stroke"], "stage": "stroke", "shape": "periodic", "size_deg": 2.0,
         "range": [0.0, 2.5], "samples": ["S1", "S2"], "sentence": "periodic in the motor stroke",
         "periodic": [{"variable": "stroke", "period": 0.5, "unit": "mm", "amplitude_deg": 0.9, "phase_rad": 0.3}]}
    diag = tmp_path / "diag.json"
    diag.write_text(json.dumps({"schema": "camtube.diagnose/1", "unexplained": u}), encoding="utf-8")
    ap = argparse.ArgumentParser()
    register_effect_commands(ap.add_subparsers())
    out = tmp_path / "drive_error.py"
    args = ap.parse_args(["effect", "new", "drive_error", "--from", str(diag), "-o", str(out)])
    assert args.func(args) == 0
    assert "wrote" in capsys.readouterr().out
    eff = _effect_from(out.read_text(encoding="utf-8"), tmp_path, "drive_error_cli")
    p = {q.name: q for q in eff.params}
    assert eff.stage == "stroke" and p["period_mm"].lo < 0.5 < p["period_mm"].hi
    assert math.isclose(math.hypot(p["sin_deg"].init, p["cos_deg"].init), 0.9, rel_tol=1e-4)
    with pytest.raises(DataError):       # the file exists
        args.func(args)
    with pytest.raises(DataError):
        starter_from_json("x", tmp_path / "missing.json")
    nothing = tmp_path / "nothing.json"
    nothing.write_text(json.dumps({"unexplained": None}), encoding="utf-8")
    with pytest.raises(DataError, match="nothing unexplained"):
        starter_from_json("x", nothing)
    with pytest.raises(DataError, match="identifier"):
        starter_source("not a name", u)
    with pytest.raises(DataError, match="kinematics"):
        starter_source("arm", None, follows="angle", stage="stroke")
    # --stage and --follows without a diagnosis
    args = ap.parse_args(["effect", "new", "arm2", "--follows", "angle", "-o", str(tmp_path / "arm2.py")])
    assert args.func(args) == 0
    assert _effect_from((tmp_path / "arm2.py").read_text(), tmp_path, "arm2").stage == "kinematics"


@pytest.mark.parametrize("argv", [["--follows", "stroke"], ["--from", "{diag}", "--follows", "stroke"]],
                         ids=["follows", "from"])
@pytest.mark.parametrize("name", ["slack", "force_zero"])
def test_a_built_in_effect_name_is_refused_before_anything_is_written(tmp_path, capsys, name, argv):
    """``model effect new slack --follows stroke`` wrote slack.py (exit 0), which ``model fit --effect-file`` then
    refused: 'two different effects are named 'slack' (built-in and slack.py)'."""
    from camtube.commands import main
    from camtube.model import EFFECT_NAMES
    from camtube.model.effects import BUILTINS

    assert name in EFFECT_NAMES and name in BUILTINS
    diag = tmp_path / "diag.json"
    diag.write_text(json.dumps({"schema": "camtube.diagnose/1", "unexplained": None}), encoding="utf-8")
    out = tmp_path / f"{name}.py"
    argv = [a.replace("{diag}", str(diag)) for a in argv]
    assert main(["model", "effect", "new", name, *argv, "-o", str(out)]) == 2
    lines = [x for x in capsys.readouterr().err.splitlines() if x.strip()]
    assert len(lines) == 1 and f"effect name '{name}': {name} is a built-in effect" in lines[0], lines
    assert f"fix: choose another name, e.g. my_{name}" in lines[0]
    assert not out.exists()
    with pytest.raises(DataError, match="built-in effect"):
        starter_source(name, None, follows="stroke")
