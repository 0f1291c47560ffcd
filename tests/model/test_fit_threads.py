"""Fits and the diagnosis limit BLAS to one thread (camtube.model.core.threads) with a controller kept between
uses."""
from __future__ import annotations

import pytest

from camtube.model.core.threads import _thread_controller, one_blas_thread


def test_fits_run_blas_on_one_thread_with_a_kept_controller():
    """The kept threadpoolctl controller limits every BLAS threadpoolctl sees, as threadpool_limits does."""
    threadpoolctl = pytest.importorskip("threadpoolctl")

    assert _thread_controller() is _thread_controller()
    before = {lib["filepath"]: lib["num_threads"] for lib in threadpoolctl.threadpool_info()}
    with one_blas_thread():           # as fit() and diagnose() hold it
        inside = threadpoolctl.threadpool_info()
        with one_blas_thread():       # nested: still one, and the outer limit is back after it
            pass
        again = threadpoolctl.threadpool_info()
    assert all(lib["num_threads"] == 1 for lib in inside + again if lib["user_api"] == "blas")
    assert {lib["filepath"]: lib["num_threads"] for lib in threadpoolctl.threadpool_info()} == before


def test_the_lag_scan_gives_the_same_estimate_on_one_thread():
    """The instruments' lag scan runs under one BLAS thread: its regressions come out as with the default."""
    import numpy as np

    from camtube.design.loader import load_pattern
    from camtube.model.diagnose.instruments import estimate_lag
    from camtube.model.sim.bench import Clock, Protocol, SampleBench, Tracker, simulate_bench
    from tests.conftest import PATTERNS

    p = load_pattern(PATTERNS / "tube2.yaml")
    rec = simulate_bench(p, (SampleBench(tracker=Tracker(n_spikes=0, n_dropouts=0)),) * 2,
                         Protocol(n_cycles=6, ramp_s=2.0, dwell_s=1.0, rest_s=1.0, first_dwell_s=1.0),
                         Clock(rate_hz=100.0), seed=7)
    default = estimate_lag(rec.data)
    with one_blas_thread():
        single = estimate_lag(rec.data)
    assert vars(single) == vars(default) and np.isfinite(default.lag_ms)   # Lag compares by identity
