"""Figures for docs/design.md: the tip-first example goal's pattern bent at three strokes; the 3-D goal's centre line.

    python scripts/make_design_figure.py     # writes docs/img/design-tip-first.png and docs/img/design-3d-hook.png
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main() -> int:
    from camtube.design.loader import load_text
    from camtube.io import write_atomic
    from camtube.joint.plot import bend_png
    from camtube.synthesis.goal import load_goal
    from camtube.synthesis.report import pattern_yaml
    from camtube.synthesis.solve import synthesize

    goal = load_goal(ROOT / "examples" / "goals" / "04-tube1-tip-first.yaml")
    design = synthesize(goal)
    p = load_text(pattern_yaml(design), ROOT / "examples" / "goals" / "tip-first.yaml").pattern
    png = bend_png(p, (0.5, 1.0, 1.5), 180.0, design.mechanics,
                   title="04-tube1-tip-first: 60 deg at 1.5 mm, tip notch bending 3x the base notch")
    print(f"wrote {write_atomic(ROOT / 'docs' / 'img' / 'design-tip-first.png', png)}")

    from camtube.joint.plot import centerline_png
    from camtube.synthesis.centerline import target_points

    goal = load_goal(ROOT / "examples" / "goals" / "13-tube1-3d-hook.yaml")
    design = synthesize(goal)
    p = load_text(pattern_yaml(design), ROOT / "examples" / "goals" / "hook.yaml").pattern
    full = {b.angle_deg: b.stroke_mm for b in goal.bends}
    png = centerline_png(p, [{a: f * s for a, s in full.items()} for f in (1 / 3, 2 / 3, 1.0)], design.mechanics,
                         target_points(goal, p),
                         title="13-tube1-3d-hook: 45 deg towards 180 deg, then 45 deg towards 90 deg\n"
                               "(both tendons at 1/3, 2/3 and all of 1.2 mm)")
    print(f"wrote {write_atomic(ROOT / 'docs' / 'img' / 'design-3d-hook.png', png)}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
