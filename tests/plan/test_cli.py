"""CLI smoke tests of the plan stage: camtube toolpath / build."""
from __future__ import annotations

import json

import ezdxf

from camtube.commands import main
from tests.conftest import PATTERNS


def test_toolpath_writes_every_output_and_prints_the_summary(tmp_path, capsys):
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "-o", str(tmp_path), "-q"]) == 0
    out = capsys.readouterr().out
    for label in ("cuts", "passes", "cut length", "estimated time", "lower bound", "ratio"):
        assert label in out
    assert "352" in out
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == [".tube1.camtube-set", "tube1.job.json", "tube1.nc", "tube1.ngc", "tube1.toolpath.dxf"]
    assert json.loads((tmp_path / "tube1.job.json").read_text())["summary"]["passes"] == 352


def test_toolpath_options(tmp_path, capsys):
    argv = ["toolpath", str(PATTERNS / "tube3.yaml"), "-o", str(tmp_path), "-q", "--ordering", "sequential",
            "--dialect", "linuxcnc", "--set", "process.repeats=2"]
    assert main(argv) == 0
    assert sorted(p.name for p in tmp_path.iterdir()) == [".tube3.camtube-set", "tube3.job.json", "tube3.ngc",
                                                          "tube3.toolpath.dxf"]
    d = json.loads((tmp_path / "tube3.job.json").read_text())
    assert d["ordering"] == "sequential" and d["repeats"] == 2 and d["summary"]["passes"] == 11 * 16


def test_build_adds_the_design_dxf_and_plans_a_dxf(tmp_path, capsys):
    assert main(["build", str(PATTERNS / "tube2.yaml"), "-o", str(tmp_path / "b"), "-q"]) == 0
    design = tmp_path / "b" / "tube2.design.dxf"
    assert len(ezdxf.readfile(design).modelspace().query("LWPOLYLINE")) == 12
    # the design DXF (as if drawn by hand) planned directly
    assert main(["toolpath", str(design), "--outer-radius", "0.85", "-o", str(tmp_path / "d")]) == 0
    d = json.loads((tmp_path / "d" / "tube2.design.job.json").read_text())
    assert d["summary"]["passes"] == 11 * 48 and d["repeats"] == 6


def test_errors_exit_2(tmp_path, capsys):
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "-o", str(tmp_path), "-q",
                 "--set", "process.drill_offset=0.1"]) == 2
    assert "vanishes" in capsys.readouterr().err
    assert not any(tmp_path.iterdir())
    dxf = tmp_path / "x.dxf"
    main(["dxf", str(PATTERNS / "tube1.yaml"), "-o", str(dxf), "-q"])
    assert main(["toolpath", str(dxf), "--outer-radius", "0.5", "-o", str(tmp_path / "o")]) == 2  # drawn for 0.75
    assert "outer radius" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_machine_profile_chooses_the_gcode_and_is_recorded(tmp_path, capsys):
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "-o", str(tmp_path), "-q",
                 "--machine", "linuxcnc-surface"]) == 0
    out = capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == [".tube1.camtube-set", "tube1.job.json", "tube1.ngc",
                                                          "tube1.toolpath.dxf"]
    d = json.loads((tmp_path / "tube1.job.json").read_text())
    assert d["machine"]["name"] == "linuxcnc-surface"
    assert "on machine linuxcnc-surface" in out
    ngc = (tmp_path / "tube1.ngc").read_text()
    assert "G64 P0.001" in ngc and " Y" in ngc  # the uniform-dose profile: blending tolerance, surface axis Y
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "-o", str(tmp_path / "x"), "-q",
                 "--machine", "linuxcnc-surface", "--dialect", "grbl"]) == 2
    assert "--machine and --dialect" in capsys.readouterr().err
    assert not (tmp_path / "x").exists()
