"""The instruments' check against the bench simulator's truth: spikes, bursts, dropouts written as values and
repeated stamps found, per file: ``python scripts/check_bench_artefacts.py [BATCH ...]`` (default: the first two
bench batches).

Per file: the spikes found against the true ones (those not in a dropout), the rows of bursts found (as spikes or
bursts), the dropouts the tracker wrote as 0 or its last reading that were set aside (those while the joint was
bent and the motor moved, and those written as 0 while it stood bent in a dwell: at rest a zero or a held value is
no error, nor is a held value in a dwell), the repeated stamps, and any row set aside that carries no artefact
("false"; the rows a load cell read the end of its range in count as artefacts), and the rows whose force jumped
before the logged stroke moved (listed apart, with the guide's slip speed: a guide that switches within a row makes
them).
"""
import argparse

import numpy as np
from benchutil import ROOT

import bench_real as B
from camtube.design.loader import load_pattern
from camtube.model.diagnose.instruments import check_instruments
from camtube.model.sim.bench import Clock, simulate_bench

ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
ap.add_argument("batches", nargs="*", metavar="BATCH",
                help=f"bench batches ({', '.join(B.BATCHES)}); default: bench bench-heldout")
batches = ap.parse_args().batches
unknown = [b for b in batches if b not in B.BATCHES]
if unknown:
    ap.error(f"unknown batch {unknown[0]!r}; fix: give one of {', '.join(B.BATCHES)}")
for batch in batches or ["bench", "bench-heldout"]:
    for spec in B.batch_specs(batch):
        name, tube, rate, benches, _, s = spec[:6]
        rec = simulate_bench(load_pattern(ROOT / "patterns" / f"{tube}.yaml"), benches, B.protocol_of(spec),
                             Clock(rate_hz=rate), seed=s)
        ok = np.isfinite(rec.data.angle_deg)
        ins = check_instruments(rec.data.take(ok))
        idx = np.flatnonzero(ok)
        aside = {k: set(idx[v]) for k, v in ins.aside.items()}
        every = set().union(*aside.values())
        drops = set(rec.dropout_rows.tolist())
        spikes = set(rec.spike_rows.tolist()) - drops
        bursts = set(rec.burst_rows.tolist()) - drops
        stroke = rec.data.stroke_mm
        bent = {i for i in drops & set(idx.tolist()) if abs(rec.angle_true_deg[i]) > 3.0
                and 0 < i < len(stroke) - 1 and stroke[i + 1] != stroke[i - 1]}
        dwell = {i for i in drops & set(idx.tolist()) if abs(rec.angle_true_deg[i]) > 3.0 and i not in bent
                 and rec.data.angle_deg[i] == 0.0}
        # a load cell at the end of its range: the rows it read its limit in (range_N; inf: none)
        smp = rec.data.sample
        limit = np.zeros(len(smp), bool)
        for b, name_s in zip(benches, np.unique(smp)):
            limit |= (smp == name_s) & (rec.data.force_N >= b.load_cell.range_N)
        artefact = spikes | bursts | drops | set(rec.repeat_rows.tolist()) | set(np.flatnonzero(limit).tolist())
        shifted = aside.get("end of record after the lag shift", set()) | aside.get("row before a gap after the lag shift", set())
        # rows whose force jumped before the logged stroke moved: no artefact of an instrument but of the stroke's
        # resolution at a start; listed on their own, with the sharpest guide's slip speed (mm/s)
        ahead = aside.get("force ahead of the stroke row", set())
        slips = [b.guide.slip_mm_s for b in benches if b.guide.mu > 0]
        slip = min(slips) if slips else None
        print(f"{batch} {name}: spikes {len(aside['angle spike'] & spikes)} of {len(spikes)}; burst rows "
              f"{len(every & bursts)} of {len(bursts)}; dropouts written as values, while bent and moving, "
              f"{len(every & bent)} of {len(bent)}, written as 0 in a dwell {len(every & dwell)} of {len(dwell)}; repeats {len(aside['repeated time stamp'] & set(rec.repeat_rows))}"
              f" of {len(rec.repeat_rows)}; force spikes {len(aside['force spike'])}; false "
              f"{len(every - artefact - shifted - ahead)}; force ahead of the stroke {len(ahead)}"
              + (f" (guide slip {slip:g} mm/s)" if slip is not None else " (no guide friction)"), flush=True)
