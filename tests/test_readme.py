"""The README's Python example runs as written (from a directory that holds the shipped patterns)."""
from __future__ import annotations

import os
import re

from tests.conftest import ROOT


def python_blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_readme_python_example_runs(tmp_path, capsys):
    blocks = python_blocks((ROOT / "README.md").read_text())
    assert blocks, "the README has a Python example"
    (tmp_path / "patterns").symlink_to(ROOT / "patterns")
    old = os.getcwd()
    os.chdir(tmp_path)
    try:
        for code in blocks:
            exec(compile(code, "README.md", "exec"), {"__name__": "__readme__"})
    finally:
        os.chdir(old)
    out = capsys.readouterr().out
    n_passes = int(out.split()[0])
    assert n_passes == 13 * 4 * 2 * 4  # (12 notches + 1 hole) x 4 repeats x 2 focus levels x 4 drill cuts
    ngc = (tmp_path / "tube1-12.ngc").read_text()
    assert ngc.count("M62 P0") == n_passes  # one gate-on per pass (LinuxCNC dialect)
