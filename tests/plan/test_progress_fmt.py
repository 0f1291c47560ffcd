"""Durations for people (h:mm:ss beside seconds), the laser-time warning, and progress reporting."""
from __future__ import annotations

import io
from dataclasses import replace

import pytest

from camtube.design.loader import load_pattern
from camtube.export.gcode import gcode
from camtube.fmt import format_duration_s, hms
from camtube.plan import estimate, plan_job
from camtube.plan.moves import time_warning
from camtube.export.outputs import write_toolpaths
from camtube.plan.report import summary_table
from camtube.progress import NO_PROGRESS, Progress, RichProgress, Task, make_progress
from tests.conftest import PATTERNS


@pytest.mark.parametrize("s,text", [(908802, "908802 s (252:26:42)"), (92.68, "92.7 s (0:01:33)"),
                                    (0, "0.0 s (0:00:00)"), (3599.6, "3600 s (1:00:00)"), (59.5, "59.5 s (0:01:00)")])
def test_format_duration(s, text):
    assert format_duration_s(s) == text


def test_hms_is_consistent_with_seconds():
    for s in (0, 1, 59, 60, 61, 3599, 3600, 86399, 86400, 908802):
        h, m, sec = map(int, hms(s).split(":"))
        assert 0 <= m < 60 and 0 <= sec < 60 and h * 3600 + m * 60 + sec == s


@pytest.fixture(scope="module")
def job():
    return plan_job(load_pattern(PATTERNS / "tube1.yaml"))


def test_time_warning_fires_above_max_time_h(job):
    est = estimate(job)
    assert time_warning(job, est) is None  # 92.7 s against the default 8 h
    short = replace(job, process=replace(job.process, max_time_h=0.01))  # 36 s
    w = time_warning(short, estimate(short))
    assert w and format_duration_s(est.total_s) in w and "process.max_time_h = 0.01 h" in w
    assert "(0:00:36)" in w
    text = gcode(short)
    header = text.split("(pass 0:")[0]
    # the header's figure is the motion-aware time on the dialect's machine; paren comments use []
    from camtube.export.dialects import LINUXCNC
    from camtube.machine.motion_time import job_estimate

    hms = format_duration_s(job_estimate(short, LINUXCNC).total_s).split("(")[1].rstrip(")")
    assert "WARNING: the estimated laser time" in header and f"[{hms}]" in header
    assert "WARNING" not in gcode(job)


def test_summary_table_shows_hms(job):
    t = summary_table(job, estimate(job))
    assert "estimated time" in t and "92.7 s (0:01:33)" in t and "85.9 s (0:01:26)" in t


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_make_progress_is_silent_unless_a_terminal(monkeypatch):
    monkeypatch.delenv("CI", raising=False)
    assert make_progress(stream=io.StringIO()) is NO_PROGRESS  # a pipe or file
    assert make_progress(quiet=True, stream=_Tty()) is NO_PROGRESS
    assert isinstance(make_progress(stream=_Tty()), RichProgress)
    monkeypatch.setenv("CI", "true")
    assert make_progress(stream=_Tty()) is NO_PROGRESS


def test_rich_bars_on_the_stream_only_for_long_tasks():
    out = _Tty()
    with RichProgress(out, min_total=1000) as p:
        with p.task("small", total=10) as t:
            t.advance(10)
        assert out.getvalue() == ""
        with p.task("G-code linuxcnc", total=5000) as t:
            for _ in range(5):
                t.advance(1000)
    text = out.getvalue()
    assert "G-code linuxcnc" in text and "5000/5000" in text and "small" not in text


class Recorder(Progress):
    def __init__(self):
        self.tasks = {}

    def task(self, label, total):
        rec = self.tasks.setdefault(label, [total, 0])

        class T(Task):
            def advance(self, n=1):
                rec[1] += n

        return T()


def test_writers_report_progress_through_the_callback(job, tmp_path):
    rec = Recorder()
    job = replace(job)  # nothing cached yet
    write_toolpaths(job, tmp_path, progress=rec)
    assert set(rec.tasks) == {"safety check, estimate", "G-code linuxcnc", "G-code grbl", "toolpath DXF",
                              "job file"}
    for label, (total, done) in rec.tasks.items():
        assert total == len(job.passes) and done == total, label
    rec = Recorder()
    plan_job(load_pattern(PATTERNS / "tube1.yaml"), progress=rec)
    assert rec.tasks["planning"][0] == rec.tasks["planning"][1] == 352
