import cProfile, pstats, sys, tempfile
from pathlib import Path
import bench_real as B
spec = B.draw_batch(20261124, ["control", "toe"])[int(sys.argv[1])]
with tempfile.TemporaryDirectory() as tmp:
    cProfile.run("B.run_file(spec, Path(tmp))", "/tmp/prof.out")
p = pstats.Stats("/tmp/prof.out"); p.sort_stats("cumulative").print_stats(35)
