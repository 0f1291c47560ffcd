"""Measurement CSV: round trip, validation errors with line numbers, selection, deadband removal."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from camtube.design.loader import load_pattern
from camtube.errors import DataError
from camtube.model.data import (
    find_slack, format_csv, load_csv, parse_csv, parse_cycles, prepare, remove_deadband,
    select_branch, select_cycles,
)
from camtube.model.sim.synth import synthesize
from tests.conftest import PATTERNS

HEADER = "sample,cycle,time_s,stroke_mm,force_N,angle_deg"
GOOD = [HEADER, "A,1,0.0,0.0,0.0,0.0", "A,1,0.1,0.1,0.2,1.0", "A,2,0.2,0.2,0.4,2.0"]


@pytest.fixture(scope="module")
def tube2():
    return load_pattern(PATTERNS / "tube2.yaml")


def _csv(lines):
    return "\n".join(lines) + "\n"


def test_round_trip_keeps_values_and_extra_columns(tube2):
    d = synthesize(tube2, n_samples=2, n_cycles=3, seed=3)
    d = type(d)(d.sample, d.cycle, d.time_s, d.stroke_mm, d.force_N, d.angle_deg,
                {"temp_C": np.full(len(d), 21.5), "note": np.array(["x"] * len(d), dtype=object)})
    text = format_csv(d)
    back = parse_csv(text)
    assert back.samples == ["1", "2"] and len(back) == len(d)
    np.testing.assert_array_equal(back.cycle, d.cycle)
    np.testing.assert_allclose(back.stroke_mm, d.stroke_mm, atol=1e-6)
    np.testing.assert_allclose(back.angle_deg, d.angle_deg, atol=1e-5)
    np.testing.assert_allclose(back.force_N, d.force_N, atol=1e-6)
    assert back.extra["temp_C"].dtype == float and back.extra["note"][0] == "x"
    assert format_csv(back) == text  # deterministic, stable


def test_comments_blank_lines_column_order_and_interleaved_samples():
    text = _csv(["# lab rig 3", "angle_deg,sample,cycle,time_s,stroke_mm,force_N,extra",
                 "1.0,A,1,0.0,0.1,0.2,7", "", "5.0,B,1,0.0,0.3,0.4,8", "2.0,A,1,0.1,0.2,0.3,9"])
    d = parse_csv(text)
    assert list(d.sample) == ["A", "A", "B"]
    np.testing.assert_array_equal(d.angle_deg, [1.0, 2.0, 5.0])
    np.testing.assert_array_equal(d.extra["extra"], [7.0, 9.0, 8.0])


def test_a_line_of_separators_among_the_rows_is_a_row_with_every_cell_missing(tmp_path):
    """A line ',,,,,' among the rows was dropped silently (fit, exit 0), while one empty cell was refused with its
    line; after the last row it is a spreadsheet's padding, skipped as a blank line is."""
    from camtube.model.data import read_measurements

    path = tmp_path / "d.csv"
    path.write_text(_csv(GOOD[:2] + [",,,,,"] + GOOD[2:] + [",,,,,", ",,,,,"]))
    with pytest.raises(DataError, match=r"d\.csv:3: every cell is empty .*; fix: delete the line"):
        load_csv(path)
    m = read_measurements(path)  # diagnose: dropped and said, as a row with a missing value is
    assert len(m.data) == 3 and m.missing_lines.tolist() == [3] and "dropped (lines 3)" in m.summary()
    path.write_text(_csv(GOOD + [",,,,,", ",,,,,"]))
    assert len(load_csv(path)) == 3


@pytest.mark.parametrize("lines, line, words", [
    ([HEADER.replace("angle_deg", "angle")] + GOOD[1:], 1, ["angle_deg", "'angle' -> 'angle_deg'"]),
    ([HEADER.replace(",force_N", "")] + [",".join(r.split(",")[:4] + r.split(",")[5:]) for r in GOOD[1:]],
     1, ["force_N"]),
    (GOOD[:2] + ["A,1,0.1,abc,0.2,1.0"] + GOOD[3:], 3, ["stroke_mm", "abc"]),
    (GOOD[:2] + ["A,1,0.1,0.1,,1.0"] + GOOD[3:], 3, ["force_N", "empty"]),
    (GOOD[:3] + ["A,2,0.2,0.2,0.4,nan"], 4, ["angle_deg", "nan"]),
    (GOOD[:2] + ["A,1,0.1,inf,0.2,1.0"] + GOOD[3:], 3, ["stroke_mm", "inf"]),
    (GOOD[:2] + ["A,1,-0.5,0.1,0.2,1.0"] + GOOD[3:], 3, ["time_s", "backwards", "'A'"]),
    (GOOD + ["A,1,0.3,0.3,0.5,3.0"], 5, ["cycle", "backwards"]),
    (GOOD[:2] + ["A,1.5,0.1,0.1,0.2,1.0"] + GOOD[3:], 3, ["cycle", "whole number"]),
    (GOOD[:2] + ["A,1,0.1,0.1,0.2"] + GOOD[3:], 3, ["5 cells", "6 columns"]),
    (GOOD[:2] + [",1,0.1,0.1,0.2,1.0"] + GOOD[3:], 3, ["sample", "empty"]),
    ([HEADER + ",cycle"] + [r + ",1" for r in GOOD[1:]], 1, ["duplicate", "cycle"]),
    ([HEADER], 1, ["no data rows"]),
])
def test_bad_csv_names_file_and_line(tmp_path, lines, line, words):
    path = tmp_path / "bad.csv"
    path.write_text(_csv(lines))
    with pytest.raises(DataError) as err:
        load_csv(path)
    msg = str(err.value)
    assert f"{path}:{line}:" in msg, msg
    for w in words:
        assert w in msg, msg


@pytest.mark.parametrize("header, words", [
    # the same quantity in another unit: renaming would change the numbers silently, so the fix says convert
    (HEADER.replace("angle_deg", "angle_rad"), ["convert 'angle_rad' from rad to deg", "'angle_deg'"]),
    (HEADER.replace("force_N", "force_mN"), ["convert 'force_mN' from mN to N"]),
    (HEADER.replace("stroke_mm", "Stroke (mm)"), ["rename 'Stroke (mm)' -> 'stroke_mm'"]),
    # a logger that does not count the pulls: how to number them (by hand, or by camtube model ingest)
    (HEADER.replace("cycle,", ""), ["number each sample's pulls in a column 'cycle'", "camtube model ingest"]),
    (HEADER.replace("cycle,", "cycles,"), ["rename 'cycles' -> 'cycle'"]),
    (HEADER.replace("sample,", ""), ["name the tube each row was measured on in a column 'sample'"]),
    # the bad-input search: an upper-case header was told to "convert 'TIME_S' from S to s"
    (HEADER.upper(), ["rename 'SAMPLE' -> 'sample', 'CYCLE' -> 'cycle', 'TIME_S' -> 'time_s'",
                      "'FORCE_N' -> 'force_N'", "letter case included"]),
])
def test_missing_column_fix_converts_other_units_and_renames_near_names(header, words):
    rows = GOOD[1:]
    if "cycle" not in header.lower():   # (a column dropped from the header: its cells too)
        rows = [r.replace("A,1,", "A,").replace("A,2,", "A,") for r in rows]
    if "sample" not in header.lower():
        rows = [r.split(",", 1)[1] for r in rows]
    with pytest.raises(DataError) as err:
        parse_csv(_csv([header] + rows), source="m.csv")
    msg = str(err.value)
    for w in words:
        assert w in msg, msg
    assert "rename 'angle_rad'" not in msg and "rename 'force_mN'" not in msg, msg


@pytest.mark.parametrize("sep, name", [(";", "';'"), ("\t", "tabs")])
def test_spreadsheet_separators_are_named(sep, name):
    # a spreadsheet's export with a decimal comma separates its columns with ';' (or tabs)
    text = _csv([r.replace(",", sep).replace(".", ",") for r in GOOD])
    with pytest.raises(DataError) as err:
        parse_csv(text, source="m.csv")
    msg = str(err.value)
    assert f"separated by {name}" in msg and "m.csv:1:" in msg, msg


def test_time_backwards_is_checked_per_sample_only():
    # sample B starts at t = 0 again after A: allowed
    d = parse_csv(_csv(GOOD + ["B,1,0.0,0.0,0.0,0.0", "B,1,0.1,0.1,0.1,0.5"]))
    assert d.samples == ["A", "B"]


@pytest.mark.parametrize("lines, line, words", [
    (GOOD[1:], 1, ["no header line", "holds numbers", "fix: add a first line naming the columns"]),
    (GOOD[:2] + ["A,1e30,0.1,0.1,0.2,1.0"] + GOOD[3:], 3, ["cycle", "from 1 to 10^9", "'1e30'", "fix:"]),
    ([HEADER + ",cycle"] + [r + ",1" for r in GOOD[1:]], 1, ["duplicate", "fix: keep one column of each name"]),
    ([HEADER], 1, ["no data rows", "fix: add the measurements"]),
])
def test_csv_mistakes_that_lacked_a_fix_or_passed(tmp_path, lines, line, words):
    """Before: a file without a header was 'duplicate column(s) 1' (no fix), a cycle of 1e30 was read as a
    garbage integer with a RuntimeWarning, and these lines had no fix."""
    path = tmp_path / "bad.csv"
    path.write_text(_csv(lines))
    with pytest.raises(DataError) as err:
        load_csv(path)
    msg = str(err.value)
    assert f"{path}:{line}:" in msg and "\n" not in msg, msg
    for w in words:
        assert w in msg, msg


def test_a_missing_file_says_what_to_do(tmp_path):
    with pytest.raises(DataError, match="no such measurement file; fix: check the path"):
        load_csv(tmp_path / "missing.csv")


def test_empty_and_missing_files(tmp_path):
    (tmp_path / "e.csv").write_text("\n# nothing\n")
    with pytest.raises(DataError, match="empty"):
        load_csv(tmp_path / "e.csv")
    with pytest.raises(DataError, match="no such"):
        load_csv(tmp_path / "missing.csv")


def _cycles_data():
    # sample A has cycles 1-50, sample B cycles 1-40
    rows = [HEADER]
    for smp, n in (("A", 50), ("B", 40)):
        for c in range(1, n + 1):
            rows.append(f"{smp},{c},{c},0.1,0.1,1.0")
    return parse_csv(_csv(rows))


@pytest.mark.parametrize("spec, a, b", [
    ("last", [50], [40]),
    ("last3", [48, 49, 50], [38, 39, 40]),
    ("5", [5], [5]),
    ("31-50", list(range(31, 51)), list(range(31, 41))),
    ("2-", list(range(2, 51)), list(range(2, 41))),
    ("-2", [1, 2], [1, 2]),
    ("1, last", [1, 50], [1, 40]),
    ("all", list(range(1, 51)), list(range(1, 41))),
])
def test_cycle_selection(spec, a, b):
    d = select_cycles(_cycles_data(), spec)
    got = {s: sorted(set(d.cycle[sl].tolist())) for s, sl in d.sample_slices()}
    assert got == {"A": a, "B": b}


@pytest.mark.parametrize("spec", ["lats", "5-2", "x-3", "1-2-3", "", "last0"])
def test_bad_cycle_spec(spec):
    with pytest.raises(DataError, match="cycle selection"):
        parse_cycles(spec if spec else " , ")


@pytest.mark.parametrize("spec", ["", "  "])
def test_an_empty_cycle_spec_is_refused_not_all(spec):
    """``--cycles ''`` selected every cycle; None (not given) still means all."""
    with pytest.raises(DataError, match="--cycles .*: an empty cycle selection; fix: e.g. --cycles last"):
        parse_cycles(spec)
    assert parse_cycles(None).everything


def test_cycle_selection_matching_nothing_says_what_exists():
    with pytest.raises(DataError, match="1-50"):
        select_cycles(_cycles_data(), "60-70")


def test_branch_follows_stroke_direction(tube2):
    d = synthesize(tube2, n_samples=1, n_cycles=2, slack_mm=0.0, seed=1)
    up = select_branch(d, "loading")
    down = select_branch(d, "unloading")
    assert len(up) + len(down) == len(d)
    for part, sign in ((up, 1), (down, -1)):
        for _, sl in part.sample_slices():
            ds = np.diff(part.stroke_mm[sl])
            same_cycle = np.diff(part.cycle[sl]) == 0
            # within a cycle and a contiguous branch, the stroke moves one way
            assert np.all(sign * ds[same_cycle & (np.abs(ds) < 0.05)] > 0)
    with pytest.raises(DataError, match="branch"):
        select_branch(d, "up")


@pytest.mark.parametrize("slack", [0.0, 0.05, 0.3])
def test_slack_found_per_cycle(tube2, slack):
    d = synthesize(tube2, n_samples=2, n_cycles=4, slack_mm=slack, seed=5)
    found = find_slack(d)
    assert sorted(found) == [(s, c) for s in ("1", "2") for c in range(1, 5)]
    for v in found.values():
        assert abs(v.stroke_mm - slack) < 0.006
        assert 0.15 < v.noise_deg < 0.35  # the generator's 0.25 deg


def test_remove_deadband_shifts_and_drops(tube2):
    d = synthesize(tube2, n_samples=1, n_cycles=2, slack_mm=0.3, seed=2)
    out = remove_deadband(d)
    assert np.all(out.stroke_mm >= 0)
    np.testing.assert_allclose(out.extra["slack_mm"], 0.3, atol=0.006)
    assert len(out) < len(d)
    # rows kept are those beyond the slack, with stroke shifted by it
    kept = d.stroke_mm - 0.3 > 0.01
    assert abs(int(kept.sum()) - len(out)) <= 8


def test_prepare_defaults_are_the_papers_comparison(tube2):
    d = synthesize(tube2, n_samples=2, n_cycles=3, slack_mm=0.1, seed=4)
    rows = prepare(d)
    assert set(rows.cycle.tolist()) == {3}
    assert np.all(rows.direction == 1)
    assert rows.stroke_mm.min() >= 0 and rows.stroke_mm.max() < 2.5 - 0.09


def test_prepare_unloading_and_both_partition_the_rows(tube2):
    d = synthesize(tube2, n_samples=1, n_cycles=3, slack_mm=0.1, seed=6)
    up = prepare(d, "all", "loading")
    down = prepare(d, "all", "unloading")
    both = prepare(d, "all", "both")
    assert len(up) + len(down) == len(both)
    assert up.stroke_mm.max() > 2.3 and down.stroke_mm.max() > 2.3
    with pytest.raises(DataError, match="branch"):
        prepare(d, branch="sideways")


def test_derived_data_is_cached_on_the_dataset_not_in_module_tables():
    # issue 20: caches are objects owned by what they cache; no module-level WeakKeyDictionary tables
    import ast
    import dataclasses

    from camtube.model.data.dataset import Cache, Dataset

    root = Path(__file__).resolve().parents[2] / "camtube"
    for path in root.rglob("*.py"):
        tree = ast.parse(path.read_text(), str(path))
        for node in tree.body:
            if isinstance(node, (ast.Assign, ast.AnnAssign)) and node.value is not None:
                assert "WeakKeyDictionary" not in ast.unparse(node.value), f"{path}: module-level cache"
    d = Dataset(np.array(["A"] * 4, dtype=object), np.ones(4, int), np.arange(4.0), np.array([0.0, 1, 2, 1]),
                np.zeros(4), np.zeros(4))
    assert list(d.direction) == [1, 1, 1, -1] and "dataset.direction" in d.cache
    sub = d.take(np.array([True, True, True, False]))
    assert isinstance(sub.cache, Cache) and len(sub.cache) == 0 and sub.cache is not d.cache
    assert dataclasses.replace(d, stroke_mm=np.arange(4.0)).cache is not d.cache


def test_recently_used_keeps_the_most_recent_and_computes_each_once():
    from camtube.model.data.dataset import recently_used

    store, calls = {}, []

    def get(k):
        return recently_used(store, k, lambda: calls.append(k) or k * 10, limit=2)

    assert [get(1), get(2), get(1), get(3)] == [10, 20, 10, 30]   # 2, the least recently used, is dropped
    assert list(store) == [1, 3] and calls == [1, 2, 3]
    assert get(2) == 20 and calls == [1, 2, 3, 2]


def test_each_samples_median_step_with_and_without_repeated_stamps():
    """Two samples: A at 0.1 s with two repeated stamps (three zero steps of seven), B at 0.04 s; a one-row sample C.
    All steps: A's median is 0.1 (four of seven steps), the positive ones the same; with most steps repeated the two
    differ. Computed once per Dataset."""
    from camtube.model.data.dataset import Dataset

    t_a = np.array([0.0, 0.1, 0.1, 0.2, 0.3, 0.3, 0.4, 0.4])
    t_b = np.arange(5) * 0.04
    t = np.concatenate((t_a, t_b, [7.0]))
    n = t.size
    d = Dataset(np.array(["A"] * 8 + ["B"] * 5 + ["C"], dtype=object), np.ones(n, int), t, np.zeros(n), np.zeros(n),
                np.zeros(n))
    assert d.median_steps_s() == pytest.approx((0.1, 0.04, 0.0))
    assert d.median_steps_s(positive=True) == pytest.approx((0.1, 0.04, 0.0))
    assert d.median_steps_s() is d.median_steps_s()
    mostly_repeated = Dataset(np.array(["A"] * 6, dtype=object), np.ones(6, int),
                              np.array([0.0, 0.0, 0.0, 0.1, 0.1, 0.1]), np.zeros(6), np.zeros(6), np.zeros(6))
    assert mostly_repeated.median_steps_s() == (0.0,)
    assert mostly_repeated.median_steps_s(positive=True) == pytest.approx((0.1,))


def test_reversed_columns_names_each_column_that_runs_the_other_way_and_not_a_zero_far_off():
    from camtube.model.data.csvfile import reversed_columns
    from camtube.model.data.dataset import Dataset

    t = np.arange(0.0, 40.0, 0.02)
    x = 1.0 - np.cos(2 * np.pi * t / 8.0)

    def record(stroke, force, angle):
        return Dataset(np.full(t.size, "A", dtype=object), (t // 8).astype(int) + 1, t, stroke, force, angle)

    assert reversed_columns(record(x, 2 * x - 10.0, 20 * x)) == {}     # a load cell's zero 10 N low: no sign turned
    assert set(reversed_columns(record(-x, -2 * x, 20 * x))) == {"force_N", "stroke_mm"}
    assert set(reversed_columns(record(x, -2 * x, 20 * x))) == {"force_N"}
    assert set(reversed_columns(record(x, 2 * x, -20 * x))) == {"angle_deg"}
    assert reversed_columns(record(x, 2 * x, 20 * x)) == {}


def test_far_zeros_names_an_absolute_stroke_or_a_tracker_s_offset_not_a_joint_resting_bent():
    from camtube.model.data.csvfile import far_zeros
    from camtube.model.data.dataset import Dataset

    t = np.arange(0.0, 40.0, 0.02)
    x = 1.0 - np.cos(2 * np.pi * t / 8.0)

    def record(stroke, angle):
        return Dataset(np.full(t.size, "A", dtype=object), (t // 8).astype(int) + 1, t, stroke, 2 * x, angle)

    assert far_zeros(record(x, 20 * x + 3.0)) == {}                      # a permanent set of 3 deg beside 40 deg
    assert far_zeros(record(x - 0.1, 20 * x)) == {}                      # a rest a little below the start
    assert list(far_zeros(record(x + 100.0, 20 * x))) == ["stroke_mm"]   # the motor's absolute position
    assert list(far_zeros(record(x, 20 * x + 90.0))) == ["angle_deg"]    # a tracker's straight joint at 90 deg
    spiky = 20 * x + 3.0
    spiky[::400] += 60.0                                                 # spikes do not widen the angle's span
    assert far_zeros(record(x, spiky)) == {}


def test_far_zeros_names_a_load_cell_not_zeroed_not_one_that_drifts_a_little():
    from camtube.model.data.csvfile import far_zeros
    from camtube.model.data.dataset import Dataset

    t = np.arange(0.0, 40.0, 0.02)
    x = 1.0 - np.cos(2 * np.pi * t / 8.0)

    def record(force):
        return Dataset(np.full(t.size, "A", dtype=object), (t // 8).astype(int) + 1, t, x, force, 20 * x)

    assert far_zeros(record(2 * x)) == {}
    assert far_zeros(record(2 * x + 0.3 + 0.01 * t)) == {}                # an offset and a drift within the span
    for off in (-10.0, -5.0, 5.0, 100.0):                                 # every reading below zero, or far above
        got = far_zeros(record(2 * x + off))
        assert list(got) == ["force_N"] and got["force_N"][0][1] == pytest.approx(off, abs=0.05), got


def test_a_clock_that_counts_from_elsewhere_reads_as_the_same_record(tube2, tmp_path):
    # a logger counting Unix seconds, or a second sample logged 1000 s after the first: the physics reads the time since
    # each sample's first row. Before, a file in Unix seconds was refused ("beyond 1e9 ... no bench measures that"),
    # and creep read the clock's time: a second sample 1000 s later had crept for 1000 s before its first pull
    from camtube.model.api import get_effect
    from camtube.model.core.predict import model_for_pattern, pattern_values
    from camtube.model.data import read_measurements
    from camtube.model.data.dataset import Dataset

    data = synthesize(tube2, n_samples=2, n_cycles=4, rate_hz=20.0, seed=3)
    later = np.where(data.sample == data.samples[1], 1000.0, 0.0)
    for offset in (later, 1.7e9):
        moved = Dataset(data.sample, data.cycle, data.time_s + offset, data.stroke_mm, data.force_N, data.angle_deg)
        assert np.allclose(moved.elapsed_s, data.elapsed_s, atol=1e-6)
        m = model_for_pattern(tube2, [get_effect("creep")])
        values = {**pattern_values(tube2), "creep.creep_mm": 0.2, "creep.tau_s": 30.0}
        assert np.allclose(m.predict(moved, values), m.predict(data, values), atol=1e-6)
    path = tmp_path / "unix.csv"
    path.write_text(format_csv(Dataset(data.sample, data.cycle, data.time_s + 1.7e9, data.stroke_mm, data.force_N,
                                       data.angle_deg)))
    read = read_measurements(path).data
    assert read.time_s[0] == pytest.approx(1.7e9) and np.allclose(read.elapsed_s, data.elapsed_s, atol=1e-3)
