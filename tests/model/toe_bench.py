"""A short bench file with a toe (three cycles, no tracker artefacts), and its rows with an empty cache: the
fixture of the tests that compare kept work with fresh evaluations to the bit."""
from __future__ import annotations

import numpy as np

from camtube.design.loader import load_pattern
from camtube.model.sim.bench import Clock, Protocol, SampleBench, Tendon, Tracker, simulate_bench
from tests.conftest import PATTERNS


def toe_bench(seed: int):
    """``(pattern, data)``: tube2, a toe of 0.2 mm, three cycles at 25 Hz."""
    p = load_pattern(PATTERNS / "tube2.yaml")
    rec = simulate_bench(p, SampleBench(tendon=Tendon(crimp_mm=0.2, crimp_shape=2.0),
                                        tracker=Tracker(n_spikes=0, n_dropouts=0)),
                         Protocol(n_cycles=3, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=1.0),
                         Clock(rate_hz=25.0), seed=seed)
    return p, rec.data


def fresh(data):
    """The same rows with an empty cache."""
    return data.take(np.ones(len(data), bool))
