"""``carriage_hold``: lost motion in the drive, a carriage that its rail's friction holds within the nut's gap."""
from __future__ import annotations

import numpy as np
import pytest

from camtube.model.data.dataset import Dataset
from camtube.model.effects.history import HOLD_BAND, RELEASE_SHARE, carriage_hold
from camtube.model.effects.kernels import hold_rows


def _rows(stroke, force, rate_hz=100.0, samples=("S1",)):
    n = len(stroke) // len(samples)
    t = np.tile(np.arange(n) / rate_hz, len(samples))
    smp = np.repeat(np.array(samples), n)
    return Dataset(stroke_mm=np.asarray(stroke, float), force_N=np.asarray(force, float),
                   angle_deg=np.zeros(len(stroke)), time_s=t, cycle=np.ones(len(stroke), int), sample=smp)


@pytest.mark.parametrize("seed", range(6))
def test_the_compiled_hold_is_the_law_row_by_row(seed):
    """The compiled law gives, to the bit, what its own Python source gives run row by row by the interpreter (the
    compiler changes nothing: no integer, float or boolean typed otherwise), per sample, within the nut's gap;
    what the law does is checked by the tests below."""
    rng = np.random.default_rng(seed)
    n = 3000
    t = np.arange(n) / 100.0
    stroke = np.clip(1.2 * np.sin(2 * np.pi * t / rng.uniform(3, 8)) + rng.uniform(-0.3, 0.3), 0.0, None)
    force = 1.5 * stroke + rng.normal(0, 0.05, n) + rng.uniform(0, 0.2) * (stroke == 0)
    force[rng.integers(0, n, 40)] = 0.0                     # releases
    data = _rows(np.concatenate([stroke, stroke[::-1]]), np.concatenate([force, force[::-1]]), samples=("S1", "S2"))
    s = np.asarray(data.stroke_mm, float)
    f = np.asarray(data.force_smoothed_N, float)
    bounds = [(sl.start, sl.stop) for _, sl in data.sample_slices()]
    starts, stops = (np.array(x, np.int64) for x in zip(*bounds))
    held = False
    for hold, gap in ((0.15, 0.2), (0.3, 0.05), (0.05, 1.0)):
        got = carriage_hold(data, s, hold, gap)
        # the law as written (numba's Python function, run by the interpreter), row by row
        law = hold_rows.py_func(s, f, starts, stops, np.full(s.size, hold), gap, HOLD_BAND, RELEASE_SHARE)
        np.testing.assert_array_equal(got, law)
        assert np.all(got >= s - 1e-12) and np.all(got <= s + gap + 1e-12)   # within the nut's gap
        held |= bool(np.any(got > s + 1e-6))
    assert held                                                                # the rail holds it somewhere


def test_a_carriage_held_at_the_bottom_keeps_the_tendon_taut_until_it_lets_go():
    # unload from 1 mm to 0 over 1 s; the tension falls with the stroke through the hold force 0.32 N at 0.16 mm,
    # then stays at 0.2 N (held); at 2.0 s it drops to zero (let go)
    t = np.arange(0, 3.0, 0.01)
    s = np.clip(1.0 - t, 0.0, None)
    f = np.where(s > 0.1, 2.0 * s, 0.2)
    f[t >= 2.0] = 0.0
    data = _rows(s, f)
    c = carriage_hold(data, s, 0.32, 0.5)
    held = (t > 0.85) & (t < 1.95)
    assert np.allclose(c[held], 0.16, atol=1e-9)              # the carriage stays where the tension fell to 0.32 N
    assert np.all(c[t >= 2.05] == s[t >= 2.05])               # let go: on the flank again
    assert np.all(c[t < 0.83] == s[t < 0.83])                 # pulled onto the flank above the hold force
    small_gap = carriage_hold(data, s, 0.32, 0.04)             # the nut's far flank pushes it down
    assert np.allclose(small_gap[(t >= 1.0) & (t < 1.95)], 0.04, atol=1e-9)


def test_a_carriage_that_slips_onto_the_flank_is_held_there_again():
    # held at 0.16 mm (the tension fell to 0.32 N there, then stays at 0.2 N); at 0.95 s, the motor at 0.05 mm, the
    # tension crept past the rail's friction and the carriage slipped onto the nut's flank (the force drops to zero);
    # the rail holds it there while the motor goes on to zero, so the next pull first takes that 0.05 mm up
    t = np.arange(0, 4.0, 0.01)
    s = np.clip(1.0 - t, 0.0, None)
    s[t >= 2.5] = t[t >= 2.5] - 2.5                            # the next pull from 2.5 s
    f = np.where(s > 0.1, 2.0 * s, 0.2)
    f[(t >= 0.95) & (t < 2.6)] = 0.0
    f[t >= 2.6] = np.maximum(2.0 * (s[t >= 2.6] - 0.05), 0.0)
    data = _rows(s, f)
    c = carriage_hold(data, s, 0.32, 0.5)
    assert np.allclose(c[(t > 0.85) & (t < 0.9)], 0.16, atol=1e-9)
    # the slip: where the (smoothed) force falls below half the hold force, on the motor's way from 0.1 to 0.04 mm
    k = int(np.flatnonzero((t > 0.85) & (np.asarray(data.force_smoothed_N) < RELEASE_SHARE * 0.32))[0])
    assert 0.04 <= s[k] <= 0.1
    assert np.allclose(c[k:250], s[k], atol=1e-9)                   # held where it slipped to, the motor below
    pull = (t >= 2.5) & (s <= s[k])
    assert np.allclose(c[pull], s[k], atol=1e-9)                    # the pull takes that gap up first
    assert np.all(c[t >= 2.7] == s[t >= 2.7])                       # then the carriage follows the nut


def test_off_and_no_held_rows_give_the_stroke_itself():
    t = np.arange(0, 3.0, 0.01)
    s = np.clip(1.0 - np.abs(t - 1.5), 0.0, None)
    data = _rows(s, 2.0 * s)
    assert np.array_equal(carriage_hold(data, s, 0.2, 0.0), s)
    assert np.array_equal(carriage_hold(data, s, 0.0, 0.3), s)
    # a tension that never falls to the hold force: the carriage follows the stroke
    assert np.array_equal(carriage_hold(_rows(s, 2.0 * s + 0.5), s, 0.2, 0.3), s)


def test_the_held_position_moves_continuously_with_the_hold_force():
    t = np.arange(0, 2.0, 0.01)
    s = np.clip(1.0 - t, 0.0, None)
    f = 2.0 * s + 0.2                                         # held at 0.2 N, above half the hold force
    data = _rows(s, f)
    a = carriage_hold(data, s, 0.3, 1.0)[-1]
    b = carriage_hold(data, s, 0.3 + 1e-6, 1.0)[-1]
    assert 0 < b - a < 1e-5                                   # no step: a fit can move the hold force


def test_carriage_gap_is_carriage_hold_within_the_nut_s_gap():
    """The built-in carriage_gap lifts the stroke as carriage_hold does while the gap does not bind, and by at most
    the gap where it does (the far flank pushes the held carriage down with the motor)."""
    from camtube.model.core.registry import builtin_registry
    from camtube.model.effects.builtin import carriage_lift_mm, held_tension_N

    t = np.arange(0, 3.0, 0.01)
    s = np.clip(1.0 - t, 0.0, None)
    f = np.where(s > 0.1, 2.0 * s, 0.2)
    f[t >= 2.0] = 0.0
    data = _rows(s, f)
    assert held_tension_N(data)[0] == pytest.approx(0.2)
    wide = carriage_lift_mm(data, 1.6, 10.0)
    assert np.array_equal(wide, carriage_lift_mm(data, 1.6))          # carriage_hold's lift: the gap never binds
    assert wide.max() == pytest.approx(0.16, abs=1e-9)
    narrow = carriage_lift_mm(data, 1.6, 0.04)
    assert narrow.max() == pytest.approx(0.04, abs=1e-9) and np.all(narrow <= wide + 1e-12)
    reg = builtin_registry()
    gap, hold = reg["carriage_gap"], reg["carriage_hold"]
    assert gap.family == hold.family == "drive" and gap.off == {"ratio": 0.0}
    assert [p.name for p in gap.params] == ["ratio", "gap_mm"]
