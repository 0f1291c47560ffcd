"""CLI smoke tests: every sub-command of the design stage, help texts, light imports."""
from __future__ import annotations

import subprocess
import sys

import ezdxf
import pytest

from camtube.cli import build_parser, main
from tests.conftest import PATTERNS


def test_design_prints_issue_numbers(capsys):
    assert main(["design", str(PATTERNS / "tube1.yaml"), "-q"]) == 0
    out = capsys.readouterr().out
    assert "backbone angle phi" in out and "2.510 rad" in out
    assert "0.464 mm" in out and "0.874 mm" in out
    assert "backbone second moment" in out and "closure angle per notch" in out and "tube length" in out


def test_design_prints_warnings_to_stderr(capsys):
    main(["design", str(PATTERNS / "tube2.yaml")])
    assert "warning:" in capsys.readouterr().err


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
