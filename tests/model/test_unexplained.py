"""The ``unexplained`` analysis against the truth of an independent simulator (examples/foreign_effects).

Each data set hides one effect camtube's library lacks; the residual of the base model (E_t fitted;
plus slack for the set, which takes its constant part) must be found to follow the variable the truth acts through, with the truth's period, and controls
must leave nothing.
"""
from __future__ import annotations

import importlib.util
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from camtube.model.data.dataset import Dataset
from camtube.model.unexplained import analyse, first_cycle_mask, variables_of

ROOT = Path(__file__).resolve().parents[2]


def _generator():
    spec = importlib.util.spec_from_file_location("foreign_generate", ROOT / "examples/foreign_effects/generate.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod          # dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


GEN = _generator()


def _dataset(rows: dict) -> Dataset:
    return Dataset(rows["sample"], rows["cycle"].astype(int), rows["time"], rows["stroke"], rows["force"],
                   rows["angle"])


def _base_residual(data: Dataset, effects=()):
    from camtube.design.loader import load_pattern
    from camtube.model.diagnose import noise_floor
    from camtube.model.core.fit import fit
    from camtube.model.core.predict import model_for_pattern, pattern_values

    p = load_pattern(ROOT / "patterns" / "tube2.yaml")
    m = model_for_pattern(p, list(effects))
    r = fit(m, data, ("E_t",) + tuple(n for n in m.param_specs if "." in n), pattern_values(p))
    return r.residuals, noise_floor(data, r.residuals)


#: Built-ins a diagnosis takes for part of the effect (the set is a stroke offset from cycle 2 on: slack).
TAKEN = {"set": ("slack",)}


def _run(effect, params=None, seed=1, cycles=20):
    rows, truth = GEN.simulate(effect, params, cycles=cycles, seed=seed, joint=GEN.Joint(rate_hz=20.0))
    data = _dataset(rows)
    res, floor = _base_residual(data, TAKEN.get(effect, ()))
    return analyse(res, variables_of(data, res), floor), truth, floor   # (the model's angle, as a diagnosis reads it)


@pytest.mark.parametrize("effect,params,seed", [
    ("drive", None, 1),
    ("drive", {"period_mm": 0.31, "amp_mm": 0.015}, 2),
    ("arm", None, 3),
    ("set", None, 4),
    ("oscillation", None, 5),
    ("oscillation", {"period_s": 23.0, "amp_mm": 0.02}, 6),
])
def test_right_variable_first_and_period(effect, params, seed):
    u, truth, floor = _run(effect, params, seed)
    assert u is not None
    assert u["follows"][0] == GEN.TRUTH_VARIABLE[effect], u["follows"]
    assert u["rmse_deg"] > 1.15 * floor
    assert set(u["samples"]) == set(truth.params)   # every sample carries the effect
    p_true = {**GEN.DEFAULTS[effect], **(params or {})}
    if effect in ("drive", "oscillation"):
        key, unit = ("period_mm", "mm") if effect == "drive" else ("period_s", "s")
        per = u["periodic"][0]
        assert per["variable"] == GEN.TRUTH_VARIABLE[effect] and per["unit"] == unit
        assert abs(per["period"] / p_true[key] - 1.0) < 0.05
        # amplitude: the stroke error over the moment arm, in deg (the model uses the measured force)
        amp_true = math.degrees(p_true["amp_mm"] / GEN.Joint().arm_mm)
        assert abs(per["amplitude_deg"] / amp_true - 1.0) < 0.2
        assert u["shape"] == "periodic"
        assert "periodic in" in u["sentence"]
    else:
        assert not [p for p in u["periodic"] if p["variable"] == "stroke"], u["periodic"]
    if effect == "arm":
        assert u["stage"] == "kinematics" and u["shape"] in ("quadratic", "saturating")
    if effect == "set":
        assert u["stage"] == "stroke" and "first cycle" in u["sentence"]


@pytest.mark.parametrize("seed", [11, 12])
def test_controls_leave_nothing(seed):
    u, _, _ = _run("none", None, seed)
    assert u is None


def test_rest_moment_is_a_per_sample_offset():
    # the tare hides a different pretension in each sample (pre-bend and stiffness differ): an offset per sample
    rows, _ = GEN.simulate("rest_moment", cycles=6, seed=8, joint=GEN.Joint(rate_hz=20.0), param_spread=0.3)
    data = _dataset(rows)
    from camtube.design.loader import load_pattern
    from camtube.model.diagnose import noise_floor
    from camtube.model.core.fit import fit
    from camtube.model.core.predict import model_for_pattern, pattern_values

    p = load_pattern(ROOT / "patterns" / "tube2.yaml")
    r = fit(model_for_pattern(p, ["angle_bias"]), data, ("E_t", "angle_bias.bias_deg"), pattern_values(p))
    u = analyse(r.residuals, variables_of(data, r.residuals), noise_floor(data, r.residuals))
    assert u is not None and u["follows"][0] == "sample"
    assert "samples differ" in u["sentence"]


def _triangle_variables(t: np.ndarray) -> dict:
    """Plain variables of one sample driven by a triangle stroke (0-2 mm, 8 s a cycle) at the times ``t``."""
    stroke = 2.0 - np.abs(2.0 - (0.5 * t) % 4.0)
    return {"stroke": stroke, "angle": 10 * stroke, "force": stroke,
            "direction": np.where(np.gradient(stroke) >= 0, 1, -1), "cycle": (t // 8).astype(int) + 1, "time": t,
            "sample": np.full(t.size, "A")}


def test_plain_arrays_and_floor_rule():
    rng = np.random.default_rng(0)
    n = 4000
    t = np.arange(n) * 0.05
    v = _triangle_variables(t)
    noise = rng.normal(0, 0.3, n)
    assert analyse(noise, v, 0.3) is None                      # at the floor: nothing left
    u = analyse(noise + 0.8 * (v["direction"] > 0), v, 0.3)    # a step with the direction of motion
    assert u is not None and u["follows"][0] == "direction" and u["shape"] == "step"
    assert first_cycle_mask(np.array(["a", "a", "b", "b"]), np.array([3, 4, 1, 2])).tolist() == [True, False, True, False]


def _two_cycling_samples():
    """Two samples S1, S2 of 50 cycles at 20 Hz (a 3 s ramp to 2 mm, a 2 s dwell, a 3 s ramp back, a 2 s rest):
    ``(sample, cycle, time s, stroke mm)``."""
    one = np.concatenate([np.linspace(0, 2, 60), np.full(40, 2.0), np.linspace(2, 0, 60), np.zeros(40)])
    stroke = np.tile(np.tile(one, 50), 2)
    n1 = stroke.size // 2
    return (np.repeat(["S1", "S2"], n1), np.tile(np.repeat(np.arange(1, 51), one.size), 2),
            np.tile(np.arange(n1) / 20.0, 2), stroke)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_tracker_drifting_in_time_is_not_read_as_following_the_angle(seed):
    # bench-heldout35's tracker drift: the tracker's zero drifts 0.3 deg over the test. Where the model is flat (the
    # rests, the dwells: 40 % of the rows here) the residual is the measured angle less a constant, so bins of the
    # measured angle sorted the residual by itself (its noise and its drift) and "the bend angle" led. Read against
    # the model's angle, what is left follows the cycle or time, as it is
    rng = np.random.default_rng(seed)
    sample, cycle, t, stroke = _two_cycling_samples()
    model = 15.0 * stroke + 1.0
    residual = rng.normal(0.0, 0.2, stroke.size) + 0.3 * t / t.max()
    data = Dataset(sample, cycle, t, stroke, 1.5 * stroke + rng.normal(0.0, 0.005, stroke.size), model + residual)
    measured = analyse(residual, variables_of(data), 0.2)
    assert measured is not None and measured["leading"] == "angle"      # the measured angle: the bias shown
    u = analyse(residual, variables_of(data, residual), 0.2)
    assert u is not None and "angle" not in u["follows"], u["follows"]
    assert u["leading"] in ("time", "cycle") and {"time", "cycle"} <= set(u["follows"]), u["follows"]


def _drifting(seed: int, drift_deg: float):
    """Two samples of 50 cycles (stroke ramps, dwells, rests; 20 Hz), white noise of 0.25 deg, and in S1 a zero that
    drifts ``drift_deg`` over the record: ``(residual, variables)``."""
    rng = np.random.default_rng(seed)
    sample, cycle, t, stroke = _two_cycling_samples()
    residual = rng.normal(0.0, 0.25, stroke.size) + np.where(sample == "S1", drift_deg * (t / t.max() - 0.5), 0.0)
    data = Dataset(sample, cycle, t, stroke, 1.5 * stroke, 15.0 * stroke + residual)
    return residual, variables_of(data, residual)


@pytest.mark.parametrize("seed", [0, 1])
def test_a_slow_drift_is_named_though_the_error_stays_within_the_stop_ratio(seed):
    # bench-heldout44's and 46's tracker drifts: the zero moved 0.3-0.4 deg over five minutes, the error stayed at
    # 1.1x the floor, below the stop ratio, and nothing was said. A drift steady over the record is named (in the
    # sample that carries it) with its size; white noise, or a drift of a tenth of the floor, is not
    residual, v = _drifting(seed, 0.4)
    rmse = float(np.sqrt(np.mean(residual ** 2)))
    assert 0.25 < rmse < 1.15 * 0.25
    u = analyse(residual, v, 0.25)
    assert u is not None and set(u["drift"]) == {"S1"} and u["samples"] == ["S1"]
    assert u["drift"]["S1"]["change_deg"] == pytest.approx(0.4, abs=0.08)
    assert u["leading"] in ("time", "cycle") and {"time", "cycle"} <= set(u["follows"]), u["follows"]
    assert "slow drift" in u["sentence"] and f"sample S1 by {u['drift']['S1']['change_deg']:+.2f} deg" in u["sentence"]
    for small in (0.0, 0.1):
        residual, v = _drifting(seed, small)
        assert analyse(residual, v, 0.245) is None


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_a_small_drift_alike_at_rest_and_under_load_is_named_as_the_instruments_and_one_under_load_is_not(seed):
    # bench-heldout47's tracker drift: 2 deg an hour over five minutes reads 0.2 floors, below the 0.3 a drift needs,
    # and was not named. A tracker's zero moves the rests (the joint straight) as much as the loaded rows; a misfit of
    # the tendon (a creep) moves the loaded rows alone. The first is named at that size, as the instrument's; the
    # second, of the same size in the cycles' means, is not
    from camtube.model.unexplained.analysis import DRIFT_ALIKE_FLOORS, DRIFT_FLOORS, slow_drift

    floor = 0.25
    residual, v = _drifting(seed, 0.2)
    sample, _, t, stroke = _two_cycling_samples()
    creep = _drifting(seed, 0.0)[0] + np.where(sample == "S1", 0.4 * (t / t.max() - 0.5) * stroke / 2.0, 0.0)
    for r in (residual, creep):    # both drifts of a size between the two thresholds, in S1's cycle means
        size = r - _drifting(seed, 0.0)[0]
        means = np.array([size[(sample == "S1") & (v["cycle"] == c)].mean() for c in range(2, 51)])
        assert DRIFT_ALIKE_FLOORS * floor < np.std(means) < DRIFT_FLOORS * floor
    u = analyse(residual, v, floor)
    assert u is not None and set(u["drift"]) == {"S1"} and u["drift"]["S1"]["alike"]
    assert u["drift"]["S1"]["change_deg"] == pytest.approx(0.2, abs=0.06)
    assert "as the tracker's zero makes" in u["sentence"] and "re-zero the tracker" in u["sentence"]
    vc = dict(v, first_cycle=np.asarray(v["cycle"]) == 1)
    assert slow_drift(creep, vc, floor) is None
    assert analyse(creep, variables_of(Dataset(sample, v["cycle"], t, stroke, 1.5 * stroke, 15.0 * stroke + creep),
                                       creep), floor) is None


def test_the_diagnosis_says_a_slow_drift_is_left_and_recommends_nothing_for_it():
    # the paper's physics (truth simulator, tube 2), one sample's tracker zero drifting 0.5 deg over the record: the
    # error stays within 1.15x the floor, nothing is recommended, and the answer names the drift in that sample
    from camtube.design.loader import load_pattern
    from camtube.model.core.predict import model_for_pattern, pattern_values
    from camtube.model.diagnose import diagnose
    from camtube.model.report.diagnosis import answer_lines, diagnosis_dict, diagnosis_text
    from camtube.model.sim.truth import Hidden, simulate

    p = load_pattern(ROOT / "patterns" / "tube2.yaml")
    sim = simulate(p, Hidden(), n_samples=2, n_cycles=40, rate_hz=10.0, seed=31)
    d0 = sim.data
    t = np.asarray(d0.elapsed_s, float)
    s = np.asarray(d0.sample).astype(str)
    mine = s == s[0]
    angle = d0.angle_deg + np.where(mine, 0.5 * (t / t[mine].max() - 0.5), 0.0)
    d = diagnose(model_for_pattern(p), Dataset(d0.sample, d0.cycle, d0.time_s, d0.stroke_mm, d0.force_N, angle),
                 ("E_t",), pattern_values(p))
    assert not d.recommended and not d.partial and d.final.rmse_deg < 1.15 * d.noise_floor_deg
    drift = diagnosis_dict(d)["unexplained"]["drift"]
    assert list(drift) == [s[0]] and 0.35 < drift[s[0]]["change_deg"] < 0.6
    lines = answer_lines(d)
    assert lines[0].startswith("answer: nothing to add")
    assert lines[1].startswith("  left: a slow drift in time"), lines[1]
    assert f"in sample {s[0]} by {drift[s[0]]['change_deg']:+.2f} deg" in lines[1], lines[1]
    assert "nothing is recommended for it" in diagnosis_text(d)


def _twelve_rows_off(seed: int):
    """20,000 rows of a triangle stroke at 20 Hz, white noise of 0.2 deg and 12 rows 20 deg off: ``(the generator,
    the times, the variables, the residual, the rows off)``."""
    rng = np.random.default_rng(seed)
    t = np.arange(20000) * 0.05
    r = rng.normal(0, 0.2, t.size)
    hit = rng.choice(t.size, 12, replace=False)
    r[hit] -= 20.0
    return rng, t, _triangle_variables(t), r, hit


def test_a_misfit_in_a_few_isolated_rows_is_named_as_such_not_as_noise():
    # bench-heldout36's sharp guide: 92 % of the error above the floor sat in 34 of 50,000 rows (the last row of each
    # dwell after a load cell at its limit, 20 deg off; a burst the check missed). Bins average them away, so it
    # "followed none of" the variables, read as noise-like; now the rows are named, with their count and times
    rng, t, v, r, hit = _twelve_rows_off(36)
    n = t.size
    u = analyse(r, v, 0.2)
    assert u is not None and u["rows"] is not None
    assert u["rows"]["n"] == 12 and u["rows"]["share"] > 0.9 and u["rows"]["samples"] == ["A"]
    assert abs(u["rows"]["max_deg"] - 20.0) < 1.5
    assert sorted(round(x[1], 2) for x in u["rows"]["time_s"]) == sorted(
        round(float(t[i]), 2) for i in hit[np.argsort(-r[hit] ** 2)[:5]])
    assert "12 rows" in u["sentence"] and "isolated" in u["sentence"]
    # a structured misfit spread over the rows is not isolated rows
    w = analyse(rng.normal(0, 0.2, n) + 0.8 * (v["direction"] > 0), v, 0.2)
    assert w is not None and w["rows"] is None and w["follows"][0] == "direction"


def test_isolated_rows_left_by_partial_effects_point_to_the_rows_not_to_a_starter():
    # what partial effects leave in a few isolated rows is no form to write an effect for: the text says to look at
    # those rows (an artefact the instruments' check missed) instead of "write the effect (start below)"
    from types import SimpleNamespace

    from camtube.model.unexplained import report

    _, _, v, r, _ = _twelve_rows_off(37)
    u = analyse(r, v, 0.2)
    assert u is not None and u["rows"] is not None and not u["leading"]
    d = SimpleNamespace(cache={"unexplained": u}, recommended=(), partial=("capstan",), noise_floor_deg=0.2)
    text = "\n".join(report.text_lines(d))
    assert "look at the rows named above" in text and "12 rows" in text
    assert "start an effect" not in text and "write the effect" not in text


def test_a_long_record_is_searched_for_a_period_in_time_within_bounded_memory():
    """A 12-hour record at 1 Hz (a creep test; or a record whose ms were read as s): the periodogram in time asked for
    22 GB (0.25 s bins, three periods tried per 1/record of frequency). Its bins widen with the record; an hourly
    misfit is still found, in well under a GB."""
    import tracemalloc

    rng = np.random.default_rng(4)
    t = np.arange(0.0, 12 * 3600.0, 1.0)
    stroke = 2.0 - np.abs(2.0 - (t / 150.0) % 4.0)           # a triangle of 600 s a cycle
    v = {"stroke": stroke, "angle": 10 * stroke, "force": stroke,
         "direction": np.where(np.gradient(stroke) >= 0, 1, -1), "cycle": (t // 600).astype(int) + 1, "time": t,
         "sample": np.full(t.size, "A")}
    r = rng.normal(0.0, 0.3, t.size) + 0.8 * np.sin(2 * np.pi * t / 3600.0)
    tracemalloc.start()
    try:
        u = analyse(r, v, 0.3)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1e9
    assert u is not None
    hourly = [p for p in u["periodic"] if p["variable"] == "time"]
    assert hourly and hourly[0]["period"] == pytest.approx(3600.0, rel=0.02)
