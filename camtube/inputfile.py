"""Reading the files a user names: a device is refused, a file or a pipe is read.

:func:`read_input_bytes` and :func:`read_input_text` read an input (a pattern, a measurement file, a log, a job
file); a device (``/dev/zero``, ``/dev/urandom``, a terminal) raises an :class:`OSError` the readers already turn
into their one line, instead of being read until memory runs out. A pipe (``<(gunzip -c data.csv.gz)``) ends, so it
is read as a file is. (Files are written by :mod:`camtube.io`.) :func:`parse_json` parses the text of a JSON input
(a calibration, a diagnosis, a job file); nesting too deep to parse is a :class:`json.JSONDecodeError` like any other
text that is not JSON, not a ``RecursionError`` traceback.
"""
from __future__ import annotations

import errno
import json
import os
import stat

#: What a device given as an input file is told (the ``strerror`` of the :class:`OSError` raised).
DEVICE_INPUT = "it is a device, not a file: reading it would not end"


def refuse_device(path: str | os.PathLike) -> None:
    """Raise :class:`OSError` (``ENODEV``, naming ``path``) when ``path`` is a character or block device; a pipe
    (``<(gunzip -c data.csv.gz)``) is read as a file is."""
    mode = os.stat(path).st_mode
    if stat.S_ISCHR(mode) or stat.S_ISBLK(mode):
        raise OSError(errno.ENODEV, DEVICE_INPUT, os.fspath(path))


def read_input_bytes(path: str | os.PathLike) -> bytes:
    """The bytes of the input file ``path``; a device is refused (:data:`DEVICE_INPUT`)."""
    refuse_device(path)
    with open(path, "rb") as fh:
        return fh.read()


def read_input_text(path: str | os.PathLike, encoding: str = "utf-8") -> str:
    """The text of the input file ``path`` (universal newlines, as :meth:`Path.read_text`); a device is refused."""
    refuse_device(path)
    with open(path, encoding=encoding) as fh:
        return fh.read()


class JSONProblem(json.JSONDecodeError):
    """JSON that :func:`parse_json` refuses though ``json.loads`` would not say why in words.

    A :class:`json.JSONDecodeError` (so a :class:`ValueError`), so every reader that already turns a file that is
    not JSON into its one line does the same for this one; its text is :attr:`problem` alone.
    """

    def __init__(self, doc: str, problem: str):
        self.problem = problem
        super().__init__(problem, doc, 0)

    def __str__(self) -> str:
        return self.problem


class JSONTooDeepError(JSONProblem):
    """JSON nested deeper than Python's parser can follow (it recurses once per ``[`` or ``{``)."""

    def __init__(self, doc: str):
        super().__init__(doc, "nested too deeply: thousands of levels of '[' or '{'")


class JSONDuplicateKeyError(JSONProblem):
    """A JSON object that gives one key twice: ``json.loads`` keeps the last without a word (a calibration's
    ``"E_t"`` given twice)."""

    def __init__(self, doc: str, key: str):
        super().__init__(doc, f"the key {key!r} is given twice in one object")


def parse_json(text: str):
    """``json.loads(text)``; nesting too deep to parse raises :class:`JSONTooDeepError`, not ``RecursionError``; a
    key given twice in one object :class:`JSONDuplicateKeyError`."""
    def pairs(items: list) -> dict:
        out = {}
        for k, v in items:
            if k in out:
                raise JSONDuplicateKeyError(text, k)
            out[k] = v
        return out

    try:
        return json.loads(text, object_pairs_hook=pairs)
    except RecursionError:
        raise JSONTooDeepError(text) from None
