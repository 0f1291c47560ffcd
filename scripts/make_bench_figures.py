"""Figures for docs/bench.md: the ingest report of the example bench logs in examples/bench/.

    python scripts/make_bench_figures.py    # writes docs/img/bench-{alignment,angle,dropouts}.png
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main() -> int:
    from camtube.io import write_atomic
    from camtube.model.ingest.merge import ingest_files
    from camtube.model.ingest.report import alignment_png, angle_png, dropouts_png
    from camtube.model.ingest.series import load_bench_map

    ex = ROOT / "examples" / "bench"
    ing = ingest_files(ex / "aurora-export.csv", ex / "daq.csv", ex / "motor.csv",
                       load_bench_map(ex / "bench.yaml"), "tube2-s1")
    for name, png in (("alignment", alignment_png(ing)), ("angle", angle_png(ing)), ("dropouts", dropouts_png(ing))):
        print(f"wrote {write_atomic(ROOT / 'docs' / 'img' / f'bench-{name}.png', png)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
