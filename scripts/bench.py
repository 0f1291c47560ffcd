"""Benchmarks of camtube's main operations: prints timings and ratios to the targets.

    python scripts/bench.py            # design-stage figures, then every scripts/bench_*.py
    python scripts/bench.py --only design

Each stage's own benchmark lives in ``scripts/bench_<stage>.py`` and is run
here in a subprocess, so one command prints every figure the issues ask for.
The plan stage (``bench_plan.py``) times what ``camtube toolpath`` does with every
output written, at 10,000 and 100,000 notches, against its G-code alone, and prints
each run's peak memory (the child process's peak resident set size).
"""
from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from benchutil import best_of  # noqa: E402


def bench_design() -> None:
    from camtube.design import load
    from camtube.design.loader import build, read_yaml
    from camtube.export.dxf import design_dxf

    print("== design stage ==")
    for name in ("tube1", "tube2", "tube3"):
        path = ROOT / "patterns" / f"{name}.yaml"
        t_load = best_of(lambda: load(path), 5)[0]
        pattern = load(path).pattern
        t_dxf = best_of(lambda: design_dxf(pattern), 5)[0]
        print(f"{name}: load+rules {t_load * 1e3:7.2f} ms   design DXF {t_dxf * 1e3:7.2f} ms")

    raw, _, _ = read_yaml(ROOT / "patterns" / "tube1.yaml")
    raw["process"] = {}
    times = {}
    for n in (1000, 10000):
        r = dict(raw, notch=dict(raw["notch"], count=n), tube=dict(raw["tube"], length=1.5 + n * 1.0 + 1.0))
        t_build = best_of(lambda: build(r))[0]
        pattern = build(r).pattern
        t_dxf = best_of(lambda: design_dxf(pattern))[0]
        times[n] = t_build + t_dxf
        print(f"{n:>6} notches: load+rules {t_build:6.3f} s   design DXF {t_dxf:6.3f} s")
    print(f"scaling 10k/1k = {times[10000] / times[1000]:.1f} (linear = 10)")

    cmd = [sys.executable, "-m", "camtube", "dxf", str(ROOT / "patterns" / "tube1.yaml"), "-o", "/tmp/camtube-bench.dxf", "-q"]
    t_cli = min(_timed(cmd) for _ in range(3))
    print(f"`camtube dxf` on a preset (whole process): {t_cli:.3f} s   target < 1 s   ratio {t_cli / 1.0:.2f}")


def _timed(cmd) -> float:
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, capture_output=True)
    return time.perf_counter() - t0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--only", help="run one stage: design, or the <stage> of a scripts/bench_<stage>.py")
    args = ap.parse_args()
    if args.only in (None, "design"):
        bench_design()
    for script in sorted((ROOT / "scripts").glob("bench_*.py")):
        stage = script.stem.removeprefix("bench_")
        if args.only in (None, stage):
            print(f"\n== {stage} ({script.name}) ==", flush=True)
            subprocess.run([sys.executable, str(script)], check=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
