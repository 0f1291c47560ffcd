import time, numpy as np
from camtube.design.loader import load_pattern
from camtube.model.sim.bench import *
from camtube.model.diagnose.instruments import check_instruments
pat = load_pattern("patterns/tube2.yaml")
for name, sb in [("control", SampleBench()), ("lag40", with_tracker(SampleBench(), lag_ms=40.0)),
                 ("toe", SampleBench(tendon=Tendon(crimp_mm=0.3))),
                 ("backlash", SampleBench(drive=Drive(backlash_mm=0.15))),
                 ("visco", SampleBench(backbone=Backbone(relax=((0.3, 2.0), (0.2, 20.0)))))]:
    r = simulate_bench(pat, sb, seed=3)
    d = r.data
    ok = np.isfinite(d.angle_deg)
    d2 = d.take(ok)
    t0 = time.time()
    ins = check_instruments(d2)
    sp = set(np.flatnonzero(ok)[ins.aside["angle spike"]])
    print(name, round(time.time()-t0,2), "true spikes", len(r.spike_rows), "found", len(sp), "hit", len(sp & set(r.spike_rows)))
    for l in ins.lines(): print("   ", l)
