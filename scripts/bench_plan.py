"""Benchmark of the plan stage: what `camtube toolpath` costs, in time and peak memory, at 10^4-10^5 notches.

    python scripts/bench_plan.py              # 1k/3k/10k in process, then the CLI at 10k and 100k notches
    python scripts/bench_plan.py --quick      # the CLI at 10k notches only

1. In process (best of N): plan, then the LinuxCNC G-code through ``iter_gcode``
   (build, check, format chunk by chunk) into /dev/null; ms/notch and the 10k/1k ratio.
2. What users run: ``python -m camtube toolpath tube1.yaml --set notch.count=N -o DIR -q``
   in a subprocess (every output written), against "its G-code alone": a subprocess that
   loads and plans the same pattern and writes only the G-code files the command writes
   (``NAME.ngc`` and ``NAME.nc``) with the same functions the CLI calls; the ratio to the
   ``.ngc`` alone is printed too. Peak memory is the child's peak resident set size
   (``resource.getrusage(RUSAGE_CHILDREN).ru_maxrss`` of a runner process that waits for
   exactly one child), which counts NumPy's buffers too. Targets: at 10k notches the CLI
   within 2x its G-code alone and under 400 MB; at 100k under 1 GB.
3. The presets' estimated-time / lower-bound ratios for both orderings.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from benchutil import best_of  # noqa: E402

PATTERN = ROOT / "patterns" / "tube1.yaml"

# runs one command as its only child; prints its wall time (s) and peak RSS (kB) as JSON
RUNNER = """
import json, resource, subprocess, sys, time
t0 = time.perf_counter()
r = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL)
dt = time.perf_counter() - t0
print(json.dumps({"s": dt, "kb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss, "rc": r.returncode}))
"""

# its G-code alone, through the functions the CLI calls: argv = pattern, outdir, dialects (a,b), overrides...
GCODE_ONLY = """
import sys
from camtube.design.loader import load_pattern
from camtube.export.dialects import DIALECTS
from camtube.export.gcode import iter_gcode
from camtube.plan import plan_job
from camtube.io import write_set
job = plan_job(load_pattern(sys.argv[1], sys.argv[4:]))
ds = [DIALECTS[n] for n in sys.argv[3].split(",")]
write_set(sys.argv[2], {job.name + d.suffix: iter_gcode(job, d) for d in ds})
"""


def overrides(count: int) -> list[str]:
    # tube 1 geometry, `count` notches at 1 mm pitch on a long enough tube
    return [f"notch.count={count}", f"tube.length={count * 1.0 + 100.0}"]


def measure(cmd: list[str], repeat: int = 1) -> dict:
    """Best wall time (s) and peak RSS (MB) of ``cmd``, each run the only child of a fresh runner."""
    runs = [_measure(cmd) for _ in range(repeat)]
    return {"s": min(r["s"] for r in runs), "MB": max(r["MB"] for r in runs)}


def _measure(cmd: list[str]) -> dict:
    env_cmd = [sys.executable, "-c", RUNNER] + cmd
    out = subprocess.run(env_cmd, check=True, capture_output=True, text=True, cwd=ROOT,
                         env=_env()).stdout.strip().splitlines()[-1]
    r = json.loads(out)
    if r["rc"] != 0:
        raise SystemExit(f"command failed ({r['rc']}): {' '.join(cmd)}")
    return {"s": r["s"], "MB": r["kb"] / 1024.0}


def _env() -> dict:
    import os

    env = dict(os.environ)
    env["PYTHONPATH"] = str(ROOT) + (os.pathsep + env["PYTHONPATH"] if env.get("PYTHONPATH") else "")
    return env


def cli_vs_gcode(count: int) -> dict:
    """The CLI and its G-code alone; best of 3 at 10k notches (a shared machine is noisy), once above."""
    from camtube.export.dialects import DIALECTS

    n = 3 if count <= 10000 else 1
    measure_n = lambda cmd: measure(cmd, n)  # noqa: E731

    with tempfile.TemporaryDirectory(prefix="camtube-bench-") as tmp:
        sets = [a for o in overrides(count) for a in ("--set", o)]
        c = measure_n([sys.executable, "-m", "camtube", "toolpath", str(PATTERN), *sets, "-o", f"{tmp}/c", "-q"])
        sizes = {p.name: p.stat().st_size for p in Path(tmp, "c").iterdir()}
        g_all = measure_n([sys.executable, "-c", GCODE_ONLY, str(PATTERN), f"{tmp}/a", ",".join(DIALECTS)]
                          + overrides(count))
        g_one = measure_n([sys.executable, "-c", GCODE_ONLY, str(PATTERN), f"{tmp}/l", "linuxcnc"]
                          + overrides(count))
    return {"count": count, "gcode": g_all, "linuxcnc": g_one, "cli": c, "sizes": sizes}


def in_process(count: int, repeat: int) -> dict:
    from camtube.design.loader import load_pattern
    from camtube.export.dialects import LINUXCNC
    from camtube.export.gcode import iter_gcode
    from camtube.plan import plan_job

    pattern = load_pattern(PATTERN, overrides(count))
    t_plan, job = best_of(lambda: plan_job(pattern), repeat)

    def post():
        n = 0
        for chunk in iter_gcode(plan_job(pattern), LINUXCNC):  # a fresh job: nothing cached
            n += len(chunk)
        return n

    t_all, size = best_of(post, repeat)
    return {"count": count, "passes": len(job.passes), "plan": t_plan, "gcode": t_all - t_plan, "MB": size / 1e6,
            "total": t_all}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="the CLI at 10k notches only (skip 100k, ~2 min)")
    args = ap.parse_args(argv)
    from camtube.design.loader import load_pattern
    from camtube.plan import DEFAULT_ORDERING, ORDERINGS, estimate, plan_job

    print("== in process: plan + LinuxCNC G-code (iter_gcode: build, check, format per chunk), best of N ==")
    rows = [in_process(1000, 7), in_process(3000, 3), in_process(10000, 3)]
    for r in rows:
        print(f"{r['count']:>6} notches: {r['passes']:>7} passes, plan {r['plan']:.3f} s, G-code {r['gcode']:.3f} s "
              f"({r['MB']:.1f} MB); total {r['total']:.3f} s = {1e3 * r['total'] / r['count']:.3f} ms/notch")
    print(f"10k / 1k time ratio {rows[-1]['total'] / rows[0]['total']:.2f} (linear = 10)")

    print("== what users run: `camtube toolpath` (all outputs written) vs its G-code alone, subprocesses ==")
    targets = {10000: 400.0, 100000: 1024.0}
    for count in (10000,) if args.quick else (10000, 100000):
        r = cli_vs_gcode(count)
        g, one, c = r["gcode"], r["linuxcnc"], r["cli"]
        ratio, ratio_one = c["s"] / g["s"], c["s"] / one["s"]
        mb = targets[count]
        total_mb = sum(r["sizes"].values()) / 1e6
        print(f"{count:>6} notches: camtube toolpath {c['s']:.1f} s, peak {c['MB']:.0f} MB, {total_mb:.0f} MB written "
              f"(job file {r['sizes'].get('tube1.job.json', 0) / 1e6:.1f} MB)")
        print(f"{'':>15}its G-code alone (.ngc + .nc) {g['s']:.1f} s, peak {g['MB']:.0f} MB; "
              f"the .ngc alone {one['s']:.1f} s, peak {one['MB']:.0f} MB")
        if count == 10000:
            print(f"{'':>15}time ratio to its G-code {ratio:.2f} (target < 2): {'ok' if ratio < 2 else 'SLOW'}; "
                  f"to the .ngc alone {ratio_one:.2f}")
        print(f"{'':>15}peak {c['MB']:.0f} / {mb:.0f} MB = {c['MB'] / mb:.2f} of the target: "
              f"{'ok' if c['MB'] < mb else 'OVER'}")

    print("== estimated time / lower bound (target <= 1.10 with the default ordering) ==")
    for name in ("tube1", "tube2", "tube3", "tube1-bidirectional"):
        p = load_pattern(ROOT / "patterns" / f"{name}.yaml")
        parts = []
        for o in ORDERINGS:
            e = estimate(plan_job(p, ordering=o))
            mark = "*" if o == DEFAULT_ORDERING else " "
            parts.append(f"{o}{mark} {e.ratio:.4f} ({e.total_s:.1f} / {e.lower_bound_s:.1f} s)")
        print(f"{name:<20} {len(plan_job(p).passes):>4} passes  " + "   ".join(parts))
    print("(* = default ordering)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
