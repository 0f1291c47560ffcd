"""Write measurements with physics camtube does not ship: a tendon that slips in its anchor.

The tendon is crimped in the tip's anchor hole; once its tension passes a
threshold the crimp slips a little and the tendon stays slipped (it never
slips back). The stroke lost grows in steps with each new force record,
then the joint repeats: ``lost = s_max * (1 - exp(-max(F_peak - F_slip, 0) / F_scale))``
where ``F_peak`` is the largest tension so far. This script simulates it with
an explicit time-stepping loop of the tendon and the joint (no camtube effect
code) and writes ``anchor_slip.csv``.

Run: ``python examples/user_effect/make_data.py [OUT.csv]``
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

from camtube.design.geometry import pattern_geometry
from camtube.design.loader import load_pattern
from camtube.io import write_atomic
from camtube.model.data import format_csv
from camtube.model.data.dataset import Dataset
from camtube.model.core.predict import joint_stiffness_nmm_per_rad
from camtube.model.sim.synth import triangle_stroke

ROOT = Path(__file__).resolve().parents[2]
SLIP_MM, F_SLIP_N, F_SCALE_N = 0.12, 1.0, 0.8


def simulate(seed: int = 0) -> Dataset:
    p = load_pattern(ROOT / "patterns" / "tube2.yaml")
    arm = pattern_geometry(p).first.moment_arm_mm
    c = p.tendon.length_mm / (p.tendon.modulus_gpa * 1e3 * p.tendon.area_mm2)
    rng = np.random.default_rng(seed)
    rows = {k: [] for k in ("sample", "cycle", "time", "stroke", "force", "angle")}
    # peak stroke grows over the cycles: each new peak force slips the anchor further
    for smp in ("1", "2"):
        k = joint_stiffness_nmm_per_rad(p) * (1 + 0.1 * rng.uniform(-1, 1))
        times, strokes, cycles = [], [], []
        t0 = 0.0
        for cyc, smax in enumerate(np.linspace(1.2, 2.5, 8), 1):
            t, s, _ = triangle_stroke(smax, 0.5, 10.0, 1)
            times.append(t + t0)
            strokes.append(s)
            cycles.append(np.full(s.size, cyc))
            t0 += 2 * smax / 0.5
        x = np.concatenate(strokes)
        f_peak, lost = 0.0, 0.0
        theta = np.zeros(x.size)
        tension = np.zeros(x.size)
        for i, xi in enumerate(x):
            # tendon length balance with the lost stroke from the previous step, then update the slip
            pull = max(xi - lost, 0.0)
            tn = pull / (arm * arm / k + c)
            theta[i], tension[i] = arm * tn / k, tn
            f_peak = max(f_peak, tn)
            lost = SLIP_MM * (1.0 - math.exp(-max(f_peak - F_SLIP_N, 0.0) / F_SCALE_N))
        m = x.size
        rows["sample"].append(np.full(m, smp, dtype=object))
        rows["cycle"].append(np.concatenate(cycles))
        rows["time"].append(np.concatenate(times))
        rows["stroke"].append(x)
        rows["force"].append(tension + rng.normal(0, 0.005, m))
        rows["angle"].append(np.degrees(theta) + rng.normal(0, 0.25, m))
    cat = {k: np.concatenate(v) for k, v in rows.items()}
    return Dataset(cat["sample"], cat["cycle"].astype(int), cat["time"], cat["stroke"], cat["force"], cat["angle"])


if __name__ == "__main__":
    out = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).with_name("anchor_slip.csv")
    data = simulate()
    print(f"wrote {write_atomic(out, format_csv(data))}: {len(data)} rows")
