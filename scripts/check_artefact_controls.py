"""A bench control with one instrument artefact the bench simulator does not draw, added to its record each time.

``python scripts/check_artefact_controls.py [--batch NAME] [--file K] [VARIANT ...]``: the K-th control of batch
NAME (default: the first of ``bench-heldout16``) is simulated once; each variant adds one artefact, writes the CSV,
runs ``camtube model diagnose`` on it as a user would, and prints one line: what was recommended or left partial,
the floor estimate against the true floor, the final RMSE against it, the answer's first line and the rows set
aside. A control should get nothing recommended, nothing unexplained, the final RMSE near the true floor.

Variants: ``plain``, ``angle_q0.1`` (the angle quantised to 0.1 deg), ``force_q2mN``, ``clock_100ppm`` (the
tracker's clock runs 100 ppm slow: a lag that grows through the record), ``sentinel`` (runs of -999),
``long_burst`` (interference of 4-8 deg lasting 0.6-1.5 s), ``many_spikes`` (0.5 % of the rows), ``force_spikes``,
``force_clip`` (a load cell that saturates at 80 % of the peak), ``noise0.5``, ``noise0.03`` (the tracker's noise),
``stamps_10ms`` (stamps rounded to 10 ms), ``gap_3s`` (the logger paused 3 s in each sample).
"""
from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
from benchutil import ROOT

import bench_real as B
from camtube.design.loader import load_pattern
from camtube.model.data import format_csv
from camtube.model.data.dataset import Dataset
from camtube.model.sim.bench import Clock, simulate_bench


def _with_force(d: Dataset, force: np.ndarray) -> Dataset:
    return Dataset(d.sample, d.cycle, d.time_s, d.stroke_mm, force, d.angle_deg)


def variants(spec, rng: np.random.Generator):
    """``(name, data, true floor deg)`` of each variant of the control ``spec``."""
    name, tube, rate, benches, _, seed = spec
    pattern = load_pattern(ROOT / "patterns" / f"{tube}.yaml")

    def record(b=benches):
        return simulate_bench(pattern, b, B.protocol_for(rate), Clock(rate_hz=rate), seed=seed)

    rec = record()
    d, floor = rec.data, rec.floor_deg
    yield "plain", d, floor
    yield "angle_q0.1", d.with_angle(np.round(d.angle_deg / 0.1) * 0.1), math.hypot(floor, 0.1 / math.sqrt(12.0))
    yield "force_q2mN", _with_force(d, np.round(d.force_N / 0.002) * 0.002), floor
    a = d.angle_deg.copy()
    for smp in np.unique(d.sample):
        m = d.sample == smp
        t = d.time_s[m]
        a[m] = np.interp(t - 1e-4 * (t - t[0]), t, d.angle_deg[m])
    yield "clock_100ppm", d.with_angle(a), floor
    a = d.angle_deg.copy()
    for _ in range(6):
        i = int(rng.integers(100, len(a) - 100))
        a[i:i + int(rng.integers(5, 40))] = -999.0
    yield "sentinel", d.with_angle(a), floor
    a = d.angle_deg.copy()
    for _ in range(4):
        i = int(rng.integers(100, len(a) - 200))
        a[i:i + int(rng.uniform(0.6, 1.5) * rate)] += rng.choice([-1, 1]) * rng.uniform(4, 8)
    yield "long_burst", d.with_angle(a), floor
    a = d.angle_deg.copy()
    k = rng.choice(len(a), len(a) // 200, replace=False)
    a[k] += rng.choice([-1, 1], k.size) * rng.uniform(2, 10, k.size)
    yield "many_spikes", d.with_angle(a), floor
    f = d.force_N.copy()
    k = rng.choice(len(f), 40, replace=False)
    f[k] += rng.uniform(0.3, 1.0, k.size)
    yield "force_spikes", _with_force(d, f), floor
    yield "force_clip", _with_force(d, np.minimum(d.force_N, 0.8 * np.nanmax(d.force_N))), floor
    for sd in (0.5, 0.03):
        r = record(tuple(replace(b, tracker=replace(b.tracker, noise_deg=sd)) for b in benches))
        yield f"noise{sd:g}", r.data, r.floor_deg
    yield "stamps_10ms", Dataset(d.sample, d.cycle, np.round(d.time_s, 2), d.stroke_mm, d.force_N, d.angle_deg), floor
    keep = np.ones(len(d), bool)
    for smp in np.unique(d.sample):
        idx = np.flatnonzero(d.sample == smp)
        i = idx[len(idx) // 2]
        keep[i:i + int(3 * rate)] = False
    yield "gap_3s", d.take(keep), floor


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--batch", default="bench-heldout16")
    ap.add_argument("--file", type=int, default=0, help="which control of the batch (0: the first)")
    ap.add_argument("only", nargs="*", help="variants to run (default: all)")
    args = ap.parse_args(argv)
    controls = [s for s in B.batch_specs(args.batch) if s[0] == "control"]
    spec = controls[args.file]
    tube = spec[1]
    with tempfile.TemporaryDirectory() as tmp:
        for tag, d, floor in variants(spec, np.random.default_rng(77)):
            if args.only and tag not in args.only:
                continue
            path, js = Path(tmp) / f"{tag}.csv", Path(tmp) / f"{tag}.json"
            path.write_text(format_csv(d))
            p = subprocess.run([sys.executable, "-m", "camtube", "model", "diagnose", str(path), "--pattern",
                                str(ROOT / "patterns" / f"{tube}.yaml"), "--json", str(js)],
                               capture_output=True, text=True)
            if p.returncode != 0:
                print(f"{tag:14s} exit {p.returncode}: {p.stderr.strip().splitlines()[-1:]}")
                continue
            j = json.loads(js.read_text())
            lines = p.stdout.splitlines()
            answer = next((x for x in lines if x.startswith("answer")), "")
            aside = next((x.strip() for x in lines if "set aside before fitting" in x), "")
            final = j["final"]["rmse_deg"]
            print(f"{tag:14s} recommended {','.join(j['recommended']) or '-'}; partial "
                  f"{','.join(x['effect'] for x in j['partial']) or '-'}; floor {j['noise_floor_deg']:.3f} true "
                  f"{floor:.3f} ({j['noise_floor_deg'] / floor:.2f}); final {final:.3f} ({final / floor:.2f}x) | "
                  f"{answer[:90]} | {aside[:120]}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
