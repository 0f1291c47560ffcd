"""Progress reporting for long work (planning, each writer), as a small object the caller passes in.

Library functions take a ``progress`` argument (default :data:`NO_PROGRESS`, which does
nothing) and report through it::

    with progress.task("G-code linuxcnc", total=len(job.passes)) as task:
        for chunk in ...:
            task.advance(len(chunk))

:func:`make_progress` gives the object a command line wants: rich progress bars on
stderr when stderr is a terminal, nothing under ``-q``, when ``CI`` is set, or when stderr
is a pipe or a file. Bars appear only for tasks of at least ``min_total`` units (the
passes of a job: small jobs finish in well under a second and print nothing).
"""
from __future__ import annotations

import os
import sys
from typing import TextIO

#: Tasks smaller than this (in passes) are not shown: they take well under two seconds.
MIN_TOTAL = 20000


class Task:
    """One unit of work with a known total; :class:`Progress.task` returns it."""

    def advance(self, n: int = 1) -> None:
        """Record ``n`` more units done."""

    def close(self) -> None:
        """The work is finished (or abandoned)."""

    def __enter__(self) -> "Task":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


class Progress:
    """No-op progress (the default): every report is ignored."""

    def task(self, label: str, total: int) -> Task:
        """Start a task of ``total`` units called ``label``."""
        return Task()

    def close(self) -> None:
        """Stop showing anything (idempotent)."""

    def __enter__(self) -> "Progress":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


#: The default of every library function: reports nothing.
NO_PROGRESS = Progress()


class _RichTask(Task):
    def __init__(self, owner: "RichProgress", task_id) -> None:
        self._owner, self._id = owner, task_id

    def advance(self, n: int = 1) -> None:
        self._owner._bars.advance(self._id, n)

    def close(self) -> None:
        bars = self._owner._bars
        t = bars.tasks[[x.id for x in bars.tasks].index(self._id)]
        bars.update(self._id, completed=t.total)
        bars.stop_task(self._id)


class RichProgress(Progress):
    """Progress bars drawn by ``rich`` on ``stream`` (stderr), one line per task.

    Parameters
    ----------
    stream : text stream
        Where the bars go (default ``sys.stderr``).
    min_total : int
        Tasks with fewer units are not shown.
    """

    def __init__(self, stream: TextIO | None = None, min_total: int = MIN_TOTAL) -> None:
        self._stream = stream if stream is not None else sys.stderr
        self._min_total = min_total
        self._bars = None

    def task(self, label: str, total: int) -> Task:
        if total < self._min_total:
            return Task()
        if self._bars is None:
            from rich.console import Console
            from rich.progress import (BarColumn, MofNCompleteColumn, Progress as Bars, TextColumn,
                                       TimeElapsedColumn, TimeRemainingColumn)

            self._bars = Bars(TextColumn("{task.description:<24}"), BarColumn(), MofNCompleteColumn(),
                              TimeElapsedColumn(), TimeRemainingColumn(),
                              console=Console(file=self._stream), transient=False)
            self._bars.start()
        return _RichTask(self, self._bars.add_task(label, total=total))

    def close(self) -> None:
        if self._bars is not None:
            self._bars.stop()
            self._bars = None


def make_progress(quiet: bool = False, stream: TextIO | None = None) -> Progress:
    """The progress object for a command: rich bars on a terminal, else :data:`NO_PROGRESS`.

    Silent when ``quiet`` (``-q``), when the ``CI`` environment variable is set, or
    when ``stream`` (default stderr) is not a terminal. Use it as a context manager
    so the bars are closed however the command ends.
    """
    stream = stream if stream is not None else sys.stderr
    if quiet or os.environ.get("CI") or not _isatty(stream):
        return NO_PROGRESS
    return RichProgress(stream)


def _isatty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # closed or not a real stream
        return False
