"""FE comparison table for docs/design.md: per-notch bending stiffness and closure angle, model vs FE.

    python scripts/fe_notch_table.py            # the three presets and the tip-first example design
    python scripts/fe_notch_table.py --fine     # also one refined mesh (convergence)

Every notch is modelled with :func:`camtube.joint.fe.notch_fe` (scikit-fem, quadratic tetrahedra, pure
moment). The model's stiffness is shown twice: the beam ``E I / h`` (the paper's, the default) and
``hinge="fe_fit"`` (h plus the root length of :data:`camtube.joint.forward.HINGE_FE_POLY`, fitted to
ten other FE runs, none of them a notch in this table). The tip-first design's notches are taken as cut
(drawn + the 20 um overcut it was designed for).
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def cases():
    from camtube.design.loader import load_pattern, load_text
    from camtube.synthesis.goal import load_goal
    from camtube.synthesis.report import pattern_yaml
    from camtube.synthesis.solve import synthesize

    for name in ("tube1", "tube2", "tube3"):
        p = load_pattern(name)
        n = p.notches[0]
        yield name, p.tube.outer_radius_mm, p.tube.inner_radius_mm, n.arc_mm, n.width_mm
    goal = load_goal(ROOT / "examples" / "goals" / "04-tube1-tip-first.yaml")
    d = synthesize(goal)
    p = load_text(pattern_yaml(d), ROOT / "examples" / "goals" / "x.yaml").pattern
    k = d.mechanics.kerf_mm
    ns = p.notches
    for label, n in (("tip", ns[0]), ("middle", ns[len(ns) // 2]), ("base", ns[-1])):
        yield f"tip-first, {label} notch", 0.75, 0.45, n.arc_mm + k, n.width_mm + k


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fine", action="store_true")
    a = ap.parse_args()
    from camtube.design.geometry import joint_geometry
    from camtube.joint.forward import hinge_extra_mm
    from camtube.joint.fe import notch_fe

    print("| notch | r_o / r_i mm | s mm | h mm | FE K N mm/rad | beam E I/h (err) | fe_fit (err) "
          "| FE closure deg | model closure deg (err) | dofs | s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    worst = {"beam": 0.0, "fe_fit": 0.0, "closure": 0.0}
    for name, ro, ri, s, h in cases():
        t0 = time.perf_counter()
        r = notch_fe(ro, ri, s, h)
        g = joint_geometry(ro, ri, s, h)
        k_fit = 2.5e3 * g.second_moment_mm4 / (h + hinge_extra_mm(ro, g.phi_rad, "fe_fit"))
        e_fit = k_fit / r.stiffness_nmm_per_rad - 1.0
        worst["beam"] = max(worst["beam"], abs(r.stiffness_error))
        worst["fe_fit"] = max(worst["fe_fit"], abs(e_fit))
        worst["closure"] = max(worst["closure"], abs(r.closure_error))
        print(f"| {name} | {ro:g} / {ri:g} | {s:.3f} | {h:.3f} | {r.stiffness_nmm_per_rad:.2f} | "
              f"{r.model_stiffness_nmm_per_rad:.2f} ({100 * r.stiffness_error:+.0f} %) | {k_fit:.2f} ({100 * e_fit:+.1f} %) | "
              f"{r.closure_deg:.2f} | {r.model_closure_deg:.2f} ({100 * r.closure_error:+.1f} %) | {r.dofs} | "
              f"{time.perf_counter() - t0:.0f} |", flush=True)
    print(f"\nlargest |error|: beam stiffness {100 * worst['beam']:.0f} %, fe_fit stiffness {100 * worst['fe_fit']:.1f} %, "
          f"closure {100 * worst['closure']:.1f} %")
    if a.fine:
        c = notch_fe(0.75, 0.45, 2.83, 0.5)
        f = notch_fe(0.75, 0.45, 2.83, 0.5, n_r=3, n_backbone=30, n_cut=16, n_lead=10, n_notch=6)
        print(f"mesh: tube1 notch K {c.stiffness_nmm_per_rad:.2f} ({c.dofs} dofs) -> {f.stiffness_nmm_per_rad:.2f} "
              f"({f.dofs} dofs), closure {c.closure_deg:.2f} -> {f.closure_deg:.2f} deg")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
