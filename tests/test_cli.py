"""CLI smoke tests: every sub-command of the design stage, help texts, light imports."""
from __future__ import annotations

import subprocess
import sys

import ezdxf
import pytest

from camtube.commands import build_parser, main
from tests.conftest import PATTERNS


def test_design_prints_issue_numbers(capsys):
    assert main(["design", str(PATTERNS / "tube1.yaml"), "-q"]) == 0
    out = capsys.readouterr().out
    assert "backbone angle phi" in out and "2.510 rad" in out
    assert "0.464 mm" in out and "0.874 mm" in out
    assert "backbone second moment" in out and "closure angle per notch" in out and "tube length" in out


@pytest.mark.parametrize("name", ["tube1", "tube2", "tube3", "tube1-bidirectional"])
def test_presets_fit_for_their_use_print_no_warning_but_a_note(name, capsys):
    """The presets run past the elastic limit as the paper's joints do: a note in the report, no warning."""
    assert main(["design", str(PATTERNS / f"{name}.yaml")]) == 0
    io = capsys.readouterr()
    assert "warning" not in io.err
    assert "note: notches at 180 deg" in io.out and "permanent set in the first cycles" in io.out


def test_design_warns_when_the_stroke_overloads_the_joint(capsys):
    # twice the stroke on tube 1: strain 0.073 > 2 x 0.03 (checked against the closed form in tests/design)
    main(["design", str(PATTERNS / "tube1.yaml"), "--set", "rules.max_stroke=4"])
    err = capsys.readouterr().err
    assert err.count("warning:") == 1 and "rules.max_strain" in err and "largest elastic bend" in err
    # far past closure on tube 3: the notches close before the stroke is reached
    main(["design", str(PATTERNS / "tube3.yaml"), "--set", "rules.max_stroke=40"])
    err = capsys.readouterr().err
    assert "a notch closes at a tendon stroke of" in err


def test_dxf_writes_readable_file(tmp_path, capsys):
    out = tmp_path / "sub" / "t.dxf"
    assert main(["dxf", str(PATTERNS / "tube3.yaml"), "-o", str(out), "-q"]) == 0
    doc = ezdxf.readfile(out)
    assert len(doc.modelspace().query("LWPOLYLINE")) == 12
    assert [p.name for p in out.parent.iterdir()] == ["t.dxf"]  # no temp files left


def test_help_texts_mention_units():
    parser = build_parser()
    text = parser.format_help()
    assert "mm" in text
    for action in parser._subparsers._group_actions:
        for name, sub in action.choices.items():
            assert sub.format_help()


@pytest.mark.parametrize("argv", [["--help"], ["dxf", str(PATTERNS / "tube1.yaml"), "-o", "{tmp}/x.dxf", "-q"]])
def test_light_commands_do_not_import_heavy_libraries(tmp_path, argv):
    argv = [a.replace("{tmp}", str(tmp_path)) for a in argv]
    code = (
        "import sys, runpy\n"
        f"sys.argv = ['camtube'] + {argv!r}\n"
        "try:\n    runpy.run_module('camtube', run_name='__main__')\n"
        "except SystemExit:\n    pass\n"
        "heavy = [m for m in ('build123d', 'matplotlib', 'trimesh', 'OCP', 'scipy') if m in sys.modules]\n"
        "print('HEAVY', heavy)\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60).stdout
    assert "HEAVY []" in out, out


def test_preview_svg_draws_every_sheet_piece(tmp_path):
    import xml.etree.ElementTree as ET

    from camtube.design import load_pattern, sheet_contours

    out = tmp_path / "p.svg"
    assert main(["preview", str(PATTERNS / "tube1-bidirectional.yaml"), "-o", str(out), "-q"]) == 0
    root = ET.parse(out).getroot()
    polys = root.findall("{http://www.w3.org/2000/svg}polygon")
    pieces = sheet_contours(load_pattern(PATTERNS / "tube1-bidirectional.yaml"))
    assert len(polys) == len(pieces) + 1  # + the outline


def test_readme_schema_table_is_current():
    from camtube.design.schema import markdown
    from tests.conftest import ROOT

    text = (ROOT / "README.md").read_text()
    block = text.split("<!-- schema:start -->")[1].split("<!-- schema:end -->")[0].strip()
    assert block == markdown().strip(), "README schema is stale: paste the output of `camtube schema`"


def test_preview_draws_slits_as_open_paths(tmp_path):
    import xml.etree.ElementTree as ET

    from tests.conftest import ROOT

    out = tmp_path / "s.svg"
    assert main(["preview", str(ROOT / "examples" / "dxf" / "slits.dxf"), "--layer", "KERF=slit", "-o", str(out),
                 "-q"]) == 0
    root = ET.parse(out).getroot()
    lines = root.findall("{http://www.w3.org/2000/svg}polyline")
    assert len(lines) == 9 and all(len(e.get("points").split()) == 2 for e in lines)


def test_a_toolpath_written_again_into_its_folder_leaves_no_g_code_of_the_earlier_run(tmp_path, capsys):
    # the bad-input search: the 10-notch tube1.nc stayed beside the 5-notch tube1.ngc written over it for LinuxCNC only
    out = tmp_path / "out"
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "-q", "-o", str(out)]) == 0
    assert {"tube1.nc", "tube1.ngc", "tube1.job.json"} <= set(p.name for p in out.iterdir())
    (out / "setup-notes.txt").write_text("the user's own file")
    assert main(["toolpath", str(PATTERNS / "tube1.yaml"), "-q", "--set", "notch.count=5", "--dialect", "linuxcnc",
                 "-o", str(out)]) == 0
    capsys.readouterr()
    names = set(p.name for p in out.iterdir() if not p.name.startswith("."))
    assert names == {"tube1.ngc", "tube1.job.json", "tube1.toolpath.dxf", "setup-notes.txt"}, names
