import numpy as np
from camtube.design.loader import load_pattern
from camtube.model.sim.bench import *
from camtube.model.diagnose import instruments as I
pat = load_pattern("patterns/tube2.yaml")
r = simulate_bench(pat, SampleBench(), seed=3)
d = r.data; ok = np.isfinite(d.angle_deg); d=d.take(ok)
sl = d.sample_slices()
print(sl)
m = I._spikes(d.angle_deg, sl)
print(m.sum())
k=np.flatnonzero(m)[:20]; print(k, d.angle_deg[k])
from scipy.ndimage import median_filter
v = d.angle_deg[sl[0][1]]
foot = np.ones(7, bool); foot[3]=False
md = median_filter(v, footprint=foot, mode="nearest")
dd = v-md
print(np.percentile(np.abs(dd),[10,25,50,75,90,99]))
print(v[:8], md[:8])
print("zero diffs", np.mean(np.diff(v)==0), "zero d", np.mean(dd==0))
from scipy.ndimage import generic_filter
print(scipy_version:=__import__("scipy").__version__)
k=np.flatnonzero(dd==0)[:3]; print(k); print(v[k[0]-3:k[0]+4], md[k[0]])
print(v[10:18], md[10:18])
