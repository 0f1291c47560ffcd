"""camtube cad (CLI) and build_outputs end to end, files read back with independent readers."""
from __future__ import annotations

import json

import pytest
import trimesh

from camtube.commands import main
from tests.cad.conftest import analytic_volume, preset
from tests.conftest import PATTERNS


def test_cad_cli_fast_path(tmp_path, capsys):
    rc = main(["cad", str(PATTERNS / "tube1.yaml"), "-q", "-o", str(tmp_path), "--no-step", "--no-pictures"])
    out = capsys.readouterr().out
    assert rc == 0 and "verification: PASS" in out
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == [".tube1.camtube-set", "tube1.ascut.stl", "tube1.design.stl", "tube1.verify.json",
                     "tube1.verify.txt"]
    m = trimesh.load(tmp_path / "tube1.design.stl", force="mesh")
    assert m.is_watertight and abs(m.volume / analytic_volume(preset("tube1")) - 1) < 0.005
    cut = trimesh.load(tmp_path / "tube1.ascut.stl", force="mesh")
    assert cut.is_watertight and cut.volume < m.volume
    assert json.loads((tmp_path / "tube1.verify.json").read_text())["passed"] is True


def test_cad_cli_help_mentions_units(capsys):
    with pytest.raises(SystemExit):
        main(["cad", "--help"])
    assert "mm" in capsys.readouterr().out


def test_build_outputs_with_planner_step_and_pictures(tmp_path):
    """End to end with camtube.plan.plan_job: STEP re-imported by OCCT, PNGs decoded by matplotlib."""
    pytest.importorskip("build123d")
    import build123d as bd
    import matplotlib.image as mpimg

    from camtube.cad import build_outputs
    from camtube.plan import plan_job

    p = preset("tube3")
    paths = build_outputs(p, plan_job(p), tmp_path)
    names = [x.name for x in paths]
    assert names == ["tube3.design.step", "tube3.design.stl", "tube3.ascut.stl", "tube3.verify.txt",
                     "tube3.verify.json", "tube3.tube.png", "tube3.unrolled.png"]
    step = bd.import_step(str(tmp_path / "tube3.design.step"))
    assert abs(step.volume / analytic_volume(p) - 1) < 0.002
    doc = json.loads((tmp_path / "tube3.verify.json").read_text())
    assert doc["passed"] is True, (tmp_path / "tube3.verify.txt").read_text()
    assert any(c["name"] == "design.step.reimport" and c["passed"] for c in doc["checks"])
    for png in ("tube3.tube.png", "tube3.unrolled.png"):
        img = mpimg.imread(tmp_path / png)
        assert img.shape[0] > 100 and img.shape[1] > 300
        assert img[..., :3].std() > 0.05  # not blank
    # no temporary files left: the one hidden entry is the list of the set's files (camtube.io.set_list_name)
    assert [x.name for x in tmp_path.glob(".*")] == [".tube3.camtube-set"]
    assert (tmp_path / ".tube3.camtube-set").read_text().split() == names
