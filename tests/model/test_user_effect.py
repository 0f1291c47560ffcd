"""A user's effect in their own .py file works exactly like a built-in one (examples/user_effect)."""
from __future__ import annotations

import importlib.util
import json

import pytest

from camtube.commands import main
from tests.conftest import PATTERNS, ROOT

EXAMPLE = ROOT / "examples" / "user_effect"


def _make_data():
    spec = importlib.util.spec_from_file_location("make_anchor_data", EXAMPLE / "make_data.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_user_effect_is_found_recommended_and_fitted(tmp_path, capsys):
    mod = _make_data()
    from camtube.model.data import format_csv

    csv = tmp_path / "slip.csv"
    csv.write_text(format_csv(mod.simulate()))
    pat = str(PATTERNS / "tube2.yaml")
    # without the user's effect: the built-ins leave an error above the noise floor
    out0 = tmp_path / "d0.json"
    assert main(["model", "diagnose", str(csv), "--pattern", pat, "-q", "--json", str(out0)]) == 0
    d0 = json.loads(out0.read_text())
    assert d0["waterfall"][-1]["rmse_deg"] > 1.2 * d0["noise_floor_deg"]
    # with it: ranked first, recommended alone, error at the noise floor, parameters recovered
    out1 = tmp_path / "d1.json"
    assert main(["model", "diagnose", str(csv), "--pattern", pat, "-q", "--json", str(out1),
                 "--effect-file", str(EXAMPLE / "anchor_slip.py")]) == 0
    d1 = json.loads(out1.read_text())
    assert d1["candidates"][0]["effect"] == "anchor_slip"
    assert d1["recommended"] == ["anchor_slip"]
    assert d1["final"]["rmse_deg"] < 1.1 * d1["noise_floor_deg"]
    prm = d1["final"]["params"]
    assert prm["anchor_slip.slip_mm"]["value"] == pytest.approx(mod.SLIP_MM, rel=0.1)
    assert prm["anchor_slip.force_N"]["value"] == pytest.approx(mod.F_SLIP_N, rel=0.15)
    assert prm["anchor_slip.scale_N"]["value"] == pytest.approx(mod.F_SCALE_N, rel=0.15)
    # the command it prints fits the same model
    cmd = d1["command"].split()
    fit_out = tmp_path / "fit.json"
    assert "--effect-file" in cmd and main(cmd[1:] + ["-q", "--json", str(fit_out)]) == 0
    assert json.loads(fit_out.read_text())["rmse_deg"] == pytest.approx(d1["final"]["rmse_deg"], rel=1e-3)
