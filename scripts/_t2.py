import time, numpy as np
from camtube.design.loader import load_pattern
from camtube.model.sim.bench import *
from camtube.model.core.predict import model_for_pattern, pattern_values
from camtube.model.core.fit import fit
pat = load_pattern("patterns/tube2.yaml")
r = simulate_bench(pat, SampleBench(), seed=1)
d = r.data
ok = np.isfinite(d.angle_deg)
ok[r.spike_rows] = False
d2 = d.take(ok)
# sort times within sample
m = model_for_pattern(pat)
t0=time.time()
f = fit(m, d2, ["E_t"], pattern_values(pat))
print(time.time()-t0, f.rmse, r.floor_deg, r.noise_deg, f.params["E_t"], pattern_values(pat))
res = d2.angle_deg - f.predicted
print(np.percentile(np.abs(res),[50,99,99.9]))
