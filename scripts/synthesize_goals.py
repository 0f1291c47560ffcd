"""Solve goal files and check every written pattern three ways; print a Markdown table.

    python scripts/synthesize_goals.py                       # the goals in examples/goals/
    python scripts/synthesize_goals.py --heldout 20 --seed 2611   # a fresh batch of random goals
    python scripts/synthesize_goals.py --fresh 6 --seed 2222     # random goals of forms unlike examples/goals

Per goal: the solve time; the forward model's bend at the design stroke and the largest relative
error of a notch's share; the independent re-simulation from the planned job's as-cut geometry
(:mod:`camtube.synthesis.check`): its bend (error against the target), strain and force against
the limits; and whether ``build`` (toolpath + CAD model + as-cut simulation) verifies the job.
For a 3-D goal: how far the forward model's centre line is from the goal's, and the tip direction of the
independent re-simulation's notch angles (composed with scipy rotations) against the goal's.
An infeasible goal shows its one-line message. The pattern is validated by the pattern loader
from the YAML text exactly as ``camtube synthesize`` writes it.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import numpy as np  # noqa: E402

from camtube.design.loader import load_text  # noqa: E402
from camtube.synthesis.check import resimulate  # noqa: E402
from camtube.synthesis.goal import build_goal, load_goal  # noqa: E402
from camtube.synthesis.report import check_design, pattern_yaml  # noqa: E402
from camtube.synthesis.solve import InfeasibleGoal, synthesize  # noqa: E402


def build_verifies(loaded) -> bool:
    from camtube.pipeline import BUILD, CadOptions, Request, outputs

    files, job, est, cad = outputs(loaded, Request(what=BUILD, cad=CadOptions(step=False, pictures=False)))
    return bool(cad.passed)


def random_goals(n: int, seed: int):
    """``n`` goals drawn from the three preset stocks, with 1 or 2 directions and the four distributions."""
    import numpy as np

    rng = np.random.default_rng(seed)
    stocks = [(0.75, 0.45, 1.0, 2.0, 3.0), (0.85, 0.55, 1.0, 2.5, 4.0), (1.25, 0.75, 2.0, 5.0, 8.0)]
    out = []
    for k in range(n):
        ro, ri, s_lo, s_hi, fmax = stocks[rng.integers(3)]
        dirs = 1 if rng.random() < 0.7 else 2
        bends = []
        for d in range(dirs):
            stroke = float(np.round(rng.uniform(s_lo, s_hi), 2))
            bend = float(np.round(rng.uniform(15.0, 70.0) * (1.0 if ro < 1 else 1.3), 1))
            bends.append({"angle_deg": [180, 0][d] if dirs == 2 else float(rng.choice([0, 90, 180, 270])),
                          "bend_deg": bend, "stroke_mm": stroke})
        dist = str(rng.choice(["uniform", "tip_first", "base_first"]))
        raw = {"tube": {"outer_radius": ro, "inner_radius": ri},
               "tendon": {"friction": float(np.round(rng.choice([0.0, 0.1, 0.2]), 2))},
               "goal": {"bends": bends, "distribution": dist, "tip_ratio": float(np.round(rng.uniform(1.5, 3), 2)),
                        "layout": str(rng.choice(["alternate", "sequential"]))},
               "limits": {"max_strain": float(np.round(rng.uniform(0.03, 0.05), 3)), "max_force_N": fmax,
                          "max_length": 30.0}}
        out.append((f"heldout-{seed}-{k:02d}", build_goal(raw, None, {}, name=f"heldout-{seed}-{k:02d}")))
    return out


def fresh_goals(n: int, seed: int):
    """``n`` goals of forms the examples do not have: stocks other than the presets (and tube 3), other tendons
    (steel, nitinol, aramid), three directions, 3-D centre lines, tip first. The stroke is drawn around the
    kinematic travel ``(r_i + r_o / 2) * bend`` so most are plausible; nothing is tuned to make them feasible."""
    import numpy as np

    rng = np.random.default_rng(seed)
    stocks = [(1.0, 0.8), (0.6, 0.4), (1.5, 1.0), (1.25, 0.75)]
    tendons = [{}, {"radius": 0.05, "length": 120.0, "modulus_gpa": 200.0, "material": "steel"},
               {"radius": 0.04, "length": 90.0, "modulus_gpa": 60.0, "material": "nitinol"},
               {"radius": 0.06, "length": 80.0, "modulus_gpa": 70.0, "material": "aramid"}]
    forms = ["three_directions", "centerline", "tip_first", "centerline", "three_directions", "tip_first"]
    out = []
    for k in range(n):
        ro, ri = stocks[rng.integers(len(stocks))]
        td = dict(tendons[rng.integers(len(tendons))], friction=float(np.round(rng.choice([0.0, 0.1, 0.2]), 2)))
        form = forms[int(rng.integers(len(forms)))]
        arm = ri + ro / 2.0

        def stroke(bend: float) -> float:
            return float(np.round(arm * np.radians(bend) * rng.uniform(1.1, 1.6), 2))

        goal: dict = {}
        if form == "three_directions":
            bends = [float(np.round(rng.uniform(15.0, 45.0), 1)) for _ in range(3)]
            goal = {"bends": [{"angle_deg": a, "bend_deg": b, "stroke_mm": stroke(b)} for a, b in zip((0, 120, 240), bends)],
                    "layout": str(rng.choice(["alternate", "sequential"]))}
        elif form == "centerline":
            m = int(rng.integers(2, 4))
            dirs = rng.permutation([0, 60, 90, 150, 180, 240, 270, 330])[:m]
            goal = {"centerline": []}
            for a in dirs:
                b = float(np.round(rng.uniform(20.0, 50.0), 1))
                goal["centerline"].append({"length_mm": float(np.round(rng.uniform(4.0, 9.0) * ro / 0.75, 1)),
                                           "bend_deg": b, "towards_deg": float(a), "stroke_mm": stroke(b)})
        else:
            b = float(np.round(rng.uniform(30.0, 80.0), 1))
            goal = {"bends": [{"angle_deg": float(rng.choice([0, 90, 180, 270])), "bend_deg": b, "stroke_mm": stroke(b)}],
                    "distribution": "tip_first", "tip_ratio": float(np.round(rng.uniform(1.5, 4.0), 2))}
        raw = {"tube": {"outer_radius": ro, "inner_radius": ri}, "tendon": td, "goal": goal,
               "limits": {"max_strain": float(np.round(rng.uniform(0.03, 0.05), 3)),
                          "max_force_N": float(np.round(4.0 * (ro / 0.75) ** 3, 1)), "max_length": 40.0}}
        name = f"fresh-{seed}-{k:02d}-{form}"
        out.append((name, build_goal(raw, None, {}, name=name)))
    return out


def run(goals, build: bool) -> int:
    print("| goal | notches | solve s | target deg @ mm | forward deg | share err % | independent deg (err %) "
          "| strain / limit | force N / limit | build verifies |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    bad = 0
    paths = []
    for name, goal in goals:
        t0 = time.perf_counter()
        try:
            design = synthesize(goal)
        except InfeasibleGoal as exc:
            print(f"| {name} | infeasible | {time.perf_counter() - t0:.2f} | "
                  + "; ".join(f"{b.bend_deg:g} @ {b.stroke_mm:g}" for b in goal.bends)
                  + f" | - | - | - | - | - | {exc.limit}: nearest {exc.nearest} |")
            continue
        secs = time.perf_counter() - t0
        loaded = load_text(pattern_yaml(design), ROOT / "examples" / "goals" / f"{name}.pattern.yaml")
        p = loaded.pattern
        checks = check_design(design, p)
        res = resimulate(p, {b.angle_deg: b.stroke_mm for b in goal.bends})
        lim = goal.limits
        ok_build = build_verifies(loaded) if build else None
        if goal.centerline:
            from camtube.synthesis.centerline import follow

            from camtube.synthesis.centerline import target_points
            from camtube.synthesis.check import tip_direction

            f = follow(goal, p, design.mechanics)
            tgt = target_points(goal, p)
            want = (tgt[-1] - tgt[-2]) / np.linalg.norm(tgt[-1] - tgt[-2])
            ind = float(np.degrees(np.arccos(np.clip(tip_direction(p, res) @ want, -1.0, 1.0))))
            paths.append((name, f, ind))
            bad += not (f.max_deviation_mm <= 0.05 and f.tip_direction_error_deg <= 0.5 and ind <= 2.0)
        for i, (b, c, r) in enumerate(zip(goal.bends, checks, res)):
            err = 100.0 * (r.bend_deg - b.bend_deg) / b.bend_deg
            good = (abs(c.predicted_deg - b.bend_deg) <= 0.5 and c.share_error <= 0.02 and abs(err) <= 5.0
                    and r.max_strain <= lim.max_strain and r.force_N <= lim.max_force_N and secs <= 10.0
                    and ok_build is not False)
            bad += not good
            print(f"| {name if i == 0 else ''} | {len(p.notches) if i == 0 else ''} | {secs:.2f} | "
                  f"{b.bend_deg:g} @ {b.stroke_mm:g} ({b.angle_deg:g} deg) | {c.predicted_deg:.2f} | "
                  f"{100 * c.share_error:.2f} | {r.bend_deg:.2f} ({err:+.1f}) | {r.max_strain:.4f} / {lim.max_strain:g} | "
                  f"{r.force_N:.2f} / {lim.max_force_N:g} | {'-' if ok_build is None else ('yes' if ok_build else 'NO')}"
                  f"{'' if good else ' **FAIL**'} |")
    if paths:
        print("\n| 3-D goal | centre line mm | farthest from target um | tip error um | tip direction error deg "
              "| independent tip direction error deg |")
        print("|---|---|---|---|---|---|")
        for name, f, ind in paths:
            print(f"| {name} | {f.length_mm:.2f} | {1000 * f.max_deviation_mm:.0f} | {1000 * f.tip_error_mm:.0f} | "
                  f"{f.tip_direction_error_deg:.3f} | {ind:.3f} |")
    print(f"\n{bad} direction(s) or centre line(s) failing a check")
    return 1 if bad else 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("goals", nargs="*", help="goal files (default: examples/goals/*.yaml)")
    ap.add_argument("--heldout", type=int, default=0, metavar="N", help="draw N random goals instead")
    ap.add_argument("--fresh", type=int, default=0, metavar="N", help="draw N random goals of new forms instead")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--no-build", action="store_true", help="skip the build + verification")
    a = ap.parse_args()
    if a.fresh:
        goals = fresh_goals(a.fresh, a.seed)
    elif a.heldout:
        goals = random_goals(a.heldout, a.seed)
    else:
        files = [Path(g) for g in a.goals] or sorted((ROOT / "examples" / "goals").glob("*.yaml"))
        goals = [(f.stem, load_goal(f)) for f in files]
    return run(goals, not a.no_build)


if __name__ == "__main__":
    raise SystemExit(main())
