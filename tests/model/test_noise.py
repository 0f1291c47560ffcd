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
