"""``play_held``: lost motion in the drive, a carriage its rail holds (it moves only when a flank of the nut pushes it)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.model.core.predict import joint_stiffness_nmm_per_rad, model_for_pattern, pattern_values
from camtube.model.core.registry import builtin_registry
from camtube.model.data.dataset import Dataset
from camtube.model.diagnose import diagnose
from tests.conftest import PATTERNS


@pytest.fixture(scope="module")
def tube2():
    return load_pattern(PATTERNS / "tube2.yaml")


def _held_carriage(motor_mm: np.ndarray, gap_mm: float) -> np.ndarray:
    """The carriage, row by row: it starts on the motor's flank and moves only when a flank pushes it."""
    out = np.empty(motor_mm.size)
    pos = motor_mm[0]
    for k, x in enumerate(motor_mm):
        if x > pos:
            pos = x                  # the near flank pushes it up
        elif x < pos - gap_mm:
            pos = x + gap_mm         # the far flank pushes it down
        out[k] = pos
    return out


def _profile(rate_hz: float, n_cycles: int, peak_mm: float, rng) -> np.ndarray:
    """Motor stroke: per cycle a rest at zero, a smooth rise, a dwell, a smooth fall (10 s)."""
    per = int(10 * rate_hz)
    u = np.arange(per) / per
    ramp = lambda v: 0.5 - 0.5 * np.cos(np.pi * np.clip(v, 0.0, 1.0))  # noqa: E731
    one = np.where(u < 0.15, 0.0, np.where(u < 0.45, ramp((u - 0.15) / 0.3),
                                           np.where(u < 0.55, 1.0, 1.0 - ramp((u - 0.55) / 0.3))))
    return np.concatenate([peak_mm * rng.uniform(0.9, 1.0) * one for _ in range(n_cycles)])


def test_the_law_is_the_held_carriage_row_by_row(tube2):
    rng = np.random.default_rng(5)
    motor = np.abs(np.cumsum(rng.normal(0.0, 0.02, 4000)))
    n = motor.size
    data = Dataset(np.array(["S1"] * n, dtype=object), np.ones(n, int), np.arange(n) / 50.0, motor,
                   np.ones(n), np.zeros(n))
    m = model_for_pattern(tube2, ["play_held"])
    ctx = m.context(data, m.initial_values(data, pattern_values(tube2)))
    for gap in (0.0, 0.03, 0.2):
        got = m.effects[0].function("stroke")(ctx, motor.copy(), {"play_mm": gap})
        np.testing.assert_allclose(got, _held_carriage(motor, gap), atol=1e-12)


def test_diagnosis_names_the_drive_for_a_held_carriage(tube2):
    """An independent toy bench (a linear joint and tendon; the carriage of :func:`_held_carriage`): one drive
    effect, recommended alone, reaches the floor; play (the carriage on the motor's flank at rest) and a sensor offset
    do not stand in for it."""
    rng = np.random.default_rng(17)
    m = model_for_pattern(tube2)
    vals = pattern_values(tube2)
    c = m.compliance_mm_per_N(vals | {"E_t": vals.get("E_t", 28.0)})
    arm = m.geometry.moment_arm_mm
    k_nmm = joint_stiffness_nmm_per_rad(tube2)
    sa, sf, rate = 0.2, 0.004, 20.0
    cols = {key: [] for key in ("s", "cyc", "t", "x", "f", "a")}
    for smp, gap in (("S1", 0.12), ("S2", 0.10)):
        motor = _profile(rate, 12, 2.0, rng)
        carriage = _held_carriage(motor, gap)
        # stroke = arm theta + c T, T = k theta / arm (the tendon taut while the carriage is above zero)
        theta = carriage / (arm + c * k_nmm / arm)
        tension = k_nmm * theta / arm
        n = motor.size
        cols["s"].append(np.full(n, smp, dtype=object))
        cols["cyc"].append(1 + np.arange(n) // int(10 * rate))
        cols["t"].append(np.arange(n) / rate)
        cols["x"].append(motor)
        cols["f"].append(tension + rng.normal(0, sf, n))
        cols["a"].append(np.degrees(theta) + rng.normal(0, sa, n))
    cat = {key: np.concatenate(v) for key, v in cols.items()}
    data = Dataset(cat["s"], cat["cyc"], cat["t"], cat["x"], cat["f"], cat["a"])
    floor = math.hypot(sa, math.degrees(c / arm) * sf)
    d = diagnose(m, data, ("E_t",), vals)
    drive = {e.name for e in builtin_registry().effects if e.family == "drive"}
    assert d.recommended and d.recommended[0] in drive, (d.recommended, d.stop_reason)
    assert not {"angle_bias", "force_zero"} & set(d.recommended), d.recommended
    assert d.final.rmse_deg <= 1.15 * floor, (d.final.rmse_deg, floor)
