import time, numpy as np
from camtube.design.loader import load_pattern
from camtube.model.sim.bench import *
pat = load_pattern("patterns/tube2.yaml")
t0=time.time()
r = simulate_bench(pat, SampleBench(), seed=1)
print(time.time()-t0, len(r.data), r.floor_deg, np.nanmax(r.data.angle_deg), r.data.force_N.max(), r.data.stroke_mm.max())
