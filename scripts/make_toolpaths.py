"""Regenerate ``toolpaths/`` (the presets' toolpath DXF, G-code per dialect, job file) and the plan figures.

    python scripts/make_toolpaths.py            # write toolpaths/ and docs/img/plan-*.svg
    python scripts/make_toolpaths.py --check    # exit 1 if toolpaths/ differs from what the code makes

Same as ``camtube toolpath patterns/NAME.yaml -o toolpaths`` for each preset
(default ordering, every dialect). ``tests/plan/test_golden.py`` checks the
committed files are byte-identical to what the current code generates.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

PRESETS = ("tube1", "tube2", "tube3", "tube1-bidirectional")
OUT = ROOT / "toolpaths"


def preset_texts(name: str) -> dict[str, str]:
    from camtube.design.loader import load_pattern
    from camtube.plan import plan_job
    from camtube.export.outputs import toolpath_texts

    return toolpath_texts(plan_job(load_pattern(ROOT / "patterns" / f"{name}.yaml")))


def offsets_figure(path: Path) -> None:
    """The drill-offset / kerf convention on one notch corner (offsets exaggerated)."""
    import matplotlib

    matplotlib.use("Agg")
    matplotlib.rcParams["svg.hashsalt"] = "camtube"
    import matplotlib.pyplot as plt
    from matplotlib.patches import Polygon as Patch

    from camtube.design.contour import rectangle
    from camtube.plan.planner import offset_contour

    design = rectangle(0.0, 0.0, 0.5, 0.6, "notch")
    drill, kerf = 0.04, 0.05
    fig, axes = plt.subplots(1, 2, figsize=(9, 5.8))
    for ax, k, title in ((axes[0], 0.0, "kerf = 0 (the paper): cut 0 on the design line"),
                         (axes[1], kerf, "kerf compensation: cut 0 moved kerf/2 inward")):
        ax.add_patch(Patch([(-0.3, -0.3), (0.8, -0.3), (0.8, 0.9), (-0.3, 0.9)], closed=True, color="#d9c38c",
                           label="tube wall (kept)"))
        ax.add_patch(Patch(design.points, closed=True, color="white", label="cut region (removed)"))
        # kerf of cut 0: the band of width `kerf` centred on its path
        x0, y0, x1, y1 = design.bounds
        g = kerf / 2 - k / 2  # how far the band reaches outside the design line
        ax.add_patch(Patch(rectangle(x0 - g, y0 - g, x1 + g, y1 + g).points, closed=True, color="#f4a6a6",
                           label=f"kerf of cut 0 ({kerf} mm wide)"))
        g = -kerf / 2 - k / 2
        ax.add_patch(Patch(rectangle(x0 - g, y0 - g, x1 + g, y1 + g).points, closed=True, color="white"))
        for d in range(4):
            xy = offset_contour(design, k / 2 + d * drill).xy
            xs, ys = list(xy[:, 0]) + [xy[0, 0]], list(xy[:, 1]) + [xy[0, 1]]
            ax.plot(xs, ys, lw=1.2, label=f"cut {d}: offset {k / 2 + d * drill:.3f} mm")
        ax.plot(*zip(*(list(design.points) + [design.points[0]])), "k--", lw=1.0, label="design line")
        ax.set_xlim(-0.15, 0.3)
        ax.set_ylim(-0.15, 0.3)
        ax.set_aspect("equal")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm, outer surface)")
    for ax in axes:
        ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, fontsize=7, frameon=False)
    fig.suptitle("Drill offsets step into the removed material (offsets drawn x8: 0.04 mm for 0.005 mm)",
                 fontsize=10)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, format="svg", metadata={"Date": None})
    plt.close(fig)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--check", action="store_true", help="compare with toolpaths/ instead of writing")
    args = ap.parse_args(argv)
    from camtube.io import write_atomic

    bad = 0
    for name in PRESETS:
        for fname, text in preset_texts(name).items():
            path = OUT / fname
            if args.check:
                same = path.exists() and path.read_bytes() == text.encode("utf-8")
                bad += not same
                print(f"{'ok     ' if same else 'DIFFERS'} {path.relative_to(ROOT)}")
            else:
                write_atomic(path, text)
                print(f"wrote {path.relative_to(ROOT)}")
    if not args.check:
        fig = ROOT / "docs" / "img" / "plan-offsets.svg"
        offsets_figure(fig)
        print(f"wrote {fig.relative_to(ROOT)}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
