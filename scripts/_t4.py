import numpy as np
from scipy.ndimage import median_filter
from camtube.design.loader import load_pattern
from camtube.model.sim.bench import *
pat = load_pattern("patterns/tube2.yaml")
r = simulate_bench(pat, SampleBench(), seed=3)
d = r.data; ok = np.isfinite(d.angle_deg); d=d.take(ok)
v = d.angle_deg[:25000]
dd = v - median_filter(v, size=7, mode="nearest")
sc = 1.4826*np.median(np.abs(dd-np.median(dd)))
print(sc, np.std(dd))
z = np.abs(dd)/sc
k = np.flatnonzero(z>8)[:10]
print(k, z[k], v[k], d.stroke_mm[k], d.time_s[k])
print("diff sd", np.std(np.diff(v))/np.sqrt(2), np.median(np.abs(np.diff(v)))*1.4826/np.sqrt(2))
print(v[:30].round(3))
print(d.time_s[:10], d.sample[:3])
