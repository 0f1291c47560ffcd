import sys, tempfile
from pathlib import Path
import bench_real as B
from camtube.model.sim.bench import *
from camtube.model.data import format_csv
from camtube.design.loader import load_pattern
kind = sys.argv[1]
spec = [s for s in B.draw_batch(20261124, B.TUNE_KINDS) if s[0] == kind][0]
name, tube, rate, benches, kinds, seed = spec
pattern = load_pattern(B.ROOT / "patterns" / f"{tube}.yaml")
rec = simulate_bench(pattern, benches, B.protocol_for(rate), Clock(rate_hz=rate), seed=seed)
Path(sys.argv[2]).write_text(format_csv(rec.data))
print(tube, rec.floor_deg, benches)
