"""Mistakes in a machine profile of one's own (camtube/machine/profile.py): one line naming the file, line
and key, exit 2, nothing written."""
from __future__ import annotations

import pytest

from tests.conftest import ROOT
from tests.test_cli_errors import TUBE1, assert_refused, camtube, listing

GRBL = (ROOT / "machines" / "grbl-flat.yaml").read_text()


@pytest.mark.parametrize("old,new,words", [
    ("suffix: .nc", "suffix: ../x", ("machine.suffix", "no folder", "'../x'")),
    ("suffix: .nc", "suffix: .job.json", ("machine.suffix", "another file camtube writes", "'.job.json'")),
    ("suffix: .nc", "suffix: .toolpath.dxf", ("machine.suffix", "another file camtube writes")),
    ("decimals: 6", "decimals: 1" + "0" * 400, ("machine.decimals", "401 digits")),
])
def test_a_profile_mistake_is_one_line_and_nothing_is_written(tmp_path, old, new, words):
    """Before: '../x' and a huge number were tracebacks; '.job.json' silently lost the G-code to the job file."""
    m = tmp_path / "m.yaml"
    assert old in GRBL
    m.write_text(GRBL.replace(old, new))
    r = camtube("toolpath", TUBE1, "-q", "-o", str(tmp_path / "o"), "--machine", str(m))
    assert_refused(r, f"{m}:", *words)
    assert listing(tmp_path) == ["m.yaml"]
