"""The readers of ``camtube model ingest``: the NDI export, the time-series logs, the bench map; and the
pieces that work on what they read (bend angle from poses, clocks, cycles), each against independent truth."""
from __future__ import annotations

import csv

import numpy as np
import pytest

from camtube.errors import DataError
from camtube.model.ingest.clock import ClockFit, align_trigger, align_xcorr, rising_edges
from camtube.model.ingest.cycles import cycle_numbers, cycle_starts
from camtube.model.ingest.ndi import load_ndi, parse_ndi
from camtube.model.ingest.poses import bend_angle
from camtube.model.ingest.series import bench_map_from_dict, load_bench_map, load_series, parse_series
from tests.conftest import ROOT

BENCH = ROOT / "examples" / "bench"


# ------------------------------------------------------------------ NDI export

def test_polaris_export_with_marker_groups_reads_every_tool_state_and_bad_float():
    log = load_ndi(BENCH / "polaris-export.csv")
    # read the same file with the csv module: the tool labels are the header cells starting with "Port"
    with open(BENCH / "polaris-export.csv", newline="") as fh:
        rows = list(csv.reader(fh))
    labels = [h for h in rows[0] if h.startswith("Port")]
    assert [t.label for t in log.tools] == labels
    a, b = log.tools
    assert (a.port, b.port) == ("01", "02")
    assert list(a.state) == [r[rows[0].index("State")] for r in rows[1:]]
    assert list(a.valid) == [True, True, False] and list(b.valid) == [True, False, True]
    assert np.all(np.isnan(b.quat_wxyz[1])) and np.all(np.isnan(b.position_mm[1]))   # -3.697314E28 -> NaN
    assert np.all(np.isnan(a.position_mm[2]))                                       # empty cells -> NaN
    assert a.position_mm[1, 0] == pytest.approx(10.01)
    assert list(a.frame) == [4410, 4413, 4416]
    assert a.time_s[1] - a.time_s[0] == pytest.approx(0.05, abs=1e-6)


def test_aurora_example_matches_its_truth_file_frame_for_frame():
    log = load_ndi(BENCH / "aurora-export.csv")
    truth = np.genfromtxt(BENCH / "truth.csv", delimiter=",", names=True, dtype=None, encoding="utf-8")
    base, tip = log.tool("0A"), log.tool("0x0B")
    assert base.label.startswith("Port 0x0A") and tip.label.startswith("Port 0x0B")
    assert log.tool("3B1F0A02") is tip                                   # by serial number
    t = tip.time_s - tip.time_s[0]
    # every exported frame is a truth frame; the truth has the absent ones too
    assert np.all(np.isin(np.round(t, 4), np.round(truth["time_s"], 4)))
    assert len(truth) - len(t) == 2
    assert set(tip.state) <= {"OK", "Missing", "Out of Volume"}


@pytest.mark.parametrize("text, message", [
    ("", "empty"),
    ("Frame,Q0\n1,1\n", "no tool column group"),
    ("Tools,Port 0x0A: x,Frame,State,Q0,Qx,Qy,Qz,Tx,Ty\n1,Port 0x0A: x,1,OK,1,0,0,0,1,2\n", "no column(s) Tz"),
    ("Tools,Port 0x0A: x,Frame,Time [sec],State,Q0,Qx,Qy,Qz,Tx,Ty,Tz,Error\n"
     "1,Port 0x0A: x,1,0.0,OK,1,0,0,0,1,2,3,0.1\n1,Port 0x0A: x,2,0.025,OK,1,0,zero,0,1,2,3,0.1\n",
     ":3: column 8 ('Qy' of 'Port 0x0A: x') is not a number"),
    ("Tools,Port 0x0A: x,Frame,Time [sec],State,Q0,Qx,Qy,Qz,Tx,Ty,Tz,Error\n"
     "1,Port 0x0A: x,1,1.0,OK,1,0,0,0,1,2,3,0.1\n1,Port 0x0A: x,2,0.5,OK,1,0,0,0,1,2,3,0.1\n",
     ":3: the time does not increase"),
    ("Tools,Port 0x0A: x,Frame,State,Q0,Qx,Qy,Qz,Tx,Ty,Tz,Error\n1,Port 0x0A: x,1,OK,1,0,0,0,1,2,3,0.1\n",
     "no time column"),
])
def test_ndi_errors_name_line_and_column(text, message):
    with pytest.raises(DataError, match=None) as exc:
        parse_ndi(text, "t.csv")
    assert message in str(exc.value) and str(exc.value).startswith("t.csv")


def test_ndi_without_time_uses_the_frame_rate_and_metres_are_converted():
    text = ("Tools,Port 0x0A: x,Frame,State,Q0,Qx,Qy,Qz,Tx,Ty,Tz,Error\n"
            "1,Port 0x0A: x,10,OK,1,0,0,0,0.1,0.2,-0.3,0.1\n1,Port 0x0A: x,12,OK,1,0,0,0,0.1,0.2,-0.3,0.1\n")
    log = parse_ndi(text, "t.csv", unit="m", rate_hz=40.0)
    assert log.tools[0].time_s[1] == pytest.approx(2 / 40.0)
    assert log.tools[0].position_mm[0] == pytest.approx([100.0, 200.0, -300.0])


def test_unknown_or_ambiguous_tool_lists_the_tools():
    log = load_ndi(BENCH / "polaris-export.csv")
    with pytest.raises(DataError, match="no tool '0x07' for the tip.*8700339"):
        log.tool("0x07", "tip")
    with pytest.raises(DataError, match="names 2 tools"):
        log.tool("s/n:3A1C000", "tip")


# ------------------------------------------------------------------ time series and bench map

def test_series_example_logs_read_with_their_units():
    bm = load_bench_map(BENCH / "bench.yaml")
    daq = load_series(BENCH / "daq.csv", bm.daq.time, bm.daq.time_unit, bm.daq.force, role="daq")
    raw = np.genfromtxt(BENCH / "daq.csv", delimiter=",", names=True)
    assert daq.time_s == pytest.approx(raw["time_ms"] / 1000.0)
    assert daq.value == pytest.approx(raw["load_V"])
    mot = load_series(BENCH / "motor.csv", bm.motor.time, bm.motor.time_unit, bm.motor.stroke, role="motor")
    raw = np.genfromtxt(BENCH / "motor.csv", delimiter=",", names=True)
    assert mot.time_s == pytest.approx(raw["t_us"] * 1e-6)
    # 512 counts/rev, 64:1, 0.5 mm/rev: one lead-screw turn is 32768 counts
    assert bm.motor.mm_per_unit == pytest.approx(0.5 / (512 * 64))


def test_series_errors():
    with pytest.raises(DataError, match=r"l.csv:1: no column 'time_s' for the time .*fix: set daq.time: time_ms"):
        parse_series("time_ms,load_V\n1,2\n", "l.csv", "time_s", "s", "load_V", role="daq")
    with pytest.raises(DataError, match=r"l.csv:3: column 'load_V' is not a number: 'n/a'"):
        parse_series("t,load_V\n1,2\n2,n/a\n", "l.csv", "t", "s", "load_V", role="daq")
    with pytest.raises(DataError, match=r"l.csv:3: column 't' does not increase"):
        parse_series("t,v\n2,2\n1,3\n", "l.csv", "t", "s", "v")


def test_a_repeated_stamp_is_set_aside_and_a_clock_that_repeats_often_refused():
    """A logger that writes a stamp twice now and then: the later line set aside (it was refused, the whole run lost);
    a time column that repeats on more than 5 % of its lines (seconds written as whole numbers) refused, naming it."""
    rows = [f"{k * 0.01:.2f},{k}" for k in range(100)]
    rows.insert(41, "0.40,999")   # line 43: the stamp of line 42 again
    got = parse_series("t,v\n" + "\n".join(rows) + "\n", "l.csv", "t", "s", "v")
    assert got.repeated.tolist() == [43] and got.time_s.size == 100 and 999.0 not in got.value
    assert np.all(np.diff(got.time_s) > 0) and got.lines[41] == 44
    coarse = "t,v\n" + "\n".join(f"{k // 10},{k}" for k in range(100)) + "\n"
    with pytest.raises(DataError, match=r"l.csv:3: column 't' repeats its time stamp on 90 of 100 lines.*fix: map"):
        parse_series(coarse, "l.csv", "t", "s", "v", role="daq")


def test_bench_map_overrides_and_unknown_keys():
    bm = bench_map_from_dict({"motor": {"gear_ratio": 64}}, "b.yaml", ["motor.sign=-1", "daq.offset_V=rest"])
    assert bm.motor.gear_ratio == 64.0 and bm.motor.sign == -1 and bm.daq.offset_V == "rest"
    with pytest.raises(DataError, match="motor.gear: unknown key; fix: did you mean 'gear_ratio'"):
        bench_map_from_dict({"motor": {"gear": 64}}, "b.yaml")
    with pytest.raises(DataError, match="daq.time_unit: 'sec' is not allowed"):
        bench_map_from_dict({"daq": {"time_unit": "sec"}}, "b.yaml")
    with pytest.raises(DataError, match="motor.lead_mm_per_rev: .* out of range"):
        bench_map_from_dict({}, "b.yaml", ["motor.lead_mm_per_rev=0"])
    # the bad-input search: taken, the whole record read as the rest
    with pytest.raises(DataError, match="tracker.rest_s: '1e9' is out of range: a rest of more than 600 s"):
        bench_map_from_dict({}, "b.yaml", ["tracker.rest_s=1e9"])
    # taken, the first frame alone read as the rest (its noise an offset in every angle)
    with pytest.raises(DataError, match="tracker.rest_s: '0' is out of range: the rest before the first pull takes"):
        bench_map_from_dict({}, "b.yaml", ["tracker.rest_s=0"])
    assert bench_map_from_dict({}, "b.yaml", ["tracker.rest_s=0.2"]).tracker.rest_s == 0.2
    # the bad-input search: read, then not used without a word
    with pytest.raises(DataError, match="daq.trigger: 'sync' is given, but motor.trigger is not"):
        bench_map_from_dict({"daq": {"trigger": "sync"}}, "b.yaml")
    with pytest.raises(DataError, match="motor.trigger: 'sync' is given, but daq.trigger is not"):
        bench_map_from_dict({"motor": {"trigger": "sync"}}, "b.yaml")
    assert bench_map_from_dict({"daq": {"trigger": "s"}, "motor": {"trigger": "s"}}, "b.yaml").daq.trigger == "s"
    with pytest.raises(DataError, match="daq.N_per_V: '7' is given, but daq.force_unit is N"):
        bench_map_from_dict({}, "b.yaml", ["daq.force_unit=N", "daq.N_per_V=7"])
    with pytest.raises(DataError, match="motor.counts_per_rev: '0.5' is not a count"):
        bench_map_from_dict({}, "b.yaml", ["motor.counts_per_rev=0.5"])


# ------------------------------------------------------------------ bend angle from poses

def _poses(theta_rad, seed=0, flip=0.5, one=False):
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(seed)
    n = theta_rad.size
    a = Rotation.from_rotvec(rng.normal(size=3) * 0.4)
    b = Rotation.from_rotvec(rng.normal(size=3) * 0.4)
    world = Rotation.from_rotvec(np.outer(np.sin(np.arange(n) / 50.0) * 0.05, rng.normal(size=3))) \
        * Rotation.from_rotvec(rng.normal(size=3))
    if one:
        world = Rotation.from_rotvec(np.tile(rng.normal(size=3), (n, 1)))
    tip = world * a * Rotation.from_rotvec(np.outer(theta_rad, [0, 0, 1])) * b
    q = lambda r: r.as_quat()[:, [3, 0, 1, 2]] * np.where(rng.random(n) < flip, -1.0, 1.0)[:, None]
    return q(world), q(tip), (a.apply([0, 0, 1]))


def test_bend_angle_is_exact_for_any_mounting_and_quaternion_signs():
    t = np.arange(400) / 40.0
    theta = np.radians(np.clip(30 * np.sin(2 * np.pi * (t - 1.0) / 6.0), 0, None)) * (t > 1.0)
    qb, qt, axis = _poses(theta)
    ok = np.ones(t.size, bool)
    ok[[50, 51, 200]] = False
    b = bend_angle(t, qt, ok, qb, np.ones(t.size, bool), rest_s=0.9)
    assert np.nanmax(np.abs(b.angle_deg - np.degrees(theta))[ok]) < 1e-8
    assert np.all(np.isnan(b.angle_deg[~ok]))
    assert abs(abs(b.axis @ axis) - 1) < 1e-9                 # the axis the joint bends about, in the base frame
    assert np.nanmax(b.out_of_plane_deg) < 1e-8


def test_bend_angle_with_one_coil_against_its_first_frames():
    t = np.arange(300) / 40.0
    theta = np.radians(20 * np.clip(np.sin(2 * np.pi * (t - 1.0) / 5.0), 0, None) * (t > 1.0))
    _, qt, _ = _poses(theta, seed=3, one=True)
    b = bend_angle(t, qt, np.ones(t.size, bool), rest_s=0.5)
    assert np.max(np.abs(b.angle_deg - np.degrees(theta))) < 1e-8


def test_out_of_plane_rotation_is_reported():
    from scipy.spatial.transform import Rotation

    t = np.arange(300) / 40.0
    theta = np.radians(20 * np.clip(np.sin(2 * np.pi * (t - 1.0) / 5.0), 0, None) * (t > 1.0))
    twist = np.radians(2.0) * np.sin(2 * np.pi * t / 3.0) * (t > 1.0)      # about an axis in the bend plane
    tip = Rotation.from_rotvec(np.column_stack([twist, np.zeros_like(t), theta]))
    q = tip.as_quat()[:, [3, 0, 1, 2]]
    b = bend_angle(t, q, np.ones(t.size, bool), rest_s=0.5)
    assert 0.5 < np.nanmax(b.out_of_plane_deg) < 2.5


# ------------------------------------------------------------------ clocks and cycles

def test_trigger_edges_give_offset_and_drift():
    rng = np.random.default_rng(4)
    true = np.sort(rng.uniform(5, 95, 12))
    t_ref = np.arange(0, 100, 0.001)
    ref = np.zeros_like(t_ref)
    t_inst = np.arange(0, 100, 0.0005)
    inst = np.zeros_like(t_inst)
    drift, offset = 50e-6, 0.7318       # inst = (ref - offset) * (1 + drift)
    for e in true:
        ref[(t_ref >= e) & (t_ref < e + 0.05)] = 5.0
        ei = (e - offset) * (1 + drift)
        inst[(t_inst >= ei) & (t_inst < ei + 0.05)] = 5.0
    assert rising_edges(t_ref, ref) == pytest.approx(true, abs=0.001)
    c = align_trigger("daq", t_inst, inst, t_ref, ref)
    probe = np.array([10.0, 50.0, 90.0])
    assert c.to_ref(probe) == pytest.approx(probe / (1 + drift) + offset, abs=0.0006)


def test_xcorr_recovers_a_lag_between_a_tracker_signal_with_gaps_and_a_dense_log():
    rng = np.random.default_rng(5)
    t_ref = np.arange(0, 120, 1 / 40.0)
    period = 10.0
    shape = lambda t: np.clip(1 - np.abs((t % period) - 5) / 5, 0, None) * ((t > 5) & (t < 115))
    ref = np.maximum(shape(t_ref) - 0.05, 0) * 30 + rng.normal(0, 0.2, t_ref.size)   # a deadband, noise
    ref[300:320] = np.nan
    offset = -1.234
    t_inst = np.arange(-2, 125, 1 / 100.0)
    inst = shape(t_inst + offset) * 2.5                                # ref time = inst time + offset
    c = align_xcorr("motor", t_ref, ref, t_inst, inst)
    assert c.to_ref(np.array([60.0]))[0] == pytest.approx(60.0 + offset, abs=0.002)
    assert c.sign == 1 and c.offset_err_s < 0.002


def test_clock_composition():
    a = ClockFit("daq", "trigger", 1.0, 100.0, 50.0)
    b = ClockFit("motor", "xcorr", -0.5, -30.0, 20.0)
    t = np.array([0.0, 50.0, 100.0])
    assert a.then(b).to_ref(t) == pytest.approx(b.to_ref(a.to_ref(t)), abs=1e-9)


def test_cycles_from_a_stroke_with_rests_and_dwells():
    t = np.arange(0, 60, 0.01)
    # 3 s rest; cycles of 2 s up, 1 s dwell at the top, 2 s down, 1 s rest at the bottom
    ph = (t - 3.0) % 6.0
    s = np.where(ph < 2, ph, np.where(ph < 3, 2.0, np.where(ph < 5, 5 - ph, 0.0))) * (t >= 3.0)
    s = np.where(t >= 57.0, 0.0, s) * 1.25
    starts = cycle_starts(t, s)
    assert starts == pytest.approx(3.0 + 6.0 * np.arange(1, 9), abs=0.011)
    cyc = cycle_numbers(t, starts)
    assert cyc[0] == 1 and cyc[-1] == 9 and np.all(np.diff(cyc) >= 0)


def test_the_capi_sample_layout_of_one_tool_reads_too_and_a_longer_row_is_refused():
    head = "#Tools,ToolInfo,Frame#,PortHandle,Face#,TransformStatus,Q0,Qx,Qy,Qz,Tx,Ty,Tz,Error,Markers,State,Tx,Ty,Tz\n"
    text = (head + "1,610029 s/n:3B1F0A01,100,Port:10,0,OK,1,0,0,0,1,2,3,0.1,0,,,,\n"
            "1,610029 s/n:3B1F0A01,101,Port:10,0,Missing,,,,,,,,,0,,,,\n")
    log = parse_ndi(text, "capi.csv", rate_hz=40.0)
    (tool,) = log.tools
    assert list(tool.state) == ["OK", "Missing"] and list(tool.valid) == [True, False]
    assert tool.time_s[1] == pytest.approx(1 / 40.0)
    with pytest.raises(DataError, match=r"capi.csv:3: 24 cells but the header \(line 1\) has 19"):
        parse_ndi(text.rstrip("\n") + ",1,2,3,4,5\n", "capi.csv", rate_hz=40.0)


def test_a_motion_that_cannot_fix_the_offset_is_refused():
    t_ref = np.arange(0, 100, 1 / 40.0)
    t_inst = np.arange(-60, 160, 1 / 100.0)            # covers the tracker's recording at every period shift
    wave = lambda t: np.abs(((t / 10.0) % 1.0) - 0.5)
    with pytest.raises(DataError, match="the motion does not fix the motor log's clock.*fix: --max-lag S"):
        align_xcorr("motor", t_ref, wave(t_ref), t_inst, wave(t_inst + 0.3))
    c = align_xcorr("motor", t_ref, wave(t_ref), t_inst, wave(t_inst + 0.3), max_lag_s=4.0)
    assert c.to_ref(np.array([50.0]))[0] == pytest.approx(50.3, abs=0.002)


def test_a_log_column_named_twice_is_refused_not_read_from_its_first_copy():
    """The bad-input search: a motor log headed t_us,enc_counts,enc_counts was read from the first copy with exit 0;
    the measurement reader refuses duplicate columns."""
    text = "t_us,enc_counts,enc_counts\n0,0,0\n1000,5,10\n2000,9,18\n"
    with pytest.raises(DataError, match=r"m\.csv:1: the header names column 'enc_counts' 2 times"):
        parse_series(text, "m.csv", "t_us", "us", "enc_counts")
    # another column twice, not read, is no matter
    parse_series("t_us,enc_counts,note,note\n0,0,a,b\n1000,5,a,b\n", "m.csv", "t_us", "us", "enc_counts")


def test_a_map_key_given_twice_is_refused():
    """The bad-input search: --map motor.gear_ratio=64 --map motor.gear_ratio=32 took the last with exit 0 (the stroke
    halved, E_t read 12 GPa); --fix given twice is refused."""
    with pytest.raises(DataError, match=r"--map motor.gear_ratio is given 2 times \('64', '32'\); fix: give it once"):
        bench_map_from_dict({}, "bench.yaml", ["motor.gear_ratio=64", "motor.gear_ratio=32"])
    assert bench_map_from_dict({}, "bench.yaml", ["motor.gear_ratio=64"]).motor.gear_ratio == 64
