"""The bench simulator (issue 19) and the instruments' check against it: spikes, missing values, lag.

Independent truth: the bench simulator (:mod:`camtube.model.sim.bench`) shares no code with the effect
library; the artefacts it puts in (spike rows, dropouts, the tracker's lag, its noise) are known exactly.
"""
from __future__ import annotations

import argparse
import json
import math
from dataclasses import replace as dc_replace

import numpy as np
import pytest

from camtube.commands import main
from camtube.commands.diagnose import fit_command_prefix
from camtube.design.loader import load_pattern
from camtube.model.core.fit import fit
from camtube.model.core.predict import model_for_pattern, pattern_values
from camtube.model.data import format_csv, read_measurements
from camtube.model.data.dataset import Dataset
from camtube.model.data.select import select_cycles
from camtube.model.diagnose.instruments import check_instruments, with_aside
from camtube.model.diagnose.search import explanation_label, explained_share
from camtube.model.sim.bench import (
    Backbone, Clock, Drive, Guide, LoadCell, Protocol, SampleBench, Tendon, Tracker, motor_profile, simulate_bench,
)
from tests.conftest import PATTERNS

TUBE2 = PATTERNS / "tube2.yaml"
SHORT = Protocol(n_cycles=8, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=2.0)
QUIET = Tracker(noise_deg=0.15, n_spikes=0, n_dropouts=0)


@pytest.fixture(scope="module")
def tube2():
    return load_pattern(TUBE2)


def test_control_bench_fits_the_paper_model_at_its_floor(tube2):
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=50.0, n_repeats=0), seed=1)
    r = fit(model_for_pattern(tube2), rec.data, ["E_t"], pattern_values(tube2))
    assert r.params["E_t"] == pytest.approx(tube2.tendon.modulus_gpa, rel=0.01)
    assert r.rmse == pytest.approx(rec.floor_deg, rel=0.05)


def test_lost_motion_in_the_drive_holds_the_carriage_once_the_tension_falls_below_the_rail_friction(tube2):
    # unloading: below the rail's friction the tendon no longer pulls the carriage back onto the retreating
    # nut, so at rest the carriage (and the joint) stay where the tension fell to the friction (within the
    # backlash); without backlash the joint comes back straight. The next pull takes that gap up first.
    clock = Clock(rate_hz=100.0, n_repeats=0, jitter_ms=0.0)
    free = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, clock, seed=2)
    loose = simulate_bench(tube2, SampleBench(drive=Drive(backlash_mm=0.2, rail_friction_N=0.3), tracker=QUIET),
                           SHORT, clock, seed=2)
    d = free.data
    rest = (d.sample == "S1") & (d.cycle == 3) & (d.stroke_mm == 0.0)
    assert rest.sum() > 50
    assert np.abs(free.angle_true_deg[rest]).max() < 0.05
    assert loose.angle_true_deg[rest].min() > 1.0
    assert np.all(loose.tension_cell_true_N[rest] <= 0.3 + 1e-9)
    # before the first pull nothing is held: both start straight
    assert loose.angle_true_deg[0] == pytest.approx(0.0, abs=1e-9)
    # the record keeps where the carriage stood: on the nut's flank or within its gap above the motor, held up at rest
    lift = loose.carriage_true_mm - d.stroke_mm
    assert lift.min() >= -1e-6 and lift.max() <= 0.2 + 1e-6
    assert lift[rest].min() > 0.05 and np.abs(free.carriage_true_mm - d.stroke_mm).max() < 1e-6


def test_a_settling_carriage_keeps_the_tension_at_the_rail_friction_through_a_rest(tube2):
    """A held carriage whose tension the backbone's recovery raises past the rail's friction at a rest. The law
    before (``settle=False``) lands it on the nut's flank in one step, and the tendon goes nearly slack in most
    rests; a settling carriage slides only until the tension is back at the friction, so it stays there in every
    rest, and the joint stays bent."""
    clock = Clock(rate_hz=100.0, n_repeats=0, jitter_ms=0.0)
    pace = Protocol(n_cycles=8, ramp_s=2.0, dwell_s=1.5, rest_s=1.5, first_dwell_s=1.5)

    def bench(settle):
        return SampleBench(drive=Drive(backlash_mm=0.3, rail_friction_N=0.15, settle=settle),
                           backbone=Backbone(relax=((0.2, 1.0),)), tracker=QUIET)

    jumps = simulate_bench(tube2, bench(False), pace, Clock(rate_hz=100.0, n_repeats=0, jitter_ms=0.0,
                                                            sim_step_ms=1.0), seed=4)
    settles = simulate_bench(tube2, bench(True), pace, clock, seed=4)
    d = settles.data
    slack, held = 0, 0
    for c in range(2, 9):
        rest = (d.sample == "S1") & (d.cycle == c) & (d.stroke_mm == 0.0)
        late = np.flatnonzero(rest)[-20:]
        slack += jumps.tension_cell_true_N[late].max() < 0.05
        held += bool(np.all(np.abs(settles.tension_cell_true_N[late] - 0.15) < 0.005)
                     and settles.angle_true_deg[late].min() > 1.0)
    assert slack >= 4 and held == 7
    # the carriage stays within the gap (the stroke is logged to 1e-6 mm)
    lift = settles.carriage_true_mm - d.stroke_mm
    assert lift.min() >= -1e-6 and lift.max() <= 0.3 + 1e-6


def test_a_settling_carriage_is_the_same_at_one_step_per_row_as_on_a_fine_step(tube2):
    """The simulator's own step (``Clock.sim_step_ms``): with a settling carriage the logged rows of a run at one
    step per row and of a run on a 1 ms step agree to a micrometre in the carriage and a thousandth of a newton in
    the tension, at 25 Hz, where a row is 40 ms of a ramp."""
    b = SampleBench(drive=Drive(backlash_mm=0.15, rail_friction_N=0.12, settle=True),
                    backbone=Backbone(relax=((0.1, 3.0),)), tracker=QUIET)
    coarse = simulate_bench(tube2, b, SHORT, Clock(rate_hz=25.0, n_repeats=0), seed=6)
    fine = simulate_bench(tube2, b, SHORT, Clock(rate_hz=25.0, n_repeats=0, sim_step_ms=1.0), seed=6)
    assert np.array_equal(coarse.data.stroke_mm, fine.data.stroke_mm)
    assert np.abs(coarse.carriage_true_mm - fine.carriage_true_mm).max() < 1e-3
    assert np.abs(coarse.tension_cell_true_N - fine.tension_cell_true_N).max() < 1e-3
    assert (coarse.carriage_true_mm - coarse.data.stroke_mm).max() > 0.05   # the carriage was held


def test_spikes_and_repeated_stamps_are_set_aside_exactly(tube2):
    tr = Tracker(noise_deg=0.15, n_spikes=10, n_dropouts=0)
    rec = simulate_bench(tube2, SampleBench(tracker=tr), SHORT, Clock(rate_hz=50.0, n_repeats=3), seed=3)
    ins = check_instruments(rec.data)
    assert set(ins.aside["angle spike"]) == set(rec.spike_rows)
    assert set(ins.aside["repeated time stamp"]) == set(rec.repeat_rows)
    assert len(ins.aside["force spike"]) == 0
    assert ins.lag.applied_ms == 0.0
    # the errors with the rows set aside counted: a perfect prediction misses exactly the spikes
    rmse, allowed, n = with_aside(ins, np.interp(np.arange(len(ins.data)), np.arange(len(ins.data)),
                                                 ins.data.angle_deg), 0.0)
    assert n == len(rec.spike_rows) + len(rec.repeat_rows)
    assert rmse == pytest.approx(allowed) and allowed > 0.0


def test_a_stroke_that_jumps_for_one_row_is_set_aside_and_its_turns_and_rests_are_not(tube2):
    """The bad-input search: one stroke of 50 mm in a 2 mm record was kept (nothing the library has explained the
    misfit, 427x the floor); the angle's and force's spikes were set aside, the stroke's not."""
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=50.0, n_repeats=0), seed=5)
    clean = check_instruments(rec.data)
    assert "stroke spike" not in clean.aside   # the motion's turns, dwells and rests: none
    stroke = rec.data.stroke_mm.copy()
    rows = [200, 201 + np.flatnonzero(stroke[201:] > 0.5 * stroke.max())[0]]   # at a rest, and on a ramp
    stroke[rows[0]] = 50.0
    stroke[rows[1]] -= 0.3 * np.ptp(stroke)
    bad = Dataset(rec.data.sample, rec.data.cycle, rec.data.time_s, stroke, rec.data.force_N, rec.data.angle_deg)
    ins = check_instruments(bad)
    assert sorted(ins.aside["stroke spike"]) == sorted(rows)
    assert len(ins.data) == len(clean.data) - 2
    r = fit(model_for_pattern(tube2), ins.data, ["E_t"], pattern_values(tube2))
    assert r.params["E_t"] == pytest.approx(tube2.tendon.modulus_gpa, rel=0.02)


@pytest.mark.parametrize("lag_ms", [0.0, 40.0])
def test_the_tracker_lag_is_estimated_within_its_uncertainty_and_corrected(tube2, lag_ms):
    tr = Tracker(noise_deg=0.15, n_spikes=0, n_dropouts=0, lag_ms=lag_ms)
    rec = simulate_bench(tube2, SampleBench(tracker=tr), Protocol(n_cycles=12, ramp_s=2.0, dwell_s=1.0,
                                                                  rest_s=1.0, first_dwell_s=2.0),
                         Clock(rate_hz=50.0, n_repeats=0), seed=4)
    ins = check_instruments(rec.data)
    assert math.isfinite(ins.lag.se_ms) and ins.lag.se_ms < 5.0
    assert abs(ins.lag.lag_ms - lag_ms) < max(3.0 * ins.lag.se_ms, 3.0)
    if lag_ms:
        assert abs(ins.lag.applied_ms - ins.lag.lag_ms) <= 10.0 + 1e-9  # whole rows at 50 Hz
        # corrected, the paper's model fits at the floor again; uncorrected it does not
        model, fixed = model_for_pattern(tube2), pattern_values(tube2)
        after = fit(model, ins.data, ["E_t"], fixed).rmse
        before = fit(model, rec.data, ["E_t"], fixed).rmse
        assert after < 1.1 * rec.floor_deg < before
    else:
        assert ins.lag.applied_ms == 0.0
    assert not ins.lag.per_sample   # both samples' trackers lag alike: one lag


def test_samples_whose_trackers_lag_differently_are_each_corrected_by_their_own_lag(tube2, capsys, tmp_path):
    # two tubes logged in two sessions: one tracker's clock 60 ms behind the load cell's, the other's aligned. One lag
    # over both read neither (bench-heldout27: 76 ms beside none read as 8 ms, not corrected, and the model then
    # fitted play and capstan for a delay); each sample's own lag is read and corrected
    prot = Protocol(n_cycles=12, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=2.0)
    benches = (SampleBench(tracker=dc_replace(QUIET, lag_ms=60.0)), SampleBench(tracker=QUIET))
    rec = simulate_bench(tube2, benches, prot, Clock(rate_hz=50.0, n_repeats=0), seed=5)
    ins = check_instruments(rec.data)
    own = {smp: (ms, se, applied) for smp, ms, se, _, applied in ins.lag.per_sample}
    assert set(own) == {"S1", "S2"}
    ms, se, applied = own["S1"]
    assert abs(ms - 60.0) < max(3.0 * se, 6.0) and abs(applied - ms) <= 20.0 + 1e-9   # whole rows at 50 Hz
    assert own["S2"][2] == 0.0
    assert ins.lag.applied_for("S1") == applied and ins.lag.applied_for("S2") == 0.0
    assert any(line.startswith("angle lag: differs between the samples") for line in ins.lines())
    # corrected so, the paper's model fits at the floor again; as logged it does not
    model, fixed = model_for_pattern(tube2), pattern_values(tube2)
    assert fit(model, ins.data, ["E_t"], fixed).rmse < 1.1 * rec.floor_deg < fit(model, rec.data, ["E_t"], fixed).rmse
    # the same correction given per sample (--lag-ms S1=..,S2=0, as the fit command printed)
    again = check_instruments(rec.data, lag_ms={"S1": applied, "S2": 0.0})
    assert again.lag.given and again.lag.as_option() == ins.lag.as_option()
    assert np.array_equal(again.kept, ins.kept) and np.array_equal(again.data.angle_deg, ins.data.angle_deg)
    # a sample the file does not have, and a malformed value: one line each, exit 2
    path = tmp_path / "two.csv"
    path.write_text(format_csv(rec.data))
    for bad, words in (("S3=20", "no sample 'S3'"), ("S1=20,S2", "is not SAMPLE=MS")):
        try:   # (a value argparse refuses exits; a sample the data lack is the check's error)
            code = main(["model", "diagnose", str(path), "--pattern", str(TUBE2), "--lag-ms", bad])
        except SystemExit as e:
            code = e.code
        assert code == 2
        err = capsys.readouterr().err.strip()
        assert words in err and len(err.splitlines()) == 1 and "Traceback" not in err


def test_a_lag_the_blocks_of_cycles_disagree_on_is_not_resolved(tube2):
    # a tracker whose clock drifts against the logger's: its delay grows from 0 to 150 ms through the record. The
    # whole record's best shift (86 ms) is no block's: each block's minimum lay at the edge of the 3 rows either side
    # of it, and the standard error of those edges (7.6 ms) read as resolved, so 90 ms was corrected. Blocks whose
    # minima lie outside that window (half of them or more) do not agree on a delay: not resolved, none corrected
    prot = Protocol(n_cycles=24, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=2.0)
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), prot, Clock(rate_hz=100.0, n_repeats=0), seed=3)
    d = rec.data
    a = d.angle_deg.copy()
    for _, sl in d.sample_slices():
        t = d.time_s[sl]
        a[sl] = np.interp(t - 0.15 * (t - t[0]) / (t[-1] - t[0]), t, d.angle_deg[sl])
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, a))
    assert not math.isfinite(ins.lag.se_ms) and ins.lag.applied_ms == 0.0
    assert any(line.startswith("angle lag: not resolved") for line in ins.lines())
    steady = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N,
                                       np.concatenate([np.interp(d.time_s[sl] - 0.075, d.time_s[sl], d.angle_deg[sl])
                                                       for _, sl in d.sample_slices()])))
    assert abs(steady.lag.lag_ms - 75.0) < 3.0 * steady.lag.se_ms + 5.0 and steady.lag.applied_ms > 0.0


@pytest.mark.parametrize("lag_ms", [0.0, 40.0])
def test_friction_at_the_guide_is_not_read_as_a_tracker_lag(tube2, lag_ms):
    """The guide's hysteresis fades in and out with the tendon's speed at every start and stop, which a delay of
    the angle mimics: the lag regression has the capstan's sliding state among its regressors (issue 19: 10-40 ms
    false lags were corrected on friction files), and a real lag beside the friction is still found."""
    tr = Tracker(noise_deg=0.15, n_spikes=0, n_dropouts=0, lag_ms=lag_ms)
    rec = simulate_bench(tube2, SampleBench(guide=Guide(mu=0.2), tracker=tr),
                         Protocol(n_cycles=12, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=2.0),
                         Clock(rate_hz=50.0, n_repeats=0), seed=6)
    ins = check_instruments(rec.data)
    assert abs(ins.lag.lag_ms - lag_ms) < max(3.0 * ins.lag.se_ms, 5.0)
    assert (ins.lag.applied_ms == 0.0) if not lag_ms else abs(ins.lag.applied_ms - lag_ms) <= 10.0 + 1e-9
    # and the capstan law then fits the guide at the floor
    model, fixed = model_for_pattern(tube2, ["capstan"]), pattern_values(tube2)
    r = fit(model, ins.data, ["E_t", "capstan.mu_wrap", "capstan.slip_mm_s", "capstan.hold"], fixed)
    assert r.rmse < 1.1 * rec.floor_deg
    assert abs(r.params["capstan.mu_wrap"] / (0.2 * math.pi / 2) - 1.0) < 0.05


@pytest.mark.parametrize("lag_ms, crimp_mm", [(0.0, 0.0), (70.0, 0.0), (0.0, 0.03), (70.0, 0.03)])
def test_a_resolved_lag_the_regression_barely_improves_with_is_tested_against_the_model(tube2, lag_ms, crimp_mm):
    """At 25 Hz a lag of two rows may lower the lag regression's residual by less than 2 %, and was left
    uncorrected (issue 19: the fourth batch's 70 ms lag). confirm_lag fits the current model with the angle read
    the estimate's whole rows later (and a row either side) and corrects the lag when that lowers the RMSE by
    5 %; on a record without a lag the same estimate is refused (the shifted angle fits worse).

    With a small toe beside it (a 0.03 mm crimp) the paper model sits above 3x the angle's noise, where the check
    was not tried (bench-heldout16's 70 ms lag); the lag's own misfit (the angle's rate times the lag) now counts
    with the noise, and the lag is corrected, and refused without one, as before."""

    from camtube.model.core.noise import white_noise_sd
    from camtube.model.diagnose.instruments import MODEL_LAG_MAX_RATIO, Lag, confirm_lag, lag_misfit_deg

    tr = Tracker(noise_deg=0.15, n_spikes=0, n_dropouts=0, lag_ms=lag_ms)
    slow = Protocol(n_cycles=6, ramp_s=7.0, dwell_s=5.0, rest_s=5.0, first_dwell_s=5.0)  # the batches' pace
    rec = simulate_bench(tube2, SampleBench(tracker=tr, tendon=Tendon(crimp_mm=crimp_mm)), slow,
                         Clock(rate_hz=25.0, n_repeats=0), seed=7)
    ins = check_instruments(rec.data, lag_ms=0.0)
    # the regression's verdict, as on the batch file: resolved (60 +- 10 ms) but a fall below 2 %
    ins = dc_replace(ins, lag=Lag(60.0, 10.0, fall=0.01))
    model, fixed = model_for_pattern(tube2), pattern_values(tube2)
    out = confirm_lag(ins, model, fixed)
    if crimp_mm:   # above 3x the noise alone: the lag's own misfit (60 ms at 4-5 deg/s RMS: 0.2-0.3 deg) counts
        r0 = fit(model, ins.data, ["E_t"], fixed)
        noise = min(white_noise_sd(r0.residuals[sl]) for _, sl in ins.data.sample_slices())
        own = lag_misfit_deg(ins.data, 60.0)
        assert MODEL_LAG_MAX_RATIO * noise < r0.rmse <= MODEL_LAG_MAX_RATIO * math.hypot(noise, own)
        assert 0.15 < own < 0.35
    if lag_ms:
        assert abs(out.lag.applied_ms - lag_ms) <= 40.0 + 1e-9 and out.lag.model_rmse_deg
        assert out.lag.model_rmse_deg[1] < 0.95 * out.lag.model_rmse_deg[0]
        assert "current model's RMSE falls" in out.lines()[-1]
    else:
        assert out is ins and out.lag.applied_ms == 0.0


@pytest.mark.parametrize("lag_ms", [0.0, 60.0])
def test_samples_own_lags_a_few_errors_apart_are_each_tested_against_the_model(tube2, lag_ms):
    """The samples' own lags 4-10 standard errors apart are not split by the regression alone (a backbone's
    relaxation biases one sample's estimate by tens of ms: bench-heldout27's three-arm backbone, no lag, read 18 +- 2.6
    beside -4.9 +- 1.5 ms); a lag in one sample beside a backbone in the other read 31.8 +- 2.5 beside -11.5 +- 4.1
    (bench-heldout28, 9 apart), and one lag over both (14.9 +- 5.0) was not resolved. Each sample's own lag is then
    tested against the current model fitted to that sample's rows: corrected where it lowers that RMSE by 5 %,
    refused where the tracker had no lag (the shifted angle fits worse)."""
    from camtube.model.diagnose.instruments import Lag, confirm_lag

    prot = Protocol(n_cycles=8, ramp_s=4.0, dwell_s=2.0, rest_s=2.0, first_dwell_s=3.0)
    benches = (SampleBench(tracker=dc_replace(QUIET, lag_ms=lag_ms)), SampleBench(tracker=QUIET))
    rec = simulate_bench(tube2, benches, prot, Clock(rate_hz=50.0, n_repeats=0), seed=8)
    ins = check_instruments(rec.data, lag_ms=0.0)
    # the regression's verdict, as on the batch file: each sample resolved, 8.5 standard errors apart
    own = (("S1", 60.0, 5.0, 0.01), ("S2", 0.0, 5.0, 0.0))
    ins = dc_replace(ins, lag=Lag(30.0, 20.0, fall=0.005, own=own))
    out = confirm_lag(ins, model_for_pattern(tube2), pattern_values(tube2))
    if lag_ms:
        applied = {smp: a for smp, _, _, _, a in out.lag.per_sample}
        assert abs(applied["S1"] - lag_ms) <= 20.0 + 1e-9 and applied["S2"] == 0.0
        (smp, before, after), = out.lag.model_rmse_deg
        assert smp == "S1" and after < 0.95 * before
        assert any("the current model's RMSE in S1 falls" in line for line in out.lines())
    else:
        assert out is ins and not out.lag.corrected


def test_samples_own_lags_apart_are_tested_on_their_own_rows_though_one_lag_was_corrected_in_both():
    # S1's tracker 60 ms late (noisy, filtered), S2's on time beside a backbone relaxing on two time scales with a
    # set: the samples' own lags read 65 +- 7 and -9 +- 3 ms, too close for the regression to split them alone, and
    # one lag over both (30 +- 10 ms) is resolved and corrected, one row of 25 ms in each. The samples' own lags are
    # then tested on their own rows with the angle as logged: S1's is confirmed by the model, S2 keeps its angle
    # (bench-heldout40's lag beside a backbone: play and friction had stood in for the 37 ms left in S1)
    from camtube.model.diagnose.instruments import confirm_lag

    tube1 = load_pattern(PATTERNS / "tube1.yaml")
    late = SampleBench(tracker=Tracker(noise_deg=0.3, n_spikes=4, n_dropouts=0, lag_ms=60.0, filter_ms=40.0),
                       backbone=Backbone(relax=((0.05, 3.0),)))
    on_time = SampleBench(tracker=Tracker(noise_deg=0.15, n_spikes=4, n_dropouts=0),
                          backbone=Backbone(relax=((0.33, 3.5), (0.12, 17.0)), yield_nmm=5.3, set_rate_per_s=0.03))
    proto = Protocol(n_cycles=16, ramp_s=4.5, dwell_s=3.0, rest_s=3.0, first_dwell_s=3.0)
    rec = simulate_bench(tube1, (late, on_time), proto, Clock(rate_hz=40.0, n_repeats=0), seed=11)
    ins = check_instruments(rec.data)
    assert ins.lag.applied_ms == pytest.approx(25.0) and not ins.lag.per_sample      # the premise: one lag in both
    got = confirm_lag(ins, model_for_pattern(tube1), pattern_values(tube1))
    assert got.lag.applied_for("S1") == pytest.approx(50.0) and got.lag.applied_for("S2") == 0.0
    (smp, before, after), = got.lag.model_rmse_deg
    assert smp == "S1" and after < 0.95 * before
    assert any("differs between the samples" in line and "--lag-ms S1=50,S2=0" in line for line in got.lines())
    # a tracker's rows shifted 50 ms in S1 only: S2's angles are as logged
    s2 = np.asarray(got.data.sample) == "S2"
    raw2 = np.asarray(rec.data.sample) == "S2"
    assert np.array_equal(got.data.angle_deg[s2], rec.data.angle_deg[raw2 & got.kept])


def test_a_load_cell_at_its_limit_in_half_the_rows_does_not_shrink_the_forces_noise_scale():
    """A cell at its limit reads one value exactly, so half a sample's row-to-row changes are 0: read over them, the
    force's noise scale came out near 0 and rows of plain noise were set aside as spikes (809 in one file of
    bench-heldout44). With the limit's rows left out of the scale, no row of noise is a spike, and a real one still is."""
    from camtube.model.diagnose.instruments import _noise_scale, _spikes

    rng = np.random.default_rng(3)
    t = np.arange(6000) * 0.02
    force = 2.0 * np.clip(np.sin(2 * np.pi * t / 12.0), 0.0, None) + rng.normal(0.0, 0.005, t.size)
    limit = force >= 0.3
    force[limit] = 0.3                     # the cell's limit: the same reading while the tension goes on
    force[450] -= 0.2                      # one real spike, at a rest
    assert not limit[450]
    slices = [("S1", slice(0, t.size))]
    assert _noise_scale(force, limit) == pytest.approx(0.005, rel=0.2)   # (the ramps add a little)
    assert _noise_scale(force) < 0.5 * _noise_scale(force, limit)
    found = np.flatnonzero(_spikes(force, slices, limit=limit) & ~limit)
    assert list(found) == [450]
    assert np.flatnonzero(_spikes(force, slices) & ~limit).size > 10   # at the scale read over the limit's rows


def test_the_lag_regressions_normal_equations_match_the_svd_and_give_way_where_columns_are_dependent():
    """The lag scan's least squares (normal equations, for speed) against the SVD's: the same residual where the
    columns are independent; where one is all zeros (a sample that never rests) or two are copies, the SVD's
    minimum-norm answer."""
    from camtube.model.diagnose.instruments import _least_squares

    rng = np.random.default_rng(7)
    x = rng.normal(size=(3000, 12)) * np.logspace(-3, 3, 12)
    a = x @ rng.normal(size=12) + rng.normal(size=3000)
    want = np.linalg.lstsq(x, a, rcond=None)[0]
    r_fast, r_svd = a - x @ _least_squares(x, a), a - x @ want
    assert abs(r_fast @ r_fast / (r_svd @ r_svd) - 1.0) < 1e-10
    for bad in (np.zeros(3000), x[:, 3].copy()):
        xb = np.column_stack([x, bad])
        np.testing.assert_allclose(_least_squares(xb, a), np.linalg.lstsq(xb, a, rcond=None)[0], rtol=1e-9, atol=1e-12)


def test_missing_values_are_dropped_and_counted_or_refused_with_the_line(tube2, tmp_path, capsys):
    tr = Tracker(noise_deg=0.15, n_spikes=4, n_dropouts=3, dropout_rows=(2, 5))
    slow = Protocol(n_cycles=4, ramp_s=6.0, dwell_s=2.0, rest_s=2.0, first_dwell_s=4.0)  # the bench files' pace
    rec = simulate_bench(tube2, SampleBench(tracker=tr), slow, Clock(rate_hz=25.0, n_repeats=1), seed=5)
    path = tmp_path / "bench.csv"
    path.write_text(format_csv(rec.data))
    meas = read_measurements(path)
    assert meas.missing_lines.size == rec.dropout_rows.size
    assert np.all(meas.missing_lines == rec.dropout_rows + 2)  # line 1 is the header
    js = tmp_path / "d.json"
    assert main(["model", "diagnose", str(path), "--pattern", str(TUBE2), "-q", "--json", str(js),
                 "--no-per-sample"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[1].startswith("answer:")
    assert f"{rec.dropout_rows.size} row(s) with a missing value (nan/empty) dropped (lines {rec.dropout_rows[0] + 2}" in out
    ins = json.loads(js.read_text())["instruments"]
    spikes = set(rec.spike_rows) - set(rec.dropout_rows)  # a dropout can fall on a spike
    assert ins["rows_dropped"] == rec.dropout_rows.size and ins["rows_set_aside"]["angle spike"] == len(spikes)
    assert main(["model", "diagnose", str(path), "--pattern", str(TUBE2), "-q", "--strict"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and f"{path}:{rec.dropout_rows[0] + 2}" in err and "'nan'" in err


def test_backward_time_stamps_are_dropped_and_counted(tmp_path):
    path = tmp_path / "t.csv"
    path.write_text("sample,cycle,time_s,stroke_mm,force_N,angle_deg\n"
                    "A,1,0.0,0,0,0\nA,1,0.1,0.1,0.1,1\nA,1,0.05,0.1,0.1,1\nA,1,0.2,0.2,0.2,2\n")
    meas = read_measurements(path)
    assert list(meas.backward_lines) == [4] and len(meas.data) == 3
    assert "time stamp goes backwards dropped (lines 4)" in meas.summary()


def _rows_csv(path, times, cycles):
    lines = ["sample,cycle,time_s,stroke_mm,force_N,angle_deg"]
    lines += [f"A,{c},{t:g},{0.1 * (i % 7)},{0.05 * (i % 7)},{i % 7}" for i, (t, c) in enumerate(zip(times, cycles))]
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("strict", [False, True])
def test_a_time_that_starts_again_with_each_cycle_is_refused_not_dropped(tmp_path, strict):
    # a logger that writes the time since the cycle began: read as glitches, every row behind the first cycle's last
    # stamp was dropped (770 of 59,949 rows analysed, said in one line among the instruments' findings)
    from camtube.errors import DataError

    times = [0.1 * (i % 20) for i in range(100)]
    path = _rows_csv(tmp_path / "t.csv", times, [1 + i // 20 for i in range(100)])
    with pytest.raises(DataError) as exc:
        read_measurements(path, strict=strict)
    msg = str(exc.value)
    assert msg.startswith(f"{path}:22: column 'time_s' starts again with each cycle in sample 'A' (4 times")
    assert "fix: give the time since the sample's record began" in msg


def test_more_backward_stamps_than_glitches_are_refused(tmp_path):
    from camtube.errors import DataError

    times = [0.1 * i for i in range(1000)]
    for i in range(500, 650):                       # 150 rows, 15 % of them, stamped 20 s early
        times[i] -= 20.0
    path = _rows_csv(tmp_path / "t.csv", times, [1] * 1000)
    with pytest.raises(DataError, match=r":502: 150 of 1000 rows have a time stamp below one before them .*"
                                        r"fix: sort each sample's rows by time"):
        read_measurements(path)
    for i in range(510, 650):                       # 10 rows: a logger's glitches, dropped and counted
        times[i] += 20.0
    meas = read_measurements(_rows_csv(tmp_path / "t.csv", times, [1] * 1000))
    assert meas.backward_lines.size == 10 and len(meas.data) == 990


def test_explanation_label_is_complete_partial_or_nothing():
    # complete within 1.15 x; partial when >= 95 % of the excess is explained and within 1.5 x, or >= 98 % and
    # within 3 x; else nothing
    assert explanation_label(5.0, 1.1, 1.0) == "complete"
    assert explanation_label(16.0, 1.3, 1.0) == "partial"
    assert explained_share(16.0, 1.3, 1.0) == pytest.approx((256 - 1.69) / 255)
    assert explanation_label(1.5, 1.16, 1.0) == ""      # a stand-in: 72 % of a small misfit
    assert explanation_label(8.67, 2.01, 1.0) == ""     # 96 % but far above the floor
    assert explanation_label(9.93, 2.84, 1.0) == ""     # 93 %: the foreign batches' stand-ins stay at or below 96 %
    # >= 98 % of the misfit explained, within 3x: a three-arm backbone beside the library's two (bench-heldout54)
    assert explanation_label(78.8, 1.79, 1.0) == "partial"
    assert explanation_label(17.08, 2.02, 1.0) == "partial"
    assert explanation_label(40.0, 3.1, 1.0) == ""      # beyond 3x, however much is explained


def test_motor_profile_dwells_rests_and_a_longer_first_dwell():
    p = Protocol(n_cycles=3, ramp_s=1.0, dwell_s=0.5, rest_s=0.5, first_dwell_s=2.0)
    t = np.arange(0.0, 3 * 3.0 + 1.5, 0.01)
    x, cyc = motor_profile(p, 2.0, t)
    assert x.max() == pytest.approx(2.0) and x.min() == pytest.approx(0.0)
    top = [float(np.sum((cyc == k) & (x > 1.999)) * 0.01) for k in (1, 2, 3)]
    assert top[0] == pytest.approx(2.0, abs=0.05) and top[1] == pytest.approx(0.5, abs=0.05)


def test_the_report_opens_with_the_answer_then_the_pictures_then_the_table(tube2, tmp_path, capsys):
    tr = Tracker(noise_deg=0.15, n_spikes=4, n_dropouts=1, dropout_rows=(2, 3))
    slow = Protocol(n_cycles=6, ramp_s=4.0, dwell_s=2.0, rest_s=2.0, first_dwell_s=4.0)
    rec = simulate_bench(tube2, SampleBench(tendon=Tendon(slack_mm=0.12), tracker=tr), slow,
                         Clock(rate_hz=25.0, n_repeats=1), seed=6)
    path = tmp_path / "slack.csv"
    path.write_text(format_csv(rec.data))
    rep = tmp_path / "rep"
    assert main(["model", "diagnose", str(path), "--pattern", str(TUBE2), "-q", "--report", str(rep),
                 "--no-per-sample"]) == 0
    out = capsys.readouterr().out
    assert out.splitlines()[1].startswith("answer: add slack")
    page = (rep / "index.html").read_text()
    order = [page.index(k) for k in ("<h2>Answer</h2>", "model.png", "waterfall.png", "artefacts.png",
                                     "<h2>Candidates</h2>", "<h2>The diagnosis in full</h2>")]
    assert order == sorted(order)
    assert "answer: add slack" in page[:page.index("model.png")]
    assert (rep / "artefacts.png").stat().st_size > 1000


def test_a_change_of_the_logging_rate_is_reported():
    from camtube.model.data import Dataset

    t = np.concatenate((np.arange(0.0, 40.0, 0.02), 40.0 + np.arange(0.0, 40.0, 0.04)))
    x = 1.0 - np.cos(2 * np.pi * t / 8.0)
    n = t.size
    d = Dataset(np.full(n, "A", dtype=object), (t // 8).astype(int) + 1, t, x, 2.0 * x, 20.0 * x)
    ins = check_instruments(d)
    assert ins.rates_hz["A"] == pytest.approx(50.0)
    assert any("sampling rate of sample A changes: 25 Hz from t = 40" in line for line in ins.lines())


def test_time_stamps_that_look_like_ms_are_asked_about():
    from camtube.model.data import Dataset

    t = np.arange(0.0, 40.0, 0.02)
    x = 1.0 - np.cos(2 * np.pi * t / 8.0)
    n = t.size

    def lines(time_col):
        d = Dataset(np.full(n, "A", dtype=object), (t // 8).astype(int) + 1, time_col, x, 2.0 * x, 20.0 * x)
        return check_instruments(d).lines()

    asked = [line for line in lines(1000.0 * t) if "in ms" in line]
    assert len(asked) == 1 and "A a row every 20 s" in asked[0] and "divided by 1000" in asked[0]
    assert not any("in ms" in line for line in lines(t))   # 50 Hz: nothing asked


def test_a_relaxing_backbone_is_recommended_in_the_place_of_the_rest_angle(tube2):
    """A backbone with a Maxwell arm (the bench simulator's joint, no set): the unloaded joint stands at
    k1 / (k + k1) of the arm's relaxed angle and creeps back. The baseline's constant rest angle takes some of it;
    `relaxation` explains it in its place (the rest angle held at 0, said so, and held in the printed command),
    with the physical share and relaxation time, to the floor."""
    from camtube.model.diagnose import diagnose
    from camtube.model.report.diagnosis import add_command, diagnosis_text
    from camtube.model.sim.bench import Backbone

    share, tau_s = 0.3, 2.0
    pace = Protocol(n_cycles=12, ramp_s=3.0, dwell_s=2.0, rest_s=3.0, first_dwell_s=2.0)
    bench = SampleBench(backbone=Backbone(relax=((share, tau_s),)), tracker=QUIET)
    rec = simulate_bench(tube2, bench, pace, Clock(rate_hz=25.0, n_repeats=0), seed=5)
    d = diagnose(model_for_pattern(tube2), rec.data, ("E_t",), pattern_values(tube2))
    assert d.baseline == ("rest_angle",) and d.recommended == ("relaxation",)
    assert d.held == {"rest_angle.rest_deg": 0.0}
    final = d.waterfall[-1]
    assert final.rmse_deg <= 1.15 * rec.floor_deg < d.waterfall[0].rmse_deg / 2.0
    assert abs(final.params["relaxation.fraction"] / (share / (1.0 + share)) - 1.0) < 0.05
    assert abs(final.params["relaxation.tau_s"] / tau_s - 1.0) < 0.1
    assert "rest_angle (the baseline) held at rest_angle.rest_deg = 0" in diagnosis_text(d)
    assert "--fix rest_angle.rest_deg=0" in add_command(d, "camtube model fit x.csv")


def test_when_only_the_chosen_effect_helped_every_other_effect_is_tried_once_more(tmp_path):
    """A backbone with two relaxing arms and a permanent set (the bench simulator's seventh held-out batch's
    backbone file, shortened to 30 cycles): on the model as given only `relaxation` (and nothing else) lowers the
    error, so the next round's narrowed pool was empty and the search stopped with a partial `relaxation`. The
    effects left out are now tried once more, and what it leaves (a bent rest, the tracker's offset) is found:
    the chain is recommended and ends within 1.15 x the true floor."""
    from camtube.model.diagnose import diagnose
    from camtube.model.effects import BUILTINS
    from camtube.model.sim.bench import Backbone, Guide, LoadCell, Tendon, Tracker

    tube1 = load_pattern(PATTERNS / "tube1.yaml")

    def bench(backlash, mu, crimp, creep, relax, yield_nmm, set_rate, noise):
        return SampleBench(drive=Drive(backlash_mm=backlash, rail_friction_N=0.05), load_cell=LoadCell(),
                           guide=Guide(mu=mu), tendon=Tendon(crimp_mm=crimp, creep_A_mm_per_s=creep),
                           backbone=Backbone(relax=relax, yield_nmm=yield_nmm, set_rate_per_s=set_rate),
                           tracker=Tracker(noise_deg=noise))

    b1 = bench(1.388e-4, 2.559e-4, 6.832e-3, 6.346e-8, ((0.3165, 1.192), (0.1340, 31.52)), 3.448, 0.02211, 0.2426)
    b2 = bench(6.663e-4, 1.321e-4, 4.202e-3, 4.261e-7, ((0.4454, 2.703), (0.1912, 23.96)), 4.740, 0.03233, 0.2279)
    pace = Protocol(n_cycles=30, ramp_s=2.0, dwell_s=4.0 / 3.0, rest_s=4.0 / 3.0, first_dwell_s=4.0 / 3.0)
    rec = simulate_bench(tube1, (b1, b2), pace, Clock(rate_hz=50.0), seed=2026122906)
    path = tmp_path / "backbone.csv"
    path.write_text(format_csv(rec.data))
    data = check_instruments(read_measurements(path).data).data
    # the library as it was then (one relaxing arm): the retry is what this test is about
    one_arm = [e for e in BUILTINS if e != "relaxation2"]
    d = diagnose(model_for_pattern(tube1), data, ("E_t",), pattern_values(tube1), candidates=one_arm)
    assert d.recommended[:1] == ("relaxation",) and len(d.recommended) > 1, (d.recommended, d.partial,
                                                                            d.stop_reason)
    assert d.final.rmse_deg <= 1.15 * rec.floor_deg
    # with the whole library the two arms are found as two: `relaxation2` first, to the floor
    d2 = diagnose(model_for_pattern(tube1), data, ("E_t",), pattern_values(tube1))
    assert d2.recommended[:1] == ("relaxation2",), (d2.recommended, d2.partial, d2.stop_reason)
    assert d2.final.rmse_deg <= 1.15 * rec.floor_deg and d2.waterfall[1].rmse_deg < d.waterfall[1].rmse_deg


def test_a_carriage_its_rail_holds_is_recommended_first_as_lost_motion_in_the_drive(tube2):
    """Lost motion in the drive, as the bench simulator makes it (its own time-stepped drive, no effect code):
    below the rail's friction the carriage stays while the nut retreats, so the joint rests bent with the tendon
    taut until the carriage lets go. Two samples with rails of different friction. `carriage_hold` is recommended
    first (said to sit in the drive, not in the tendon), in the place of the baseline's rest angle, and the chain
    ends within 1.15 x the true floor."""
    from camtube.model.diagnose import diagnose
    from camtube.model.report.diagnosis import diagnosis_text
    from camtube.model.sim.bench import Backbone

    def bench(friction_N):
        return SampleBench(drive=Drive(backlash_mm=0.2, rail_friction_N=friction_N),
                           backbone=Backbone(relax=((0.08, 3.0),)), tracker=QUIET)

    pace = Protocol(n_cycles=16, ramp_s=3.0, dwell_s=2.0, rest_s=2.0, first_dwell_s=2.0)
    rec = simulate_bench(tube2, (bench(0.17), bench(0.12)), pace, Clock(rate_hz=50.0, n_repeats=0), seed=11)
    d = diagnose(model_for_pattern(tube2), rec.data, ("E_t",), pattern_values(tube2))
    assert d.recommended[:1] == ("carriage_hold",), (d.recommended, d.partial, d.stop)
    assert d.final.rmse_deg <= 1.15 * rec.floor_deg < d.waterfall[0].rmse_deg / 1.5
    assert "sits in the drive" in diagnosis_text(d)



def test_a_carriage_the_baseline_rest_angle_stood_in_for_is_credited_with_it(tube2):
    """A rail that holds its carriage at 0.16 N within a 0.16 mm gap, beside a small toe and a backbone that relaxes
    (one sample, 50 cycles at 40 Hz). The baseline's rest angle joins first (the held carriage keeps the joint bent at
    rest as a rest angle would) and takes most of the misfit, so the drive's own step looked small and the chain's
    share of the misfit, counted from the model with the baseline, fell short of a partial explanation: nothing was
    recommended at twice the floor. The share is counted from the model as given where a recommended effect can stand
    in for a baseline effect that joined: the drive is recommended first."""
    from camtube.model.diagnose import diagnose
    from camtube.model.sim.bench import Backbone

    pace = Protocol(n_cycles=50, ramp_s=4.5, dwell_s=3.0, rest_s=3.0, first_dwell_s=3.0)
    held = SampleBench(drive=Drive(backlash_mm=0.16, rail_friction_N=0.16), tendon=Tendon(crimp_mm=0.0056),
                       backbone=Backbone(relax=((0.09, 3.0),)), tracker=Tracker(noise_deg=0.2, n_spikes=0, n_dropouts=0))
    rec = simulate_bench(tube2, (held,), pace, Clock(rate_hz=40.0, n_repeats=0), seed=3)
    d = diagnose(model_for_pattern(tube2), rec.data, ("E_t",), pattern_values(tube2))
    assert "rest_angle" in d.baseline
    assert d.recommended[:1] in (("carriage_gap",), ("carriage_hold",)), (d.recommended, d.partial, d.stop)
    # the rest angle took most of it: counted from the model with it, the chain explains less than a partial share
    assert explained_share(d.waterfall[0].rmse_deg, d.final.rmse_deg, d.noise_floor_deg) < 0.95
    assert explained_share(d.given.rmse_deg, d.final.rmse_deg, d.noise_floor_deg) >= 0.95
    assert d.final.rmse_deg <= 1.5 * rec.floor_deg
    if d.explanation == "partial":
        assert "can stand in for the baseline's rest_angle" in d.stop_reason
    # the answer says where the rest angle's share went
    from camtube.model.report.diagnosis import diagnosis_text
    assert f"but {d.recommended[0]} can stand in for it" in diagnosis_text(d)

def _drifting_zero(tube2, drift_N_per_h: float, offset_N: float = 0.0, seed: int = 7):
    """A 12-cycle bench file at 25 Hz whose sample S1's load cell zero drifts (S2's is steady)."""
    from dataclasses import replace

    from camtube.model.sim.bench import LoadCell

    slow = Protocol(n_cycles=12, ramp_s=6.0, dwell_s=2.0, rest_s=3.0, first_dwell_s=4.0)
    s1 = SampleBench(load_cell=LoadCell(drift_N_per_h=drift_N_per_h), tracker=QUIET)
    rec = simulate_bench(tube2, (s1, SampleBench(tracker=QUIET)), slow, Clock(rate_hz=25.0, n_repeats=0), seed=seed)
    if offset_N:
        m = rec.data.sample == "S1"
        rec = replace(rec, data=rec.data.with_force(rec.data.force_N + offset_N * m))
    return rec


def _from_first_pull(data: Dataset) -> Dataset:
    """``data`` without each sample's rows before its stroke first moves (a record started with the first pull)."""
    keep = np.ones(len(data), bool)
    for _, sl in data.sample_slices():
        s = data.stroke_mm[sl]
        keep[sl.start:sl.start + int(np.flatnonzero(s > s.min() + 1e-3 * np.ptp(s))[0])] = False
    return data.take(np.flatnonzero(keep))


def test_a_drifting_load_cell_zero_is_read_at_the_rests_and_corrected(tube2, tmp_path, capsys):
    """The tendon is slack at every rest, so the force there is the load cell's zero: a drift of the zero is found
    (within 20 % of the truth), corrected at every rest in that sample only, said, and carried into the fit
    command (--rezero), which then gives the diagnosis's own fit."""
    rec = _drifting_zero(tube2, 2.0)
    t1 = rec.data.time_s[rec.data.sample == "S1"]
    true_change = 2.0 * (t1[-1] - t1[0]) / 3600.0
    ins = check_instruments(rec.data)
    z1, z2 = ins.zeros["S1"], ins.zeros["S2"]
    assert z1.applied and not z2.applied and not z2.drifts
    assert z1.change_N == pytest.approx(true_change, rel=0.2), (z1.change_N, true_change)
    rest = (ins.data.sample == "S1") & (ins.data.stroke_mm == 0.0)
    assert abs(float(np.median(ins.data.force_N[rest]))) < 0.1 * true_change
    assert abs(float(np.median(rec.data.force_N[(rec.data.sample == "S1") & (rec.data.stroke_mm == 0.0)]))) > 0.3 * true_change
    # the same file as read: the command line says it and carries it into the fit command
    path = tmp_path / "zero.csv"
    path.write_text(format_csv(rec.data))
    js = tmp_path / "d.json"
    assert main(["model", "diagnose", str(path), "--pattern", str(TUBE2), "-q", "--json", str(js)]) == 0
    out = capsys.readouterr().out
    assert "load cell zero: at S1's rests (motor at zero, tendon slack)" in out and "corrected" in out
    got = json.loads(js.read_text())
    assert got["instruments"]["load_cell_zero"]["S1"]["rezeroed"] is True
    assert got["instruments"]["load_cell_zero"]["S2"]["rezeroed"] is False
    # the reading before the first pull: a cell zeroed before the test reads 0 there (its drift starts from it)
    first = got["instruments"]["load_cell_zero"]["S1"]
    assert abs(first["before_first_pull_N"]) < 0.02 and first["held_at_rest"] is False
    assert not set(got["recommended"]) & {"creep", "creep_load", "viscoelastic", "force_zero"}, got["recommended"]
    assert "--rezero" in fit_command_prefix(argparse.Namespace(data=str(path), pattern=str(TUBE2), overrides=[],
                                                               cycles="all", effect_file=[], fix=[]),
                                            check_instruments(read_measurements(path).data)).split()
    fj = tmp_path / "f.json"
    fit_cmd = ["model", "fit", str(path), "--pattern", str(TUBE2), "--set-aside", "--rezero", "--cycles", "all",
               "--branch", "both", "--no-deadband",
               "--effects", ",".join(got["final"]["effects"]), "--json", str(fj)]
    assert main(fit_cmd) == 0
    assert "the force re-zeroed at every rest (--rezero)" in capsys.readouterr().out
    assert json.loads(fj.read_text())["rmse_deg"] == pytest.approx(got["final"]["rmse_deg"], rel=1e-3)
    assert main([a for a in fit_cmd if a != "--rezero"]) == 0   # without --rezero: the drift stays in the force
    capsys.readouterr()
    assert json.loads(fj.read_text())["rmse_deg"] > 2.0 * got["final"]["rmse_deg"]
    # --no-rezero keeps the force as read, and says so
    assert main(["model", "diagnose", str(path), "--pattern", str(TUBE2), "-q", "--no-rezero", "--no-per-sample",
                 "--max-effects", "0"]) == 0
    out = capsys.readouterr().out
    assert "not corrected (--no-rezero)" in out and "--rezero" not in out.replace("--no-rezero", "")


def test_a_force_that_stays_at_rest_is_not_taken_for_the_zero(tube2):
    """A carriage its rail holds keeps the tendon taut at every rest (lost motion in the drive): the force there is
    tension, not the load cell's zero; a cell not zeroed before the test reads an offset at the first rests. Neither
    is re-zeroed, and each is said."""
    held = simulate_bench(tube2, SampleBench(drive=Drive(backlash_mm=0.2, rail_friction_N=0.3), tracker=QUIET),
                          Protocol(n_cycles=10, ramp_s=4.0, dwell_s=1.0, rest_s=2.0, first_dwell_s=2.0),
                          Clock(rate_hz=50.0, n_repeats=0), seed=2)
    ins = check_instruments(held.data)
    assert not any(z.applied for z in ins.zeros.values())
    assert ins.zeros["S1"].held and ins.zeros["S1"].start_N > 0.1
    assert any(line.startswith("load cell at rest: S1's force stays at") and "lost motion in the drive" in line
               for line in ins.lines()), ins.lines()
    off = _drifting_zero(tube2, 2.0, offset_N=0.08)
    # a record that starts with the first pull: the rests alone cannot tell a drift from an offset beside a held tension
    cut = _from_first_pull(off.data)
    ins = check_instruments(cut)
    assert ins.zeros["S1"].drifts and not ins.zeros["S1"].zeroed and not ins.zeros["S1"].applied
    assert np.array_equal(ins.data.force_N, cut.force_N[ins.kept])
    assert any("not corrected, the cell does not read zero at the first rests" in line for line in ins.lines())
    # with the rows before the first pull, the cell reads 0.08 N there with the joint straight: its zero, drifting from
    # there (the rests read the same at the start), re-zeroed at every rest
    ins = check_instruments(off.data)
    z = ins.zeros["S1"]
    assert z.offset_at_start and not z.held_beside_offset and z.applied and z.first_N == pytest.approx(0.08, abs=0.01)
    at_rest = (ins.data.sample == "S1") & (ins.data.stroke_mm == 0.0)
    assert abs(float(np.median(ins.data.force_N[at_rest]))) < 0.01


def test_a_load_cell_reading_below_zero_at_every_rest_is_re_zeroed(tube2):
    """S1's load cell reads 0.4 N low (not zeroed before the test), S2's is zeroed: at S1's rests the force reads
    below zero, which no tension does (a tendon cannot push), so it is the cell's zero: re-zeroed at every rest in
    S1, said, and the diagnosis is the zeroed record's (nothing to add; before, angle_bias stood in for it). A cell
    reading above zero at rest stays as read (a tendon held taut would do it too: the test above)."""
    from camtube.model.diagnose import diagnose

    rec = _drifting_zero(tube2, 0.0, offset_N=-0.4)
    ins = check_instruments(rec.data)
    z1, z2 = ins.zeros["S1"], ins.zeros["S2"]
    assert z1.below_zero and z1.applied and not z2.below_zero and not z2.applied
    rest = (ins.data.sample == "S1") & (ins.data.stroke_mm == 0.0)
    assert abs(float(np.median(ins.data.force_N[rest]))) < 0.01
    s2 = ins.data.sample == "S2"
    assert np.array_equal(ins.data.force_N[s2], rec.data.force_N[ins.kept][s2])
    assert any(line.startswith("load cell zero: before S1's first pull (motor at zero, the joint never loaded) the "
                               f"force reads {z1.first_N:.3g} N") and "a tendon cannot push" in line
               and "re-zeroed at every rest" in line and z1.first_N == pytest.approx(-0.4, abs=0.01)
               for line in ins.lines()), ins.lines()
    # a record that starts with the first pull (no reading before it): the rests alone say so
    cut = check_instruments(_from_first_pull(rec.data))
    assert cut.zeros["S1"].first_rows == 0 and cut.zeros["S1"].below_zero and cut.zeros["S1"].applied
    assert any(line.startswith("load cell zero: at S1's rests (motor at zero, tendon slack) the force reads -0.4")
               and "a tendon cannot push" in line for line in cut.lines()), cut.lines()
    d = diagnose(model_for_pattern(tube2), ins.data, ["E_t"], pattern_values(tube2))
    assert not d.recommended and not d.partial
    assert d.final.rmse_deg < 1.1 * rec.floor_deg


def test_a_load_cell_reading_above_zero_at_rest_with_the_joint_straight_is_re_zeroed(tube2):
    """S1's tendon is 0.15 mm slack and its load cell reads 1.5 N high (not zeroed before the test). At the rests the
    force reads 1.5 N while the joint is straight, though 1.5 N bends it by about 12 deg on the pulls: no tension
    holds it, so it is the cell's zero: re-zeroed, said, and slack is recommended (before, nothing was: relaxation and
    slack partial at 85x the floor). A tendon a carriage holds taut at rest bends the joint as its tension does, and
    stays as read (the test above)."""
    from dataclasses import replace

    from camtube.model.diagnose import diagnose

    slow = Protocol(n_cycles=12, ramp_s=6.0, dwell_s=2.0, rest_s=3.0, first_dwell_s=4.0)
    rec = simulate_bench(tube2, (SampleBench(tendon=Tendon(slack_mm=0.15), tracker=QUIET), SampleBench(tracker=QUIET)),
                         slow, Clock(rate_hz=25.0, n_repeats=0), seed=7)
    rec = replace(rec, data=rec.data.with_force(rec.data.force_N + 1.5 * (rec.data.sample == "S1")))
    ins = check_instruments(rec.data)
    z1, z2 = ins.zeros["S1"], ins.zeros["S2"]
    assert z1.unloaded_offset and z1.applied and not z2.applied
    assert abs(z1.rest_deg) < 1.0 and z1.implied_deg > 8.0
    rest = (ins.data.sample == "S1") & (ins.data.stroke_mm == 0.0)
    assert abs(float(np.median(ins.data.force_N[rest]))) < 0.01
    assert any(line.startswith("load cell zero: before S1's first pull (motor at zero, the joint never loaded) the "
                               "force reads 1.5 N") and "with the joint straight" in line and "the cell's zero" in line
               for line in ins.lines()), ins.lines()
    # a record that starts with the first pull (no reading before it): the rests alone say so
    cut = check_instruments(_from_first_pull(rec.data))
    assert cut.zeros["S1"].first_rows == 0 and cut.zeros["S1"].unloaded_offset and cut.zeros["S1"].applied
    assert any(line.startswith("load cell zero: at S1's rests (motor at zero) the force reads 1.5 N at the start")
               and "while the joint there is nearly straight" in line and "that is the cell's zero" in line
               for line in cut.lines()), cut.lines()
    # rows that begin after the first cycle (--cycles 5-12): the rest before their first pull reads the zero as well,
    # but the joint was loaded in the cycles before, and the words say so (they said "the joint never loaded")
    later = check_instruments(select_cycles(rec.data, "5-12"))
    assert later.zeros["S1"].first_cycle == 5 and later.zeros["S1"].applied
    lines = [line for line in later.lines() if line.startswith("load cell zero: before S1's first pull")]
    assert len(lines) == 1 and "never loaded" not in lines[0], later.lines()
    assert lines[0].startswith("load cell zero: before S1's first pull in these rows (they begin with cycle 5: the "
                               "joint was loaded in the cycles before; motor at zero) the force reads 1.5 N"), lines
    d = diagnose(model_for_pattern(tube2), ins.data, ["E_t"], pattern_values(tube2))
    assert d.recommended[:1] == ("slack",) and "force_zero" not in d.recommended
    assert d.final.rmse_deg < 1.15 * rec.floor_deg
    # a zero that drifts from a cell not zeroed (1 N high): the drift's rule needs a cell zeroed before the test and
    # left it; the joint straight at the rests says the readings there are the zero, and it is taken off at every rest
    drift = _drifting_zero(tube2, 2.0, offset_N=1.0)
    ins = check_instruments(drift.data)
    z1 = ins.zeros["S1"]
    assert z1.drifts and not z1.zeroed and z1.unloaded_offset and z1.applied
    at_rest = (ins.data.sample == "S1") & (ins.data.stroke_mm == 0.0)
    assert abs(float(np.median(ins.data.force_N[at_rest]))) < 0.01


def test_a_cell_not_zeroed_beside_a_backbone_that_rests_bent_is_read_before_the_first_pull(tube2):
    """S1's backbone relaxes and sets, so its joint rests bent (about 10 deg), and its load cell reads 0.9 N high. At
    the rests the reading cannot be told from a tension holding the joint bent, and was left (bench-heldout43's
    backbone file: nothing recommended at 41x the floor). Before the first pull the joint has never been loaded and
    is straight though 0.9 N bends it by several degrees: that reading is the cell's zero. Re-zeroed at every rest,
    said; S2 (zeroed) as read."""
    from camtube.model.sim.bench import Backbone

    pace = Protocol(n_cycles=12, ramp_s=4.0, dwell_s=2.0, rest_s=3.0, first_dwell_s=3.0)
    bent = SampleBench(backbone=Backbone(relax=((0.3, 2.0), (0.2, 25.0)), yield_nmm=3.5, set_rate_per_s=0.045),
                       load_cell=LoadCell(offset_N=0.9), tracker=QUIET)
    rec = simulate_bench(tube2, (bent, SampleBench(tracker=QUIET)), pace, Clock(rate_hz=25.0, n_repeats=0), seed=5)
    ins = check_instruments(rec.data)
    z1, z2 = ins.zeros["S1"], ins.zeros["S2"]
    # the rests alone: the joint there is bent by more than a quarter of what 0.9 N bends it by (the old rules leave it)
    assert z1.rest_deg > 0.25 * z1.implied_deg and not z1.unloaded_offset and not z1.below_zero
    assert z1.first_rows >= 3 and z1.first_N == pytest.approx(0.9, abs=0.02) and abs(z1.first_deg) < 1.0
    assert z1.offset_at_start and not z1.held_beside_offset and z1.applied and not z2.applied
    rest = (ins.data.sample == "S1") & (ins.data.stroke_mm == 0.0)
    assert abs(float(np.median(ins.data.force_N[rest]))) < 0.01
    s2 = ins.data.sample == "S2"
    assert np.array_equal(ins.data.force_N[s2], rec.data.force_N[ins.kept][s2])
    assert any(line.startswith("load cell zero: before S1's first pull (motor at zero, the joint never loaded) the "
                               "force reads 0.9") and "with the joint straight" in line and "re-zeroed at every rest"
               in line for line in ins.lines()), ins.lines()


@pytest.mark.parametrize("offset_N", [0.5, -0.3])
def test_a_tension_held_at_rest_beside_a_cell_not_zeroed_is_kept(tube2, offset_N):
    """A carriage its rail holds keeps the tendon taut at rest (about 0.15 N), and the cell reads ``offset_N`` off.
    Taking the rests' reading for the zero took the held tension off with it (bench-heldout41's and 42's lost motion:
    the drive's effects then had nothing to fit). The reading before the first pull, with nothing held yet, is the
    zero: taken off throughout, the held tension stays as in the same record read by a zeroed cell."""
    from camtube.model.sim.bench import Backbone

    pace = Protocol(n_cycles=12, ramp_s=4.0, dwell_s=2.0, rest_s=3.0, first_dwell_s=3.0)

    def record(off):
        held = SampleBench(drive=Drive(backlash_mm=0.16, rail_friction_N=0.16, settle=True),
                           backbone=Backbone(relax=((0.09, 3.0),)), load_cell=LoadCell(offset_N=off), tracker=QUIET)
        return simulate_bench(tube2, (held,), pace, Clock(rate_hz=25.0, n_repeats=0), seed=3)

    zeroed, rec = check_instruments(record(0.0).data), check_instruments(record(offset_N).data)
    z = rec.zeros["S1"]
    held_N = zeroed.zeros["S1"].start_N
    assert held_N > 0.1 and not zeroed.zeros["S1"].applied
    assert z.offset_at_start and z.held_beside_offset and z.applied
    assert z.first_N == pytest.approx(offset_N, abs=0.01)
    rest = rec.data.stroke_mm == 0.0
    assert float(np.median(rec.data.force_N[rest])) == pytest.approx(
        float(np.median(zeroed.data.force_N[zeroed.data.stroke_mm == 0.0])), abs=0.01)
    assert any(line.startswith("load cell zero: before S1's first pull") and "taken off throughout" in line
               and "a tension held at rest" in line for line in rec.lines()), rec.lines()


def test_a_zero_drifting_fast_from_a_cell_not_zeroed_is_not_taken_for_a_held_tension(tube2):
    """A cell 0.3 N high whose zero drifts 6 N/h: its first three rests read 0.06 N above the reading before the first
    pull, as a tension held at rest beside the offset would. The rests' line, taken back to the first pull, reads the
    offset there: the zero drifts from it, and the force is re-zeroed at every rest (nothing held is kept)."""
    rec = _drifting_zero(tube2, 6.0, offset_N=0.3)
    ins = check_instruments(rec.data)
    z = ins.zeros["S1"]
    assert z.offset_at_start and z.drifts and z.applied
    assert z.start_N - z.first_N > 0.04   # the first rests alone would say "held"
    assert abs(z.rests_at_first_N - z.first_N) < 0.01 and not z.held_beside_offset
    at_rest = (ins.data.sample == "S1") & (ins.data.stroke_mm == 0.0)
    assert abs(float(np.median(ins.data.force_N[at_rest]))) < 0.01
    assert any(line.startswith("load cell zero: before S1's first pull") and "re-zeroed at every rest" in line
               and "the rests' line reads" in line for line in ins.lines()), ins.lines()


def test_a_reading_before_the_first_pull_that_bends_the_joint_is_a_preload_not_an_offset():
    """Before the first pull the cell reads 0.3 N: where the joint is bent by what 0.3 N bends it by on the pulls, that
    is a tension (a preload) and nothing is taken off; where the joint is straight, it is the cell's zero."""
    from camtube.model.diagnose.instruments import read_zero

    t = np.arange(0.0, 402.0, 0.05)
    cycle = (np.maximum(t - 2.0, 0.0) // 10).astype(int)
    stroke = np.clip(np.sin(2 * np.pi * (t - 2.0) / 10.0), 0.0, None) * 2.0   # 2 s at rest, then 40 cycles
    rng = np.random.default_rng(2)
    n = t.size
    base = dict(sample=np.full(n, "S1", dtype=object), cycle=cycle + 1, time_s=t, stroke_mm=stroke)
    force = 2.0 * stroke + 0.3 + rng.normal(0.0, 0.003, n)
    preload = read_zero(Dataset(force_N=force, angle_deg=8.0 * force + rng.normal(0.0, 0.05, n), **base))["S1"]
    offset = read_zero(Dataset(force_N=force, angle_deg=8.0 * (force - 0.3) + rng.normal(0.0, 0.05, n), **base))["S1"]
    for z in (preload, offset):
        assert z.first_rows == 41 and z.first_N == pytest.approx(0.3, abs=0.002)
        assert z.first_implied_deg == pytest.approx(2.4, rel=0.05)
    assert not preload.offset_at_start and not preload.rezeroes
    assert offset.offset_at_start and offset.rezeroes and not offset.held_beside_offset


def test_a_carriage_held_within_a_gap_that_binds_is_lost_motion_in_the_drive(tube2):
    """A nut's gap narrower than the stroke at which the rail holds the carriage: the far flank pushes the held
    carriage down with the motor, so the joint rests bent by what the gap keeps, the tendon taut (sample 1, 0.11 mm
    and 0.18 N). carriage_hold leaves that out and the joint's rest angle or relaxation took its place; they hold
    the joint bent with the tendon slack, which the force at rest contradicts. carriage_gap is recommended first
    and the chain ends at the floor; the joint's effects are refused, saying why."""
    from camtube.model.diagnose import diagnose
    from camtube.model.sim.bench import Backbone

    def bench(gap_mm, friction_N):
        return SampleBench(drive=Drive(backlash_mm=gap_mm, rail_friction_N=friction_N),
                           backbone=Backbone(relax=((0.05, 3.0),)), tracker=QUIET)

    pace = Protocol(n_cycles=16, ramp_s=3.0, dwell_s=2.0, rest_s=2.0, first_dwell_s=2.0)
    rec = simulate_bench(tube2, (bench(0.11, 0.18), bench(0.13, 0.12)), pace, Clock(rate_hz=50.0, n_repeats=0),
                         seed=11)
    d = diagnose(model_for_pattern(tube2), rec.data, ("E_t",), pattern_values(tube2))
    assert d.recommended[:1] == ("carriage_gap",), (d.recommended, d.partial, d.stop_reason)
    assert d.final.rmse_deg <= 1.15 * rec.floor_deg
    gap = [v for k, v in d.final.params.items() if k.startswith("carriage_gap.gap_mm@S1")]
    assert gap and gap[0] == pytest.approx(0.11, rel=0.15), d.final.params
    # the joint's resting effects never hold S1's joint bent beside its taut tendon: refused, saying why, or (since an
    # effect one sample refuses is fitted in the others, after bench-heldout34) held off in S1, far behind the drive
    first = {c.effect: c for c in d.rounds[0]}
    for name in ("relaxation", "relaxation2"):
        c = first[name]
        held_off = c.held.get(f"{name}.fraction@S1") == 0.0
        assert "the tendon is taut at rest" in c.why or (
            held_off and c.heldout_rmse_deg > 2.0 * first["carriage_hold"].heldout_rmse_deg), (name, c.why, c.held)


def test_the_joint_resting_bent_by_itself_is_refused_where_the_force_at_rest_stays():
    """rest_angle's and the relaxations' check: a joint held bent at the rests while the force there stays well
    above zero is a taut tendon, not a joint resting by itself; the same joint with the force at zero passes."""
    from camtube.model.effects.builtin import REST_ANGLE, _rest_angle_check
    from camtube.model.data.dataset import Dataset

    t = np.arange(0.0, 60.0, 0.02)
    stroke = np.clip(np.sin(2 * np.pi * t / 10.0), 0.0, None) * 2.0   # pulls and rests at zero, 6 cycles
    rng = np.random.default_rng(0)
    force = 2.0 * stroke + rng.normal(0.0, 0.005, t.size)
    pred = np.where(stroke == 0.0, 1.5, 10.0 * stroke)                  # the effect holds the joint bent at rest
    n = t.size
    base = dict(sample=np.full(n, "S1", dtype=object), cycle=(t // 10).astype(int) + 1, time_s=t, stroke_mm=stroke,
                angle_deg=pred)
    slack = Dataset(force_N=force, **base)
    taut = Dataset(force_N=np.where(stroke == 0.0, force + 0.15, force), **base)
    assert _rest_angle_check(slack, pred) == ""
    why = _rest_angle_check(taut, pred)
    assert why.startswith("in S1 it holds the joint bent at rest (1.5 deg) while the force there stays at 0.1")
    assert "the tendon is taut at rest" in why
    assert REST_ANGLE.check is _rest_angle_check
    assert _rest_angle_check(taut, np.where(stroke == 0.0, 0.0, pred)) == ""   # not held bent: nothing to refuse
    # with the drive's effect in the model, the taut tendon at rest is explained: the joint may rest bent beside it
    from camtube.model.effects.builtin import CARRIAGE_GAP, CARRIAGE_HOLD, RELAXATION
    assert _rest_angle_check(taut, pred, effects=(CARRIAGE_GAP, REST_ANGLE)) == ""
    assert _rest_angle_check(taut, pred, effects=(CARRIAGE_HOLD, RELAXATION)) == ""
    assert _rest_angle_check(taut, pred, effects=(RELAXATION, REST_ANGLE)) == why


def test_a_chain_that_drops_the_drive_keeps_the_joint_s_resting_effects_to_their_check():
    """The search drops a chosen effect that a later one explains (:meth:`Search.drop_candidate`). A joint's
    resting effects joined beside the drive's effect, whose taut tendon at rest their check allows; once the drive's
    effect would go, the chain left must pass those checks again: rest_angle and a relaxation holding the joint bent
    while the force at rest stays at 0.15 N contradict it, so the drive stays (bench-heldout22's lost motion with its
    carriages settling: the drive was dropped for rest_angle, angle_bias and relaxation). The chain's other checks
    (those that do not read the chain) are not run again."""
    from camtube.model.core.model import check_reads_chain
    from camtube.model.data.dataset import Dataset
    from camtube.model.diagnose.search import _chain_form_problems
    from camtube.model.effects.builtin import CARRIAGE_GAP, REST_ANGLE, RELAXATION, TOE
    from camtube.model.core.predict import model_for_pattern

    t = np.arange(0.0, 60.0, 0.02)
    stroke = np.clip(np.sin(2 * np.pi * t / 10.0), 0.0, None) * 2.0
    rng = np.random.default_rng(2)
    force = 2.0 * stroke + rng.normal(0.0, 0.005, t.size)
    pred = np.where(stroke == 0.0, 1.5, 10.0 * stroke)
    n = t.size
    taut = Dataset(sample=np.full(n, "S1", dtype=object), cycle=(t // 10).astype(int) + 1, time_s=t,
                   stroke_mm=stroke, force_N=np.where(stroke == 0.0, force + 0.15, force), angle_deg=pred)
    base = model_for_pattern(load_pattern(TUBE2))
    left = base.with_effects([REST_ANGLE, RELAXATION])
    problems = _chain_form_problems(left, taut, pred)
    assert [p.split(":")[0] for p in problems] == ["rest_angle", "relaxation"], problems
    assert all("the tendon is taut at rest" in p for p in problems)
    assert _chain_form_problems(base.with_effects([CARRIAGE_GAP, REST_ANGLE, RELAXATION]), taut, pred) == []
    assert _chain_form_problems(base.with_effects([REST_ANGLE]), taut, np.where(stroke == 0.0, 0.0, pred)) == []
    assert check_reads_chain(REST_ANGLE) and not check_reads_chain(CARRIAGE_GAP)
    assert TOE.check is None or not check_reads_chain(TOE)


def test_a_force_at_rest_that_steps_from_rest_to_rest_is_not_taken_for_a_drifting_zero():
    """A carriage its rail holds at some rests and not at others puts the held tension at rest in one step, after
    half the record at zero: a line through the rests' readings has a resolved slope and a small scatter, but no
    zero moves in one step by most of its change; a zero drifting as much, a little each cycle, is corrected."""
    from camtube.model.diagnose.instruments import ZERO_JUMP, read_zero, rezero_force
    from camtube.model.data.dataset import Dataset

    t = np.arange(0.0, 400.0, 0.05)
    cycle = (t // 10).astype(int)
    stroke = np.clip(np.sin(2 * np.pi * t / 10.0), 0.0, None) * 2.0   # 40 cycles of pulls and rests at zero
    rng = np.random.default_rng(1)
    noise = rng.normal(0.0, 0.003, t.size)
    held = np.where((stroke == 0.0) & (cycle >= 20), 0.09, 0.0)       # held taut at the rests of the second half
    drift = 0.09 * t / t[-1]                                          # a zero drifting as much, smoothly
    n = t.size
    base = dict(sample=np.full(n, "S1", dtype=object), cycle=cycle + 1, time_s=t, stroke_mm=stroke,
                angle_deg=np.zeros(n))
    steps = read_zero(Dataset(force_N=2.0 * stroke + held + noise, **base))["S1"]
    assert steps.drifts and steps.jump_N > ZERO_JUMP * abs(steps.change_N) and not steps.smooth
    assert not rezero_force(Dataset(force_N=2.0 * stroke + held + noise, **base), {"S1": steps})[1]["S1"].applied
    smooth = read_zero(Dataset(force_N=2.0 * stroke + drift + noise, **base))["S1"]
    assert smooth.drifts and smooth.smooth and smooth.zeroed
    assert smooth.jump_N < 0.1 * abs(smooth.change_N)


def _moving_rows(rec, min_angle_deg: float, rng, k: int, length: int) -> list[np.ndarray]:
    """``k`` runs of ``length`` rows, apart, inside one sample, where the joint is bent more than ``min_angle_deg``
    and the motor moves."""
    a = np.abs(rec.angle_true_deg)
    moving = np.abs(np.gradient(rec.data.stroke_mm)) > 1e-6
    ok = np.flatnonzero(np.convolve((a > min_angle_deg) & moving, np.ones(length + 6), "same") >= length + 6)
    runs: list[np.ndarray] = []
    for i in rng.permutation(ok):
        r = np.arange(i - length // 2, i - length // 2 + length)
        if all(abs(int(r[0]) - int(q[0])) > 60 for q in runs) and len(set(rec.data.sample[r - 3])) == 1:
            runs.append(r)
        if len(runs) == k:
            break
    return runs


def test_bursts_of_interference_and_a_tracker_writing_zeros_are_set_aside_row_for_row(tube2):
    # interference that lasts several samples, and a tracker that writes 0 while it has lost the sensor: runs of
    # displaced rows whose neighbours either side agree. A single-row test misses every row of them (each row's
    # neighbours inside the run are displaced too); the clean record's reversals, dwells and rests give none
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=50.0, n_repeats=0), seed=11)
    clean = check_instruments(rec.data)
    assert set(clean.aside) == {"repeated time stamp", "angle spike", "force spike"}
    assert sum(len(v) for v in clean.aside.values()) == 0
    rng = np.random.default_rng(5)
    angle = rec.data.angle_deg.copy()
    burst = _moving_rows(rec, 8.0, rng, 8, 4)
    for j, r in enumerate(burst):
        angle[r[: 2 + j % 3]] += (-1) ** j * rng.uniform(5.0, 9.0)   # runs of 2, 3 and 4 rows
    zeros = _moving_rows(rec, 8.0, rng, 16, 12)[8:]
    for r in zeros:
        angle[r] = 0.0
    want = {int(i) for j, r in enumerate(burst) for i in r[: 2 + j % 3]} | {int(i) for r in zeros for i in r}
    ins = check_instruments(rec.data.with_angle(angle))
    assert set(ins.aside["angle burst row"]) == want
    assert len(ins.aside["angle spike"]) == 0 and "frozen angle row" not in ins.aside
    assert any("angle burst rows" in line for line in ins.lines())


def test_a_frozen_tracker_is_set_aside_while_the_stroke_moves_and_kept_at_rest(tube2):
    # the tracker holds its last value: exact repeats of the angle across which the stroke moves; the first value
    # is a real reading and stays. At rest the stroke does not move, so nothing there is taken for a freeze
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=50.0, n_repeats=0), seed=12)
    angle = rec.data.angle_deg.copy()
    runs = _moving_rows(rec, 4.0, np.random.default_rng(6), 5, 9)
    for r in runs:
        angle[r[1:]] = angle[r[0]]
    rest = np.flatnonzero((rec.data.stroke_mm == 0.0) & (rec.data.sample == "S1"))[100:110]
    angle[rest[1:]] = angle[rest[0]]
    ins = check_instruments(rec.data.with_angle(angle))
    assert set(ins.aside["frozen angle row"]) == {int(i) for r in runs for i in r[1:]}


def test_a_tracker_writing_zeros_through_a_dwell_is_set_aside_longer_than_a_burst(tube2):
    # at 25 Hz a burst is at most 12 rows (0.5 s); a tracker that loses the sensor for 16 rows while the joint
    # stands bent at the top of a stroke writes 0 where the stroke rests, so neither the burst nor the freeze while
    # the stroke moves saw it (bench-heldout16's lag file: 13 rows of 0 at 32 deg doubled the RMSE). A value held
    # in a dwell (no jump to it) and a quantised reading repeating at rest stay
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=25.0, n_repeats=0), seed=13)
    d = rec.data
    still = np.concatenate(([False], np.diff(d.stroke_mm) == 0.0))
    top = still & (np.abs(rec.angle_true_deg) > 8.0) & (d.sample == "S1")
    runs = np.flatnonzero(np.convolve(top, np.ones(20), "valid") == 20)
    assert runs.size
    zero = np.arange(runs[0] + 2, runs[0] + 18)                       # 16 rows of 0 inside one dwell
    held_at = runs[runs > zero[-1] + 40]
    held = np.arange(held_at[0] + 2, held_at[0] + 12)                 # 10 rows holding the dwell's last reading
    rest = np.flatnonzero((d.stroke_mm == 0.0) & (d.sample == "S1"))[100:110]
    angle = d.angle_deg.copy()
    angle[zero] = 0.0
    angle[held] = angle[held[0] - 1]
    angle[rest] = np.round(angle[rest[0]], 1)
    ins = check_instruments(d.with_angle(angle))
    aside = {int(i) for v in ins.aside.values() for i in v}
    assert set(zero) <= aside
    assert not (set(held) | set(rest)) & aside
    assert set(ins.aside["frozen angle row"]) == set(zero)


def test_interference_lasting_a_second_is_set_aside_through_the_ramps(tube2):
    # bursts of 20-60 rows at 50 Hz (0.4-1.2 s), displaced by 3-9 deg: through a ramp the angle moves more than
    # that within the burst, so the range test of a burst (at most 0.5 s) missed most of them and a control read
    # "unexplained" at 1.5x the floor. The jump in and the jump back set them aside, one that runs to the end of
    # a sample too; nothing else is. (Where two bursts of different sizes overlap, their difference is left between
    # the jumps: a record where none does)
    tr = Tracker(noise_deg=0.15, n_spikes=4, n_dropouts=0, n_bursts=6, burst_rows=(20, 60))
    rec = simulate_bench(tube2, SampleBench(tracker=tr), SHORT, Clock(rate_hz=50.0, n_repeats=0), seed=24)
    b = rec.burst_rows
    assert b.size > 400 and (np.abs(rec.data.angle_deg[b] - rec.angle_true_deg[b]) > 2.0).all()
    ins = check_instruments(rec.data)
    aside = {int(i) for v in ins.aside.values() for i in v}
    assert set(b) <= aside <= set(rec.spike_rows) | set(b)
    from camtube.model.diagnose import diagnose

    d = diagnose(model_for_pattern(tube2), ins.data, ["E_t"], pattern_values(tube2))
    assert not d.recommended and not d.partial
    assert d.final.rmse_deg < 1.1 * rec.floor_deg


@pytest.mark.parametrize("form", ["overlapping", "nested", "inside a short burst", "overlapping, alike, 3.1 s",
                                  "overlapping, unlike, 3.1 s"])
def test_two_bursts_of_interference_one_over_the_other_are_set_aside_together(tube2, form):
    # the jumps of two bursts that overlap add: 8 deg, 4 more, 8 back, 4 back (a 100 Hz control of bench-heldout17
    # kept 217 rows 4-8 deg off, at 1.63x the floor); one inside the other: 8, 4, 4 back, 8 back. Two of about the
    # same size, each 1.8 s, that overlap: -5.2, -4.8 more, +5.2 back, +4.8 back, the last 3.1 s after the first (more
    # than a burst lasts): the inner two match each other, and bench-heldout44's control kept the outer rows 5 deg off;
    # of unlike sizes, -4.4 and -7.1 (bench-heldout46's lag file kept 30 rows 7.5 deg off): no two jumps match
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=5)
    d = rec.data
    n = len(d)
    a = d.angle_deg.copy()
    first, second = {"overlapping": ((1000, 1150), (1060, 1260)), "nested": ((1000, 1250), (1060, 1150)),
                     "inside a short burst": ((1000, 1200), (1080, 1100)),
                     "overlapping, alike, 3.1 s": ((1000, 1180), (1130, 1310)),
                     "overlapping, unlike, 3.1 s": ((1000, 1180), (1130, 1310))}[form]
    sizes = {"overlapping, alike, 3.1 s": (-5.2, -4.8), "overlapping, unlike, 3.1 s": (-4.4, -7.1)}.get(form, (8.0, 4.0))
    a[slice(*first)] += sizes[0]
    a[slice(*second)] += sizes[1]
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, a))
    aside = {int(i) for v in ins.aside.values() for i in v}
    displaced = set(range(min(first[0], second[0]), max(first[1], second[1])))
    assert displaced <= aside
    assert len(aside - displaced) <= 2, sorted(aside - displaced)   # (a row beside a jump, at most)
    assert n - len(aside) > 0.9 * n


@pytest.mark.parametrize("inside", [1.6, -1.6])
def test_a_burst_with_a_smaller_jump_inside_it_is_set_aside_whole(tube2, inside):
    # bench-heldout24's friction file at 100 Hz: interference of -5.1 deg for 1.7 s with a 1.6 deg jump of the joint's
    # own inside it (a tracker that held its last value and caught up at the top of the stroke), and -8.2 deg with a
    # 1.4 deg jump; each jump was paired with the next one only, and 148 rows 5-8 deg off were kept (the friction file
    # partial at 2.4x the floor). The smaller jump inside is read as part of the displacement; a jump as large as the
    # burst's between its two jumps is not (two displacements: see the overlapping bursts above)
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=5)
    d = rec.data
    a = d.angle_deg.copy()
    r0, rm, r1 = 1000, 1090, 1170
    a[r0:r1] -= 5.0
    a[rm:] += inside          # a step that stays: it begins inside the burst and lasts after it
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, a))
    aside = {int(i) for v in ins.aside.values() for i in v}
    displaced = set(range(r0, r1))
    assert displaced <= aside, len(displaced - aside)
    assert len(aside - displaced) <= 2, sorted(aside - displaced)   # (a row beside a jump, at most)


def test_a_burst_a_few_times_the_noise_is_paired_though_its_two_jumps_read_differently(tube2):
    # each jump's size is read from one row's change, two noisy rows: a 4.5 deg burst of 1.4 s at 100 Hz read +4.1 in
    # and -5.2 out (bench-heldout18's slack file kept it, 0.22 deg RMS over the record, 1.39x the floor)
    tr = Tracker(noise_deg=0.3, n_spikes=0, n_dropouts=0)
    rec = simulate_bench(tube2, SampleBench(tracker=tr), SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=8)
    d = rec.data
    rng = np.random.default_rng(3)
    a = d.angle_deg.copy()
    starts = np.sort(rng.choice(np.arange(200, len(d) - 400, 400), 12, replace=False))
    displaced = set()
    for r0 in starts:
        r1 = r0 + int(rng.integers(60, 200))
        a[r0:r1] += float(rng.choice([-1.0, 1.0])) * 4.0
        displaced |= set(range(int(r0), r1))
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, a))
    aside = {int(i) for v in ins.aside.values() for i in v}
    assert displaced <= aside, len(displaced - aside)
    assert len(aside - displaced) <= 24    # (a row beside a jump, at most)


def _ramp_rows(rec, rng, k: int, end_margin: int = 300) -> list[int]:
    """``k`` rows, 600 apart at least, each the first row on a ramp (the joint moving) after a random row."""
    rate = np.abs(np.gradient(rec.angle_true_deg))
    out = []
    for r0 in np.sort(rng.choice(np.arange(300, len(rec.data) - end_margin, 600), k, replace=False)):
        out.append(int(r0 + np.argmax(rate[r0:r0 + 300] > 0.1)))
    return out


def _aside_mask(ins, n: int) -> np.ndarray:
    """(n,) bool: the rows the instruments' check set aside, for any reason."""
    aside = np.zeros(n, bool)
    for v in ins.aside.values():
        aside[v] = True
    return aside


@pytest.mark.parametrize("where", ["inside", "at its start"])
def test_a_long_burst_with_a_dropout_in_it_is_set_aside_whole(tube2, where):
    # a 0.9 s burst of +4.4 deg on a ramp at 100 Hz, the tracker lost for 0.1 s within it (the reader drops those
    # rows): read row by row, the ramp's progress across the gap (-2.2 deg) was a jump of its own, the burst's jumps
    # did not pair and 79 rows stayed 4.4 deg off (bench-heldout20's lost-motion file: 1.26x the floor, partial).
    # Read over the time each change spans, the gap is the ramp's and the burst is set aside whole; a dropout that
    # opens the burst leaves its jump in, read across the gap
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=21)
    d = rec.data
    a = d.angle_deg.copy()
    keep = np.ones(len(d), bool)
    displaced = np.zeros(len(d), bool)
    for r0 in _ramp_rows(rec, np.random.default_rng(5), 6):
        a[r0:r0 + 90] += 4.4
        displaced[r0:r0 + 90] = True
        g0 = r0 + (40 if where == "inside" else 0)
        keep[g0:g0 + 10] = False                                     # the tracker lost: those rows dropped
    data = Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, a).take(keep)
    aside = _aside_mask(check_instruments(data), len(data))
    off = displaced[keep]
    assert aside[off].all(), int((off & ~aside).sum())
    assert (aside & ~off).sum() <= 12, int((aside & ~off).sum())      # (a row beside a jump, at most)


@pytest.mark.parametrize("beside", ["a repeated stamp before it", "a spike before it", "a repeated stamp after it"])
def test_a_long_burst_beside_a_row_set_aside_is_set_aside_whole(tube2, beside):
    # bench-heldout26's three-arm backbone at 100 Hz: a repeated time stamp one row before a 1.5 s burst of +7.9 deg on
    # a ramp. Read across the line between its neighbours, the row set aside split the jump into two (4.1 and
    # 2.6 deg), neither the size of the jump back (-7.8), and 146 rows 8 deg off were kept (2.5x the floor). Left
    # out, the change across it is one jump, read over the rows it spans
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=26)
    d = rec.data
    rng = np.random.default_rng(26)
    t, a = d.time_s.copy(), d.angle_deg.copy()
    displaced = np.zeros(len(d), bool)
    for r0 in _ramp_rows(rec, rng, 5, end_margin=400):
        r1 = r0 + int(rng.integers(100, 160))
        a[r0:r1] += 7.9
        displaced[r0:r1] = True
        if beside == "a repeated stamp before it":
            t[r0 - 1] = t[r0 - 2]
        elif beside == "a spike before it":
            a[r0 - 1] -= 9.0
        else:
            t[r1] = t[r1 - 1]
    ins = check_instruments(Dataset(d.sample, d.cycle, t, d.stroke_mm, d.force_N, a))
    aside = _aside_mask(ins, len(d))
    assert aside[displaced].all(), int((displaced & ~aside).sum())
    assert (aside & ~displaced).sum() <= 10, int((aside & ~displaced).sum())   # (the rows beside, at most)


def test_a_long_burst_just_after_the_tracker_wrote_zeros_is_set_aside_whole(tube2):
    # bench-heldout35's tracker drift at 100 Hz: the tracker wrote 0 for 9 rows on a ramp, then read 8.3 deg low for
    # 0.9 s. The zeros were taken as a short burst, which the long bursts' reading did not leave out: the jump into
    # the burst split in two (-16 deg to the zeros, +6 from them), unpaired, and 94 rows 8 deg off were kept (twice
    # the floor; what was left read as following the bend angle). Left out, as a frozen tracker's rows are, the change
    # across them is one jump, read over the rows it spans; and the zeros are still set aside
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=35)
    d = rec.data
    rng = np.random.default_rng(35)
    a = d.angle_deg.copy()
    zeros = np.zeros(len(d), bool)
    displaced = np.zeros(len(d), bool)
    for r0 in _ramp_rows(rec, rng, 5, end_margin=400):
        r1 = r0 + 9 + int(rng.integers(80, 120))
        a[r0:r0 + 9] = 0.0
        zeros[r0:r0 + 9] = True
        a[r0 + 9:r1] -= 8.3
        displaced[r0 + 9:r1] = True
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, a))
    aside = _aside_mask(ins, len(d))
    assert aside[zeros].all(), int((zeros & ~aside).sum())
    assert aside[displaced].all(), int((displaced & ~aside).sum())
    assert (aside & ~(displaced | zeros)).sum() <= 10, int((aside & ~(displaced | zeros)).sum())


def test_a_long_burst_over_the_joints_own_jump_under_a_cell_at_its_limit_is_set_aside_whole(tube2):
    # a guide whose friction switches within a row lets go as the stroke reaches the top: the joint rises ~3 deg in
    # a row. With the load cell at the end of its range the force cannot show that switch, so the jump stood inside
    # a 5 deg burst as a third jump and the burst's two did not pair (bench-sharp's 100 Hz file: 96 rows 5 deg off
    # kept). Within a few rows of the stroke stopping or starting, where the cell reads its limit, the jump is the
    # joint's; the bursts are set aside whole and nothing else is
    b = SampleBench(guide=Guide(mu=0.15, slip_mm_s=1e-6), tracker=QUIET)
    rec = simulate_bench(tube2, b, SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=27)
    d = rec.data
    force = np.minimum(d.force_N, 0.8 * float(d.force_N.max()))
    s = d.stroke_mm
    moving = np.concatenate(([False], np.diff(s) != 0.0))
    stops = np.flatnonzero(~moving[1:] & moving[:-1] & (s[1:] > 0.5 * s.max())) + 1   # the stroke reaches the top
    rng = np.random.default_rng(27)
    a = d.angle_deg.copy()
    displaced = np.zeros(len(d), bool)
    for k, r in enumerate(stops[1:-1:2]):
        if d.sample[r] != d.sample[r - 120] or d.sample[r] != d.sample[r + 120]:
            continue
        r0 = int(r - rng.integers(30, 90))
        r1 = int(r + rng.integers(30, 90))
        a[r0:r1] += (-1) ** k * 5.2
        displaced[r0:r1] = True
    assert displaced.sum() > 300
    own = [float(np.abs(np.diff(rec.angle_true_deg[r - 1:r + 4])).max()) for r in stops]
    assert np.median(own) > 2.0, own             # the joint's own jump, within a few rows of a stop
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, force, a))
    aside = _aside_mask(ins, len(d))
    assert aside[displaced].all(), int((displaced & ~aside).sum())
    burst = np.zeros(len(d), bool)
    burst[ins.aside["angle burst row"]] = True
    assert (burst & ~displaced).sum() <= 10, int((burst & ~displaced).sum())   # (the rows beside, at most)


def test_a_long_burst_that_begins_as_the_stroke_starts_under_a_cell_at_its_limit_is_set_aside_whole(tube2):
    # the other side of the test above: no guide to switch, interference that begins in the row the stroke starts
    # back from the top, the cell still at its limit. Its jump in is not the joint's; read without it the burst's
    # rows below the limit were kept (4 rows 7.8 deg off in bench-heldout25's control)
    b = SampleBench(tracker=QUIET)
    rec = simulate_bench(tube2, b, SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=28)
    d = rec.data
    force = np.minimum(d.force_N, 0.8 * float(d.force_N.max()))
    s = d.stroke_mm
    moving = np.concatenate(([False], np.diff(s) != 0.0))
    starts = np.flatnonzero(moving[1:] & ~moving[:-1] & (s[:-1] > 0.5 * s.max())) + 1   # back from the top
    rng = np.random.default_rng(28)
    a = d.angle_deg.copy()
    displaced = np.zeros(len(d), bool)
    for k, r in enumerate(starts[1:-1:2]):
        if d.sample[r] != d.sample[r + 200]:
            continue
        r1 = int(r + rng.integers(60, 150))
        a[r:r1] += (-1) ** k * 7.8
        displaced[r:r1] = True
    assert displaced.sum() > 300 and (force[displaced] < force.max()).any()
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, force, a))
    aside = _aside_mask(ins, len(d))
    assert aside[displaced].all(), int((displaced & ~aside).sum())


@pytest.mark.parametrize("where", ["end", "start", "end, as the ramp comes to rest"])
def test_interference_the_record_ends_or_begins_in_at_rest_is_set_aside(tube2, where):
    # bench-heldout27's three-arm backbone beside a guide: 6.7 deg for the last 68 rows of a sample, the joint at
    # rest: one jump and no jump back, kept as the joint's own (0.2 deg RMS over the sample; nothing recommended,
    # three effects partial at 1.8x the floor). A joint at rest under a steady tension does not jump by itself: the
    # rows from the jump to the record's end (from its start to the jump back) are set aside, and only they. Also
    # where the jump comes as the ramp's slow last steps come in (bench-heldout44's slack file: 3.3 deg for the last
    # 1.2 s, the stroke's last 0.007 mm moving within three rows before it: kept, 1.23x the true floor)
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=29)
    d = rec.data
    if where == "start":   # (the protocol starts with a pull: each sample's record taken from its first rest on)
        keep = np.zeros(len(d), bool)
        for _, sl in d.sample_slices():
            s_ = d.stroke_mm[sl]
            keep[sl.start + int(np.argmax((s_ == 0.0) & (np.arange(s_.size) > 100))):sl.stop] = True
        d = d.take(keep)
    a = d.angle_deg.copy()
    displaced = np.zeros(len(d), bool)
    for smp, sl in d.sample_slices():
        rows = np.arange(sl.start, sl.stop)
        if where == "end, as the ramp comes to rest":
            s_ = d.stroke_mm[sl]
            arrives = int(np.flatnonzero(np.diff(s_) != 0.0)[-1]) + 1   # the row the stroke's last step comes in
            part = rows[arrives - 1:]
            moved = float(np.ptp(d.stroke_mm[part[0] - 3:sl.stop]))
            assert 0.0 < moved < 0.01 * np.ptp(s_) and part.size <= 300   # (moving within 3 rows before the jump)
        else:
            part, rest = (rows[-70:], rows[-80:]) if where == "end" else (rows[:40], rows[:50])
            assert np.ptp(d.stroke_mm[rest]) == 0.0            # (at rest, from a few rows before the jump)
        a[part] += 6.7 if smp == "S1" else -5.5
        displaced[part] = True
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, a))
    aside = _aside_mask(ins, len(d))
    assert aside[displaced].all(), int((displaced & ~aside).sum())
    assert not (aside & ~displaced).any(), int((aside & ~displaced).sum())
    assert sum(len(v) for v in check_instruments(d).aside.values()) == 0   # (the clean record: nothing)


def test_dropouts_on_ramps_without_interference_set_nothing_aside(tube2):
    # the other side of the test above: 40 runs of 0.02-0.3 s of rows missing, on ramps (the joint moves degrees
    # across a gap) and at the turns of the motion, no interference. Read row by row, a ramp's progress across a gap
    # was a jump, and two gaps paired into a burst: 151 real rows set aside here (265 with gaps up to 0.15 s, 799 with
    # 0.16-0.3 s). Read over the time each change spans, none. (Gaps of 0.3-0.5 s on a ramp still read as jumps: 142
    # rows in 40 such gaps; the rate either side no longer tells the motion across them)
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=22)
    d = rec.data
    rng = np.random.default_rng(9)
    keep = np.ones(len(d), bool)
    for r0 in rng.choice(np.arange(100, len(d) - 100, 60), 40, replace=False):
        keep[r0:r0 + int(rng.integers(2, 31))] = False
    ins = check_instruments(d.take(keep))
    assert sum(len(v) for v in ins.aside.values()) == 0, {k: len(v) for k, v in ins.aside.items()}


def test_real_rows_between_a_long_burst_and_a_jump_of_the_joint_are_kept(tube2):
    # a 2 s burst of -3.6 deg ended 5 rows before the carriage slipped (the joint fell 1.2 deg at once, 10 noise
    # scales; here 8 and 3 deg under the short record's larger scale): the 5 real rows between stood above both their
    # neighbours, the burst's on one side and the fallen joint's on the other,
    # and were set aside as a short burst (bench-heldout18's second lost-motion file). Read across the long burst,
    # they are the joint's
    tr = Tracker(noise_deg=0.1, n_spikes=0, n_dropouts=0)
    rec = simulate_bench(tube2, SampleBench(tracker=tr), SHORT, Clock(rate_hz=40.0, n_repeats=0), seed=12)
    d = rec.data
    rest = np.flatnonzero((d.stroke_mm == 0.0) & (np.arange(len(d)) > 200))
    r1 = int(rest[len(rest) // 2])              # the burst ends at a rest, the joint still (no ramp)
    a = d.angle_deg.copy()
    a[r1 - 80:r1] -= 8.0
    a[r1 + 5:] -= 3.0                            # the joint's own jump (it stays: no jump back)
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, a))
    aside = {int(i) for v in ins.aside.values() for i in v}
    assert set(range(r1 - 80, r1)) <= aside
    assert not set(range(r1, r1 + 5)) & aside, sorted(set(range(r1, r1 + 5)) & aside)


def test_a_load_cell_at_the_end_of_its_range_is_set_aside_and_said(tube2):
    # the cell saturates at 80 % of the peak tension: the force reads a flat limit while the stroke goes on, and
    # the paper's physics read 26x the floor with friction and viscoelastic "partial". The rows at the limit are
    # set aside and the level named; the control is clean again. A force quantised to 10 mN repeats its top
    # reading only in the dwells, where the stroke rests: nothing is set aside for it
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=25.0, n_repeats=0), seed=14)
    d = rec.data
    limit = 0.8 * float(d.force_N.max())
    force = np.minimum(d.force_N, limit)
    clipped = Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, force, d.angle_deg)
    ins = check_instruments(clipped)
    assert set(ins.aside["load cell limit row"]) == set(np.flatnonzero(force == limit))
    assert set(ins.limits) == set(d.sample[force == limit]) and all(v == limit for v, _ in ins.limits.values())
    assert any("load cell at the end of its range: S1 reads" in line for line in ins.lines())
    from camtube.model.diagnose import diagnose

    d_fit = diagnose(model_for_pattern(tube2), ins.data, ["E_t"], pattern_values(tube2))
    assert not d_fit.recommended and not d_fit.partial
    assert d_fit.final.rmse_deg < 1.1 * rec.floor_deg
    quantised = Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, np.round(d.force_N / 0.01) * 0.01, d.angle_deg)
    q = check_instruments(quantised)
    assert "load cell limit row" not in q.aside and not q.limits
    # a cell at its limit in most rows (its median is the limit: a cell too small, or not zeroed): the same (it was
    # taken for a force that never rises, and nothing was set aside)
    low = 0.3 * float(d.force_N.max())
    most = Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, np.minimum(d.force_N, low), d.angle_deg)
    assert np.median(most.force_N[most.sample == "S1"]) == low
    m = check_instruments(most)
    assert set(m.aside["load cell limit row"]) == set(np.flatnonzero(most.force_N == low))


def test_a_lag_is_read_by_time_across_the_rows_a_load_cell_at_its_limit_set_aside(tube2):
    # a 40 ms lag at 50 Hz beside a load cell that reaches its range every cycle: a fifth of the rows set aside in
    # chunks. Shifted by rows across those chunks, the regression paired readings a chunk apart and read 46 +- 6 ms,
    # not corrected. By time (pairs that reach across rows set aside left out) it reads 40 +- 2 and corrects it;
    # a row whose angle two rows later was set aside is set aside too
    b = SampleBench(tracker=Tracker(noise_deg=0.15, n_spikes=4, n_dropouts=0, lag_ms=40.0),
                    load_cell=LoadCell(range_N=3.2))
    proto = Protocol(n_cycles=16, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=2.0)
    rec = simulate_bench(tube2, b, proto, Clock(rate_hz=50.0, n_repeats=0), seed=16)
    ins = check_instruments(rec.data)
    assert len(ins.aside["load cell limit row"]) > 0.15 * len(rec.data)
    assert ins.lag.se_ms < 3.0 and abs(ins.lag.lag_ms - 40.0) < 3.0 * ins.lag.se_ms
    assert ins.lag.applied_ms == pytest.approx(40.0)
    before = ins.aside["row before a gap after the lag shift"]
    other = set(ins.aside["load cell limit row"]) | set(ins.aside["angle spike"])
    assert before.size and all({i + 1, i + 2} & other for i in before)


def _limited(tube2, lag_ms: float, seed: int = 2, **parts):
    """Two samples of a bench whose load cells read their limit at the top of every stroke (a third of the rows),
    the trackers ``lag_ms`` late, at 50 Hz; ``(record, instruments, the lag read against the force alone)``."""
    from camtube.model.diagnose import instruments as ins_mod

    b = SampleBench(tracker=Tracker(noise_deg=0.15, n_spikes=4, n_dropouts=0, lag_ms=lag_ms),
                    load_cell=LoadCell(range_N=3.6), **parts)
    proto = Protocol(n_cycles=16, ramp_s=3.6, dwell_s=2.4, rest_s=2.4, first_dwell_s=2.4)
    rec = simulate_bench(tube2, (b, b), proto, Clock(rate_hz=50.0, n_repeats=0), seed=seed)
    aside, kept, rep, _ = ins_mod._artefacts(rec.data, rec.data.sample_slices())
    by_force = ins_mod.estimate_lags(ins_mod._with_speed(rec.data.take(kept), rec.data, kept, rep))
    return rec, check_instruments(rec.data), by_force


def test_a_lag_under_a_load_cell_at_its_limit_is_read_against_the_stroke(tube2):
    # both trackers 35 ms late, a backbone relaxing by 5 % in 3 s, each load cell at its limit through the top of
    # every stroke: over the rows the force reads, the lag regression sees the ramps and the rests only and reads
    # 24 ms (one row of 20 corrected; bench-heldout39's lag file read 26.5 +- 1.7). The stroke is logged whole there:
    # against it the lag reads 31 ms, and two rows are corrected. Said in the findings
    rec, ins, by_force = _limited(tube2, 35.0, backbone=Backbone(relax=((0.05, 3.0),)))
    assert len(ins.aside["load cell limit row"]) > 0.25 * len(rec.data)
    assert by_force.lag_ms < 28.0 and by_force.lag_ms > 3.0 * by_force.se_ms        # the premise: biased, resolved
    assert ins.lag.against == "stroke"
    assert abs(ins.lag.lag_ms - 35.0) < 0.2 * 35.0 and ins.lag.se_ms < 3.0
    assert ins.lag.applied_ms == pytest.approx(40.0)
    lines = ins.lines()
    assert any(line.startswith("angle lag read against the motor's stroke: the load cell's limit") for line in lines)
    assert any("the tracker lags the motor's stroke by 31" in line for line in lines)


def test_lost_motion_under_a_load_cell_at_its_limit_is_not_read_as_a_lag_against_the_stroke(tube2):
    # the carriage held within 0.1 mm of backlash sits between the motor and the joint: against the stroke the angle
    # reads -23 ms, against the force nothing. The stroke only measures a delay the force shows: none corrected. With
    # the trackers 35 ms late the force reads it well (35 +- 1): the force's reading stands
    drive = Drive(backlash_mm=0.1, rail_friction_N=0.3, settle=True)
    _, ins, by_force = _limited(tube2, 0.0, drive=drive)
    assert not abs(by_force.lag_ms) > 3.0 * by_force.se_ms
    assert ins.lag.against == "force" and ins.lag.applied_ms == 0.0
    _, ins, by_force = _limited(tube2, 35.0, drive=drive)
    assert ins.lag.against == "force" and ins.lag.lag_ms == by_force.lag_ms
    assert ins.lag.applied_ms == pytest.approx(40.0)


@pytest.mark.parametrize("rate_hz", [25.0, 100.0])
def test_the_drives_speed_is_read_across_the_rows_a_load_cell_at_its_limit_set_aside(tube2, rate_hz):
    # friction at the guide, and a cell whose range ends below the peak tension: the top of every stroke is set
    # aside (a third of the rows). Read from the rows kept, the speed across that gap put the end of the pull, the
    # dwell and the start of the release in one step, and the guide's law fitted 6-11x the floor; read on every
    # row whose stamp is sound, it fits at the floor and finds the guide's mu * wrap
    from camtube.model.core.build import build_registry
    from camtube.model.data.dataset import SPEED_COLUMN

    b = SampleBench(guide=Guide(mu=0.2), tracker=QUIET, load_cell=LoadCell(range_N=3.2))
    rec = simulate_bench(tube2, b, SHORT, Clock(rate_hz=rate_hz, n_repeats=3), seed=21)
    ins = check_instruments(rec.data)
    assert len(ins.aside["load cell limit row"]) > 0.25 * len(rec.data)
    reg, _ = build_registry([])
    capstan = model_for_pattern(tube2, [reg.get_effect("capstan")])
    r = fit(capstan, ins.data, ["E_t", "capstan.mu_wrap", "capstan.slip_mm_s", "capstan.hold"],
            pattern_values(tube2), grid=2)
    assert r.rmse < 1.1 * rec.floor_deg
    assert r.params["capstan.mu_wrap"] == pytest.approx(0.2 * math.pi / 2, rel=0.05)
    sound = np.ones(len(rec.data), bool)
    sound[ins.aside["repeated time stamp"]] = False
    speed = rec.data.take(sound).stroke_speed_mm_s
    assert np.array_equal(ins.data.extra[SPEED_COLUMN], speed[np.cumsum(sound)[ins.kept] - 1])


def test_a_guides_hold_the_rows_kept_do_not_resolve_is_held_not_a_reason_to_refuse_it(tube2, tmp_path, capsys):
    # friction at the guide in both samples, each load cell at its limit: the dwells at the top, where the guide's
    # hold (what it keeps while the drive rests) shows, are set aside. capstan takes the error from 21x to the floor
    # but its hold ended on its bound (-0.5, moving it across its range changes the error by 1.5 %), and nothing was
    # recommended. Such a parameter is held at its start value, said, and held in the printed command
    b = SampleBench(guide=Guide(mu=0.2), tracker=QUIET, load_cell=LoadCell(range_N=3.2))
    proto = Protocol(n_cycles=16, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=2.0)
    rec = simulate_bench(tube2, b, proto, Clock(rate_hz=50.0, n_repeats=0), seed=5)
    path = tmp_path / "guide.csv"
    path.write_text(format_csv(rec.data))
    out_json = tmp_path / "d.json"
    assert main(["model", "diagnose", str(path), "--pattern", str(TUBE2), "--json", str(out_json)]) == 0
    text = capsys.readouterr().out
    doc = json.loads(out_json.read_text())
    assert doc["recommended"][0] == "capstan", text
    assert doc["held"] == {"capstan.hold": 0.5}
    assert "capstan.hold held at 0.5: the rows kept barely depend on it" in text
    assert "--fix capstan.hold=0.5" in text
    assert doc["final"]["rmse_deg"] < 1.1 * rec.floor_deg


@pytest.mark.parametrize("seed", [3, 6])
def test_friction_beside_a_relaxing_backbone_with_the_guides_cell_at_its_limit_is_not_left_silent(seed):
    # bench-heldout21's friction / backbone file, 30 cycles: sample 1 friction at the guide, its cell at its limit
    # (the dwells at the top set aside), sample 2 a backbone relaxing on two time scales with a set, its guide
    # barely acting. capstan takes the error from 6.5x the floor to 3.5x, but its hold in sample 1 had an infinite
    # standard error (not on a bound: the unresolved rule did not reach it), and on every row its hold in sample 2,
    # where the guide does 0.001 deg of the 1.8 deg it does in sample 1, ended on its bound: nothing was recommended.
    # The first is held (unresolved, as on a bound), the second sample holds the guide off (it does not show it)
    p = load_pattern(PATTERNS / "tube1.yaml")
    t1 = Tracker(noise_deg=0.25, n_spikes=8, spike_deg=(3.0, 9.0), n_dropouts=4, dropout_rows=(2, 15),
                 dropout="hold", n_bursts=6, burst_rows=(2, 80))
    t2 = Tracker(noise_deg=0.18, n_spikes=8, spike_deg=(3.0, 9.0), n_dropouts=4, dropout_rows=(2, 15), n_bursts=1,
                 burst_rows=(2, 80))
    s1 = SampleBench(guide=Guide(mu=0.1), load_cell=LoadCell(range_N=2.34), tendon=Tendon(creep_A_mm_per_s=9e-7),
                     backbone=Backbone(relax=((0.1, 3.0),)), tracker=t1)
    s2 = SampleBench(guide=Guide(mu=0.0007), tendon=Tendon(crimp_mm=0.008, creep_A_mm_per_s=6e-7),
                     backbone=Backbone(relax=((0.25, 2.0), (0.2, 18.0)), yield_nmm=6.0, set_rate_per_s=0.025),
                     tracker=t2)
    proto = Protocol(n_cycles=30, ramp_s=4.5, dwell_s=3.0, rest_s=3.0, first_dwell_s=3.0)
    rec = simulate_bench(p, (s1, s2), proto, Clock(rate_hz=40.0), seed=seed)
    ok = np.isfinite(rec.data.angle_deg)
    ins = check_instruments(rec.data.take(ok))
    assert "load cell limit row" in ins.aside
    from camtube.model.diagnose import diagnose

    d = diagnose(model_for_pattern(p), ins.data, ["E_t"], pattern_values(p))
    assert d.recommended and d.recommended[0] == "capstan", (d.recommended, d.partial)
    assert set(d.recommended) & {"relaxation", "relaxation2"}, d.recommended
    assert d.held.get("capstan.hold@S1") == 0.5
    assert "capstan.mu_wrap@S1" not in d.held                     # the guide of sample 1 is never held off
    assert d.final.rmse_deg < 1.25 * rec.floor_deg


def test_a_guide_whose_friction_switches_within_a_row_is_read_as_its_law_at_the_sharp_limit(tube2):
    # Coulomb's step at the guide (the bench's sliding state regularised over 1e-6 mm/s; 0.05 by default): capstan
    # took the error from 21x the floor to 2x, but its slip speed ended on its lower bound and it was refused, and
    # the partial list read friction, hardstop. A decade above that bound the error moves by 0.015 deg of the 4.5
    # deg the guide's law takes off: the law at its sharp limit, held there, and the guide's law leads. (The rows
    # where the logged stroke and the guide disagree on when the drive started or stopped are set aside by the
    # instruments' check: see the test after the next)
    b = SampleBench(guide=Guide(mu=0.15, slip_mm_s=1e-6), tracker=Tracker(noise_deg=0.2, n_spikes=8, n_dropouts=4))
    proto = Protocol(n_cycles=20, ramp_s=3.0, dwell_s=2.0, rest_s=2.0, first_dwell_s=2.0)
    rec = simulate_bench(tube2, b, proto, Clock(rate_hz=50.0), seed=1)
    ok = np.isfinite(rec.data.angle_deg)
    ins = check_instruments(rec.data.take(ok))
    from camtube.model.diagnose import diagnose

    d = diagnose(model_for_pattern(tube2), ins.data, ["E_t"], pattern_values(tube2))
    first = next(c for c in d.rounds[0] if c.effect == "capstan" and not c.replaces)
    assert first.significant, first.why
    assert (d.recommended or d.partial)[0] == "capstan", (d.recommended, d.partial)
    steps = d.waterfall if d.recommended else d.partial_steps
    from camtube.model.effects.builtin import CAPSTAN

    sharp = next(p for p in CAPSTAN.params if p.name == "slip_mm_s")
    assert steps[1].params["capstan.slip_mm_s"] == pytest.approx(sharp.lo)   # held on the bound, the sharp limit
    assert steps[1].rmse_deg < 0.1 * steps[0].rmse_deg


@pytest.mark.parametrize("dropout", ["zero", "hold"])
def test_the_simulators_bursts_and_dropouts_written_as_values_are_set_aside_and_nothing_else(tube2, dropout):
    # the bench simulator's tracker with bursts of interference and dropouts written as 0 or as its last reading
    # (no missing values in the file): what the check sets aside is those rows, and a control is diagnosed clean
    tr = Tracker(noise_deg=0.15, n_spikes=4, spike_deg=(5.0, 9.0), n_dropouts=6, dropout_rows=(4, 12),
                 dropout=dropout, n_bursts=8, burst_rows=(2, 6))
    rec = simulate_bench(tube2, SampleBench(tracker=tr), SHORT, Clock(rate_hz=50.0, n_repeats=0), seed=21)
    assert np.isfinite(rec.data.angle_deg).all() and rec.burst_rows.size >= 16
    ins = check_instruments(rec.data)
    aside = {int(i) for k, v in ins.aside.items() for i in v}
    assert aside <= set(rec.spike_rows) | set(rec.burst_rows) | set(rec.dropout_rows)
    found = set(ins.aside.get("angle burst row", ())) | set(ins.aside["angle spike"])
    assert len(found & set(rec.burst_rows)) >= 0.9 * rec.burst_rows.size
    # a dropout while the joint is bent and the motor moves is set aside (at rest a zero or a held value is no error)
    bent = {int(i) for i in rec.dropout_rows if abs(rec.angle_true_deg[i]) > 3.0
            and abs(rec.data.stroke_mm[min(i + 1, len(rec.data) - 1)] - rec.data.stroke_mm[i - 1]) > 0}
    assert bent and bent <= aside
    model = model_for_pattern(tube2)
    from camtube.model.diagnose import diagnose

    d = diagnose(model, ins.data, ["E_t"], pattern_values(tube2))
    assert not d.recommended and not d.partial
    assert d.final.rmse_deg < 1.1 * rec.floor_deg


def test_a_tracker_that_filters_its_readings_leaves_a_control_clean(tube2):
    # the tracker's noise passes a 40 ms first-order filter (correlated from row to row at 100 Hz): read from
    # neighbouring rows the floor was 40 % low, and the paper's physics was left "unexplained" at 1.6x
    tr = Tracker(noise_deg=0.2, n_spikes=4, n_dropouts=2, filter_ms=40.0)
    rec = simulate_bench(tube2, SampleBench(tracker=tr), SHORT, Clock(rate_hz=100.0, n_repeats=0), seed=31)
    a = rec.data.angle_deg - rec.angle_true_deg
    ok = np.isfinite(a)
    ok[rec.spike_rows] = False
    assert np.corrcoef(a[ok][1:], a[ok][:-1])[0, 1] > 0.7
    ins = check_instruments(rec.data.take(np.isfinite(rec.data.angle_deg)))
    from camtube.model.diagnose import diagnose
    from camtube.model.unexplained import report as unexplained_report

    d = diagnose(model_for_pattern(tube2), ins.data, ["E_t"], pattern_values(tube2))
    assert not d.recommended and not d.partial and not unexplained_report.of_diagnosis(d)
    assert d.noise_lag_rows > 1
    assert abs(d.noise_floor_deg / rec.floor_deg - 1.0) < 0.1


SHARP = Protocol(n_cycles=12, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=2.0)


@pytest.mark.parametrize("seed", [1, 2])
def test_rows_whose_force_reads_a_guides_switch_the_stroke_has_not_logged_are_set_aside(tube2, seed):
    # a guide whose friction switches within a row (Coulomb's step): where the drive starts by less than the stroke
    # resolves, the load cell already reads the reversed tension with the stroke at rest; where it stops, the row
    # after its last step can still read the sliding guide. No law of the rows' stamps fits them (13 deg off in
    # rows of bench-heldout25, and a false lag of 25 ms): they are set aside, and the guide's law then fits at the
    # floor; a smooth guide and a control have no such row
    b = SampleBench(guide=Guide(mu=0.15, slip_mm_s=1e-6), tracker=QUIET)
    rec = simulate_bench(tube2, b, SHARP, Clock(rate_hz=50.0, n_repeats=0), seed=seed)
    ins = check_instruments(rec.data)
    ahead = ins.aside["force ahead of the stroke row"]
    assert 6 <= ahead.size <= 2 * 2 * SHARP.n_cycles          # at most one per start and stop
    s = rec.data.stroke_mm
    # each one next to a start or a stop of the stroke: it rests on one side of the row and moves on the other
    assert all((s[i] == s[i - 1]) != (s[i + 1] == s[i]) or (s[i - 1] == s[i - 2]) != (s[i] == s[i - 1])
               for i in ahead)
    assert any("force ahead of the stroke" in line for line in ins.lines())
    model, fixed = model_for_pattern(tube2, ["capstan"]), pattern_values(tube2)
    names = ["E_t", "capstan.mu_wrap", "capstan.slip_mm_s", "capstan.hold"]
    kept = fit(model, ins.data, names, fixed).rmse
    every = fit(model, rec.data, names, fixed).rmse
    assert kept < 1.15 * rec.floor_deg < 1.5 * rec.floor_deg < every
    assert ins.lag.applied_ms == 0.0
    for guide in (Guide(mu=0.15), Guide()):
        smooth = simulate_bench(tube2, SampleBench(guide=guide, tracker=QUIET), SHARP,
                                Clock(rate_hz=50.0, n_repeats=0), seed=seed)
        assert "force ahead of the stroke row" not in check_instruments(smooth.data).aside


def _sharp_releases_at_a_limit(tube2, seed: int):
    """A guide that switches within a row, a load cell whose range ends just above the tension of the rows where
    the release begins (so the dwell before reads the limit, and those rows barely below it): the record, the first
    moving rows back from the top whose switch came in that row, the force as read."""
    rec = simulate_bench(tube2, SampleBench(guide=Guide(mu=0.15, slip_mm_s=1e-6), tracker=QUIET), SHARP,
                         Clock(rate_hz=50.0, n_repeats=0), seed=seed)
    d = rec.data
    s = d.stroke_mm
    moving = np.concatenate(([False], np.diff(s) != 0.0))
    rel = np.flatnonzero(moving[1:] & ~moving[:-1] & (s[:-1] >= s.max() - 1e-9)) + 1
    rel = np.array([r for r in rel if d.sample[r] == d.sample[r - 1] and d.force_N[r - 1] > d.force_N[r] + 0.3])
    force = np.minimum(d.force_N, float(d.force_N[rel].max()) + 0.01)
    return rec, rel, force


@pytest.mark.parametrize("seed", [3, 4])
def test_a_release_the_stroke_has_not_logged_under_a_cell_that_read_its_limit_is_set_aside(tube2, seed):
    # bench-heldout36's sharp guide: the last row of each dwell read 3.206 N against the cell's limit of 3.219 N,
    # the joint 3 deg up as the guide switched, the stroke still at the top (the drive's first step below what it
    # resolves). The force's change into the row was 2 noise scales (the tension before it was above the range), so
    # the row was not "ahead of the stroke"; the model's loading branch missed it by 20 deg, and 13 such rows held
    # 60 % of what the partial chain left. Leaving the limit the way the release takes the force is the switch
    rec, rel, force = _sharp_releases_at_a_limit(tube2, seed)
    d = rec.data
    s = d.stroke_mm.copy()
    s[rel] = s[rel - 1]                       # the first step back not logged: the row reads the switch at rest
    assert rel.size >= 15 and (force[rel - 1] > force[rel]).all()
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, s, force, d.angle_deg))
    aside = _aside_mask(ins, len(d))
    assert aside[rel].all(), int((~aside[rel]).sum())
    model, fixed = model_for_pattern(tube2, ["capstan"]), pattern_values(tube2)
    kept = fit(model, ins.data, ["E_t", "capstan.mu_wrap", "capstan.slip_mm_s", "capstan.hold"], fixed).rmse
    assert kept < 1.15 * rec.floor_deg


def test_a_long_burst_over_the_guides_switch_as_the_cell_leaves_its_limit_is_set_aside_whole(tube2):
    # bench-heldout36's sharp guide: interference of -4.5 deg began in the dwell (the cell at its limit) and ended
    # 0.4 s into the release; the guide switched 3 deg within it in the row the cell left its limit, the stroke's
    # first step. Only a jump in a row at the limit was read as possibly the joint's own, so this one stood between
    # the burst's jumps, and 18 rows 4.5 deg off were kept
    rec, rel, force = _sharp_releases_at_a_limit(tube2, 5)
    d = rec.data
    rng = np.random.default_rng(5)
    a = d.angle_deg.copy()
    displaced = np.zeros(len(d), bool)
    for r in rel[::2]:
        r0, r1 = int(r - rng.integers(4, 10)), int(r + rng.integers(12, 25))
        a[r0:r1] -= 4.5
        displaced[r0:r1] = True
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, force, a))
    aside = _aside_mask(ins, len(d))
    assert displaced.sum() > 100
    assert aside[displaced].all(), int((displaced & ~aside).sum())


def test_an_angle_the_check_missed_does_not_shift_the_lag(tube2):
    # the lag regression reads every k-th row; it shifted the angle, so which angles it read changed with the shift,
    # and a burst's remnant the check missed (11 rows 6 deg off, bench-heldout25) was left out by a shift of one row
    # and not by none: a false lag of 25 ms, corrected. The angles are now the same for every shift
    rec = simulate_bench(tube2, SampleBench(tracker=QUIET), SHORT, Clock(rate_hz=50.0, n_repeats=0), seed=3)
    d = rec.data
    a = d.angle_deg.copy()
    moving = np.flatnonzero(np.abs(np.gradient(d.stroke_mm)) > 0)
    for r in moving[200::600][:6]:
        a[r] -= 6.0                     # single rows off: what a missed remnant leaves
    off = Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, a)
    from camtube.model.diagnose.instruments import estimate_lag

    lag = estimate_lag(off, max_rows=len(off) // 5)
    assert abs(lag.lag_ms) < max(3.0 * lag.se_ms, 5.0), lag


def test_a_burst_with_the_joints_own_jump_inside_it_is_set_aside_whole(tube2):
    # interference of -5 deg over the top of a stroke where a guide that switches within a row moves the joint 3 deg
    # in one row as it releases: the joint's jump inside the burst stopped the jump in and the jump back from being
    # paired, and 10 rows 5 deg off were kept (bench-heldout25). The load cell jumps in that row too, so the angle's
    # jump there is the joint's, not an edge of the interference
    b = SampleBench(guide=Guide(mu=0.15, slip_mm_s=1e-6), tracker=QUIET)
    rec = simulate_bench(tube2, b, SHARP, Clock(rate_hz=50.0, n_repeats=0), seed=1)
    d = rec.data
    s, f = d.stroke_mm, d.force_N
    # the first release at the top: the row where the stroke starts down
    top = int(np.flatnonzero((np.diff(s) < 0) & (s[:-1] == s.max()))[0]) + 1
    own = abs(rec.angle_true_deg[top + 1] - rec.angle_true_deg[top - 2])
    assert own > 2.5 and abs(f[top + 1] - f[top - 2]) > 0.2      # the joint's own jump, the cell's with it
    a = d.angle_deg.copy()
    r0, r1 = top - 15, top + 20
    a[r0:r1] -= 5.0
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, s, f, a))
    aside = {int(i) for k, v in ins.aside.items() if k != "force ahead of the stroke row" for i in v}
    displaced = set(range(r0, r1))
    assert displaced <= aside, sorted(displaced - aside)
    assert len(aside - displaced) <= 2, sorted(aside - displaced)


def test_a_sample_whose_own_lag_is_unresolved_is_tested_with_the_lag_another_sample_confirms(tube2):
    """One tracker 60 ms late in both samples; the regression resolves it in S1 but not in S2 (bench-heldout33: S2's
    load cell at its limit set aside the top of every cycle, and its own lag read -12.1 +- 4.9 ms beside S1's 46.6 +-
    7.4, both 51 ms late). S1's lag, confirmed by the model, is tested on S2's rows too, and corrected there as the
    model confirms it. (Where S2's tracker is on time, the test above: S1's lag is refused on S2's rows.)"""
    from camtube.model.diagnose.instruments import Lag, confirm_lag

    prot = Protocol(n_cycles=8, ramp_s=4.0, dwell_s=2.0, rest_s=2.0, first_dwell_s=3.0)
    late = dc_replace(QUIET, lag_ms=60.0)
    benches = (SampleBench(tracker=late), SampleBench(tracker=late))
    rec = simulate_bench(tube2, benches, prot, Clock(rate_hz=50.0, n_repeats=0), seed=8)
    ins = check_instruments(rec.data, lag_ms=0.0)
    own = (("S1", 60.0, 5.0, 0.01), ("S2", -12.0, 5.0, 0.0))
    ins = dc_replace(ins, lag=Lag(30.0, 20.0, fall=0.005, own=own))
    out = confirm_lag(ins, model_for_pattern(tube2), pattern_values(tube2))
    applied = {smp: a for smp, _, _, _, a in out.lag.per_sample}
    assert abs(applied["S1"] - 60.0) <= 20.0 + 1e-9 and abs(applied["S2"] - 60.0) <= 20.0 + 1e-9
    by_model = {smp: (before, after) for smp, before, after in out.lag.model_rmse_deg}
    assert by_model["S2"][1] < 0.95 * by_model["S2"][0]
    assert any("S2 -12 +- 5 ms, unresolved, corrected by the lag another sample shows" in line for line in out.lines())


@pytest.mark.parametrize("s2_lag_ms", [0.0, 60.0])
def test_a_sample_the_regression_s_split_left_uncorrected_is_tested_against_the_model(tube2, s2_lag_ms):
    """The regression split the samples' lags (bench-heldout34's lag: S1 52.2 +- 1.4 ms corrected, S2 30.2 +- 1.6,
    resolved but lowering its residual by less than MIN_FALL, left as it was; one tracker 51 ms late in both). S2's
    own lag is then tested against the model on its rows, as a lag the regression leaves uncorrected is where the
    samples agree: corrected where its tracker is late, refused where it is on time."""
    from camtube.model.diagnose.instruments import Lag, confirm_lag

    prot = Protocol(n_cycles=8, ramp_s=4.0, dwell_s=2.0, rest_s=2.0, first_dwell_s=3.0)
    benches = (SampleBench(tracker=dc_replace(QUIET, lag_ms=60.0)), SampleBench(tracker=dc_replace(QUIET, lag_ms=s2_lag_ms)))
    rec = simulate_bench(tube2, benches, prot, Clock(rate_hz=50.0, n_repeats=0), seed=8)
    ins = check_instruments(rec.data, lag_ms={"S1": 60.0})
    own = (("S1", 60.0, 1.4, 0.02), ("S2", 35.0, 1.6, 0.001))
    ins = dc_replace(ins, lag=Lag(45.0, 3.0, fall=0.01, per_sample=(own[0] + (60.0,), own[1] + (0.0,)), own=own))
    out = confirm_lag(ins, model_for_pattern(tube2), pattern_values(tube2))
    if s2_lag_ms:
        applied = {smp: a for smp, _, _, _, a in out.lag.per_sample}
        assert applied["S1"] == pytest.approx(60.0) and abs(applied["S2"] - s2_lag_ms) <= 20.0 + 1e-9
        (smp, before, after), = out.lag.model_rmse_deg
        assert smp == "S2" and after < 0.95 * before
        # its own lag, resolved, confirmed by the model (not another sample's)
        assert any("S2 35 +- 1.6 ms, corrected: read" in line for line in out.lines())
    else:
        assert out is ins and out.lag.applied_for("S2") == 0.0


def test_stamps_jittering_back_at_new_cycles_are_glitches_not_a_restarting_time(tmp_path):
    # a logger's jitter that stamps the first row of each new cycle a few ms before the last of the cycle before
    times = [0.1 * i for i in range(100)]
    for i in range(20, 100, 20):
        times[i] = times[i - 1] - 0.004
    meas = read_measurements(_rows_csv(tmp_path / "t.csv", times, [1 + i // 20 for i in range(100)]))
    assert list(meas.backward_lines) == [22, 42, 62, 82] and len(meas.data) == 96


def test_the_drive_s_history_runs_through_rows_set_aside_for_the_angle_alone(tube2):
    """bench-heldout49's lost motion: a burst of interference hid 2 s of the angle over the end of an unloading, where
    the force fell to the rail's hold. The carriage's law ran on the rows kept only, so it saw the force already at
    the held level after the gap and let the carriage go at once: the rest after it read 8 deg off, and nothing was
    recommended at 16x the floor. The rows set aside for the angle alone keep their stroke and force for the drive's
    history: the model on the rows kept gives, at every row, what it gives without the burst."""
    from camtube.model.effects import CARRIAGE_HOLD

    rec = simulate_bench(tube2, SampleBench(drive=Drive(backlash_mm=0.2, rail_friction_N=0.3), tracker=QUIET),
                         Protocol(n_cycles=10, ramp_s=4.0, dwell_s=1.0, rest_s=3.0, first_dwell_s=2.0),
                         Clock(rate_hz=50.0, n_repeats=0), seed=2)
    # S1's load cell not zeroed before the test (1 N high): its zero is taken off (a new force, as in that file)
    data = rec.data.with_force(rec.data.force_N + 1.0 * (np.asarray(rec.data.sample) == "S1"))
    t, s = np.asarray(data.elapsed_s, float), np.asarray(data.stroke_mm, float)
    mine = (np.asarray(data.sample) == "S1") & (np.asarray(data.cycle) == 4)
    # from where the unloading passes half the stroke, 2 s of the angle 6 deg off (past the stroke's bottom)
    start = np.flatnonzero(mine & (np.asarray(data.direction) < 0) & (s < 0.5 * s.max()))[0]
    burst = (t >= t[start]) & (t < t[start] + 2.0) & (np.asarray(data.sample) == "S1")
    assert s[burst].min() == 0.0 and s[burst].max() > 0.4 * s.max()
    hit = check_instruments(data.with_angle(data.angle_deg + 6.0 * burst))
    clean = check_instruments(data)
    assert set(np.flatnonzero(burst)) <= set(hit.aside["angle burst row"])
    assert hit.zeros["S1"].applied and clean.zeros["S1"].applied
    model = model_for_pattern(tube2, [CARRIAGE_HOLD])
    values = {**pattern_values(tube2), "carriage_hold.ratio": 1.0}
    got, want = model.predict(hit.data, values), model.predict(clean.data, values)
    common = np.isin(clean.kept.nonzero()[0], hit.kept.nonzero()[0])
    assert np.abs(got - want[common]).max() < 1e-6
    # the rest after the burst: the carriage held, the joint bent by it, as in the other rests
    rest = (hit.data.elapsed_s > t[start] + 2.0) & (hit.data.stroke_mm == 0.0) & (hit.data.cycle == 4) \
        & (np.asarray(hit.data.sample) == "S1")
    assert rest.sum() > 20 and got[rest].mean() > 1.0


@pytest.mark.parametrize("seed", [1, 6])
def test_a_long_burst_that_begins_in_the_row_the_guide_switches_is_set_aside_whole(tube2, seed):
    # bench-heldout51's sharp guide: interference of 6 deg began in the row where the release switched the guide (the
    # load cell jumped down, the joint up by its own 1-3 deg) and ended at the rest 1.8 s later. The angle's jump in
    # the force's row was taken for the joint's own whole, its jump back at the rest was left unpaired, and 185 rows
    # 6 deg off were kept: the partial chain at 1.6x the floor and nothing recommended. The joint's own jump is the
    # one every release shows; what is beyond it is the interference's edge
    b = SampleBench(guide=Guide(mu=0.15, slip_mm_s=1e-6), tracker=QUIET)
    rec = simulate_bench(tube2, b, SHARP, Clock(rate_hz=50.0, n_repeats=0), seed=seed)
    d = rec.data
    s = d.stroke_mm
    tops = np.flatnonzero((np.diff(s) < 0) & (s[:-1] == s.max())) + 1
    assert tops.size >= 10
    a = d.angle_deg.copy()
    displaced = np.zeros(len(d), bool)
    for top in tops[[2, 7]]:
        # from the release's row to the rest after the ramp down (2 s at 50 Hz) and 0.3 s into it
        r0, r1 = int(top), int(top) + 115
        assert s[r1 - 5:r1 + 5].max() == 0.0 and abs(d.force_N[top] - d.force_N[top - 1]) > 0.2
        a[r0:r1] += 6.0
        displaced[r0:r1] = True
    ins = check_instruments(Dataset(d.sample, d.cycle, d.time_s, s, d.force_N, a))
    aside = _aside_mask(ins, len(d))
    assert aside[displaced].all(), int((displaced & ~aside).sum())
    assert (aside & ~displaced).sum() <= 0.01 * len(d), int((aside & ~displaced).sum())


@pytest.mark.parametrize("s2_lag_ms", [60.0, 20.0])
def test_a_sample_whose_own_lag_is_resolved_but_short_reads_the_lag_another_sample_shows_when_the_model_fits_it_better(
        tube2, s2_lag_ms):
    """bench-heldout51: one tracker 57 ms late in both samples; S2's load cell at its limit in 45 % of its rows, and
    its regression read 28.8 +- 4.6 ms (resolved) beside S1's 55.8 +- 0.8. S2 was tried at its own whole rows and one
    either side (0, 20, 40 ms) and corrected by 40. S1's confirmed lag is tried on S2's rows too, and taken where the
    model fits it better (60 ms). Where S2's tracker truly lags 20 ms, its own stays."""
    from camtube.model.diagnose.instruments import Lag, confirm_lag

    prot = Protocol(n_cycles=8, ramp_s=4.0, dwell_s=2.0, rest_s=2.0, first_dwell_s=3.0)
    benches = (SampleBench(tracker=dc_replace(QUIET, lag_ms=60.0)),
               SampleBench(tracker=dc_replace(QUIET, lag_ms=s2_lag_ms)))
    rec = simulate_bench(tube2, benches, prot, Clock(rate_hz=50.0, n_repeats=0), seed=8)
    ins = check_instruments(rec.data, lag_ms=0.0)
    own = (("S1", 60.0, 5.0, 0.01), ("S2", 25.0, 4.0, 0.01))   # S2's own: resolved, short of 60 by 35 ms
    ins = dc_replace(ins, lag=Lag(40.0, 3.0, fall=0.005, own=own))
    out = confirm_lag(ins, model_for_pattern(tube2), pattern_values(tube2))
    applied = {smp: a for smp, _, _, _, a in out.lag.per_sample}
    assert abs(applied["S1"] - 60.0) <= 1e-6
    assert abs(applied["S2"] - s2_lag_ms) <= 1e-6, applied
    said = "S2 25 +- 4 ms, corrected by the lag another sample shows, which the model fits better than its own"
    assert any(said in line for line in out.lines()) == (s2_lag_ms == 60.0), out.lines()


def test_samples_that_show_different_effects_are_diagnosed_alone_though_a_stand_in_chain_reaches_the_floor():
    # bench-heldout51's slack beside a guide's friction: S1's tendon slack (its load cell 1.35 N low), S2's guide. The
    # joint search took a toe first (it served S1's slack and a part of S2's friction), then capstan and force_zero,
    # at 0.92x the floor: complete, so the samples were not diagnosed alone, and the slack went unnamed. A complete
    # chain that holds an effect off in a sample (the samples differ) now tries the samples' union too, taken where
    # it lowers the error and the BIC: each sample alone shows slack and capstan
    from camtube.model.diagnose import diagnose

    p = load_pattern(PATTERNS / "tube1.yaml")
    prot = Protocol(n_cycles=12, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=2.0)
    b1 = SampleBench(load_cell=LoadCell(offset_N=-1.35), tendon=Tendon(slack_mm=0.197),
                     tracker=Tracker(noise_deg=0.10, n_spikes=0, n_dropouts=0, filter_ms=20.0))
    b2 = SampleBench(guide=Guide(mu=0.188), tracker=Tracker(noise_deg=0.22, n_spikes=0, n_dropouts=0, filter_ms=25.0))
    rec = simulate_bench(p, (b1, b2), prot, Clock(rate_hz=100.0, n_repeats=0), seed=1)
    ins = check_instruments(rec.data)
    d = diagnose(model_for_pattern(p), ins.data, ["E_t"], pattern_values(p))
    assert set(d.recommended) == {"slack", "capstan"}, d.recommended
    assert d.explanation == "complete" and d.final.rmse_deg < 1.1 * rec.floor_deg
    alone = [n for n in d.sample_notes if n.startswith("each sample diagnosed alone: ")]
    assert alone and "S1 shows slack" in alone[0] and "S2 shows capstan" in alone[0], d.sample_notes
