"""Independent pieces of work on the machine's cores, with results identical to running them one after another.

:func:`map_forked` runs ``fn(0) .. fn(n - 1)`` in this process and in worker processes forked for the call (each
inherits this process's memory, so ``fn`` may close over models, data and a user's effect files; only a worker's
result crosses back, pickled). Every process runs BLAS on one thread, as the fits do, so the numbers are those of the
sequential run. Off Linux (Windows has no fork; on macOS a forked process may crash in the system's libraries, which
is why Python spawns there) or with one core, the pieces run in this process alone.
"""
from __future__ import annotations

import os
import pickle
import select
import signal
import struct
import sys
import threading
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


#: Bytes of a piece's index in the queue of pieces (a pipe every process takes the next index from).
_INDEX = struct.Struct("<I")
#: Bytes of the length of a result message.
_LENGTH = struct.Struct("<Q")


def map_forked(fn: Callable[[int], T], n: int) -> list[T]:
    """``[fn(0), ..., fn(n - 1)]``, on up to :func:`cores` processes: this one and workers forked now; in this process
    alone off Linux, with one core or one piece. An exception in a piece is raised here, as it would be in a loop
    (the first piece's first).

    Each process takes the next piece from one queue until none is left (dynamic: a long piece does not hold the
    others up), with BLAS on one thread (:func:`~camtube.model.core.threads.one_blas_thread`), so the numbers are
    those of the sequential run. A worker's results cross back pickled; this process's stay as they are. A worker
    that dies (killed, out of memory) leaves its unfinished pieces to this process. Ctrl-C or SIGTERM here ends the
    workers at once. Never nested: within a piece, a further ``map_forked`` runs its pieces in turn.

    speed: a diagnosis calls this 30-90 times; a pool of forked workers cost 45-55 ms a call (the fork of a
    several-hundred-MB process twice, the executor's queues and threads), one forked worker beside this process about
    12 ms, and this process works instead of waiting.
    """
    global _JOB
    workers = min(n, cores())
    if workers < 2 or not sys.platform.startswith("linux") or _JOB is not None or n * _INDEX.size > select.PIPE_BUF * 8:
        return [fn(i) for i in range(n)]
    _JOB = fn
    try:
        return _shared_queue(fn, n, workers)
    finally:
        _JOB = None


def _shared_queue(fn: Callable[[int], T], n: int, workers: int) -> list[T]:
    """:func:`map_forked`'s pieces on this process and ``workers - 1`` forked ones."""
    from camtube.model.core.threads import one_blas_thread

    queue_r, queue_w = os.pipe()
    os.write(queue_w, b"".join(_INDEX.pack(i) for i in range(n)))   # (n x 4 bytes: within the pipe's buffer)
    os.close(queue_w)
    done: dict[int, tuple[bool, object]] = {}
    children: list[tuple[int, int]] = []
    readers = []
    try:
        for _ in range(workers - 1):
            res_r, res_w = os.pipe()
            _flush()   # (what this process has buffered is not written twice, by the worker too)
            pid = os.fork()
            if pid == 0:   # the worker: pieces from the queue until it is empty, each result sent back
                os.close(res_r)
                _worker(fn, queue_r, res_w)
            os.close(res_w)
            children.append((pid, res_r))
        # (the threads start once every worker is forked: a fork copies this thread alone)
        readers = [threading.Thread(target=_collect, args=(res_r, done), daemon=True) for _, res_r in children]
        for reader in readers:
            reader.start()
        with one_blas_thread():
            while True:
                i = _next_index(queue_r)
                if i is None:
                    break
                done[i] = _piece(fn, i)
            for reader in readers:
                reader.join()
            for i in range(n):
                if i not in done:   # a worker died in it: here
                    done[i] = _piece(fn, i)
    except BaseException:   # Ctrl-C, SIGTERM (camtube.io.Terminated): the workers end now
        for pid, _ in children:
            _kill(pid)
        raise
    finally:
        for pid, _ in children:
            _reap(pid)
        for reader in readers:
            reader.join()
        for _, res_r in children:
            os.close(res_r)
        os.close(queue_r)
    for i in range(n):
        ok, value = done[i]
        if not ok:
            raise value
    return [done[i][1] for i in range(n)]


def _piece(fn: Callable[[int], T], i: int) -> tuple[bool, object]:
    """``(True, fn(i))``, or ``(False, the exception)`` (raised later, in the pieces' order, as in a loop)."""
    try:
        return True, fn(i)
    except Exception as exc:
        return False, exc


def _next_index(queue_r: int) -> int | None:
    """The next piece's index from the queue, or None when it is empty (each read takes one whole index: the pipe
    gives a read all of the bytes asked for that are there, and every index was written before the first read)."""
    got = os.read(queue_r, _INDEX.size)
    return _INDEX.unpack(got)[0] if len(got) == _INDEX.size else None


def _worker(fn: Callable[[int], T], queue_r: int, res_w: int) -> None:
    """A forked worker's life: SIGTERM ends it at once (as before the command line made SIGTERM an interrupt in the
    process it was forked from); each piece's ``(index, ok, result or exception)`` sent pickled (one that does not
    pickle is not sent: the process it was forked from runs that piece itself); then it exits."""
    code = 0
    try:
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        from camtube.model.core.threads import one_blas_thread

        with one_blas_thread():
            while True:
                i = _next_index(queue_r)
                if i is None:
                    break
                try:
                    msg = pickle.dumps((i,) + _piece(fn, i), protocol=pickle.HIGHEST_PROTOCOL)
                except Exception:   # a result (or an error) that does not pickle: the piece runs again there
                    continue
                _send(res_w, msg)
    except BaseException:   # interrupted: the process this one was forked from sees the pieces it did not send
        code = 1
    finally:
        _flush()
        os._exit(code)


def _flush() -> None:
    """Flush the standard streams; one that cannot be written (a reader that went away: ``| head``) is left as it is,
    for the command's own output to meet."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass


def _send(fd: int, msg: bytes) -> None:
    view = memoryview(_LENGTH.pack(len(msg)) + msg)
    while view:
        view = view[os.write(fd, view):]


def _read_exactly(fd: int, size: int) -> bytes | None:
    parts, left = [], size
    while left:
        got = os.read(fd, min(left, 1 << 20))
        if not got:
            return None
        parts.append(got)
        left -= len(got)
    return b"".join(parts)


def _collect(res_r: int, done: dict) -> None:
    """A worker's results into ``done`` (``index -> (ok, value)``) until its pipe closes (a thread: the reads wait
    without holding the interpreter, and the worker never blocks on a full pipe)."""
    while True:
        head = _read_exactly(res_r, _LENGTH.size)
        if head is None:
            return
        body = _read_exactly(res_r, _LENGTH.unpack(head)[0])
        if body is None:
            return   # the worker died mid-message: its piece runs here
        try:
            i, ok, value = pickle.loads(body)
        except Exception:   # (a result that does not unpickle here: its piece runs here instead)
            continue
        done[i] = (ok, value)


def _kill(pid: int) -> None:
    try:
        os.kill(pid, signal.SIGKILL)
    except ProcessLookupError:
        pass


def _reap(pid: int) -> None:
    try:
        os.waitpid(pid, 0)
    except ChildProcessError:
        pass
