"""Spikes and repeated stamps found by the instruments check against the bench simulator's truth, on both bench
batches: ``python scripts/check_bench_artefacts.py``."""
from benchutil import ROOT
import numpy as np, bench_real as B
from camtube.design.loader import load_pattern
from camtube.model.sim.bench import simulate_bench, Clock
from camtube.model.diagnose.instruments import check_instruments
for batch in ("bench", "bench-heldout"):
    seed, kinds = B.BATCHES[batch]
    for spec in B.draw_batch(seed, kinds):
        name, tube, rate, benches, _, s = spec
        rec = simulate_bench(load_pattern(ROOT / "patterns" / f"{tube}.yaml"), benches, B.protocol_for(rate), Clock(rate_hz=rate), seed=s)
        ok = np.isfinite(rec.data.angle_deg)
        ins = check_instruments(rec.data.take(ok))
        idx = np.flatnonzero(ok)
        found = set(idx[ins.aside["angle spike"]]); true = set(rec.spike_rows) - set(rec.dropout_rows)
        rep = set(idx[ins.aside["repeated time stamp"]])
        print(batch, name, "spikes found", len(found), "true", len(true), "hits", len(found & true), "false", len(found - true), "repeats", len(rep & set(rec.repeat_rows)), "/", len(rec.repeat_rows), "force spikes", len(ins.aside["force spike"]))
