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
    # a check that takes the keyword ``effects`` gets the fitted model's effects (one that does not, two arguments)
    seen = []
    eff = make(lambda d, pred, effects=(): seen.append(tuple(e.name for e in effects)) or "")
    assert form_problem(eff, None, np.zeros(3), (eff,)) == "" and seen == [("odd",)]


# mistakes that were a traceback (a string returned), a silent wrong result (complex numbers cast to real,
# a second effect of the same name ignored), a bare exit status (sys.exit in the file) or a line without a fix
@pytest.mark.parametrize("body,words", [
    ('    return "abc"', ["returned str 'abc', not numbers", "fix: return one number per row"]),
    ('    return x + 1j', ["returned complex numbers", "fix: return one number per row"]),
    ('    return x[:3]', ["returned shape (3,)", "fix: return one number per row"]),
    ('    raise SystemExit(5)', ["called sys.exit()", "fix: correct the effect's function"]),
    ('    raise ValueError("bad")', ["ValueError: bad", "fix: correct the effect's function"]),
    ('    return x * np.nan', ["non-finite angle", "fix: an effect returned NaN or inf", "broken ("]),
    # (the bad-input search: ``s -= k`` changed the array the model keeps for the effects after it: exit 0, 72 deg)
    ('    x *= p["gain"]\n    return x', ["eff.py:7), stage stroke: changes the stroke array it is given in place",
                                        "fix: return a new array at that line"]),
])
def test_a_wrong_return_or_exit_in_apply_is_one_line_with_a_fix(tmp_path, capsys, data_csv, body, words):
    f = tmp_path / "eff.py"
    f.write_text(HEAD + body + TAIL, encoding="utf-8")
    code = main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--effect-file", str(f),
                 "--effects", "broken"])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    for w in words:
        assert w in err, err


@pytest.mark.parametrize("text,words", [
    ("import sys\nsys.exit(3)\n", [":2:", "it called sys.exit()", "fix: correct the file at that line"]),
    ("raise RuntimeError('boom')\n", [":1:", "RuntimeError: boom", "fix:"]),
    ("x = 1\n", ["defines no Effect", "fix: add one"]),
    (HEAD + "    return x" + TAIL + "\nAGAIN = Effect(name='broken', stage='stroke', params=(), apply=_apply)\n",
     ["two different effects named 'broken'", "fix: give each Effect a name of its own"]),
    (HEAD + "    return x" + TAIL.replace('0.0, 2.0, 1.0', '2.0, 0.0, 1.0'),
     ["parameter 'gain' has lo 2 > hi 0", "fix: swap them"]),
    # (the bad-input search: a start outside the bounds loaded, and the fit said "ended on its bound")
    (HEAD + "    return x" + TAIL.replace('0.0, 2.0, 1.0', '0.0, 2.0, 5.0'),
     ["parameter 'gain' starts at 5, outside its bounds 0..2", "fix: give a start within them"]),
])
def test_a_file_that_exits_raises_or_defines_nothing_usable(tmp_path, capsys, data_csv, text, words):
    f = tmp_path / "eff.py"
    f.write_text(text, encoding="utf-8")
    code = main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--effect-file", str(f)])
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert "Traceback" not in err and len(err.splitlines()) == 1 and str(f) in err, err
    for w in words:
        assert w in err, err


@pytest.mark.parametrize("which,words", [("missing", ["no such effect file", "fix:"]),
                                         ("dir", ["not a file", "fix:"]),
                                         ("csv", ["cannot import the effect file", "fix:"])])
def test_an_effect_file_path_that_is_no_python_file(tmp_path, capsys, data_csv, which, words):
    path = {"missing": tmp_path / "nope.py", "dir": tmp_path, "csv": data_csv}[which]
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--effect-file", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and str(path) in err, err
    for w in words:
        assert w in err, err


@pytest.mark.parametrize("old,new,words", [
    ('name="broken"', 'name="lead screw!"', ["'lead screw!'", "not a Python identifier", "fix: e.g. name='lead_screw'"]),
    ('Param("gain"', 'Param("gain x"', ["parameter 'gain x'", "not a Python identifier", "fix: e.g. Param('gain_x'"]),
])
def test_an_effect_or_parameter_name_that_is_not_an_identifier_is_refused(tmp_path, capsys, data_csv, old, new,
                                                                           words):
    """Before: accepted, though the name cannot be written NAME.param on the command line."""
    src = HEAD + "    return x * p[\"gain\"]\n" + TAIL.replace(old, new)
    f = tmp_path / "eff.py"
    f.write_text(src, encoding="utf-8")
    js = tmp_path / "o.json"
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--effect-file", str(f),
                 "--json", str(js)]) == 2
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    line = src.splitlines().index(next(ln for ln in src.splitlines() if ln.startswith("BROKEN = "))) + 1
    assert f"{f}:{line}:" in err, err
    for w in words:
        assert w in err, err
    assert not js.exists()


# a Param written wrong (its arguments after name, unit): (arguments, words the message must hold)
PARAMS = [
    ('0.0, 2.0, "one", "g"', ["init must be a finite number", "'one'"]),
    ('"0", "2", 1.0, "g"', ["lo and hi must be numbers"]),
    ('0.0, 2.0, float("nan"), "g"', ["init must be a finite number", "nan"]),
    ('0.0, 2.0, 1.0, "g", starts=("a",)', ["starts must be a tuple of finite numbers"]),
    ('0.0, 2.0, lambda d, c: float("nan"), "g"', ["mine.gain", "its init gave nan"]),
    ('0.0, 2.0, lambda d, c: 1 / 0, "g"', ["mine.gain", "its init function raised ZeroDivisionError"]),
]


@pytest.mark.parametrize("args,words", PARAMS)
def test_a_param_written_wrong_is_one_line_naming_it(tmp_path, capsys, data_csv, args, words):
    """Found by fuzzing (issue 19's session): a string or nan init, string bounds, bad starts and an init function that
    raises or gives nan were tracebacks in the fit."""
    f = tmp_path / "eff.py"
    f.write_text(HEAD + "    return x\n\n\nMINE = Effect(name=\"mine\", stage=\"stroke\", params=(Param(\"gain\", \"\", "
                 + args + "),), apply=_apply)\n", encoding="utf-8")
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--effect-file", str(f),
                 "--effects", "mine"]) == 2
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    assert "eff.py" in err and "fix:" in err, err
    for w in words:
        assert w in err, (w, err)


# bug 08 (fuzzing): a BaseException that is no Exception (a class of the user's own, GeneratorExit) raised by an
# effect file was a traceback with exit 1, at import and in its functions; Ctrl-C stays an interrupt (130)
OWN = "class Stop(BaseException):\n    pass\n\n\n"


@pytest.mark.parametrize("where,raise_,words", [
    ("import", 'raise Stop("halt")', ["cannot load the effect file: Stop: halt", "fix: correct the file"]),
    ("import", "raise GeneratorExit", ["cannot load the effect file: GeneratorExit", "fix: correct the file"]),
    ("import", "raise SystemExit(3)", ["it called sys.exit()", "fix: correct the file"]),
    ("apply", 'raise Stop("halt")', ["'broken'", "stage stroke: Stop: halt", "fix: correct the effect's function"]),
    ("apply", "raise GeneratorExit", ["'broken'", "GeneratorExit", "fix: correct the effect's function"]),
    ("init", 'raise Stop("halt")', ["broken.gain", "its init function raised Stop: halt", "fix:"]),
])
@pytest.mark.parametrize("cmd", ["fit", "diagnose"])
def test_a_base_exception_of_an_effect_file_is_one_line_naming_file_and_line(tmp_path, capsys, data_csv, where,
                                                                             raise_, words, cmd):
    src = OWN + HEAD + ("    " + raise_ + "\n" if where == "apply" else "") + "    return x * p['gain']\n\n\n"
    if where == "init":
        src += "def _init(data, ctx):\n    " + raise_ + "\n\n\n"
    src += TAIL.lstrip("\n").replace("1.0, \"gain\"", "_init, \"gain\"" if where == "init" else "1.0, \"gain\"")
    if where == "import":
        src += raise_ + "\n"
    f = tmp_path / "eff.py"
    f.write_text(src, encoding="utf-8")
    argv = ["model", cmd, str(data_csv), "--pattern", TUBE2, "-q", "--effect-file", str(f)]
    argv += ["--effects", "broken"] if cmd == "fit" else ["--candidates", "broken"]
    code = main(argv)
    err = capsys.readouterr().err.strip()
    assert code == 2, err
    assert "Traceback" not in err and len(err.splitlines()) == 1, err
    line = max(i for i, ln in enumerate(src.splitlines(), 1) if ln.strip() == raise_)
    assert f"{f}:{line}" in err, err
    for w in words:
        assert w in err, err


def test_a_base_exception_of_a_check_is_one_line():
    import numpy as np

    from camtube.model.api import Effect, FitError, Param
    from camtube.model.core.model import form_problem

    class Stop(BaseException):
        pass

    def check(d, pred):
        raise Stop("halt")

    eff = Effect(name="odd", stage="angle", params=(Param("b_deg", "deg", -5.0, 5.0, 0.1, "offset"),),
                 apply=lambda c, a, p: a + p["b_deg"], check=check, source="odd.py")
    with pytest.raises(FitError, match=r"effect 'odd' \(odd\.py\), check: Stop: halt; fix: correct the check"):
        form_problem(eff, None, np.zeros(3))


@pytest.mark.parametrize("where", ["import", "apply"])
def test_a_keyboard_interrupt_in_an_effect_file_is_still_an_interrupt(tmp_path, capsys, data_csv, where):
    src = HEAD + ("    raise KeyboardInterrupt\n" if where == "apply" else "") + "    return x" + TAIL
    if where == "import":
        src += "raise KeyboardInterrupt\n"
    f = tmp_path / "eff.py"
    f.write_text(src, encoding="utf-8")
    assert main(["model", "fit", str(data_csv), "--pattern", TUBE2, "-q", "--effect-file", str(f),
                 "--effects", "broken"]) == 130
    assert "interrupted" in capsys.readouterr().err
