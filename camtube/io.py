"""File handling: the only place that writes files, always atomically.

Writers elsewhere return ``str``/``bytes`` (or an iterable of text chunks, for
outputs too large to hold); this layer puts them on disk.

- :func:`write_atomic`: one file, via a temporary file in the same directory
  and :func:`os.replace`, so a crash or a rejected input never leaves a
  half-written file behind.
- :func:`write_set`: the whole set of files one command writes, so that they
  appear all at once or not at all (a new G-code is never found beside an old
  job file). The set is written into a sibling staging directory; a new output
  directory is then renamed into place, an existing one is swapped with it in
  one ``renameat2(RENAME_EXCHANGE)`` call (Linux), keeping the entries of the
  old directory that the new set does not replace. A set written for a job
  (``write_set(..., job=NAME)``) replaces the set an earlier run wrote for that
  job: its files the new set does not have are gone with the swap (a hidden
  list, ``.NAME.camtube-set``, names them), so a folder never holds a new
  G-code beside an old one of another dialect or an old STEP beside a new STL;
  every other entry stays. An output directory given as
  a symbolic link gets the set in the folder it links to; the link is kept.
- :func:`write_together`: the outputs of one command that go to different places
  (``--json`` and ``--plot``, a CSV and a ``--report`` folder): every file and
  set is staged first, then all are published, or none (a file already
  published is put back as it was when a later one fails).

Every failure to write is raised as :class:`OutputError`, which names the path,
the reason and the fix.
"""
from __future__ import annotations

import ctypes
import ctypes.util
import errno
import os
import shutil
import signal
import tempfile
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Iterable, Mapping, Union

from camtube.errors import CamtubeError

#: What a writer may hand to the file layer: all of it, or an iterable of chunks.
Payload = Union[str, bytes, Iterable[Union[str, bytes]]]

_FIXES = {
    errno.EROFS: "choose an output location on a writable file system",
    errno.EACCES: "choose an output location you may write to, or change its permissions",
    errno.EPERM: "choose an output location you may write to, or change its permissions",
    errno.EISDIR: "name a file, not a directory",
    errno.ENOTDIR: "a part of the path is a file, not a directory: choose another path",
    errno.EEXIST: "name a directory that does not exist yet or is a directory, not a file",
    errno.ENOSPC: "free some disk space or write elsewhere",
    errno.ENAMETOOLONG: "use a shorter path",
}


class PublishedInterrupt(KeyboardInterrupt):
    """Ctrl-C arrived once a set of outputs had been published: the set on disk is whole and new.

    Attributes
    ----------
    paths : list of Path
        The files of the set, as published.
    """

    def __init__(self, paths: list[Path]):
        super().__init__()
        self.paths = list(paths)


class Terminated(KeyboardInterrupt):
    """SIGTERM (``kill``, a job scheduler, a closed session) arrived: the command stops as for Ctrl-C.

    A ``KeyboardInterrupt``, so that every clean-up that Ctrl-C runs (staging folders and temporary
    files removed, nothing half-published) runs for it too. Raised by :func:`raise_terminated`, the
    SIGTERM handler the command line installs.
    """


def raise_terminated(signum, frame) -> None:
    """SIGTERM handler: raise :class:`Terminated` in the main thread, where the command runs."""
    raise Terminated()


@contextmanager
def _uninterrupted():
    """Hold Ctrl-C (SIGINT) and SIGTERM back while the body runs; one that came meanwhile is raised at the end.

    Each signal with a Python-level handler (SIGINT's default raises ``KeyboardInterrupt``, the command
    line's SIGTERM handler :class:`Terminated`) has it swapped for one that only notes the signal
    (whichever thread the operating system delivered it to, Python runs handlers in the main thread),
    then put back and called. Only in the main thread, where handlers can be set; elsewhere the body
    runs as is.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    noted: list[tuple[int, object]] = []
    old = {}
    for signum in (signal.SIGINT, signal.SIGTERM):
        handler = signal.getsignal(signum)
        if callable(handler):
            old[signum] = signal.signal(signum, lambda signum, frame: noted.append((signum, frame)))
    try:
        yield
    finally:
        for signum, handler in old.items():
            signal.signal(signum, handler)
        if noted:
            signum, frame = noted[0]
            old[signum](signum, frame)  # raises KeyboardInterrupt (or Terminated) here


def import_whole(*modules: str) -> None:
    """Import ``modules`` with Ctrl-C and SIGTERM held back (:func:`_uninterrupted`): one that comes meanwhile is raised
    once they are imported. A library that guards its optional imports with ``except BaseException`` (trimesh) swallowed
    a Ctrl-C that came while it imported, so the command ran on and published its outputs, or left a module it was
    importing half made (scipy.ndimage: a ``NameError`` later)."""
    import importlib

    with _uninterrupted():
        for name in modules:
            importlib.import_module(name)


class OutputError(CamtubeError, OSError):
    """An output could not be written; the message names the path and the fix.

    Also an ``OSError``, so code that caught the file system's error keeps working.
    """

    def __init__(self, path: str | os.PathLike, reason: str, fix: str):
        self.path, self.reason, self.fix = str(path), reason, fix
        super().__init__(f"{path}: cannot write: {reason}; fix: {fix}")

    def __str__(self) -> str:
        return f"{self.path}: cannot write: {self.reason}; fix: {self.fix}"


def output_error(path: str | os.PathLike, exc: OSError) -> OutputError:
    """An :class:`OutputError` for an ``OSError`` raised while writing ``path``."""
    if exc.errno in (errno.EEXIST, errno.ENOTDIR):
        # a folder of the path is a file ("cannot write: File exists" said nothing of which one)
        blocker = next((q for q in Path(path).parents if q.exists() and not q.is_dir()), None)
        if blocker is not None:
            return OutputError(path, f"{blocker} is a file, not a folder",
                               "choose an output path under a folder, or move that file away")
    reason = exc.strerror or str(exc)
    return OutputError(path, reason, _FIXES.get(exc.errno or 0, "check the output path"))


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def _publish(tmp: str, path: Path) -> None:
    """Give the temporary file ordinary permissions (0666 less the umask) and move it into place."""
    os.chmod(tmp, 0o666 & ~_umask())
    os.replace(tmp, path)


def _not_empty(path: str | os.PathLike, what: str) -> None:
    """Refuse an empty path (``-o ''`` would otherwise mean the working directory)."""
    if not str(path).strip():
        raise OutputError(repr(str(path)), "the path is empty", f"give the output {what}'s name")


def _check_file_target(path: Path) -> None:
    if path.is_dir():
        raise OutputError(path, "it is a directory", "name a file (e.g. add the file name to the path)")


@contextmanager
def _staged(path: Path, prefix: str, suffix: str):
    """Yield ``(fd, tmp)`` of a temporary file beside ``path``; publish it on success, remove it on failure.

    A ``path`` that is a symbolic link is written through: the file it points to is replaced (staged beside that
    file) and the link is kept, as a shell's ``>`` or an editor's save leaves it."""
    _check_file_target(path)   # (is_dir follows a link: a link to a folder is refused here, named as given)
    path = _followed(path)
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=path.parent)
        yield fd, tmp
        _publish(tmp, path)
    except OSError as exc:
        _discard(tmp)
        raise output_error(path, exc) from None
    except BaseException:
        _discard(tmp)
        raise


def _discard(tmp: str | None) -> None:
    if tmp is None:
        return
    try:
        os.unlink(tmp)
    except FileNotFoundError:
        pass


def _write_payload(fh, data: Payload) -> None:
    if isinstance(data, str):
        fh.write(data.encode("utf-8"))
    elif isinstance(data, (bytes, bytearray, memoryview)):
        fh.write(bytes(data))
    else:
        for chunk in data:
            fh.write(chunk.encode("utf-8") if isinstance(chunk, str) else bytes(chunk))


def write_atomic(path: str | os.PathLike, data: Payload) -> Path:
    """Write ``data`` to ``path`` atomically and return the path.

    ``str`` is encoded as UTF-8 with ``\\n`` line endings, unchanged; an
    iterable of chunks is written chunk by chunk. Parent directories are created.

    Raises
    ------
    OutputError
        The file cannot be written (read-only location, a directory of that name, ...).
    """
    _not_empty(path, "file")
    path = Path(path)
    with _staged(path, f".{path.name}.", ".tmp") as (fd, _tmp):
        with os.fdopen(fd, "wb") as fh:
            _write_payload(fh, data)
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


# ------------------------------------------------------------------ sets of files
_RENAME_EXCHANGE = 2


def _exchange(a: Path, b: Path) -> bool:
    """Swap two directories atomically (Linux ``renameat2``); False where unsupported."""
    libc_name = ctypes.util.find_library("c")
    if not libc_name:
        return False
    libc = ctypes.CDLL(libc_name, use_errno=True)
    fn = getattr(libc, "renameat2", None)
    if fn is None:
        return False
    AT_FDCWD = -100
    rc = fn(AT_FDCWD, os.fsencode(a), AT_FDCWD, os.fsencode(b), _RENAME_EXCHANGE)
    if rc == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.EOPNOTSUPP):
        return False
    raise OSError(err, os.strerror(err), str(a))


def _link_tree(src: Path, dst: Path) -> None:
    """Hard-link (or copy, across devices) ``src`` into ``dst``."""
    if src.is_dir() and not src.is_symlink():
        shutil.copytree(src, dst, symlinks=True, copy_function=_link_or_copy)
    elif src.is_symlink():
        os.symlink(os.readlink(src), dst)
    else:
        _link_or_copy(src, dst)


def _link_or_copy(src, dst) -> None:
    try:
        os.link(src, dst)
    except OSError:
        shutil.copy2(src, dst)


def _contains_cwd(path: Path) -> bool:
    try:
        cwd = Path.cwd().resolve()
    except OSError:
        return False
    p = path.resolve()
    return cwd == p or p in cwd.parents


def _swap_in(stage: Path, out: Path, files: Mapping[str, Payload]) -> Path | None:
    """Make the staged set ``out``'s; returns what is left to remove (the old folder), or None. The files of the set
    an earlier run wrote for the same job (:func:`earlier_set`) go with the old folder."""
    if not out.exists():
        os.chmod(stage, 0o777 & ~_umask())
        os.rename(stage, out)
        return None
    earlier = earlier_set(out, files)
    listed = [set_list_name(files.job)] if isinstance(files, JobSet) else []
    if _contains_cwd(out):
        # the working directory cannot be swapped away under the user: move the files in one by one
        for name in [*files, *listed]:
            os.replace(stage / name, out / name)
        for name in earlier:
            os.unlink(out / name)
        return stage
    for entry in out.iterdir():
        if entry.name not in files and entry.name not in listed and entry.name not in earlier:
            _link_tree(entry, stage / entry.name)
    os.chmod(stage, out.stat().st_mode & 0o7777)
    if not _exchange(stage, out):
        old = stage.with_name(stage.name + ".old")
        os.rename(out, old)
        os.rename(stage, out)
        return old
    return stage


def check_writable_dir(outdir: str | os.PathLike) -> None:
    """Refuse, before any work is done, an output directory that :func:`write_set` could not write.

    The nearest existing folder of ``outdir`` (itself, or the parent it would be created in) must
    take a new entry: a probe folder is made there and removed at once, so nothing is left behind.

    Raises
    ------
    OutputError
        The location is read-only, not a folder, or cannot hold new entries.
    """
    _not_empty(outdir, "directory")
    out = Path(outdir).absolute()
    probe_in = out if out.is_dir() else out.parent
    while not probe_in.exists() and probe_in != probe_in.parent:
        probe_in = probe_in.parent
    if not probe_in.is_dir():
        raise OutputError(out, f"{probe_in} is not a folder", "give an output directory under a folder")
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".camtube-probe.", dir=probe_in))
    except OSError as exc:
        raise OutputError(out, f"{probe_in} takes no new folder ({exc.strerror or exc})",
                          "give an output directory in a folder you can write to") from None


class JobSet(dict):
    """The files of one job's set (a dict of file name -> payload) and the job's name (:func:`write_set`)."""

    def __init__(self, files: Mapping[str, Payload], job: str):
        super().__init__(files)
        self.job = job


def set_list_name(job: str) -> str:
    """The hidden file in an output directory that lists the files of ``job``'s set written there last."""
    return f".{job}.camtube-set"


def earlier_set(out: Path, files: Mapping[str, Payload]) -> set[str]:
    """The files of the set an earlier run wrote into ``out`` for the job of ``files`` (a :class:`JobSet`) that the
    new set does not have: plain names of files, as its list names them; empty for another payload or no list."""
    if not isinstance(files, JobSet):
        return set()
    try:
        names = (out / set_list_name(files.job)).read_text(encoding="utf-8").splitlines()
    except (OSError, UnicodeDecodeError):
        return set()
    return {n for n in names if n and Path(n).name == n and n not in (".", "..") and n not in files
            and (out / n).is_file() and not (out / n).is_symlink()}


def write_set(outdir: str | os.PathLike, files: Mapping[str, Payload], job: str | None = None) -> list[Path]:
    """Write a set of files into ``outdir`` so that they appear together or not at all.

    Parameters
    ----------
    outdir : path
        Output directory; created if missing. Entries already in it that the
        set does not replace are kept, but for the files of the set an earlier
        run wrote there for the same ``job``. A symbolic link to a directory is
        followed: the set goes into the directory, the link stays.
    files : mapping of file name -> str | bytes | iterable of chunks
        File names relative to ``outdir`` (no sub-directories). Iterables are
        consumed once, chunk by chunk, so a large output is never held whole.
    job : str, optional
        The job the set is for (a pattern's name): the set replaces the one
        written there for it before (its files the new set does not have are
        removed in the same swap), and a hidden list of the set's files
        (:func:`set_list_name`) is written with it.

    Returns
    -------
    list of Path
        The paths of the set's files in ``outdir``, in the order given.

    Raises
    ------
    OutputError
        ``outdir`` cannot be created or written (it names a file, the location is
        read-only, ...); nothing of the new set is visible then.
    """
    return write_together([(outdir, files if job is None else JobSet(files, job))])[0]


def _check_set(out: Path, files: Mapping[str, Payload]) -> None:
    """Refuse, before anything is written, a set :func:`_stage_set` could not publish into ``out``."""
    if isinstance(files, JobSet) and (Path(files.job).name != files.job or files.job in ("", ".", "..")
                                      or set_list_name(files.job) in files):
        raise ValueError(f"write_set: job {files.job!r} is not a plain name")
    if out.exists() and not out.is_dir():
        raise OutputError(out, "a file of that name exists", "name a directory (new or existing), not a file")
    for name in files:
        if Path(name).name != name or name in ("", ".", ".."):
            raise ValueError(f"write_set: {name!r} is not a plain file name")
        if (out / name).is_dir() and not (out / name).is_symlink():
            # the swap would replace the folder and everything in it with the new file
            raise OutputError(out / name, "a folder of that name is in the way of the output file",
                              "move or rename the folder, or choose another output directory")


def _stage_set(out: Path, files: Mapping[str, Payload], staged: list) -> None:
    """Write ``files`` into a new staging folder beside ``out``, noted in ``staged`` as soon as it exists."""
    parent = out.absolute().parent
    parent.mkdir(parents=True, exist_ok=True)
    stage = Path(tempfile.mkdtemp(prefix=f".{out.name}.", suffix=".staging", dir=parent))
    staged.append(stage)
    listed = {set_list_name(files.job): "".join(f"{name}\n" for name in files)} if isinstance(files, JobSet) else {}
    for name, data in {**files, **listed}.items():
        with open(stage / name, "wb") as fh:
            _write_payload(fh, data)
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(stage / name, 0o666 & ~_umask())


def _stage_file(path: Path, data: Payload, staged: list) -> None:
    """Write ``data`` into a temporary file beside ``path``, noted in ``staged`` as soon as it exists."""
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    staged.append(Path(tmp))
    with os.fdopen(fd, "wb") as fh:
        _write_payload(fh, data)
        fh.flush()
        os.fsync(fh.fileno())


def _keep_old(path: Path) -> Path | None:
    """A hard link (or copy) of the file at ``path`` in a new hidden folder beside it, to put back; None if none."""
    if not os.path.lexists(path):
        return None
    keep = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".old", dir=path.parent))
    try:
        if path.is_symlink():
            os.symlink(os.readlink(path), keep / path.name)
        else:
            _link_or_copy(path, keep / path.name)
    except BaseException:
        shutil.rmtree(keep, ignore_errors=True)
        raise
    return keep


def _followed(out: Path) -> Path:
    """Where an output given as ``out`` is written: ``out``, or what it links to when it is a symbolic link.

    A link is the user's way of naming the output (``-o current -> jobs/2024-05``, ``report.html ->
    runs/7/report.html``): the set or the file is written where the link points, and the link is kept (the swap or
    the rename would otherwise replace the link itself). Used for sets (:func:`write_set`) and files (:func:`_staged`).
    """
    return Path(os.path.realpath(out)) if out.is_symlink() else out


def output_clash(where: list[Path], is_file: list[bool]) -> tuple[int, int] | None:
    """The first ``(i, j)`` of outputs at paths ``where`` (normalised by the caller) where output ``i`` is at the path
    of output ``j``, or inside it, and ``j`` is written as a file (so writing one destroys the other); None if none.
    Shared by :func:`write_together` and the command line's check before any work."""
    for i, a in enumerate(where):
        for j, b in enumerate(where):
            if i != j and is_file[j] and (a == b or b in a.parents):
                return i, j
    return None


def _check_apart(targets: list[Path], is_set: list[bool]) -> None:
    """Refuse two outputs at one path, or an output inside another output that is a file."""
    where = [Path(os.path.normpath(t.absolute())) for t in targets]
    clash = output_clash(where, [not s for s in is_set])
    if clash is None:
        return
    i, j = clash
    if where[i] == where[j]:
        first, later = sorted(clash)
        raise OutputError(targets[later], f"it is also the path of another output ({targets[first]})",
                          "give each output a path of its own")
    raise OutputError(targets[i], f"it lies inside {targets[j]}, which is written as a file",
                      f"give it a path outside {targets[j]}")


def write_together(outputs) -> list:
    """Write the outputs of one command (files and sets, in different places) all together or not at all.

    Parameters
    ----------
    outputs : sequence of (path, payload)
        A payload that is a mapping of file name -> payload is a set, written into the directory ``path`` as
        :func:`write_set` does (at most one set, published last); any other payload is one file at ``path``.

    Returns
    -------
    list
        Per output, in the order given: the file's ``Path``, or the list of a set's paths.

    Raises
    ------
    OutputError
        An output cannot be written; nothing new is visible then: files already published are put back
        as they were.
    """
    is_set = [isinstance(data, Mapping) for _, data in outputs]
    if sum(is_set) > 1:
        raise ValueError("write_together: at most one set of files")
    for (path, _), s in zip(outputs, is_set):
        _not_empty(path, "directory" if s else "file")  # (before Path(''), which is '.')
    outputs = [(Path(p), data) for p, data in outputs]
    for (path, data), s in zip(outputs, is_set):
        if s:
            _check_set(path, data)
        else:
            _check_file_target(path)
    _check_apart([p for p, _ in outputs], is_set)
    order = [i for i, s in enumerate(is_set) if not s] + [i for i, s in enumerate(is_set) if s]
    staged: list[Path] = []       # temporary files and staging folders, in the order of ``order``
    done: list[tuple[Path, Path | None]] = []   # files published: (path, the folder keeping the old file)
    leftover: Path | None = None
    results: list = [None] * len(outputs)
    path = outputs[order[0]][0] if outputs else None
    published = False
    try:
        for i in order:
            path, data = outputs[i]
            if is_set[i]:
                _stage_set(_followed(path), data, staged)
            else:
                _stage_file(path, data, staged)
        try:
            with _uninterrupted():  # publishing runs whole: a Ctrl-C now is answered once it is done
                for i, tmp in zip(order, staged):
                    path, data = outputs[i]
                    if is_set[i]:
                        leftover = _swap_in(tmp, _followed(path), data)
                        results[i] = [path / name for name in data]
                    else:
                        done.append((path, _keep_old(path)))
                        _publish(str(tmp), path)
                        results[i] = path
                published = True
        except KeyboardInterrupt:
            if published:
                raise PublishedInterrupt([q for r in results for q in (r if isinstance(r, list) else [r])]) from None
            raise
        return results
    except OSError as exc:
        raise output_error(path, exc) from None
    finally:
        if not published:
            for target, keep in reversed(done):   # put back what was there before
                try:
                    if keep is not None:
                        os.replace(keep / target.name, target)
                    else:
                        os.unlink(target)
                except OSError:
                    pass
        for tmp in staged:
            if tmp.is_dir() and not tmp.is_symlink():
                shutil.rmtree(tmp, ignore_errors=True)
            else:
                _discard(str(tmp))
        for _, keep in done:
            if keep is not None:
                shutil.rmtree(keep, ignore_errors=True)
        if leftover is not None and leftover.exists():
            shutil.rmtree(leftover, ignore_errors=True)
