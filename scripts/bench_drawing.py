"""Time the drawing reader on large drawings: a design DXF of N bidirectional notches, and N filleted notches.

    PYTHONPATH=. python scripts/bench_drawing.py [N]      # default 1000 and 300
"""
from __future__ import annotations

import math
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from camtube.design.drawing import load_drawing  # noqa: E402
from camtube.design.loader import build  # noqa: E402
from camtube.design.source import DrawingOptions  # noqa: E402
from camtube.export.dxf import design_dxf  # noqa: E402
from examples.dxf.make_examples import Sheet, bulge_rounded_rect, draw_outline  # noqa: E402


def best_of(fn, repeat: int = 3) -> float:
    out = math.inf
    for _ in range(repeat):
        t = time.perf_counter()
        fn()
        out = min(out, time.perf_counter() - t)
    return out


def main() -> int:
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 1000
    with tempfile.TemporaryDirectory() as tmp:
        raw = {"tube": {"outer_radius": 1.0, "inner_radius": 0.7, "length": n + 2.0},
               "notch": {"layout": "bidirectional", "count": n, "width": 0.5, "spacing": 0.5, "arc": 3.0,
                         "first_offset": 1.0, "angle_deg": 0.0}}
        path = Path(tmp) / "rect.dxf"
        path.write_text(design_dxf(build(raw).pattern))
        t = best_of(lambda: load_drawing(path, [], DrawingOptions()))
        print(f"{n} rectangular notches (half split at the seam): {t:.2f} s")
        m = max(n * 3 // 10, 1)
        s = Sheet()
        draw_outline(s, length=m + 2.0)
        for i in range(m):
            y0 = 0.3 if i % 2 else math.pi + 0.3
            bulge_rounded_rect(s, 1.0 + i, y0, 1.5 + i, y0 + 2.5, 0.1, "NOTCHES")
        path = Path(tmp) / "fillet.dxf"
        s.doc.saveas(path)
        t = best_of(lambda: load_drawing(path, [], DrawingOptions()))
        print(f"{m} filleted notches drawn with bulges: {t:.2f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
