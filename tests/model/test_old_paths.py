"""The earlier flat module paths of ``camtube.model`` warn and hand on the same objects; nothing imports them."""
from __future__ import annotations

import ast
import importlib
import sys

import pytest

from tests.conftest import ROOT

OLD = {"dataset": "data.dataset", "fit": "core.fit", "predict": "core.predict", "synth": "sim.synth",
       "truth": "sim.truth", "atlas": "diagnose.atlas", "plot": "report.plot", "report_fit": "report.fit"}


@pytest.mark.parametrize("old,new", sorted(OLD.items()))
def test_an_old_path_warns_and_hands_on_the_same_objects(old, new):
    sys.modules.pop(f"camtube.model.{old}", None)
    with pytest.warns(FutureWarning, match=f"camtube.model.{old} is camtube.model.{new}"):
        mod = importlib.import_module(f"camtube.model.{old}")
    target = importlib.import_module(f"camtube.model.{new}")
    names = [n for n in vars(mod) if not n.startswith("_") and n not in ("annotations", "warnings")]
    assert names and all(getattr(mod, n) is getattr(target, n) for n in names)


def test_nothing_of_the_project_imports_an_old_path():
    olds = {f"camtube.model.{k}" for k in OLD}
    bad = []
    for folder in ("camtube", "tests", "scripts", "examples"):
        for path in (ROOT / folder).rglob("*.py"):
            if path.parent == ROOT / "camtube" / "model" and path.stem in OLD:
                continue
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                mods = []
                if isinstance(node, ast.ImportFrom) and node.module:
                    mods = [node.module] + [f"{node.module}.{a.name}" for a in node.names]
                elif isinstance(node, ast.Import):
                    mods = [a.name for a in node.names]
                bad += [f"{path.relative_to(ROOT)}:{node.lineno}: {m}" for m in mods if m in olds]
    assert not bad, bad
