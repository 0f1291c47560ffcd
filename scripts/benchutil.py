"""Shared helpers of the benchmark scripts (``scripts/bench*.py``)."""
from __future__ import annotations

import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))


def best_of(fn, repeat: int = 3) -> tuple[float, object]:
    """``(best wall time in s, last result)`` of ``repeat`` calls of ``fn()``."""
    best, out = float("inf"), None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t0)
    return best, out
