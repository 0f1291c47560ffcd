"""Independent pieces on the machine's cores: the same results as one after another."""
from __future__ import annotations

import numpy as np
import pytest

from camtube.model.core import parallel
from camtube.model.core.model import FitError


def test_pieces_run_here_and_in_forked_workers_and_return_in_order():
    # this process takes pieces from the queue too (a fork per call costs; it would otherwise wait)
    import os
    import time

    big = np.arange(1_000_000, dtype=float)  # inherited by the workers, never pickled

    def piece(i: int):
        time.sleep(0.05)   # long enough for every process to take some
        return i, float(big[i::7].sum()), os.getpid()

    got = parallel.map_forked(piece, 6)
    assert [g[:2] for g in got] == [(i, float(big[i::7].sum())) for i in range(6)]
    if parallel.cores() > 1:
        workers = {g[2] for g in got} - {os.getpid()}
        assert workers   # some ran in a worker
        for pid in workers:   # and every worker is gone, reaped (a zombie would still take a signal)
            with pytest.raises(ProcessLookupError):
                os.kill(pid, 0)


def test_an_error_in_a_piece_is_raised_as_in_a_loop():
    def piece(i: int):
        if i == 2:
            raise FitError(f"piece {i} cannot be fitted")
        return i

    with pytest.raises(FitError, match="piece 2 cannot be fitted"):
        parallel.map_forked(piece, 4)


def test_one_core_or_one_piece_runs_here(monkeypatch):
    import os

    monkeypatch.setattr(parallel, "cores", lambda: 1)
    assert parallel.map_forked(lambda i: (i, os.getpid()), 3) == [(i, os.getpid()) for i in range(3)]


def test_a_worker_that_dies_leaves_the_pieces_to_this_process():
    import os

    parent = os.getpid()

    def piece(i: int):
        if os.getpid() != parent and i == 1:
            os._exit(3)  # a worker killed mid-piece
        return i * i

    assert parallel.map_forked(piece, 3) == [0, 1, 4]


def test_camtube_workers_caps_the_cores(monkeypatch):
    monkeypatch.setenv("CAMTUBE_WORKERS", "1")
    assert parallel.cores() == 1
    monkeypatch.setenv("CAMTUBE_WORKERS", "64")
    assert parallel.cores() >= 1
    monkeypatch.setenv("CAMTUBE_WORKERS", "many")  # not a count: ignored
    assert parallel.cores() >= 1


@pytest.mark.skipif(parallel.cores() < 2, reason="one core: the pieces run here, no workers to stop")
def test_sigterm_in_the_parent_stops_the_workers_at_once(tmp_path):
    """Bug 27: SIGTERM is an interrupt (camtube.io.Terminated) for a command; leaving the executor waited for every
    piece to finish first (a long diagnosis went on for minutes). Now the workers are ended and it stops at once."""
    import os
    import signal
    import threading
    import time

    from camtube.io import Terminated, raise_terminated

    def piece(i: int):
        (tmp_path / f"{i}.pid").write_text(str(os.getpid()))
        time.sleep(30)
        return i

    old = signal.signal(signal.SIGTERM, raise_terminated)
    timer = threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGTERM))
    t0 = time.monotonic()
    try:
        timer.start()
        with pytest.raises(Terminated):
            parallel.map_forked(piece, 4)
    finally:
        timer.cancel()
        signal.signal(signal.SIGTERM, old)
    assert time.monotonic() - t0 < 10
    workers = [int(f.read_text()) for f in tmp_path.glob("*.pid") if int(f.read_text()) != os.getpid()]
    assert workers   # (this process ran a piece too)
    for pid in workers:  # the workers are gone
        with pytest.raises(ProcessLookupError):
            os.kill(pid, 0)


def test_a_result_or_an_error_that_does_not_pickle_comes_back_as_in_a_loop():
    # a worker's result crosses back pickled; one that cannot (a closure, an error of a class made inside a function)
    # is not lost or turned into another error: the piece runs again in this process
    import time

    class Local(Exception):
        pass

    def closure(i: int):
        time.sleep(0.05)   # (every process takes some)
        return lambda: i * i

    got = parallel.map_forked(closure, 6)
    assert [f() for f in got] == [0, 1, 4, 9, 16, 25]

    def piece(i: int):
        time.sleep(0.05)
        if i % 2:
            raise Local(f"piece {i}")
        return i

    with pytest.raises(Local, match="piece 1"):   # the first piece's error, as in a loop
        parallel.map_forked(piece, 6)


def test_a_standard_stream_that_cannot_be_written_does_not_stop_the_pieces(monkeypatch):
    # `camtube model diagnose ... --report R | head`: once head has gone, flushing stdout raises; the fits must go on
    # (the report is written; the command's own printing meets the broken pipe, as before workers flushed it)
    import io
    import time

    class Gone(io.StringIO):
        def flush(self):
            raise BrokenPipeError(32, "Broken pipe")

    monkeypatch.setattr("sys.stdout", Gone())

    def piece(i: int):
        time.sleep(0.02)
        return i * 3

    assert parallel.map_forked(piece, 4) == [0, 3, 6, 9]
