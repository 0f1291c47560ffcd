"""The diagnosis finds hidden physics in data from the independent truth simulator (and nothing in a control)."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from camtube.commands import main
from camtube.design.loader import load_pattern
from camtube.model.diagnose.atlas import residual_atlas
from camtube.model.data import format_csv
from camtube.model.diagnose import diagnose, noise_floor
from camtube.model.core.predict import model_for_pattern, pattern_values
from camtube.model.sim.truth import Hidden, simulate
from tests.conftest import PATTERNS

TRAP = 0.05  # N mm of joint friction in every case: measured-force hysteresis the model absorbs

# (case id, tube, hidden physics, acceptable first effects, {param: true value, relative tolerance})
CASES = [
    ("slack-tube1", "tube1", Hidden(slack_mm=0.1, joint_friction_nmm=TRAP), {"slack"},
     {"slack.deadband_mm": (0.1, 0.1)}),
    ("slack-tube3", "tube3", Hidden(slack_mm=0.3, joint_friction_nmm=0.0), {"slack"}, {"slack.deadband_mm": (0.3, 0.1)}),
    ("play-tube2", "tube2", Hidden(play_mm=0.06, joint_friction_nmm=TRAP), {"play"}, {"play.play_mm": (0.06, 0.1)}),
    ("play-tube1", "tube1", Hidden(play_mm=0.15, joint_friction_nmm=0.0), {"play"}, {"play.play_mm": (0.15, 0.1)}),
    ("toe-tube1", "tube1", Hidden(toe_mm=0.2, joint_friction_nmm=TRAP), {"toe"}, {"toe.toe_mm": (0.2, 0.1)}),
    ("toe-tube2", "tube2", Hidden(toe_mm=0.4, joint_friction_nmm=0.0), {"toe"}, {"toe.toe_mm": (0.4, 0.1)}),
    ("visco-tube2", "tube2", Hidden(visco_ratio=0.3, visco_tau_s=1.0, joint_friction_nmm=TRAP), {"viscoelastic"},
     {"viscoelastic.ratio": (0.3, 0.15), "viscoelastic.tau_s": (1.0, 0.2)}),
    ("visco-tube3", "tube3", Hidden(visco_ratio=0.6, visco_tau_s=3.0, joint_friction_nmm=0.0), {"viscoelastic"},
     {"viscoelastic.ratio": (0.6, 0.15), "viscoelastic.tau_s": (3.0, 0.2)}),
    ("creep-tube1", "tube1", Hidden(creep_mm_per_N=0.05, creep_tau_s=20.0, joint_friction_nmm=TRAP), {"creep"}, {}),
    ("creep-tube2", "tube2", Hidden(creep_mm_per_N=0.03, creep_tau_s=40.0, joint_friction_nmm=0.0), {"creep"}, {}),
    ("slack+play-tube2", "tube2", Hidden(slack_mm=0.08, play_mm=0.06, joint_friction_nmm=TRAP), {"slack", "play"},
     {"slack.deadband_mm": (0.08, 0.1), "play.play_mm": (0.06, 0.1)}),
    ("play+creep-tube3", "tube3", Hidden(play_mm=0.2, creep_mm_per_N=0.02, creep_tau_s=30.0, joint_friction_nmm=0.0), {"play", "creep"},
     {"play.play_mm": (0.2, 0.1)}),
]


#: The shift of toe_shape's linear part per unit of a hidden effect it is declared indistinguishable from.
SHAPED_TOE = {"toe.toe_mm": 0.5, "slack.deadband_mm": 1.0}


def _run(tube: str, hidden: Hidden, seed: int = 7):
    p = load_pattern(PATTERNS / f"{tube}.yaml")
    sim = simulate(p, hidden, n_samples=2, n_cycles=10, rate_hz=10.0, seed=seed)
    d = diagnose(model_for_pattern(p), sim.data, ("E_t",), pattern_values(p))
    return p, sim, d


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_finds_the_hidden_effect(case):
    _, tube, hidden, want, truth = case
    p, sim, d = _run(tube, hidden)
    first = d.candidates[0]
    # ranked first, or an effect it declares indistinguishable from the first
    assert want & ({first.effect} | set(first.equivalent)), [(c.effect, c.heldout_rmse_deg) for c in d.candidates]
    hidden_found = want & ({r for r in d.recommended}
                           | {e for rnd in d.rounds for c in rnd if c.effect in d.recommended
                              for e in c.equivalent})
    assert hidden_found == want, (d.recommended, d.stop_reason)
    assert len(d.recommended) <= len(want) + 1
    # the error falls to the noise floor: estimated and true
    assert d.final.rmse_deg <= 1.3 * d.noise_floor_deg
    assert d.final.rmse_deg <= 1.3 * sim.sensor_floor_deg
    assert abs(d.noise_floor_deg / sim.sensor_floor_deg - 1) < 0.15
    # fed the true tension, the model with the recommended effects reproduces the true angle (where the
    # tendon is taut: a slack tendon leaves the joint wherever the friction trap holds it)
    clean = sim.data.with_angle(sim.angle_true_deg)
    clean = type(clean)(clean.sample, clean.cycle, clean.time_s, clean.stroke_mm, sim.tension_true_N,
                        clean.angle_deg)
    pred = model_for_pattern(p, list(d.final.effects)).predict(clean, d.final.params)
    taut = sim.tension_true_N > 0.01
    err = float(np.sqrt(np.mean((pred - sim.angle_true_deg)[taut] ** 2)))
    assert err < 0.5 * sim.sensor_floor_deg, err
    for name, (value, tol) in truth.items():
        if name in SHAPED_TOE and name not in d.final.params and "toe_shape" in d.final.effects:
            # the shaped toe law, declared indistinguishable from the hidden effect, was chosen: the shift of
            # its linear part is the hidden effect's (half the quadratic law's toe length; all of a slack)
            name, value = "toe_shape.offset_mm", value * SHAPED_TOE[name]
        assert abs(d.final.params[name] / value - 1) < tol, (name, d.final.params[name], value)
    assert abs(d.final.params["E_t"] / 28.0 - 1) < 0.05


@pytest.mark.parametrize("tube", ["tube1", "tube2", "tube3"])
def test_control_recommends_nothing(tube):
    _, sim, d = _run(tube, Hidden(joint_friction_nmm=TRAP), seed=11)
    assert d.recommended == ()
    assert d.final.rmse_deg <= 1.15 * d.noise_floor_deg


def test_control_with_the_search_forced_finds_nothing_significant():
    """Even when the search runs (stop ratio 0), no effect passes the significance tests on pure noise."""
    p = load_pattern(PATTERNS / "tube2.yaml")
    sim = simulate(p, Hidden(joint_friction_nmm=0.0), n_cycles=10, seed=3)
    d = diagnose(model_for_pattern(p), sim.data, ("E_t",), pattern_values(p), stop_ratio=0.0)
    assert d.recommended == () and d.rounds and not any(c.significant for c in d.candidates)


def test_series_compliance_is_declared_confounded_with_e_t():
    _, _, d = _run("tube1", Hidden(slack_mm=0.1, joint_friction_nmm=0.0))
    ser = next(c for c in d.candidates if c.effect == "series")
    assert not ser.significant and any(s.startswith("E_t") for s in ser.confounded)


def test_noise_floor_is_robust_to_model_error():
    p = load_pattern(PATTERNS / "tube2.yaml")
    sim = simulate(p, Hidden(play_mm=0.1, visco_ratio=0.3, joint_friction_nmm=0.0), n_cycles=10, seed=2)
    base = model_for_pattern(p)
    resid = sim.data.angle_deg - base.predict(sim.data, pattern_values(p))
    assert abs(noise_floor(sim.data, resid) / sim.sensor_floor_deg - 1) < 0.15


def test_atlas_shows_direction_for_play():
    p = load_pattern(PATTERNS / "tube1.yaml")
    sim = simulate(p, Hidden(play_mm=0.15, joint_friction_nmm=0.0), n_cycles=4, seed=1)
    r = sim.data.angle_deg - model_for_pattern(p).predict(sim.data, pattern_values(p))
    at = residual_atlas(sim.data, r)
    dirn = at.panel("direction")
    assert dirn.median[1] < dirn.median[0]  # loading (+1) lags: negative residual
    assert at.panel("direction").explained > 0.3 and at.panel("cycle").explained < 0.05


def test_cli_json_report_and_fit_command(tmp_path, capsys):
    p = load_pattern(PATTERNS / "tube2.yaml")
    sim = simulate(p, Hidden(slack_mm=0.08, play_mm=0.06, joint_friction_nmm=0.0), n_cycles=6, seed=5)
    csv = tmp_path / "d.csv"
    csv.write_text(format_csv(sim.data))
    out, rep = tmp_path / "d.json", tmp_path / "rep"
    pat = str(PATTERNS / "tube2.yaml")
    assert main(["model", "diagnose", str(csv), "--pattern", pat, "-q", "--json", str(out),
                 "--report", str(rep)]) == 0
    text = capsys.readouterr().out
    js = json.loads(out.read_text())
    assert js["recommended"] == ["slack", "play"]
    assert {"rmse_deg"} <= set(js["base"]) and js["noise_floor_deg"] > 0
    for c in js["candidates"]:
        assert {"effect", "rmse_deg", "heldout_rmse_deg", "delta_bic", "params"} <= set(c)
    assert "lost motion" in text and "--effects slack,play" in js["command"]
    for f in ("index.html", "model.png", "atlas.png", "ranking.png", "waterfall.png"):
        assert (rep / f).stat().st_size > 1000
    assert "http" not in (rep / "index.html").read_text()  # offline: no external resources
    # the printed command fits the model with the effects
    cmd = js["command"].split()
    assert cmd[:3] == ["camtube", "model", "fit"]
    fit_json = tmp_path / "fit.json"
    assert main(cmd[1:] + ["-q", "--json", str(fit_json)]) == 0
    fitted = json.loads(fit_json.read_text())
    assert fitted["rmse_deg"] == pytest.approx(js["waterfall"][-1]["rmse_deg"], rel=1e-3)
    assert math.isclose(fitted["params"]["play.play_mm"]["value"], 0.06, rel_tol=0.1)


def test_cli_baseline_rest_angle_is_printed_reproduced_and_can_be_turned_off(tmp_path, capsys):
    # a control paused at zero stroke: the joint's friction holds it bent there; the rest angle joins the
    # baseline, the printed command (with it) reproduces the final RMSE, --no-baseline makes it a candidate
    p = load_pattern(PATTERNS / "tube1.yaml")
    sim = simulate(p, Hidden(), n_samples=2, n_cycles=12, seed=8, dwell_s=2.0)
    csv = tmp_path / "d.csv"
    csv.write_text(format_csv(sim.data))
    pat = str(PATTERNS / "tube1.yaml")
    out = tmp_path / "d.json"
    assert main(["model", "diagnose", str(csv), "--pattern", pat, "-q", "--json", str(out)]) == 0
    text = capsys.readouterr().out
    js = json.loads(out.read_text())
    assert js["recommended"] == [] and [b["effect"] for b in js["baseline"]] == ["rest_angle"]
    assert js["given"]["rmse_deg"] > js["final"]["rmse_deg"]
    assert "baseline: rest_angle joins the model" in text and "recommended: nothing" in text
    assert "--effects rest_angle" in js["command"] and js["command"] in text
    fit_json = tmp_path / "fit.json"
    assert main(js["command"].split()[1:] + ["-q", "--json", str(fit_json)]) == 0
    fitted = json.loads(fit_json.read_text())
    assert fitted["rmse_deg"] == pytest.approx(js["final"]["rmse_deg"], rel=1e-3)
    off = tmp_path / "off.json"
    assert main(["model", "diagnose", str(csv), "--pattern", pat, "-q", "--json", str(off), "--no-baseline"]) == 0
    js_off = json.loads(off.read_text())
    assert js_off["baseline"] == [] and (js_off["recommended"] or [c["effect"] for c in js_off["partial"]])[0] \
        == "rest_angle"


# ----------------------------------------------------------------------------- trust (issue 11)

def test_cycle_blocks_test_every_cycle_and_cycle_one_in_both_folds():
    from camtube.model.diagnose.search import cycle_blocks

    p = load_pattern(PATTERNS / "tube2.yaml")
    sim = simulate(p, Hidden(joint_friction_nmm=0.0), n_samples=2, n_cycles=10, seed=1)
    d = sim.data
    block, fold = cycle_blocks(d)
    first = np.asarray(d.cycle) == 1
    s1 = d.sample == "1"
    # every row is a test row of exactly one fold; cycle 1 of sample 1 is tested in one fold, of sample 2 in the other
    assert set(np.unique(fold)) == {0, 1}
    assert np.unique(fold[first & s1]).size == 1 and np.unique(fold[first & ~s1]).size == 1
    assert fold[first & s1][0] != fold[first & ~s1][0]
    # blocks hold whole cycles
    for b in np.unique(block):
        cyc = set(np.asarray(d.cycle)[block == b].tolist())
        assert all(((np.asarray(d.cycle) == c) & (block != b) & (d.sample == d.sample[block == b][0])).sum() == 0
                   for c in cyc)


def test_a_control_gets_nothing_even_with_the_stop_rule_off():
    p = load_pattern(PATTERNS / "tube1.yaml")
    sim = simulate(p, Hidden(), n_samples=2, n_cycles=8, seed=21)  # friction distractor on (the default)
    d = diagnose(model_for_pattern(p), sim.data, ("E_t",), pattern_values(p), stop_ratio=None)
    assert d.recommended == (), [(c.effect, c.why) for c in d.candidates[:3]]
    # and the candidates that fail say why
    assert all(c.why for c in d.candidates if not c.significant)


def test_samples_that_differ_get_their_own_values_and_the_output_says_so():
    p = load_pattern(PATTERNS / "tube2.yaml")
    sim = simulate(p, [Hidden(slack_mm=0.04), Hidden(slack_mm=0.10)], n_samples=2, n_cycles=6, seed=8)
    d = diagnose(model_for_pattern(p), sim.data, ("E_t",), pattern_values(p))
    assert d.recommended[0] == "slack" and "slack.deadband_mm" in d.per_sample
    assert d.final.params["slack.deadband_mm@1"] == pytest.approx(0.04, rel=0.1)
    assert d.final.params["slack.deadband_mm@2"] == pytest.approx(0.10, rel=0.1)
    assert any("samples differ in slack.deadband_mm" in n for n in d.sample_notes)
    base, final = d.waterfall[0].rmse_per_sample, d.final.rmse_per_sample
    assert all(final[s] < base[s] for s in base)
    assert d.final.rmse_deg <= 1.15 * sim.sensor_floor_deg


def test_every_recommended_step_lowers_the_rmse_and_its_parameters_are_identified():
    p = load_pattern(PATTERNS / "tube2.yaml")
    sim = simulate(p, Hidden(play_mm=0.05, toe_mm=0.3, toe_form="exponential"), n_samples=2, n_cycles=6, seed=4)
    d = diagnose(model_for_pattern(p), sim.data, ("E_t",), pattern_values(p))
    # recommended when the chain reaches 1.15 x the floor, else the same checked steps are listed as partial
    chain, steps = (d.recommended, d.waterfall) if d.recommended else (d.partial, d.partial_steps)
    assert chain and chain[0] in ("toe", "toe_shape", "play")
    assert (steps[-1].rmse_deg <= 1.15 * d.noise_floor_deg) == bool(d.recommended)
    for a, b in zip(steps, steps[1:]):
        assert b.rmse_deg < a.rmse_deg
    for k, v in steps[-1].stderr.items():
        assert math.isfinite(v) and v > 0, k
    assert 1.0 <= steps[-1].params["E_t"] <= 300.0


def test_fit_warns_when_a_history_effect_is_fitted_on_the_default_selection(tmp_path, capsys):
    p = load_pattern(PATTERNS / "tube2.yaml")
    sim = simulate(p, Hidden(play_mm=0.06), n_samples=1, n_cycles=3, seed=2)
    csv = tmp_path / "d.csv"
    csv.write_text(format_csv(sim.data))
    main(["model", "fit", str(csv), "--pattern", str(PATTERNS / "tube2.yaml"), "-q", "--effects", "play"])
    out = capsys.readouterr().out
    assert "warning: play" in out and "--branch both" in out


def _wobble_data(start_period_mm: float):
    """A user's periodic stroke error (true period 0.7 mm, amplitude 0.03 mm) on tube 2 data with 0.25 deg noise,
    declared with the start value ``start_period_mm``: ``(pattern, data, registry with the effect)``."""
    from camtube.model.core import Effect, Param
    from camtube.model.core.registry import builtin_registry
    from camtube.model.sim.synth import synthesize

    def apply(ctx, s, p):
        return s + p["amp_mm"] * np.sin(2 * np.pi * s / p["period_mm"])

    wob = Effect(name="wobble", stage="stroke", apply=apply,
                 params=(Param("amp_mm", "mm", 0.0, 0.1, 0.01),
                         Param("period_mm", "mm", 0.1, 2.0, start_period_mm)))
    p = load_pattern(PATTERNS / "tube2.yaml")
    d = synthesize(p, 2, 4, seed=4, slack_mm=0.0)
    m = model_for_pattern(p, [wob])
    truth = {**m.initial_values(d, pattern_values(p)), "wobble.amp_mm": 0.03, "wobble.period_mm": 0.7}
    d = d.with_angle(m.predict(d, truth) + np.random.default_rng(0).normal(0, 0.25, len(d)))
    return p, d, builtin_registry().with_effects([wob])


def test_diagnose_init_start_values_reach_a_multimodal_user_effect():
    p, d, reg = _wobble_data(0.3)
    stuck = diagnose(model_for_pattern(p), d, ("E_t",), pattern_values(p), registry=reg, candidates=["wobble"],
                     grid=0)
    got = diagnose(model_for_pattern(p), d, ("E_t",), pattern_values(p), registry=reg, candidates=["wobble"],
                   grid=0, init={"wobble.period_mm": 0.68})
    assert stuck.final.rmse_deg > 1.5 * got.final.rmse_deg  # from its default start the period is not found
    assert got.recommended == ("wobble",)
    assert got.final.params["wobble.period_mm"] == pytest.approx(0.7, rel=0.01)
    assert "--init wobble.period_mm=0.7" in " ".join(f"--init {k}={v:.2g}" for k, v in got.final.init.items())


def test_user_effect_is_multi_started_over_its_declared_range():
    """A period starting at 0.5 mm finds a true 0.7 mm with the default starts (no --init): the scan of the range."""
    p, d, reg = _wobble_data(0.5)
    stuck = diagnose(model_for_pattern(p), d, ("E_t",), pattern_values(p), registry=reg, candidates=["wobble"],
                     grid=0)
    got = diagnose(model_for_pattern(p), d, ("E_t",), pattern_values(p), registry=reg, candidates=["wobble"])
    assert stuck.recommended == ()  # from its start value alone the fit stays in the 0.5 mm minimum
    assert got.recommended == ("wobble",)
    assert got.final.params["wobble.period_mm"] == pytest.approx(0.7, rel=0.01)
    assert got.final.rmse_deg < 1.05 * 0.25


def _stopped(angle_deg: np.ndarray, stop_deg: float, contact_share: float) -> np.ndarray:
    """A joint whose notches close at ``stop_deg``: past it the angle rises ``contact_share`` as fast (contact)."""
    a = np.asarray(angle_deg, float)
    return np.where(a > stop_deg, stop_deg + contact_share * (a - stop_deg), a)


def test_a_joint_that_stops_gets_hardstop_and_its_stop_angle():
    p = load_pattern(PATTERNS / "tube1.yaml")
    sim = simulate(p, Hidden(), n_samples=2, n_cycles=10, rate_hz=10.0, seed=11)
    top = float(np.nanmax(sim.data.angle_deg))
    data = sim.data.with_angle(_stopped(sim.data.angle_deg, 0.85 * top, 0.03))
    d = diagnose(model_for_pattern(p), data, ("E_t",), pattern_values(p))
    assert d.recommended[:1] == ("hardstop",), [(c.effect, c.why) for c in d.candidates]
    assert d.final.params["hardstop.stop_deg"] == pytest.approx(0.85 * top, rel=0.03)


def test_hardstop_is_refused_where_the_angle_keeps_rising_past_the_stop():
    """A load-cell zero that drifts over the cycles moves the top of each cycle: a stop can clip the cycles the
    model overshoots (on the bench simulator's zero-drift file it lowered the error 0.80 -> 0.67 deg), but past it
    the measured angle keeps rising with the stroke within each cycle: refused. A joint that does stop passes."""
    from camtube.model.effects.builtin import HARDSTOP

    p = load_pattern(PATTERNS / "tube1.yaml")
    sim = simulate(p, Hidden(), n_samples=2, n_cycles=10, rate_hz=10.0, seed=12)
    d0 = sim.data
    drift = 0.25 * np.asarray(d0.cycle, float)  # deg per cycle, the same in both samples
    model = model_for_pattern(p)
    vals = pattern_values(p)
    top = float(np.nanmax(model.predict(d0, vals)))
    stopped = model_for_pattern(p, ["hardstop"]).predict(d0, vals | {"hardstop.stop_deg": top - 4.0})
    assert HARDSTOP.check(d0.with_angle(_stopped(d0.angle_deg, top - 4.0, 0.03)), stopped) == ""
    reason = HARDSTOP.check(d0.with_angle(np.asarray(d0.angle_deg) + drift), stopped)
    assert reason.startswith("no plateau"), reason


def test_where_nothing_is_recommended_a_builtin_refused_only_for_its_bound_that_halves_the_error_is_named_nearest():
    # bench-shapes: tube 3's backbone, its set ratcheting from 10 to 46 deg; relaxation2 took the error from 14.1 to
    # 1.9 deg with its slow arm's ratio on its bound (not recommended), and the answer named only angle_bias and slack,
    # partial at 26x the floor: the user was pointed at the instruments and the tendon, not the backbone. The answer now
    # names the nearest built-in, its bound and where it sits; a candidate that gains less, or is refused for another
    # reason, is not named
    from dataclasses import replace

    from camtube.model.diagnose.search import Candidate
    from camtube.model.report.diagnosis import answer_lines, diagnosis_dict, nearest_on_bound

    p = load_pattern(PATTERNS / "tube2.yaml")
    sim = simulate(p, Hidden(), n_samples=2, n_cycles=10, rate_hz=10.0, seed=5)
    d = diagnose(model_for_pattern(p), sim.data, ("E_t",), pattern_values(p))
    assert not d.recommended and nearest_on_bound(d) is None      # the control: nothing named

    def cand(effect, ho, why, significant=False):
        return Candidate(effect, (effect,), ho, ho, -100.0, {}, significant=significant, why=why)

    left = replace(d.waterfall[0], rmse_deg=4.6)
    rounds = ((cand("angle_bias", 9.7, "", True), cand("relaxation2", 1.95, "relaxation2.slow_ratio@S1 = 2 is on its "
                                                      "bound; cannot be told apart from relaxation"),
               cand("creep", 1.0, "held-out RMSE falls by 1.0% < 2%")),
              (cand("slack", 4.6, "", True), cand("relaxation2", 1.29, "relaxation2.slow_ratio@S1 = 2 is on its bound"),
               cand("relaxation", 2.4, "relaxation.fraction = 0.9 is on its bound")))
    steps = (replace(d.waterfall[0], rmse_deg=14.1), replace(d.waterfall[0], rmse_deg=9.7), left)
    hit = replace(d, rounds=rounds, partial=("angle_bias", "slack"), partial_steps=steps)
    near = nearest_on_bound(hit)
    assert near["effect"] == "relaxation2" and near["heldout_rmse_deg"] == pytest.approx(1.29)
    assert near["bound"] == "relaxation2.slow_ratio@S1 = 2 is on its bound" and "backbone" in near["side"]
    line = next(x for x in answer_lines(hit) if x.startswith("  nearest:"))
    assert "relaxation2 lowers the error most (1.290 deg held out, against 4.600 with the effects listed partial)" in line
    assert diagnosis_dict(hit)["nearest_on_bound"]["effect"] == "relaxation2"
    # one that does not halve what the partial effects leave is not named
    assert nearest_on_bound(replace(hit, partial_steps=steps[:2] + (replace(left, rmse_deg=2.0),))) is None


def test_nothing_to_add_at_the_floor_skips_the_stiffness_test(monkeypatch):
    """An answer of nothing to add at the noise floor stands whatever the samples' stiffness test would find (a second
    search can only replace it with fewer effects): the test and its second search are not run (speed)."""
    from camtube.model.diagnose import search as search_mod

    p = load_pattern(PATTERNS / "tube2.yaml")
    sim = simulate(p, Hidden(joint_friction_nmm=0.0), n_cycles=10, seed=3)

    def refuse(self, d):
        raise AssertionError("stiffness test run")

    monkeypatch.setattr(search_mod.Search, "stiffness_differs", refuse)
    d = diagnose(model_for_pattern(p), sim.data, ("E_t",), pattern_values(p))
    assert d.recommended == () and d.final.rmse_deg <= 1.15 * d.noise_floor_deg
