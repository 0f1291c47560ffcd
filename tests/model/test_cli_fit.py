"""Smoke tests of ``camtube model synth`` and ``camtube model fit`` (files read back independently)."""
from __future__ import annotations

import csv
import json

import pytest

from camtube.commands import build_parser, main
from camtube.model.sim.synth import noise_floor_deg
from tests.conftest import PATTERNS

TUBE2 = str(PATTERNS / "tube2.yaml")


@pytest.fixture(scope="module")
def data_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("m") / "d.csv"
    assert main(["model", "synth", "--pattern", TUBE2, "-o", str(path), "--cycles", "6", "-q"]) == 0
    return path


def test_synth_writes_a_csv_the_csv_module_reads(data_csv):
    with open(data_csv, newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["sample", "cycle", "time_s", "stroke_mm", "force_N", "angle_deg"]
    assert {r["sample"] for r in rows} == {"1", "2"}
    assert {int(r["cycle"]) for r in rows} == set(range(1, 7))
    assert max(float(r["stroke_mm"]) for r in rows) == pytest.approx(2.5, abs=0.02)


def test_fit_prints_table_and_writes_json_and_plot(data_csv, tmp_path, capsys):
    js, png = tmp_path / "f.json", tmp_path / "f.png"
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--json", str(js), "--plot", str(png)]) == 0
    out = capsys.readouterr().out
    assert "RMSE deg" in out and "E_t" in out and "GPa" in out
    doc = json.loads(js.read_text())
    assert set(doc["per_sample"]) == {"1", "2"}
    assert doc["params"]["E_t"]["unit"] == "GPa" and doc["params"]["E_t"]["stderr"] > 0
    assert abs(doc["params"]["E_t"]["value"] - 28.0) < 0.84
    from camtube.design.loader import load_pattern

    assert doc["rmse_deg"] == pytest.approx(noise_floor_deg(load_pattern(TUBE2)), rel=0.2)
    assert doc["n_points"] > 300
    import matplotlib.image as mpimg

    img = mpimg.imread(png)
    assert img.ndim == 3 and img.shape[0] > 300 and img.shape[1] > 600


def test_fit_options_cycles_branch_fit_and_fix(data_csv, tmp_path):
    js = tmp_path / "g.json"
    argv = ["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--cycles", "2-", "--branch", "both",
            "--fit", "E_t,arm_scale", "--fix", "L0=70", "--json", str(js)]
    assert main(argv) == 0
    doc = json.loads(js.read_text())
    assert doc["params"]["arm_scale"]["fitted"] and doc["correlation"]["names"] == ["E_t", "arm_scale"]
    assert doc["selection"] == {"cycles": "2-", "branch": "both", "deadband": True}


def test_user_effect_file_and_effects(data_csv, tmp_path, capsys):
    f = tmp_path / "my_effect.py"
    f.write_text(
        "from camtube.model.api import Effect, Param\n"
        "zero = Effect('cli_test_zero', 'angle', (Param('bias_deg', 'deg', -5, 5, 0.0),),\n"
        "              lambda ctx, a, p: a + p['bias_deg'])\n"
    )
    js = tmp_path / "h.json"
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--effect-file", str(f),
                 "--effects", "cli_test_zero", "--fit", "E_t,cli_test_zero.bias_deg", "--json", str(js)]) == 0
    doc = json.loads(js.read_text())
    assert doc["effects"] == ["cli_test_zero"]
    assert abs(doc["params"]["cli_test_zero.bias_deg"]["value"]) < 0.2


@pytest.mark.parametrize("extra, words", [
    (["--effects", "no_such_effect"], "unknown effect"),
    (["--fit", "E_T"], "did you mean 'E_t'"),
    (["--cycles", "lats"], "cycle selection"),
    (["--fix", "L0"], "NAME=VALUE"),
])
def test_bad_options_exit_2_with_a_message(data_csv, capsys, extra, words):
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q"] + extra) == 2
    assert words in capsys.readouterr().err


def test_bad_csv_exit_2_with_line(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("sample,cycle,time_s,stroke_mm,force_N,angle_deg\nA,1,0,0,0,0\nA,1,1,x,0,0\n")
    assert main(["model", "fit", str(bad), "--pattern", TUBE2, "-q"]) == 2
    assert f"{bad}:3:" in capsys.readouterr().err


def test_model_group_lists_its_subcommands():
    parser = build_parser()
    text = [a for a in parser._subparsers._group_actions][0].choices["model"].format_help()
    assert "fit" in text and "synth" in text


def test_fit_per_sample_init_and_starts(data_csv, tmp_path, capsys):
    js = tmp_path / "p.json"
    argv = ["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--cycles", "all", "--branch", "both",
            "--no-deadband", "--effects", "slack", "--per-sample", "slack", "--init", "slack.deadband_mm@2=0.06",
            "--starts", "3", "--json", str(js)]
    assert main(argv) == 0
    doc = json.loads(js.read_text())
    for s in ("1", "2"):
        prm = doc["params"][f"slack.deadband_mm@{s}"]
        assert prm["fitted"] and abs(prm["value"] - 0.05) < 0.005 and prm["stderr"] > 0
    assert not doc["params"]["slack.deadband_mm"]["fitted"]
    # the same options give the same numbers
    js2 = tmp_path / "p2.json"
    assert main(argv[:-1] + [str(js2)]) == 0
    assert json.loads(js2.read_text())["params"] == doc["params"]
    capsys.readouterr()
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--init", "E_t"]) == 2
    assert "--init 'E_t'" in capsys.readouterr().err
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--effects", "slack",
                 "--per-sample", "slak"]) == 2


@pytest.mark.parametrize("spike_mm", [50.0, 1e6])
def test_a_stroke_that_jumps_for_one_row_is_named_or_set_aside(data_csv, tmp_path, capsys, spike_mm):
    """The bad-input search: a stroke of 50 mm for one row was fitted as is (E_t at its bound); one of 1e6 mm was
    called 'a stroke logged in um: divide it by 1000'. The row is named (sample, cycle, time); --set-aside sets it
    aside and the fit is the clean file's."""
    rows = list(csv.reader(open(data_csv, newline="")))
    k = 40
    t = rows[k][rows[0].index("time_s")]
    rows[k][rows[0].index("stroke_mm")] = f"{spike_mm:g}"
    bad = tmp_path / "spike.csv"
    with open(bad, "w", newline="") as fh:
        csv.writer(fh).writerows(rows)
    assert main(["model", "fit", str(bad), "--pattern", TUBE2, "-q", "--cycles", "all"]) == 2
    err = capsys.readouterr().err
    assert f"t = {float(t):g} s: stroke_mm jumps to {spike_mm:g} mm for one row" in err and "reads like" not in err, err
    assert "fix: correct or delete that line, or add --set-aside" in err
    j_bad, j_clean = tmp_path / "bad.json", tmp_path / "clean.json"
    assert main(["model", "fit", str(bad), "--pattern", TUBE2, "-q", "--cycles", "all", "--set-aside",
                 "--json", str(j_bad)]) == 0
    assert "1 stroke spike" in capsys.readouterr().out
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--cycles", "all", "--set-aside",
                 "--json", str(j_clean)]) == 0
    e_bad, e_clean = (json.loads(p.read_text())["params"]["E_t"]["value"] for p in (j_bad, j_clean))
    assert e_bad == pytest.approx(e_clean, rel=0.01)
