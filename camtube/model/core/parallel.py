"""Independent pieces of work on the machine's cores, with results identical to running them one after another.

:func:`map_forked` runs ``fn(0) .. fn(n - 1)`` in forked worker processes (each inherits the parent's memory,
so ``fn`` may close over models, data and a user's effect files; only its result crosses back, pickled). Each
worker runs BLAS on one thread, as the parent's fits do, so the numbers are those of the sequential run. Off
Linux (Windows has no fork; on macOS a forked process may crash in the system's libraries, which is why Python
spawns there) or with one core, the pieces run in this process.
"""
from __future__ import annotations

import multiprocessing
import os
import signal
import sys
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Callable, TypeVar

T = TypeVar("T")

_JOB: Callable | None = None


def cores() -> int:
    """Cores this process may run on; at most ``CAMTUBE_WORKERS`` when that is set (``1``: one after another)."""
    try:
        n = len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        n = os.cpu_count() or 1
    cap = os.environ.get("CAMTUBE_WORKERS", "").strip()
    return max(1, min(n, int(cap))) if cap.isdigit() else n


def _worker_start() -> None:
    """In a new worker: SIGTERM ends it at once, as before the command line made SIGTERM an interrupt in the
    process the worker was forked from (a killed worker is a broken pool, whose pieces then run in the parent)."""
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def _stop_workers(ex: ProcessPoolExecutor, futures) -> None:
    """Ctrl-C or SIGTERM in the parent: cancel the pieces not started and end the workers now (leaving the
    executor would otherwise wait for every piece to finish)."""
    for f in futures:
        f.cancel()
    for proc in list((getattr(ex, "_processes", None) or {}).values()):
        try:
            proc.kill()
        except (OSError, ValueError, AttributeError):
            pass


def _run(i: int):
    from camtube.model.core.threads import one_blas_thread

    with one_blas_thread():
        return _JOB(i)


def map_forked(fn: Callable[[int], T], n: int) -> list[T]:
    """``[fn(0), ..., fn(n - 1)]``, on up to :func:`cores` forked processes; in this process off Linux, with one
    core or one piece. An exception in a piece is raised here, as it would be in a loop
    (the first piece's first)."""
    global _JOB
    workers = min(n, cores())
    if workers < 2 or not sys.platform.startswith("linux") or _JOB is not None:
        return [fn(i) for i in range(n)]   # (and never nested: a worker runs its pieces in turn)
    _JOB = fn
    try:
        with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("fork"),
                                 initializer=_worker_start) as ex:
            futures = [ex.submit(_run, i) for i in range(n)]
            try:
                return [f.result() for f in futures]
            except KeyboardInterrupt:
                _stop_workers(ex, futures)
                raise
    except BrokenProcessPool:  # a worker died (killed, out of memory): the pieces again, here
        pass
    finally:
        _JOB = None
    return [fn(i) for i in range(n)]
