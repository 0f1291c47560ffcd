"""Fits and the diagnosis limit BLAS to one thread (camtube.model.core.threads) with a controller kept between
uses."""
from __future__ import annotations

import pytest

from camtube.model.core.fit import _blas_single_thread
from camtube.model.core.threads import _thread_controller, one_blas_thread


def test_fits_run_blas_on_one_thread_with_a_kept_controller():
    """The kept threadpoolctl controller limits every BLAS threadpoolctl sees, as threadpool_limits does."""
    threadpoolctl = pytest.importorskip("threadpoolctl")

    assert _thread_controller() is _thread_controller()
    before = {lib["filepath"]: lib["num_threads"] for lib in threadpoolctl.threadpool_info()}
    with _blas_single_thread():
        inside = threadpoolctl.threadpool_info()
        with one_blas_thread():       # nested: still one, and the outer limit is back after it
            pass
        again = threadpoolctl.threadpool_info()
    assert all(lib["num_threads"] == 1 for lib in inside + again if lib["user_api"] == "blas")
    assert {lib["filepath"]: lib["num_threads"] for lib in threadpoolctl.threadpool_info()} == before
