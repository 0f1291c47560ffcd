"""The drive's law against the bench's own carriage (issue 19): ``carriage_hold`` at each sample's true rail friction
and nut gap, against where the bench simulator's carriage stood, for every lost-motion sample of the bench batches.

Run: ``python scripts/carriage_law.py [BATCH ...]`` (default: every batch of ``scripts/bench_real.py``). Prints one
line per sample (the gap, the rail's friction, the rms and largest difference of the carriage's position, um) and the
mean rms. The law is read here at the truth, not fitted: what it gets wrong is the form, not the fit.
"""
from __future__ import annotations

import sys

import numpy as np
from bench_real import BATCHES, ROOT, draw_batch, protocol_for

from camtube.design.loader import load_pattern
from camtube.model.effects.history import carriage_hold
from camtube.model.sim.bench import Clock, simulate_bench


def main(batches: list[str]) -> None:
    rms_all = []
    print("| batch | file | sample | gap mm | rail N | rms um | max um |")
    print("|---|---|---|---|---|---|---|")
    for b in batches:
        seed, kinds = BATCHES[b]
        for name, tube, rate, benches, ks, sim_seed in draw_batch(seed, kinds):
            if "lost motion" not in ks:
                continue
            pattern = load_pattern(ROOT / "patterns" / f"{tube}.yaml")
            rec = simulate_bench(pattern, benches, protocol_for(rate), Clock(rate_hz=rate), seed=sim_seed)
            for i, (smp, sl) in enumerate(rec.data.sample_slices()):
                if ks[i] != "lost motion":
                    continue
                sub = rec.data.take(np.arange(sl.start, sl.stop))
                drive = benches[i].drive
                law = carriage_hold(sub, np.asarray(sub.stroke_mm, float), drive.rail_friction_N, drive.backlash_mm)
                err_um = 1000.0 * (law - rec.carriage_true_mm[sl])
                rms = float(np.sqrt(np.mean(err_um ** 2)))
                rms_all.append(rms)
                print(f"| {b} | {name} | {smp} | {drive.backlash_mm:.3f} | {drive.rail_friction_N:.3f} | {rms:.1f} | "
                      f"{float(np.max(np.abs(err_um))):.0f} |", flush=True)
    print(f"{len(rms_all)} samples: rms {min(rms_all):.1f}-{max(rms_all):.1f} um, mean {np.mean(rms_all):.1f} um")


if __name__ == "__main__":
    main(sys.argv[1:] or [b for b in BATCHES if b != "bench-heldout12"])
