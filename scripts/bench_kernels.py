"""Time the history laws that carry a state from row to row (issue 19, speed): the lag on jittered stamps and the
carriage its rail holds, on one 30,000-row sample, microseconds per call (the lag's steps kept, as in a fit); and the
relaxing backbone's law compiled against its NumPy passes.

Run: ``python scripts/bench_kernels.py`` (run it on an older checkout to compare: ffe5fab, before the laws were
compiled, gave 243 us and 2,245 us on this machine; the compiled laws 64 us and 124 us).
"""
from __future__ import annotations

import numpy as np
from benchutil import best_of

from camtube.model.data.dataset import Dataset
from camtube.model.effects.history import carriage_hold, first_order_lag


def per_call_us(fn, calls: int = 300) -> float:
    """Microseconds per call of ``fn()``: the best of three runs of ``calls`` calls, after one to warm up."""
    def run() -> None:
        for _ in range(calls):
            fn()

    fn()
    return best_of(run)[0] / calls * 1e6


def main() -> None:
    rng = np.random.default_rng(0)
    n = 30_000
    t = np.cumsum(0.04 + rng.normal(0.0, 0.002, n))    # 25 Hz with a logger's jitter
    t -= t[0]
    stroke = np.clip(1.2 * np.sin(2 * np.pi * t / 12.0), 0.0, None)
    force = 1.5 * stroke + rng.normal(0.0, 0.02, n) + 0.1 * (stroke == 0)
    data = Dataset(np.array(["S1"] * n, dtype=object), np.ones(n, int), t, stroke, force, np.zeros(n))
    u = np.cumsum(rng.normal(size=n))
    lag = per_call_us(lambda: first_order_lag(data, u, 1.0))
    hold = per_call_us(lambda: carriage_hold(data, stroke, 0.15, 0.2))
    print(f"one sample of {n:,} rows: first_order_lag {lag:.0f} us, carriage_hold {hold:.0f} us per call")
    # the relaxing backbone (two arms): its compiled law against the same law as NumPy passes (the same numbers)
    from unittest import mock

    from camtube.model.effects import builtin

    ctx = type("Ctx", (), {"data": data})()
    theta = np.radians(30.0) * stroke / stroke.max()
    arms = ((0.25, 1.0), (0.15, 30.0))
    fast = per_call_us(lambda: builtin._relaxed(ctx, theta, arms))
    with mock.patch.object(builtin, "relaxed_compiled", lambda *a: None):
        slow = per_call_us(lambda: builtin._relaxed(ctx, theta, arms))
    print(f"relaxation2's law: {fast:.0f} us compiled, {slow:.0f} us as NumPy passes ({slow / fast:.1f}x)")


if __name__ == "__main__":
    main()
