"""The atomic file layer: complete files or none."""
from __future__ import annotations

import os
import stat

import pytest

from camtube.io import write_atomic, write_atomic_with


def test_write_atomic_text_bytes_and_permissions(tmp_path):
    p = write_atomic(tmp_path / "a" / "b.txt", "x\n")
    assert p.read_text() == "x\n"
    assert write_atomic(p, b"\x00\x01").read_bytes() == b"\x00\x01"
    mask = os.umask(0)
    os.umask(mask)
    assert stat.S_IMODE(p.stat().st_mode) == 0o666 & ~mask
    assert sorted(x.name for x in p.parent.iterdir()) == ["b.txt"]


def test_failed_writer_leaves_nothing_and_keeps_old_file(tmp_path):
    p = tmp_path / "m.stl"
    p.write_text("old")

    def broken(tmp):
        with open(tmp, "w") as fh:
            fh.write("half")
        raise RuntimeError("exporter crashed")

    with pytest.raises(RuntimeError):
        write_atomic_with(p, broken)
    assert p.read_text() == "old"
    assert [x.name for x in tmp_path.iterdir()] == ["m.stl"]
    with pytest.raises(OSError, match="no output"):
        write_atomic_with(tmp_path / "empty.stl", lambda tmp: None)
    assert [x.name for x in tmp_path.iterdir()] == ["m.stl"]


def test_write_atomic_with_publishes(tmp_path):
    def ok(tmp):
        assert tmp.endswith(".step")
        with open(tmp, "w") as fh:
            fh.write("ISO-10303-21;")

    assert write_atomic_with(tmp_path / "t.step", ok).read_text() == "ISO-10303-21;"
