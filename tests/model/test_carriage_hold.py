"""``carriage_hold``: lost motion in the drive, a carriage that its rail's friction holds within the nut's gap."""
from __future__ import annotations

import numpy as np
import pytest

from camtube.model.data.dataset import Dataset
from camtube.model.effects.history import HOLD_BAND, RELEASE_SHARE, carriage_hold


def _rows(stroke, force, rate_hz=100.0, samples=("S1",)):
    n = len(stroke) // len(samples)
    t = np.tile(np.arange(n) / rate_hz, len(samples))
    smp = np.repeat(np.array(samples), n)
    return Dataset(stroke_mm=np.asarray(stroke, float), force_N=np.asarray(force, float),
                   angle_deg=np.zeros(len(stroke)), time_s=t, cycle=np.ones(len(stroke), int), sample=smp)


def _by_rows(data, s, hold, gap):
    """The law row by row (the reference the vectorised operator is checked against)."""
    f = np.asarray(data.force_smoothed_N, float)
    out = s.copy()
    for _, sl in data.sample_slices():
        low_prev, seen, gone, c = False, False, False, 0.0
        for k in range(sl.start, sl.stop):
            first = k == sl.start
            slip = False
            if f[k] > HOLD_BAND * hold:                        # pulled onto the flank: a new run may start
                seen = gone = False
            else:
                seen = seen or f[k] <= hold
                slip = not gone and f[k] < RELEASE_SHARE * hold    # slips onto the flank, held there again
                gone = gone or slip
            if not seen or f[k] > HOLD_BAND * hold:
                c, low_prev = s[k], False
                continue
            if slip:
                c = s[k]
            elif not low_prev:                                 # held from here: where the force fell to hold_N
                if first or f[k - 1] <= hold:
                    c = s[k]
                elif k - 2 >= sl.start and f[k - 2] > f[k - 1]:    # along the unloading from the two rows before
                    c = s[k - 1] + (s[k - 1] - s[k - 2]) * (f[k - 1] - hold) / (f[k - 2] - f[k - 1])
                else:
                    c = s[k - 1] + (s[k] - s[k - 1]) * (f[k - 1] - hold) / (f[k - 1] - f[k])
                c = min(max(c, min(s[k], s[k - 1])), max(s[k], s[k - 1])) if not first else c
                c = min(max(c, s[k]), s[k] + gap)
            else:
                c = min(max(c, s[k]), s[k] + gap)
            out[k] = c
            low_prev = True
    return out


@pytest.mark.parametrize("seed", range(6))
def test_the_vectorised_hold_is_the_law_row_by_row(seed):
    rng = np.random.default_rng(seed)
    n = 3000
    t = np.arange(n) / 100.0
    stroke = np.clip(1.2 * np.sin(2 * np.pi * t / rng.uniform(3, 8)) + rng.uniform(-0.3, 0.3), 0.0, None)
    force = 1.5 * stroke + rng.normal(0, 0.05, n) + rng.uniform(0, 0.2) * (stroke == 0)
    force[rng.integers(0, n, 40)] = 0.0                     # releases
    data = _rows(np.concatenate([stroke, stroke[::-1]]), np.concatenate([force, force[::-1]]), samples=("S1", "S2"))
    s = np.asarray(data.stroke_mm, float)
    for hold, gap in ((0.15, 0.2), (0.3, 0.05), (0.05, 1.0)):
        np.testing.assert_allclose(carriage_hold(data, s, hold, gap), _by_rows(data, s, hold, gap), atol=1e-12)


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
