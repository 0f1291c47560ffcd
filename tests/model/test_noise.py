"""The white-noise estimate from high-order differences (the noise floor's and the instruments' building block)."""
from __future__ import annotations

import numpy as np
import pytest

from camtube.model.core.noise import white_noise_sd


@pytest.mark.parametrize("sd", [0.01, 0.2])
def test_white_noise_on_a_smooth_signal_with_a_few_spikes(sd):
    rng = np.random.default_rng(3)
    t = np.linspace(0.0, 60.0, 20_000)
    x = 30.0 * (1.0 - np.cos(2.0 * np.pi * t / 12.0)) + rng.normal(0.0, sd, t.size)
    x[rng.choice(t.size, 20, replace=False)] += 8.0  # interference spikes
    assert white_noise_sd(x) == pytest.approx(sd, rel=0.05)


def test_too_short_a_signal_has_no_estimate():
    assert white_noise_sd(np.arange(6.0)) == 0.0


@pytest.mark.parametrize("step", [0.01, 0.02])
def test_a_signal_read_in_steps_coarser_than_its_noise_has_the_steps_noise(step):
    # a load cell logged to 0.01 or 0.02 N with 2 mN of noise: most rows repeat the last reading, every robust
    # estimate from the differences reads 0; the reading's error is uniform within half a step either side
    rng = np.random.default_rng(5)
    t = np.linspace(0.0, 60.0, 20_000)
    force = np.clip(1.5 * np.sin(2.0 * np.pi * t / 12.0), 0.0, None) + rng.normal(0.0, 0.002, t.size)
    read = np.round(force / step) * step
    assert white_noise_sd(read) == pytest.approx(step / np.sqrt(12.0), rel=0.02)


def test_a_smooth_signal_without_noise_reads_none():
    assert white_noise_sd(np.linspace(0.0, 3.0, 500)) < 1e-12   # (the float rounding of the ramp's steps)
    assert white_noise_sd(np.full(500, 0.25)) == 0.0


def test_a_signal_without_noise_that_holds_and_steps_reads_none():
    # a load cell's noise-free reading that holds 0.2 N at a rest, then 0: one step, no steps of a resolution
    assert white_noise_sd(np.concatenate((np.full(100, 0.2), np.zeros(100)))) == 0.0
