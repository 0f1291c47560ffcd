"""One BLAS thread for the model's numerics (fits, the diagnosis), when threadpoolctl is installed.

Why: the model's linear algebra is tall and thin (n rows, a few columns). OpenBLAS threads bring nothing
there, and waking them costs milliseconds per call when the cores are busy: on a 2-core machine with another
process on one core, a dot product of 12,000 values took 8 ms with two threads and 2 us with one. The
diagnosis makes thousands of such calls (the lag scan's regressions, the grid starts' sums of squares).

With one thread OpenBLAS sums a long dot product in one pass instead of two halves added at the end, so
such a sum may differ in its last bit; the regressions (QR and SVD products) come out the same.
"""
from __future__ import annotations

import contextlib
import sys

__all__ = ["one_blas_thread"]

_CONTROLLER: list = []


def one_blas_thread():
    """Context manager: BLAS limited to one thread inside (a no-op without threadpoolctl). Nests."""
    controller = _thread_controller()
    return contextlib.nullcontext() if controller is None else controller.limit(limits=1, user_api="blas")


def _thread_controller():
    """A threadpoolctl controller of the loaded libraries, or ``None`` without threadpoolctl.

    speed: building one scans every loaded library (about a millisecond, and a diagnosis fits hundreds of
    times), so it is kept, and built again only when modules were imported since (a new BLAS comes in with an
    import: the limit must reach it as ``threadpool_limits`` would).
    """
    if _CONTROLLER and _CONTROLLER[0] == len(sys.modules):
        return _CONTROLLER[1]
    try:
        from threadpoolctl import ThreadpoolController
    except ModuleNotFoundError:
        return None
    controller = ThreadpoolController()
    _CONTROLLER[:] = [len(sys.modules), controller]
    return controller
