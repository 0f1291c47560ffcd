"""Write the example bench logs of docs/bench.md: a short recording of a tube-2 joint made by
:func:`camtube.model.sim.rawlogs.simulate_bench` (three cycles, two coils, dropouts, a DAQ gap).

    python examples/bench/make_examples.py
"""
from __future__ import annotations

from pathlib import Path

from camtube.design.loader import load_pattern
from camtube.model.data.csvfile import format_csv
from camtube.model.sim.rawlogs import BenchSetup, simulate_bench

HERE = Path(__file__).resolve().parent
SETUP = BenchSetup(seed=7, n_cycles=3, daq_rate_hz=200.0, motor_rate_hz=50.0, n_bursts=3, n_absent=2)


def main() -> None:
    logs = simulate_bench(load_pattern(HERE.parents[1] / "patterns" / "tube2.yaml"), SETUP)
    for name, text in (("aurora-export.csv", logs.tracker_csv), ("daq.csv", logs.daq_csv),
                       ("motor.csv", logs.motor_csv), ("bench.yaml", logs.bench_map_yaml),
                       ("truth.csv", format_csv(logs.truth))):
        (HERE / name).write_text(text)


if __name__ == "__main__":
    main()
