"""Raw bench logs from a known truth, to test ``camtube model ingest`` against it.

One joint is actuated by ``n_cycles`` stroke triangles between rests; its angle and force follow the base
model (as in :mod:`camtube.model.sim.synth`). Three instruments record it, each with its own clock, rate
and faults:

* an NDI Aurora export (:mod:`camtube.model.ingest.ndi` layout) of two coils, base and tip, each mounted
  with an arbitrary rotation; the base (the whole bench) wobbles slowly; orientation noise per coil and
  axis; quaternion signs flipped at random; bursts of frames flagged ``Missing`` / ``Out of Volume`` with
  NDI's bad-float cells, and frames absent from the file;
* a DAQ log of the load cell in volts (calibration N/V, zero offset), time in ms, its clock offset and
  drifting against the tracker's, with a stretch of samples lost (a buffer overrun);
* a motor log of encoder counts (counts per revolution, 64:1 gearbox, lead screw), time in us, its own
  offset and drift.

:func:`simulate_bench` returns the three files' text, a bench map for them, and the truth: the noise-free
measurement rows at every tracker frame, the true clock maps and the dropouts.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from camtube.design.geometry import pattern_geometry
from camtube.design.pattern import Pattern
from camtube.model.core.predict import (
    POLYIMIDE_MODULUS_GPA, joint_stiffness_nmm_per_rad, pattern_compliance_mm_per_N, stroke_only_angle_rad,
)
from camtube.model.data.dataset import Dataset

BAD_FLOAT = "-3.697314E28"


@dataclass(frozen=True)
class BenchSetup:
    """Settings of one simulated recording (times in s, true clock = tracker clock minus its epoch)."""

    n_cycles: int = 12
    max_stroke_mm: float | None = None
    speed_mm_s: float = 0.5
    slack_mm: float = 0.05
    rest_s: float = 4.0
    tracker_rate_hz: float = 40.0
    daq_rate_hz: float = 500.0
    motor_rate_hz: float = 100.0
    daq_start_s: float = -1.3
    motor_start_s: float = -0.6
    daq_drift_ppm: float = 40.0
    motor_drift_ppm: float = -25.0
    tracker_epoch_s: float = 1778067000.0
    noise_rot_deg: float = 0.1
    noise_pos_mm: float = 0.05
    noise_force_N: float = 0.005
    n_bursts: int = 6
    n_absent: int = 4
    daq_gap_s: float = 0.4
    flip_fraction: float = 0.3
    N_per_V: float = 2.5
    offset_V: float = 0.12
    counts_per_rev: int = 512
    gear_ratio: float = 64.0
    lead_mm_per_rev: float = 0.5
    trigger: bool = False
    mount_deg: float = 25.0
    wobble_deg: float = 2.0
    seed: int = 0


@dataclass(frozen=True, eq=False)
class BenchLogs:
    """The simulated files and their truth.

    Attributes
    ----------
    tracker_csv, daq_csv, motor_csv, bench_map_yaml : str
        File contents.
    truth : Dataset
        Noise-free rows at every tracker frame (tracker clock, from its first frame), sample ``"1"``.
    truth_frame_time_s : (n,) float
        Tracker-clock time of each truth row as written in the export (epoch included).
    clock_true : dict
        ``{"daq": (start_s, drift_ppm, unit_s), "motor": ...}``: the instrument clock reads
        ``(tau - start_s) (1 + drift) / unit_s`` at true time ``tau``.
    flagged : dict
        Frames flagged per tool label and state, e.g. ``{("tip", "Missing"): 7}``.
    absent_frames : int
        Frames left out of the export.
    daq_gap_true_s : tuple of float
        True-time interval of the lost DAQ samples.
    """

    tracker_csv: str
    daq_csv: str
    motor_csv: str
    bench_map_yaml: str
    truth: Dataset
    truth_frame_time_s: np.ndarray
    clock_true: dict
    flagged: dict = field(default_factory=dict)
    absent_frames: int = 0
    daq_gap_true_s: tuple = (0.0, 0.0)

    def to_ref(self, name: str, t_inst_s: np.ndarray) -> np.ndarray:
        """True tracker-clock time (epoch included) of instrument clock readings ``t_inst_s`` (s)."""
        start, drift, _ = self.clock_true[name]
        return self.truth_frame_time_s[0] - self.truth.time_s[0] + start + np.asarray(t_inst_s) / (1 + drift * 1e-6)


def _stroke(tau: np.ndarray, s: BenchSetup, smax: float) -> tuple[np.ndarray, np.ndarray]:
    ramp = smax / s.speed_mm_s
    period = 2 * ramp
    x = tau - s.rest_s
    k = np.floor(x / period)
    ph = x - k * period
    stroke = smax - np.abs(smax - s.speed_mm_s * ph)
    inside = (x >= 0) & (k < s.n_cycles)
    stroke = np.where(inside, stroke, 0.0)
    cycle = np.clip(k + 1, 1, s.n_cycles).astype(int)
    return stroke, cycle


def simulate_bench(pattern: Pattern, setup: BenchSetup = BenchSetup(), modulus_gpa: float | None = None) -> BenchLogs:
    """Simulate the three raw logs of one recording of ``pattern`` (see the module docstring)."""
    from scipy.spatial.transform import Rotation

    s = setup
    rng = np.random.default_rng(s.seed)
    g = pattern_geometry(pattern).first
    e_t = pattern.tendon.modulus_gpa if modulus_gpa is None else modulus_gpa
    c = pattern_compliance_mm_per_N(pattern, e_t)
    k_st = joint_stiffness_nmm_per_rad(pattern, POLYIMIDE_MODULUS_GPA)
    arm = g.moment_arm_mm
    smax = pattern.rules.max_stroke_mm if s.max_stroke_mm is None else s.max_stroke_mm
    duration = 2 * s.rest_s + s.n_cycles * 2 * smax / s.speed_mm_s

    def truth_at(tau):
        st, cy = _stroke(tau, s, smax)
        th = stroke_only_angle_rad(st - s.slack_mm, arm, k_st, c)
        return st, cy, th, k_st * th / arm

    # ---- tracker
    n = int(duration * s.tracker_rate_hz)
    tau = np.arange(n) / s.tracker_rate_hz
    st, cy, th, fo = truth_at(tau)
    frame_no = 18000 + np.arange(n)
    t_trk = s.tracker_epoch_s + tau
    truth = Dataset(np.full(n, "1", dtype=object), cy, tau, st, fo, np.degrees(th))
    mount_a = Rotation.from_rotvec(rng.normal(size=3) * np.radians(s.mount_deg) / np.sqrt(3))
    mount_b = Rotation.from_rotvec(rng.normal(size=3) * np.radians(s.mount_deg) / np.sqrt(3))
    world = Rotation.from_rotvec(rng.uniform(-1, 1, 3) * 2.0)
    wob_axis = rng.normal(size=3)
    wob_axis /= np.linalg.norm(wob_axis)
    wob = Rotation.from_rotvec(np.outer(np.radians(s.wobble_deg) * np.sin(2 * np.pi * tau / 37.0), wob_axis))
    r_base = world * wob
    r_tip = r_base * mount_a * Rotation.from_rotvec(np.outer(th, [0, 0, 1])) * mount_b
    sig = np.radians(s.noise_rot_deg)
    r_base_m = r_base * Rotation.from_rotvec(rng.normal(0, sig, (n, 3)))
    r_tip_m = r_tip * Rotation.from_rotvec(rng.normal(0, sig, (n, 3)))
    p0 = np.array([15.0, -40.0, -180.0])
    p_base = p0 + rng.normal(0, s.noise_pos_mm, (n, 3))
    p_tip = p0 + r_base.apply(np.array([0.0, 0.0, 20.0])) + rng.normal(0, s.noise_pos_mm, (n, 3))

    def quats(r):
        q = r.as_quat()[:, [3, 0, 1, 2]]
        flip = rng.random(n) < s.flip_fraction
        q[flip] *= -1
        return q

    q_base, q_tip = quats(r_base_m), quats(r_tip_m)
    state = {"base": np.full(n, "OK", dtype=object), "tip": np.full(n, "OK", dtype=object)}
    flagged: dict = {}
    for _ in range(s.n_bursts):
        who = ("base", "tip")[int(rng.integers(2))]
        what = ("Missing", "Out of Volume")[int(rng.integers(2))]
        a = int(rng.integers(int(s.rest_s * s.tracker_rate_hz) + 10, n - 10))
        state[who][a:a + int(rng.integers(2, 9))] = what
    for who in ("base", "tip"):
        for what in ("Missing", "Out of Volume"):
            cnt = int(np.sum(state[who] == what))
            if cnt:
                flagged[(who, what)] = cnt
    absent = np.zeros(n, bool)
    cand = np.flatnonzero((state["base"] == "OK") & (state["tip"] == "OK"))
    cand = cand[(cand > s.rest_s * s.tracker_rate_hz + 5) & (cand < n - 5)]
    absent[rng.choice(cand, size=s.n_absent, replace=False)] = True
    labels = {"base": "Port 0x0A: 610029  s/n:3B1F0A01", "tip": "Port 0x0B: 610029  s/n:3B1F0A02"}
    cols = ["Frame", "Time [sec]", "Face", "State", "Q0", "Qx", "Qy", "Qz", "Tx", "Ty", "Tz", "Error"]
    head = ["Tools"]
    for who in ("base", "tip"):
        head += [labels[who]] + cols
    out = [",".join(head)]
    for k in np.flatnonzero(~absent):
        cells = ["2"]
        for who, q, p in (("base", q_base, p_base), ("tip", q_tip, p_tip)):
            stt = state[who][k]
            if stt == "OK":
                pose = [f"{v:.7f}" for v in q[k]] + [f"{v:.3f}" for v in p[k]] + [f"{abs(rng.normal(0.1, 0.03)):.4f}"]
            else:
                pose = [BAD_FLOAT] * 7 + ["0.0000"]
            cells += [labels[who], str(frame_no[k]), f"{t_trk[k]:.6f}", "1", stt] + pose
        out.append(",".join(cells))
    tracker_csv = "\n".join(out) + "\n"

    # ---- DAQ (volts, ms) and motor (counts, us)
    def clock(start, drift, rate, name):
        t_inst = np.arange(int((duration + 2.0 - start) * rate)) / rate         # its own clock, s
        tau_i = start + t_inst / (1 + drift * 1e-6)
        return t_inst, tau_i

    t_d, tau_d = clock(s.daq_start_s, s.daq_drift_ppm, s.daq_rate_hz, "daq")
    _, _, _, f_d = truth_at(tau_d)
    volts = f_d / s.N_per_V + s.offset_V + rng.normal(0, s.noise_force_N / s.N_per_V, tau_d.size)
    g0 = float(rng.uniform(s.rest_s + 10, duration - 10))
    keep = ~((tau_d >= g0) & (tau_d < g0 + s.daq_gap_s))
    kept_tau = tau_d[keep]
    gap_true = (float(kept_tau[kept_tau < g0].max()), float(kept_tau[kept_tau >= g0 + s.daq_gap_s].min()))
    pulses = np.arange(1.0, duration, 13.7137)                     # a shared TTL line: 50 ms pulses, true times

    def ttl(tau_i):
        k = np.searchsorted(pulses, tau_i, side="right") - 1
        return np.where((k >= 0) & (tau_i - pulses[np.clip(k, 0, None)] < 0.05), 5.0, 0.0)

    if s.trigger:
        daq_csv = "time_ms,load_V,sync\n" + "".join(f"{a * 1e3:.3f},{v:.6f},{g:.0f}\n" for a, v, g in
                                                    zip(t_d[keep], volts[keep], ttl(tau_d)[keep]))
    else:
        daq_csv = "time_ms,load_V\n" + "".join(f"{a * 1e3:.3f},{v:.6f}\n" for a, v in zip(t_d[keep], volts[keep]))
    t_m, tau_m = clock(s.motor_start_s, s.motor_drift_ppm, s.motor_rate_hz, "motor")
    st_m, _, _, _ = truth_at(tau_m)
    counts = np.round(st_m / s.lead_mm_per_rev * s.gear_ratio * s.counts_per_rev).astype(np.int64)
    if s.trigger:
        motor_csv = "t_us,enc_counts,sync\n" + "".join(f"{int(round(a * 1e6))},{v},{g:.0f}\n" for a, v, g in
                                                      zip(t_m, counts, ttl(tau_m)))
    else:
        motor_csv = "t_us,enc_counts\n" + "".join(f"{int(round(a * 1e6))},{v}\n" for a, v in zip(t_m, counts))
    trig = ", trigger: sync" if s.trigger else ""
    bench_map = (
        "tracker: {base: \"0A\", tip: \"0B\", unit: mm, rest_s: 3.0}\n"
        f"daq: {{time: time_ms, time_unit: ms, force: load_V, force_unit: V, N_per_V: {s.N_per_V}, offset_V: rest{trig}}}\n"
        f"motor: {{time: t_us, time_unit: us, stroke: enc_counts, stroke_unit: counts, counts_per_rev: {s.counts_per_rev},"
        f" gear_ratio: {s.gear_ratio:g}, lead_mm_per_rev: {s.lead_mm_per_rev}, sign: 1{trig}}}\n")
    return BenchLogs(tracker_csv, daq_csv, motor_csv, bench_map, truth, t_trk,
                     {"daq": (s.daq_start_s, s.daq_drift_ppm, 1e-3), "motor": (s.motor_start_s, s.motor_drift_ppm, 1e-6)},
                     flagged, int(absent.sum()), gap_true)


def random_setups(n: int = 6, seed: int = 2311) -> list[tuple[str, BenchSetup]]:
    """``n`` recordings drawn at random, not picked: (preset name, setup) with the joint, cycles, speed,
    slack, rates, clock offsets and drifts, noise and dropouts drawn from ``seed``.

    ``random_setups(6, 2311)`` is the held-out set of docs/bench.md, drawn once the method was final.
    """
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        out.append((str(rng.choice(["tube1", "tube2", "tube3"])), BenchSetup(
            seed=int(rng.integers(10_000, 99_999)), n_cycles=int(rng.integers(5, 21)),
            speed_mm_s=float(rng.choice([0.5, 1.0])), slack_mm=float(rng.uniform(0.0, 0.1)),
            tracker_rate_hz=float(rng.choice([40.0, 40.0, 60.0])), daq_rate_hz=float(rng.choice([200.0, 500.0, 1000.0])),
            motor_rate_hz=float(rng.choice([50.0, 100.0, 200.0])), daq_start_s=float(rng.uniform(-3.0, 0.0)),
            motor_start_s=float(rng.uniform(-3.0, 0.0)), daq_drift_ppm=float(rng.uniform(-100, 100)),
            motor_drift_ppm=float(rng.uniform(-100, 100)), noise_rot_deg=float(rng.uniform(0.0, 0.2)),
            noise_force_N=float(rng.uniform(0.002, 0.01)), n_bursts=int(rng.integers(0, 12)),
            n_absent=int(rng.integers(1, 8)), flip_fraction=float(rng.uniform(0, 0.5)))))
    return out
