"""toolpaths/ holds exactly what the current code generates (regenerate: python scripts/make_toolpaths.py)."""
from __future__ import annotations

import importlib.util

import pytest

from tests.conftest import ROOT

spec = importlib.util.spec_from_file_location("make_toolpaths", ROOT / "scripts" / "make_toolpaths.py")
make_toolpaths = importlib.util.module_from_spec(spec)
spec.loader.exec_module(make_toolpaths)


@pytest.mark.parametrize("name", make_toolpaths.PRESETS)
def test_committed_toolpaths_are_byte_identical(name):
    texts = make_toolpaths.preset_texts(name)
    assert set(texts) == {f"{name}.toolpath.dxf", f"{name}.ngc", f"{name}.nc", f"{name}.job.json"}
    for fname, text in texts.items():
        path = ROOT / "toolpaths" / fname
        assert path.exists(), f"{path} missing: run python scripts/make_toolpaths.py"
        assert path.read_bytes() == text.encode("utf-8"), f"{path} is stale: run python scripts/make_toolpaths.py"
