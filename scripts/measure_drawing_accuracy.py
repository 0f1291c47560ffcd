"""Worst import error of the accepted example drawings against make_examples' truth (area, centroid, angle).

    PYTHONPATH=. python scripts/measure_drawing_accuracy.py
"""
from __future__ import annotations

import math
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from camtube.design.contour import cut_contour  # noqa: E402
from camtube.design.drawing import load_drawing  # noqa: E402
from camtube.design.source import DrawingOptions  # noqa: E402


def main() -> int:
    from shapely.geometry import LineString, Polygon

    examples = ROOT / "examples" / "dxf"
    expected = yaml.safe_load((examples / "expected.yaml").read_text())
    ro = expected["outer_radius_mm"]
    circ = 2 * math.pi * ro

    def dy(a: float, b: float) -> float:
        d = (a - b) % circ
        return min(d, circ - d)

    rows = []
    for name, case in expected["cases"].items():
        if "cuts" not in case:
            continue
        o = case["options"]
        opts = DrawingOptions(outer_radius_mm=o.get("outer_radius_mm"), units=o.get("units"),
                              layers=tuple(tuple(x) for x in o.get("layers", ())))
        got = []
        for cut in load_drawing(examples / case["file"], [], opts).pattern.cuts:
            con = cut_contour(cut, ro)
            g = LineString(con.points) if cut.kind == "slit" else Polygon(con.points)
            pt = g.interpolate(0.5, normalized=True) if cut.kind == "slit" else g.centroid
            got.append((cut, g, (pt.x, pt.y)))
        for w in case["cuts"]:
            wp = w.get("centroid_mm") or w["midpoint_mm"]
            cut, g, pt = min(got, key=lambda t: math.hypot(t[2][0] - wp[0], dy(t[2][1], wp[1])))
            ref = w.get("area_mm2") or w["length_mm"]
            val = g.length if cut.kind == "slit" else g.area
            d = (cut.angle_deg - w["angle_deg"]) % 360.0
            rows.append((abs(val - ref) / ref, math.hypot(pt[0] - wp[0], dy(pt[1], wp[1])), min(d, 360 - d),
                         f"{name}: {cut.kind} at x = {cut.x_mm:.3f} mm"))
    worst = max(rows)
    print(f"{len(rows)} cuts in {len(expected['cases'])} cases")
    print(f"worst relative area (slit: length) error {worst[0]:.2e} ({worst[3]})")
    print(f"worst centroid error {max(r[1] for r in rows):.2e} mm; worst angle error {max(r[2] for r in rows):.2e} deg")
    return 0


if __name__ == "__main__":
    sys.exit(main())
