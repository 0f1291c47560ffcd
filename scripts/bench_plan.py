"""Benchmark of the plan stage: plan + safety check + LinuxCNC G-code for 1,000 and 10,000 notches.

    python scripts/bench_plan.py

Prints the time of each step (best of 3), the total for 10k notches (target < 3 s)
and the 10k/1k ratio (linear growth: ~10), then the presets' estimated-time /
lower-bound ratios for both orderings (target <= 1.10 with the default).
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from benchutil import best_of  # noqa: E402


def pattern_with(count: int):
    from camtube.design.loader import load_pattern

    # tube 1 geometry, `count` notches at 1 mm pitch on a long enough tube
    return load_pattern(ROOT / "patterns" / "tube1.yaml",
                        [f"notch.count={count}", f"tube.length={count * 1.0 + 3.0}"])


def run(count: int, repeat: int = 3) -> dict:
    from camtube.export.dialects import LINUXCNC
    from camtube.export.gcode import emit, machine_moves
    from camtube.plan.packed import no_gc
    from camtube.plan import plan_job
    from camtube.plan.safety import check_moves

    pattern = pattern_with(count)
    t_plan, job = best_of(lambda: plan_job(pattern), repeat)
    t_moves, mm = best_of(lambda: machine_moves(job, LINUXCNC), repeat)
    t_check, _ = best_of(lambda: check_moves(job, mm.unrolled()), repeat)

    def post():
        with no_gc():  # as gcode() does
            return emit(job, mm)

    t_emit, text = best_of(post, repeat)
    return {"count": count, "passes": len(job.passes), "moves": len(mm.neutral), "plan": t_plan,
            "moves_s": t_moves, "check": t_check, "emit": t_emit, "MB": len(text) / 1e6,
            "total": t_plan + t_moves + t_check + t_emit}


def main() -> int:
    from camtube.design.loader import load_pattern
    from camtube.plan import ORDERINGS, DEFAULT_ORDERING, estimate, plan_job

    print("== plan stage: plan + move list + safety check + LinuxCNC G-code ==")
    # small sizes are noisy on a shared machine: more repeats there (best of N)
    rows = [run(1000, 9), run(3000, 5), run(10000, 3)]
    for r in rows:
        print(f"{r['count']:>6} notches: {r['passes']:>7} passes, {r['moves']:>8} moves, plan {r['plan']:.3f} s, "
              f"moves {r['moves_s']:.3f} s, check {r['check']:.3f} s, G-code {r['emit']:.3f} s "
              f"({r['MB']:.1f} MB); total {r['total']:.3f} s = {1e3 * r['total'] / r['count']:.3f} ms/notch")
    rows = [rows[0], rows[-1]]
    ratio = rows[1]["total"] / rows[0]["total"]
    print(f"10k notches total {rows[1]['total']:.2f} s (target < 3 s): {'ok' if rows[1]['total'] < 3 else 'SLOW'}")
    print(f"10k / 1k time ratio {ratio:.2f} (linear = 10)")
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
