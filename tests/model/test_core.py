"""The model core: one parameter set, per-sample values, an explicit registry, broken effects named."""
from __future__ import annotations

import math
import subprocess
import sys

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.model.core import Effect, FitError, Param, Parameters, builtin_registry, load_effect_file
from camtube.model.core.fit import fit, grid_starts
from camtube.model.core.predict import model_for_pattern, pattern_values
from camtube.model.sim.synth import synthesize
from tests.conftest import PATTERNS, ROOT

P2 = load_pattern(PATTERNS / "tube2.yaml")
EXAMPLE = ROOT / "examples" / "user_effect" / "anchor_slip.py"


def test_parameters_is_one_value_with_names_bounds_vary_and_per_sample_copies():
    d = synthesize(P2, 2, 2, seed=1)
    m = model_for_pattern(P2, ["slack"])
    ps = m.make_params(d, ("E_t", "slack.deadband_mm"), pattern_values(P2), per_sample=("slack",))
    assert isinstance(ps, Parameters)
    assert ps.varying == ("E_t", "slack.deadband_mm@1", "slack.deadband_mm@2")
    assert not ps["slack.deadband_mm"].vary and ps["slack.deadband_mm@2"].sample == "2"
    assert (ps["E_t"].lo, ps["E_t"].hi, ps["E_t"].unit) == (0.5, 500.0, "GPa")
    ps2 = ps.set("E_t", value=30.0)
    assert ps["E_t"].value == 28.0 and ps2["E_t"].value == 30.0  # immutable
    assert ps.for_sample("2")["slack.deadband_mm"] == ps["slack.deadband_mm@2"].value


def test_log_parameters_get_log_spaced_start_grids():
    spec = builtin_registry()["viscoelastic"].params[1]
    g = spec.grid(3)
    assert spec.log and len(g) == 3
    assert math.log(g[1] / g[0]) == pytest.approx(math.log(g[2] / g[1]))
    assert spec.lo < g[0] < g[2] < spec.hi


def test_per_sample_slack_is_recovered_for_each_sample():
    # two samples with different slack (synth adds the same slack to all: make two files and join them)
    a = synthesize(P2, 1, 3, seed=2, slack_mm=0.04)
    b = synthesize(P2, 1, 3, seed=3, slack_mm=0.10)
    from camtube.model.data import Dataset

    d = Dataset(np.concatenate([a.sample, np.full(len(b), "2", dtype=object)]),
                np.concatenate([a.cycle, b.cycle]), np.concatenate([a.time_s, b.time_s]),
                np.concatenate([a.stroke_mm, b.stroke_mm]), np.concatenate([a.force_N, b.force_N]),
                np.concatenate([a.angle_deg, b.angle_deg]))
    m = model_for_pattern(P2, ["slack"])
    shared = fit(m, d, ("E_t", "slack.deadband_mm"), pattern_values(P2))
    per = fit(m, d, ("E_t", "slack.deadband_mm"), pattern_values(P2), per_sample=("slack.deadband_mm",))
    assert per.params["slack.deadband_mm@1"] == pytest.approx(0.04, rel=0.1)
    assert per.params["slack.deadband_mm@2"] == pytest.approx(0.10, rel=0.1)
    assert per.rmse < 0.8 * shared.rmse
    assert per.parameters["slack.deadband_mm@2"].stderr < 0.005


def test_grid_starts_cover_the_declared_range():
    d = synthesize(P2, 1, 2, seed=1)
    m = model_for_pattern(P2, ["viscoelastic"])
    ps = m.make_params(d, ("E_t", "viscoelastic.ratio", "viscoelastic.tau_s"), pattern_values(P2))
    pts = grid_starts(ps, ["viscoelastic.ratio", "viscoelastic.tau_s"], 3)
    assert len(pts) == 9 and len({p["viscoelastic.tau_s"] for p in pts}) == 3


def _wobble():
    def apply(ctx, s, p):
        return s + p["amp_mm"] * np.sin(2 * np.pi * s / p["period_mm"])

    return Effect(name="wobble", stage="stroke", apply=apply,
                  params=(Param("amp_mm", "mm", 0.0, 0.1, 0.01),
                          Param("period_mm", "mm", 0.1, 2.0, 0.3, log=True)))


def test_multistart_escapes_a_bad_start_and_is_deterministic():
    # a periodic stroke error: the period's fit is multimodal; one start at 0.3 mm stays stuck
    d = synthesize(P2, 1, 3, seed=4, slack_mm=0.0)
    m = model_for_pattern(P2, [_wobble()])
    truth = {**m.initial_values(d, pattern_values(P2)), "wobble.amp_mm": 0.03, "wobble.period_mm": 0.7}
    rng = np.random.default_rng(0)
    d = d.with_angle(m.predict(d, truth) + rng.normal(0, 0.25, len(d)))
    names = ("E_t", "wobble.amp_mm", "wobble.period_mm")
    one = fit(m, d, names, pattern_values(P2))
    many = fit(m, d, names, pattern_values(P2), grid=7)
    again = fit(m, d, names, pattern_values(P2), grid=7)
    assert many.rmse < 0.8 * one.rmse and many.rmse < 1.1 * 0.25
    assert many.params["wobble.period_mm"] == pytest.approx(0.7, rel=0.02)
    assert many.params == again.params and many.starts_tried > 1


def test_loading_an_effect_file_changes_nothing_for_later_calls():
    before = tuple(builtin_registry())
    effs = load_effect_file(EXAMPLE)
    assert [e.name for e in effs] == ["anchor_slip"] and effs[0].source == str(EXAMPLE)
    assert tuple(builtin_registry()) == before and "anchor_slip" not in builtin_registry()
    from camtube.model.diagnose import diagnose

    d = synthesize(P2, 1, 2, seed=5)
    dg = diagnose(model_for_pattern(P2), d, ("E_t",), pattern_values(P2), max_effects=0)
    assert dg.catalog.keys() <= set(before)


def test_no_import_circles_between_cli_modules_or_api_and_effects():
    code = ("import sys; import camtube.commands.diagnose; assert 'camtube.commands.model' not in sys.modules; "
            "import camtube.model.effects; assert 'camtube.model.api' not in sys.modules; "
            "import camtube.model.core.registry")
    subprocess.run([sys.executable, "-c", code], check=True, cwd=ROOT)


def _broken(apply, params=(Param("a_mm", "mm", 0.0, 1.0, 0.1),)):
    return Effect(name="broken", stage="stroke", params=params, apply=apply, source="my_effect.py")


@pytest.mark.parametrize("apply,word", [
    (lambda ctx, s, p: s - p["b_mm"], "'b_mm'"),
    (lambda ctx, s, p: s[:3], "shape"),
])
def test_a_broken_effect_is_named_with_its_file(apply, word):
    d = synthesize(P2, 1, 1, seed=1)
    m = model_for_pattern(P2, [_broken(apply)])
    with pytest.raises(FitError) as err:
        m.predict(d, m.initial_values(d, pattern_values(P2)))
    assert "broken" in str(err.value) and "my_effect.py" in str(err.value) and word in str(err.value)


def test_an_effect_on_two_stages_shares_its_parameters():
    def stroke(ctx, s, p):
        return np.maximum(s - p["loss_mm"], 0.0)

    def elong(ctx, e, p):
        return e * (1.0 + p["soft"] * ctx.first_cycle)

    eff = Effect(name="first", stage=("stroke", "elongation"), apply={"stroke": stroke, "elongation": elong},
                 params=(Param("loss_mm", "mm", 0.0, 1.0, 0.0), Param("soft", "", 0.0, 5.0, 0.0)))
    d = synthesize(P2, 1, 3, seed=1, slack_mm=0.0)
    m = model_for_pattern(P2, [eff])
    v = m.initial_values(d, pattern_values(P2))
    base = m.predict(d, v)
    shifted = m.predict(d, {**v, "first.loss_mm": 0.1, "first.soft": 0.5})
    first = np.asarray(d.cycle) == 1
    assert np.all(shifted <= base + 1e-12)
    assert np.mean(base[first] - shifted[first]) > np.mean(base[~first] - shifted[~first])
    with pytest.raises(ValueError, match="apply"):
        Effect(name="x", stage=("stroke", "angle"), params=(), apply=stroke)


def test_ready_made_signals_of_the_context():
    d = synthesize(P2, 2, 2, seed=1)
    m = model_for_pattern(P2)
    ctx = m.context(d, m.initial_values(d, pattern_values(P2)))
    assert ctx.first_cycle.sum() == len(d) // 2  # 2 samples x 2 cycles
    pk = ctx.peak_force_N
    for _, sl in d.sample_slices():
        assert np.all(np.diff(pk[sl]) >= 0)
    ts = ctx.time_since_reversal_s
    assert ts.min() == 0.0 and ts.max() <= 2 * 2.5 / 0.5 / 2 + 1e-9
