"""The atomic file layer: complete files or none."""
from __future__ import annotations

import os
import stat
from pathlib import Path

import pytest

from camtube.io import OutputError, write_atomic, write_atomic_with


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


def test_write_set_appears_whole_or_not_at_all(tmp_path):
    from camtube.io import write_set

    out = tmp_path / "job"
    paths = write_set(out, {"j.ngc": "G0 X0\n", "j.job.json": b"{}", "j.dxf": iter(["0\n", "EOF\n"])})
    assert [p.name for p in paths] == ["j.ngc", "j.job.json", "j.dxf"]
    assert (out / "j.dxf").read_text() == "0\nEOF\n"
    (out / "notes.txt").write_text("the user's own file")

    def exploding():
        yield "G0 X1\n"
        raise RuntimeError("killed between files")

    with pytest.raises(RuntimeError):
        write_set(out, {"j.ngc": "G0 X9\n", "j.job.json": exploding()})
    # the old set is untouched: no new G-code beside an old job file
    assert (out / "j.ngc").read_text() == "G0 X0\n" and (out / "j.job.json").read_bytes() == b"{}"
    assert sorted(os.listdir(tmp_path)) == ["job"]  # no staging directory left
    write_set(out, {"j.ngc": "G0 X2\n", "j.job.json": "{\"v\": 2}"})
    assert (out / "j.ngc").read_text() == "G0 X2\n" and (out / "j.job.json").read_text() == '{"v": 2}'
    assert (out / "notes.txt").read_text() == "the user's own file" and (out / "j.dxf").exists()
    assert sorted(os.listdir(tmp_path)) == ["job"]


@pytest.mark.parametrize("in_cwd", [False, True])
def test_a_job_s_set_replaces_the_set_written_for_that_job_before(tmp_path, monkeypatch, in_cwd):
    # the bad-input search: `toolpath tube1 -o out` (G-code for both dialects), then `toolpath tube1 --set
    # notch.count=5 --dialect linuxcnc -o out` left the 10-notch tube1.nc beside the 5-notch tube1.ngc and job file.
    # A job's set replaces that job's earlier set; the folder's other files (the user's, another job's) stay
    from camtube.io import set_list_name, write_set

    out = tmp_path / "out"
    write_set(out, {"a.ngc": "G0 X0\n", "a.nc": "G0 X0\n", "a.job.json": "{}"}, job="a")
    write_set(out, {"b.ngc": "G0 X7\n"}, job="b")
    (out / "notes.txt").write_text("the user's own file")
    write_set(out, {"loose.txt": "no job"})
    if in_cwd:   # the working directory is not swapped away: the files are moved in, the earlier ones removed
        monkeypatch.chdir(out)
    paths = write_set(out, {"a.ngc": "G0 X5\n", "a.job.json": "{\"v\": 2}"}, job="a")
    assert [p.name for p in paths] == ["a.ngc", "a.job.json"]
    assert sorted(os.listdir(out)) == sorted([set_list_name("a"), set_list_name("b"), "a.job.json", "a.ngc", "b.ngc",
                                              "loose.txt", "notes.txt"])
    assert (out / "a.ngc").read_text() == "G0 X5\n" and (out / "b.ngc").read_text() == "G0 X7\n"
    assert (out / set_list_name("a")).read_text() == "a.ngc\na.job.json\n"
    # a list naming what is not a plain file of the folder removes nothing
    (out / set_list_name("b")).write_text("../elsewhere.txt\nnotes.txt/\nsub\n")
    (tmp_path / "elsewhere.txt").write_text("outside")
    (out / "sub").mkdir()
    write_set(out, {"b.ngc": "G0 X8\n"}, job="b")
    assert (tmp_path / "elsewhere.txt").exists() and (out / "sub").is_dir() and (out / "notes.txt").exists()
    # without a job the folder keeps every entry the set does not replace, as before
    write_set(out, {"a.nc": "G0 X1\n"})
    write_set(out, {"a.ngc": "G0 X6\n"})
    assert (out / "a.nc").exists() and (out / "a.job.json").exists()


def test_write_set_refuses_a_file_as_directory(tmp_path):
    from camtube.io import OutputError, write_set

    (tmp_path / "f").write_text("x")
    with pytest.raises(OutputError, match="a file of that name exists"):
        write_set(tmp_path / "f", {"a": "b"})
    assert (tmp_path / "f").read_text() == "x"


@pytest.mark.parametrize("under", ["f/x.csv", "f/a/b/x.csv"])
def test_a_file_where_a_folder_of_the_path_should_be_is_named(tmp_path, under):
    # was "cannot write: File exists; fix: name a directory that does not exist yet or is a directory, not a file"
    (tmp_path / "f").write_text("x")
    with pytest.raises(OutputError) as exc:
        write_atomic(tmp_path / under, "data")
    assert f"{tmp_path / 'f'} is a file, not a folder" in str(exc.value), exc.value
    assert "fix: choose an output path under a folder" in str(exc.value)
    assert (tmp_path / "f").read_text() == "x"


def test_write_together_puts_back_a_published_file_when_the_set_fails(tmp_path, monkeypatch):
    """Bug 13: the outputs of one command in different places (a JSON, a report folder) appear all or none."""
    import camtube.io as io

    (tmp_path / "d.json").write_text("old")
    paths = io.write_together([(tmp_path / "d.json", "new"), (tmp_path / "rep", {"index.html": "<p>"}),
                               (tmp_path / "p.png", b"png")])
    assert paths == [tmp_path / "d.json", [tmp_path / "rep" / "index.html"], tmp_path / "p.png"]
    assert (tmp_path / "d.json").read_text() == "new" and (tmp_path / "rep" / "index.html").read_text() == "<p>"

    def swap_fails(stage, out, files):
        raise OSError(13, "Permission denied")

    monkeypatch.setattr(io, "_swap_in", swap_fails)
    with pytest.raises(io.OutputError, match="rep: cannot write: Permission denied"):
        io.write_together([(tmp_path / "d.json", "newer"), (tmp_path / "new.png", b"x"),
                           (tmp_path / "rep", {"index.html": "<p>2"})])
    assert (tmp_path / "d.json").read_text() == "new"  # put back, not "newer" beside the old report
    assert sorted(os.listdir(tmp_path)) == ["d.json", "p.png", "rep"]  # no new.png, no staging, no kept copies
    assert (tmp_path / "rep" / "index.html").read_text() == "<p>"


def test_write_together_refuses_an_output_inside_another_output_file(tmp_path):
    from camtube.io import OutputError, write_together

    with pytest.raises(OutputError, match="lies inside"):
        write_together([(tmp_path / "a.json", "{}"), (tmp_path / "a.json" / "rep", {"index.html": "x"})])
    with pytest.raises(OutputError, match="also the path of another output"):
        write_together([(tmp_path / "a.json", "{}"), (tmp_path / "a.json", "[]")])
    with pytest.raises(OutputError, match="the path is empty"):
        write_together([(tmp_path / "a.json", "{}"), ("", {"index.html": "x"})])  # not '.', the working folder
    assert os.listdir(tmp_path) == []


def test_write_set_into_a_link_to_a_folder_writes_into_the_folder_and_keeps_the_link(tmp_path):
    """Bug 14: ``-o current`` where current -> jobs/v2: the swap replaced the link with a real folder (the
    link was left as a ``.current.*.staging`` entry) and jobs/v2 never got the set."""
    from camtube.io import write_set

    target = tmp_path / "jobs" / "v2"
    target.mkdir(parents=True)
    (target / "notes.txt").write_text("mine")
    (target / "j.ngc").write_text("old")
    link = tmp_path / "current"
    link.symlink_to(Path("jobs") / "v2")
    assert write_set(link, {"j.ngc": "G0 X1\n", "j.job.json": "{}"}) == [link / "j.ngc", link / "j.job.json"]
    assert link.is_symlink() and os.readlink(link) == str(Path("jobs") / "v2")
    assert sorted(os.listdir(target)) == ["j.job.json", "j.ngc", "notes.txt"]
    assert (target / "j.ngc").read_text() == "G0 X1\n" and (target / "notes.txt").read_text() == "mine"
    assert sorted(os.listdir(tmp_path)) == ["current", "jobs"]  # no staging left beside the link
    assert sorted(os.listdir(tmp_path / "jobs")) == ["v2"]  # nor beside the folder
    # a link to a folder not made yet: the folder is made, the link kept
    (tmp_path / "next").symlink_to(tmp_path / "jobs" / "v3")
    write_set(tmp_path / "next", {"j.ngc": "G0 X3\n"})
    assert (tmp_path / "next").is_symlink() and (tmp_path / "jobs" / "v3" / "j.ngc").read_text() == "G0 X3\n"


def test_write_atomic_through_a_link_to_a_file_replaces_the_file_and_keeps_the_link(tmp_path):
    """A ``-o report.html`` that is a link (report.html -> runs/7/report.html) lost its link: the staged file was
    renamed onto the link itself, and the file it pointed to kept the old contents."""
    (tmp_path / "runs" / "7").mkdir(parents=True)
    target = tmp_path / "runs" / "7" / "report.html"
    target.write_text("old\n")
    link = tmp_path / "report.html"
    link.symlink_to(Path("runs") / "7" / "report.html")
    assert write_atomic(link, "new\n") == link
    assert link.is_symlink() and os.readlink(link) == str(Path("runs") / "7" / "report.html")
    assert target.read_text() == "new\n"
    assert sorted(os.listdir(tmp_path)) == ["report.html", "runs"] and os.listdir(target.parent) == ["report.html"]
    # a link to a file not made yet (dangling): the file is made where it points
    (tmp_path / "next.html").symlink_to(tmp_path / "runs" / "8.html")
    write_atomic(tmp_path / "next.html", "x")
    assert (tmp_path / "runs" / "8.html").read_text() == "x" and (tmp_path / "next.html").is_symlink()
    # a link to a folder is still refused as a file's target
    (tmp_path / "dir.html").symlink_to(tmp_path / "runs")
    with pytest.raises(OutputError, match="directory"):
        write_atomic(tmp_path / "dir.html", "x")


def test_a_ctrl_c_while_a_library_imports_is_raised_once_it_is_imported(tmp_path, monkeypatch):
    """A library that guards its optional imports with ``except BaseException`` (trimesh) swallowed a Ctrl-C that came
    while it imported: ``camtube cad`` then ran on and published its outputs. Held by import_whole, it is raised
    after the import, which is whole."""
    import sys

    from camtube.io import import_whole

    (tmp_path / "greedy_lib.py").write_text(
        "import os, signal\n"
        "try:\n"
        "    os.kill(os.getpid(), signal.SIGINT)   # Ctrl-C arrives while an optional part imports\n"
        "    import time; time.sleep(0.05)\n"
        "except BaseException:\n"
        "    pass\n"
        "WHOLE = True\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, "greedy_lib", raising=False)
    with pytest.raises(KeyboardInterrupt):
        import_whole("greedy_lib")
    assert sys.modules["greedy_lib"].WHOLE
    # without it, the library eats the Ctrl-C: nothing is raised
    monkeypatch.delitem(sys.modules, "greedy_lib")
    import importlib

    importlib.import_module("greedy_lib")   # (returns: the Ctrl-C is gone)
    assert sys.modules["greedy_lib"].WHOLE
