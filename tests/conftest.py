from __future__ import annotations

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PATTERNS = ROOT / "patterns"
PRESETS = ("tube1", "tube2", "tube3")


def require_tool(name: str) -> str:
    """Path of a system tool; under CI (CI=true) a missing tool fails, locally it skips."""
    path = shutil.which(name)
    if path:
        return path
    if os.environ.get("CI"):
        pytest.fail(f"{name} is not installed; .ci/run installs it")
    pytest.skip(f"{name} not installed")


@pytest.fixture
def preset_path():
    def get(name: str) -> Path:
        return PATTERNS / f"{name}.yaml"

    return get


# Property tests never read or write a local example database: every run (a fresh clone, CI, a
# developer's machine) draws its examples from the seed alone (`pytest --hypothesis-seed N`).
from hypothesis import settings as _hyp_settings  # noqa: E402

_hyp_settings.register_profile("camtube", database=None)
_hyp_settings.load_profile("camtube")
