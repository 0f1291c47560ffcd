"""The house's walls: no stage imports a stage above it, no import circle, commands on top.

Read with Python's own ``ast`` from the source (nothing is imported), so an import inside a
function counts the same as one at the top of a module: a circle hidden in a function is
still a circle.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

from tests.conftest import ROOT

PACKAGE = ROOT / "camtube"

#: Floor of every top-level part of camtube, lowest first. A module may import from its own
#: part and from parts on lower floors; parts on one floor do not import each other.
FLOORS: dict[str, int] = {
    # the ground: errors, tolerances, number formats and reading an input file; then the YAML, file and progress
    # helpers
    "errors": 0, "tol": 0, "fmt": 0, "inputfile": 0, "__init__": 0,
    "yamltext": 1, "io": 1, "progress": 1,
    "design": 2,
    "joint": 3, "plan": 3,
    "machine": 4,
    "export": 5,
    "cad": 6, "motion": 6, "model": 6,
    "synthesis": 7,
    "pipeline": 8,
    "commands": 9,
    "__main__": 10,
}


def _modules() -> dict[str, Path]:
    out = {}
    for path in PACKAGE.rglob("*.py"):
        rel = path.relative_to(ROOT).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = path
    return out


MODULES = _modules()


def _part(module: str) -> str:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else "__init__"


def _resolve(name: str) -> str | None:
    """The camtube module an imported dotted name lives in (a package's ``__init__`` or a module)."""
    while name:
        if name in MODULES:
            return name
        name = name.rpartition(".")[0]
    return None


def _imports(module: str) -> set[str]:
    """camtube modules that ``module`` imports anywhere in its body (function-level imports too)."""
    path = MODULES[module]
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    is_pkg = path.name == "__init__.py"
    out: set[str] = set()
    for node in ast.walk(tree):
        names: list[str] = []
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = module.split(".")
                base = base if is_pkg else base[:-1]
                base = base[: len(base) - (node.level - 1)]
                prefix = ".".join(base + ([node.module] if node.module else []))
            else:
                prefix = node.module or ""
            # `from pkg import mod` imports the module; `from pkg import name` the package that holds the name
            names = [f"{prefix}.{a.name}" if f"{prefix}.{a.name}" in MODULES else prefix for a in node.names]
        for n in names:
            if n.startswith("camtube"):
                m = _resolve(n)
                if m and m != module:
                    out.add(m)
    return out


GRAPH = {m: _imports(m) for m in MODULES}


def test_every_part_has_a_floor():
    unknown = sorted({_part(m) for m in MODULES} - set(FLOORS))
    assert not unknown, f"camtube parts without a floor in FLOORS: {unknown}; place them in the layering"


def test_no_import_runs_up_or_across():
    bad = []
    for m, targets in GRAPH.items():
        for t in targets:
            a, b = _part(m), _part(t)
            if a != b and FLOORS.get(b, 99) >= FLOORS.get(a, -1):
                bad.append(f"{m} (floor {FLOORS.get(a)}) imports {t} (floor {FLOORS.get(b)})")
    assert not bad, "imports that run up or across the stages:\n" + "\n".join(sorted(bad))


def _cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return out


def test_no_import_circles():
    circles = _cycles(GRAPH)
    assert not circles, "import circles (function-level imports count):\n" + "\n".join(
        " <-> ".join(c) for c in circles)


def test_the_stages_never_import_the_commands():
    bad = sorted(m for m, t in GRAPH.items() if _part(m) not in ("commands", "__main__")
                 and any(_part(x) == "commands" for x in t))
    assert not bad, f"stage modules that import camtube.commands: {bad}"


@pytest.mark.parametrize("module", ["camtube.design.loader", "camtube.commands.model"])
def test_the_reader_sees_function_level_imports(module):
    """The graph is not empty by accident: known imports are found, function-level ones too."""
    assert GRAPH[module], module
    if module == "camtube.commands.model":
        assert "camtube.model.core.fit" in GRAPH[module]  # imported inside a handler
