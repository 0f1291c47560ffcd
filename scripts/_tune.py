import sys
import bench_diagnose as BD
rows = [BD.run_set(*s, seed=100 + k) for k, s in enumerate(BD.TUNE)]
print(BD.table(rows)); print(BD.verdicts(rows))
