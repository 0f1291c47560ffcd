"""Motion-aware estimate against closed-form trapezoids and between its two entry points."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.export.dialects import LINUXCNC, dialect_from_profile
from camtube.export.gcode import gcode
from camtube.machine import load_profile
from camtube.plan import plan_job
from camtube.machine.motion_time import estimate_program, job_estimate, trajectory_time
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def rotary():
    return load_profile("linuxcnc-rotary")


def trapezoid_s(L, v, a):
    return L / v + v / a if L >= v * v / a else 2 * math.sqrt(L / a)


def test_single_moves_are_trapezoids_and_triangles(rotary):
    # X: 50 mm/s, 500 mm/s^2 -> 5 mm reaches speed, 0.5 mm does not
    for L, v in ((5.0, 25.0), (0.5, 25.0), (5.0, math.inf)):
        d = np.array([[L, 0.0, 0.0]])
        t = trajectory_time(d, ("X", "A", "Z"), rotary, np.array([v]), np.array([False])).total_s
        assert t == pytest.approx(trapezoid_s(L, min(v, 50.0), 500.0), rel=1e-12)
    # a pure rotary move uses the A limits (deg): 3600 deg/s, 36000 deg/s^2
    d = np.array([[0.0, 720.0, 0.0]])
    t = trajectory_time(d, ("X", "A", "Z"), rotary, np.array([math.inf]), np.array([False])).total_s
    assert t == pytest.approx(trapezoid_s(720.0, 3600.0, 36000.0), rel=1e-12)
    # a combined X + A move is slowed so that neither axis exceeds its limits
    d = np.array([[1.0, 360.0, 0.0]])
    t = trajectory_time(d, ("X", "A", "Z"), rotary, np.array([math.inf]), np.array([False])).total_s
    assert t == pytest.approx(max(trapezoid_s(1.0, 50.0, 500.0), trapezoid_s(360.0, 3600.0, 36000.0)), rel=1e-9)


def test_joined_collinear_moves_run_as_one():
    surface = load_profile("linuxcnc-surface")
    d = np.array([[1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    v = np.full(3, 25.0)
    joined = trajectory_time(d, ("X", "Y", "Z"), surface, v, np.array([True, True, False])).total_s
    stops = trajectory_time(d, ("X", "Y", "Z"), surface, v, np.zeros(3, bool)).total_s
    assert joined == pytest.approx(trapezoid_s(4.0, 25.0, 500.0), rel=1e-12)
    assert stops == pytest.approx(2 * trapezoid_s(1.0, 25.0, 500.0) + trapezoid_s(2.0, 25.0, 500.0), rel=1e-12)


@pytest.mark.parametrize("machine", ["linuxcnc-rotary", "linuxcnc-surface"])
def test_the_job_estimate_is_the_estimate_of_the_written_program(machine):
    dialect = dialect_from_profile(load_profile(machine))
    job = plan_job(load_pattern(PATTERNS / "tube1.yaml", ["notch.count=2", "process.repeats=1"]))
    text = gcode(job, dialect)
    est = job_estimate(job, dialect)
    assert est.machine == machine and est.total_s > est.lower_bound_s
    assert estimate_program(text, dialect.profile).total_s == pytest.approx(est.total_s, rel=1e-9)
    assert f"on machine {machine}" in text.splitlines()[3]


def test_default_dialect_is_exact_stop():
    assert "G61" in LINUXCNC.preamble and LINUXCNC.profile.exact_stop


def test_the_old_module_path_warns_and_nothing_of_camtube_imports_it():
    """camtube.export.motion_time moved to camtube.machine.motion_time: the old path is a shim that warns."""
    import ast
    import importlib
    import sys
    import warnings

    from tests.conftest import ROOT

    sys.modules.pop("camtube.export.motion_time", None)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        old = importlib.import_module("camtube.export.motion_time")
    assert any(issubclass(w.category, FutureWarning) and "camtube.machine.motion_time" in str(w.message)
               for w in caught)
    assert old.job_estimate is job_estimate
    users = []
    for path in (ROOT / "camtube").rglob("*.py"):
        if path.name == "motion_time.py" and path.parent.name == "export":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.ImportFrom) and node.module == "camtube.export.motion_time":
                users.append(str(path))
    assert not users


def test_a_semicolon_inside_a_paren_comment_is_no_comment_start():
    """LinuxCNC reads ``(a; b X1)`` as one comment: the estimate must not take ``X1`` for a move (a profile's
    description with a ';' in it once made the estimate count a move of 250 mm)."""
    from camtube.machine import load_profile
    from camtube.machine.motion_time import estimate_program

    p = load_profile("linuxcnc-path")
    plain = estimate_program("G21 G90 G61\nG0 X1\nM2\n", p)
    assert estimate_program("(header; limits X250 Y250)\nG21 G90 G61\nG0 X1\nM2\n", p) == plain
    assert estimate_program("G21 G90 G61\nG0 X1 ; X250\nM2\n", p) == plain
