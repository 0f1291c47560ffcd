"""The second tutorial of docs/diagnose.md, run as written: an effect the library lacks (a periodic
lead-screw error), the unexplained section finding it, the starter file, the user's edit, the error
falling to the noise floor. Independent truth: the simulator's period 0.5 mm and error 0.02 mm at phase 0.4.
"""
from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

from camtube.commands import main

ROOT = Path(__file__).resolve().parents[2]


def test_second_tutorial(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    # 1. data with an effect the library lacks (an independent numpy simulator)
    subprocess.run([sys.executable, str(ROOT / "examples/foreign_effects/generate.py"), "--effect", "drive",
                    "--cycles", "20", "-o", "drive.csv"], check=True, capture_output=True)
    # 2. the diagnosis: nothing built-in fits; the unexplained section says what is left
    assert main(["model", "diagnose", "drive.csv", "--pattern", str(ROOT / "patterns/tube2.yaml"),
                 "--json", "diag.json", "-q"]) == 0
    out = capsys.readouterr().out
    assert "recommended: nothing" in out
    assert "periodic in the motor stroke" in out and "lead screw" in out
    u = json.loads(Path("diag.json").read_text())["unexplained"]
    assert u["follows"][0] == "stroke" and u["shape"] == "periodic"
    per = u["periodic"][0]
    assert per["variable"] == "stroke" and per["unit"] == "mm" and abs(per["period"] / 0.5 - 1) < 0.05
    floor_before = json.loads(Path("diag.json").read_text())["noise_floor_deg"]
    rmse_before = json.loads(Path("diag.json").read_text())["final"]["rmse_deg"]
    assert rmse_before > 2.5 * floor_before
    # 3. the starter file runs as written and already finds the error
    assert main(["model", "effect", "new", "drive_error", "--from", "diag.json"]) == 0
    capsys.readouterr()
    assert main(["model", "diagnose", "drive.csv", "--pattern", str(ROOT / "patterns/tube2.yaml"),
                 "--effect-file", "drive_error.py", "--json", "diag2.json", "-q"]) == 0
    d2 = json.loads(Path("diag2.json").read_text())
    assert d2["recommended"][:1] == ["drive_error"]
    # 4. the user's edit (physics in mm of stroke, the screw's lead): the error falls to the floor
    capsys.readouterr()
    assert main(["model", "diagnose", "drive.csv", "--pattern", str(ROOT / "patterns/tube2.yaml"),
                 "--effect-file", str(ROOT / "examples/foreign_effects/lead_screw.py"), "--json", "diag3.json",
                 "-q"]) == 0
    out = capsys.readouterr().out
    d3 = json.loads(Path("diag3.json").read_text())
    assert d3["recommended"][:1] == ["lead_screw"] and d3["unexplained"] is None
    assert d3["final"]["rmse_deg"] <= 1.15 * d3["noise_floor_deg"]
    p = d3["final"]["params"]
    assert abs(p["lead_screw.lead_mm"]["value"] / 0.5 - 1) < 0.005
    amp = math.hypot(p["lead_screw.sin_mm"]["value"], p["lead_screw.cos_mm"]["value"])
    assert abs(amp / 0.02 - 1) < 0.05
    assert "unexplained:" not in out
