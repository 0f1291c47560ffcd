"""Figure for docs/design.md: the tip-first example goal's pattern bent at three strokes.

    python scripts/make_design_figure.py     # writes docs/img/design-tip-first.png
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
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
