"""File handling: the only place that writes files, always atomically.

Writers elsewhere return ``str``/``bytes``; this layer puts them on disk via a
temporary file in the same directory and :func:`os.replace`, so a crash or a
rejected input never leaves a half-written output behind.
"""
from __future__ import annotations

import os
import tempfile
from contextlib import contextmanager
from pathlib import Path


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _publish(tmp: str, path: Path) -> None:
    """Give the temporary file ordinary permissions (0666 less the umask) and move it into place."""
    os.chmod(tmp, 0o666 & ~_umask())
    os.replace(tmp, path)


@contextmanager
def _staged(path: Path, prefix: str, suffix: str):
    """Yield ``(fd, tmp)`` of a temporary file beside ``path``; publish it on success, remove it on failure."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=path.parent)
    try:
        yield fd, tmp
        _publish(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except FileNotFoundError:
            pass
        raise


def write_atomic(path: str | os.PathLike, data: str | bytes) -> Path:
    """Write ``data`` to ``path`` atomically and return the path.

    ``str`` is encoded as UTF-8 with ``\\n`` line endings, unchanged.
    Parent directories are created.
    """
    path = Path(path)
    payload = data.encode("utf-8") if isinstance(data, str) else bytes(data)
    with _staged(path, f".{path.name}.", ".tmp") as (fd, _tmp):
        with os.fdopen(fd, "wb") as fh:
            fh.write(payload)
            fh.flush()
            os.fsync(fh.fileno())
    return path


def write_atomic_with(path: str | os.PathLike, writer) -> Path:
    """Atomically create ``path`` with a library that insists on writing a file.

    ``writer(tmp_path: str)`` writes the complete file at ``tmp_path`` (same
    directory, same suffix); on success it is renamed onto ``path``.
    Used for STEP/STL exporters that take a filename.
    """
    path = Path(path)
    with _staged(path, f".{path.stem}.", path.suffix) as (fd, tmp):
        os.close(fd)
        writer(tmp)
        if os.path.getsize(tmp) == 0:
            raise OSError(f"writer produced no output for {path}")
    return path
