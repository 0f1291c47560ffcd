"""Example: the planner used from Python, sweeping the notch count of tube 1.

    python scripts/sweep_notch_count.py [--ordering sequential]

For each notch count, plan the job and print passes, total cut length, the
time estimate, its lower bound and their ratio.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from camtube.design.loader import load_pattern  # noqa: E402
from camtube.plan import DEFAULT_ORDERING, ORDERINGS, estimate, plan_job  # noqa: E402


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ordering", choices=ORDERINGS, default=DEFAULT_ORDERING)
    ap.add_argument("--counts", type=int, nargs="+", default=[2, 5, 10, 15, 20, 30])
    args = ap.parse_args(argv)
    print(f"{'notches':>7} {'passes':>7} {'cut mm':>9} {'time s':>8} {'bound s':>8} {'ratio':>7}")
    for n in args.counts:
        pattern = load_pattern(ROOT / "patterns" / "tube1.yaml", [f"notch.count={n}", f"tube.length={n + 4}"])
        e = estimate(plan_job(pattern, ordering=args.ordering))
        print(f"{n:>7} {e.passes:>7} {e.cut_length_mm:>9.1f} {e.total_s:>8.1f} {e.lower_bound_s:>8.1f} {e.ratio:>7.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
