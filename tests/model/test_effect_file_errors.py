"""A broken user effect file: one line naming the file, the line in it, the effect and the problem; exit 2."""
from __future__ import annotations

import pytest

from camtube.commands import main
from tests.conftest import PATTERNS

TUBE2 = str(PATTERNS / "tube2.yaml")

HEAD = '''from camtube.model.api import Effect, Param
import numpy as np


def _apply(ctx, s, p):
    x = np.asarray(s, float)
'''
TAIL = '''

BROKEN = Effect(name="broken", stage="stroke", params=(Param("gain", "", 0.0, 2.0, 1.0, "gain"),), apply=_apply)
'''
# (body of _apply, words the message must hold); the faulty line is the first body line: line 7 of the file
CASES = [
    ('    y = x * p["gian"]\n    return y', ["'gian'", "'gain'"]),
    ('    y = x / (p["gain"] - p["gain"]) if False else x.reshape(-1, 1)[:, 0] + undefined_name\n    return y',
     ["NameError", "undefined_name"]),
    ('    y = x[:-1] * p["gain"]\n    return y', ["shape"]),
]


@pytest.fixture(scope="module")
def data_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("e") / "d.csv"
    assert main(["model", "synth", "--pattern", TUBE2, "-o", str(path), "--cycles", "2", "-q"]) == 0
    return path


@pytest.mark.parametrize("body,words", CASES)
@pytest.mark.parametrize("cmd", ["fit", "diagnose"])
def test_broken_effect_names_file_line_and_effect(tmp_path, capsys, data_csv, body, words, cmd):
    src = HEAD + body + TAIL
    f = tmp_path / "eff.py"
    f.write_text(src, encoding="utf-8")
    argv = ["model", cmd, str(data_csv), "--pattern", TUBE2, "-q", "--effect-file", str(f)]
    argv += ["--effects", "broken"] if cmd == "fit" else ["--candidates", "broken"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    # the line: the faulty statement's (the function's def line for a wrong shape: the return is not a frame)
    line = src.splitlines().index(body.splitlines()[0]) + 1
    want = line if words != ["shape"] else src.splitlines().index("def _apply(ctx, s, p):") + 1
    assert f"{f}:{want}" in err and "'broken'" in err, err
    for w in words:
        assert w in err, err


@pytest.mark.parametrize("kw,words", [
    ('off={"gian": 0.0}', ["gian", "off"]),
    ('stage="strok"', ["strok", "stage"]),
])
def test_a_bad_effect_definition_names_its_line_also_from_a_relative_path(tmp_path, capsys, monkeypatch, kw, words):
    # an Effect(...) the constructor refuses (a ValueError raised inside camtube): the line of the file, not
    # the message for a file that is not Python text
    src = HEAD + "    return x\n\n\nBAD = Effect(name=\"bad\", stage=\"stroke\", params=(Param(\"gain\", \"\", 0.0, 2.0, 1.0, " \
        "\"gain\"),), apply=_apply)\n"
    src = src.replace('stage="stroke"', kw) if kw.startswith("stage") else src.replace("apply=_apply)", f"apply=_apply, {kw})")
    (tmp_path / "bad.py").write_text(src)
    monkeypatch.chdir(tmp_path)
    data = tmp_path / "d.csv"
    assert main(["model", "synth", "--pattern", TUBE2, "-o", str(data), "--cycles", "2", "-q"]) == 0
    capsys.readouterr()
    assert main(["model", "fit", str(data), "--pattern", TUBE2, "--effect-file", "bad.py", "--effects", "bad"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.count("\n") == 1
    line = src.splitlines().index(next(ln for ln in src.splitlines() if ln.startswith("BAD = "))) + 1
    assert f"bad.py:{line}:" in err, err
    for w in words:
        assert w in err, err
    assert "give a Python source file" not in err


def test_a_broken_check_names_the_effect_and_its_file():
    """An effect's ``check`` (its form against its signature) that raises or returns a non-string: one line."""
    import numpy as np

    from camtube.model.api import Effect, FitError, Param
    from camtube.model.core.model import form_problem

    def make(check):
        return Effect(name="odd", stage="angle", params=(Param("b_deg", "deg", -5.0, 5.0, 0.1, "offset"),),
                      apply=lambda c, a, p: a + p["b_deg"], check=check, source="odd.py")

    assert form_problem(make(lambda d, pred: ""), None, np.zeros(3)) == ""
    assert form_problem(make(lambda d, pred: "no plateau"), None, np.zeros(3)) == "no plateau"
    with pytest.raises(FitError, match=r"effect 'odd' \(odd\.py\), check: ZeroDivisionError"):
        form_problem(make(lambda d, pred: 1 / 0), None, np.zeros(3))
    with pytest.raises(FitError, match="returned float, expected a string"):
        form_problem(make(lambda d, pred: 0.5), None, np.zeros(3))
