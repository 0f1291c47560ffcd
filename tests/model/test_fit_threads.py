"""Fits limit BLAS to one thread (camtube.model.core.fit._blas_single_thread) with a controller kept between fits."""
from __future__ import annotations

import pytest


def test_fits_run_blas_on_one_thread_with_a_kept_controller():
    """The kept threadpoolctl controller limits every BLAS threadpoolctl sees, as threadpool_limits does."""
    threadpoolctl = pytest.importorskip("threadpoolctl")
    from camtube.model.core.fit import _blas_single_thread, _thread_controller

    assert _thread_controller() is _thread_controller()
    with _blas_single_thread():
        inside = threadpoolctl.threadpool_info()
    assert all(lib["num_threads"] == 1 for lib in inside if lib["user_api"] == "blas")
