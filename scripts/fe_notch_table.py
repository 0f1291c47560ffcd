"""FE comparison table for docs/design.md: per-notch bending stiffness and closure angle, model vs FE.

    python scripts/fe_notch_table.py            # the three presets and the tip-first example design
    python scripts/fe_notch_table.py --heldout  # also six isolated notches of new geometry (the fe_fit check)
    python scripts/fe_notch_table.py --fine     # also one refined mesh and rows of 3 and 7 (convergence)
    python scripts/fe_notch_table.py --alternating  # also a row of notches on alternate sides (example 07's kind)

Every notch is modelled with :func:`camtube.joint.fe.notch_fe` (scikit-fem, quadratic tetrahedra, pure
moment) twice: alone between two leads of plain tube (``FE K alone``), and in its row (``FE K in its row``:
the notch's own rotation between the middle sections of the webs on either side): a preset's notch as the
middle and as the end notch of a row of ``ROW`` equal notches at the pattern's own web, the tip-first design's
tip, middle and base notch in the design's whole row as cut (drawn + the 20 um overcut it was designed for, at
its 0.28 mm web as cut). The model's stiffness is shown three times: the beam ``E I / h`` (the paper's),
``hinge="fe_fit"`` (h plus a lone notch's root length, :data:`camtube.joint.forward.HINGE_FE_POLY`) and
``hinge="fe_row"`` (the default: the root shortened by the webs to the neighbours, :data:`HINGE_ROW`, fitted to
the row runs of ``scripts/fe_row_runs.py``, none of them a notch of this table). Errors are against the row.
"""
from __future__ import annotations

import argparse
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

#: Notches in the row model (per-notch figures converge within ~2 % by 5; see docs/design.md).
ROW = 5

#: Isolated notches of geometry used nowhere else: (r_o, r_i, phi rad, h) mm.
HELDOUT = ((1.0, 0.7, 2.0, 0.4), (0.6, 0.45, 3.5, 0.25), (1.5, 0.9, 2.5, 0.6), (0.75, 0.45, 1.6, 1.0),
           (0.85, 0.55, 4.0, 0.35), (1.25, 1.0, 2.2, 0.5))


def cases():
    """``(label, r_o, r_i, s, widths, web, k)`` of the table's rows: the notch ``k`` of a row of notches of
    ``widths`` (base to tip, mm) at ``web`` (mm, edge to edge): a preset's middle notch and end notch in a row of
    ``ROW``; the tip-first design's tip, middle and base notch in the design's own row (as cut; ``s`` is then each
    notch's arc)."""
    from camtube.design.loader import load_pattern, load_text
    from camtube.synthesis.goal import load_goal
    from camtube.synthesis.report import pattern_yaml
    from camtube.synthesis.solve import synthesize

    for name in ("tube1", "tube2", "tube3"):
        p = load_pattern(name)
        n, m = p.notches[0], p.notches[1]
        web = abs(m.x_mm - n.x_mm) - n.width_mm
        row = (n.width_mm,) * ROW
        yield name, p.tube.outer_radius_mm, p.tube.inner_radius_mm, n.arc_mm, row, web, ROW // 2
        yield f"{name}, end of row", p.tube.outer_radius_mm, p.tube.inner_radius_mm, n.arc_mm, row, web, ROW - 1
    goal = load_goal(ROOT / "examples" / "goals" / "04-tube1-tip-first.yaml")
    d = synthesize(goal)
    p = load_text(pattern_yaml(d), ROOT / "examples" / "goals" / "x.yaml").pattern
    k = d.mechanics.kerf_mm
    ns = sorted(p.notches, key=lambda n: -n.x_mm)  # base to tip
    row = tuple(n.width_mm + k for n in ns)
    arcs = tuple(n.arc_mm + k for n in ns)
    for label, i in (("base", 0), ("middle", len(ns) // 2), ("tip", len(ns) - 1)):
        yield f"tip-first ({d.mechanics.hinge}), {label} notch", 0.75, 0.45, arcs, row, goal.web_mm - k, i


def model_stiffness(ro: float, ri: float, s: float, h: float, hinge: str, webs=(math.inf, math.inf),
                    modulus_gpa: float = 2.5) -> float:
    from camtube.design.geometry import joint_geometry
    from camtube.joint.forward import hinge_extra_mm

    g = joint_geometry(ro, ri, s, h)
    return modulus_gpa * 1e3 * g.second_moment_mm4 / (h + hinge_extra_mm(ro, g.phi_rad, hinge, inner_radius_mm=ri,
                                                                            webs_mm=webs))


def pct(model: float, fe: float) -> str:
    return f"{100 * (model / fe - 1):+.0f} %"


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--fine", action="store_true")
    ap.add_argument("--heldout", action="store_true")
    ap.add_argument("--alternating", action="store_true")
    a = ap.parse_args()
    from camtube.joint.fe import notch_fe

    print("| notch | r_o / r_i mm | s mm | h mm | webs mm | FE K alone | FE K in its row | beam E I/h (err) "
          "| fe_fit (err) | fe_row (err) | FE closure deg (row) | model closure deg (err) | seconds |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    worst = {"beam": 0.0, "fe_fit": 0.0, "fe_row": 0.0, "closure": 0.0}
    rows = {}
    for name, ro, ri, s, widths, web, i in cases():
        t0 = time.perf_counter()
        h = widths[i]
        arcs, s = (s, s[i]) if isinstance(s, tuple) else ((s,) * len(widths), s)
        one = notch_fe(ro, ri, s, h)
        key = (ro, ri, arcs, widths, web)
        if key not in rows:
            rows[key] = notch_fe(ro, ri, arcs, widths, web_mm=web)
        row = rows[key]
        webs = (web if i > 0 else math.inf, web if i < len(widths) - 1 else math.inf)
        k_row = row.per_notch_nmm_per_rad[i]
        k = {hg: model_stiffness(ro, ri, s, h, hg, webs) for hg in ("beam", "fe_fit", "fe_row")}
        for hg in k:
            worst[hg] = max(worst[hg], abs(k[hg] / k_row - 1))
        from camtube.design.geometry import joint_geometry

        c_model = math.degrees(joint_geometry(ro, ri, s, h).closure_angle_rad)
        c_fe = row.per_notch_closure_deg[i]
        worst["closure"] = max(worst["closure"], abs(c_model / c_fe - 1))
        w_txt = " / ".join("-" if math.isinf(w) else f"{w:.2f}" for w in webs)
        print(f"| {name} | {ro:g} / {ri:g} | {s:.3f} | {h:.3f} | {w_txt} | {one.stiffness_nmm_per_rad:.2f} | "
              f"{k_row:.2f} | {k['beam']:.2f} ({pct(k['beam'], k_row)}) | {k['fe_fit']:.2f} ({pct(k['fe_fit'], k_row)}) | "
              f"{k['fe_row']:.2f} ({100 * (k['fe_row'] / k_row - 1):+.1f} %) | {c_fe:.2f} | {c_model:.2f} "
              f"({100 * (c_model / c_fe - 1):+.1f} %) | {time.perf_counter() - t0:.0f} |", flush=True)
    print(f"\nlargest |error| against the notch in its row: beam {100 * worst['beam']:.0f} %, fe_fit "
          f"{100 * worst['fe_fit']:.0f} %, fe_row {100 * worst['fe_row']:.1f} %, closure {100 * worst['closure']:.1f} %")
    if a.heldout:
        print("\nheld-out isolated notches (geometry not used for HINGE_FE_POLY nor above):\n")
        print("| r_o / r_i mm | phi rad | s mm | h mm | FE K alone | beam (err) | fe_fit (err) | fe_row alone (err) "
              "| FE closure deg | model closure deg (err) |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        for ro, ri, phi, h in HELDOUT:
            s = ro * (2.0 * math.pi - phi)
            r = notch_fe(ro, ri, s, h)
            k_fit = model_stiffness(ro, ri, s, h, "fe_fit")
            k_row = model_stiffness(ro, ri, s, h, "fe_row")
            print(f"| {ro:g} / {ri:g} | {phi:.2f} | {s:.3f} | {h:.3f} | {r.stiffness_nmm_per_rad:.2f} | "
                  f"{r.model_stiffness_nmm_per_rad:.2f} ({pct(r.model_stiffness_nmm_per_rad, r.stiffness_nmm_per_rad)}) | "
                  f"{k_fit:.2f} ({100 * (k_fit / r.stiffness_nmm_per_rad - 1):+.1f} %) | "
                  f"{k_row:.2f} ({100 * (k_row / r.stiffness_nmm_per_rad - 1):+.1f} %) | {r.closure_deg:.2f} | "
                  f"{r.model_closure_deg:.2f} ({100 * r.closure_error:+.1f} %) |", flush=True)
    if a.alternating:
        # tube 1, phi 2.0 rad, h 0.45, web 0.28 mm as cut: about example 07's notches (two directions alternating)
        ro, ri, s, h, w = 0.75, 0.45, 3.21, 0.45, 0.28
        same = notch_fe(ro, ri, s, h, count=ROW, web_mm=w)
        alt = notch_fe(ro, ri, s, h, count=ROW, web_mm=w, angles_deg=[180 if k % 2 == 0 else 0 for k in range(ROW)])
        far = 2 * w + h  # to the next notch of the same direction, across the other direction's
        print(f"\nalternating sides (tube 1, s {s} mm, h {h} mm, web {w} mm): middle notch K {alt.middle_nmm_per_rad:.2f} "
              f"(each: {', '.join(f'{x:.2f}' for x in alt.per_notch_nmm_per_rad)}); all on one side "
              f"{same.middle_nmm_per_rad:.2f}; lone {notch_fe(ro, ri, s, h).stiffness_nmm_per_rad:.2f}; fe_row "
              f"{model_stiffness(ro, ri, s, h, 'fe_row', (far, far)):.2f} (webs to its own direction's notches, "
              f"{far:.2f} mm), {model_stiffness(ro, ri, s, h, 'fe_row', (w, w)):.2f} (to the nearest notch); beam "
              f"{model_stiffness(ro, ri, s, h, 'beam'):.2f}")
    if a.fine:
        c = notch_fe(0.75, 0.45, 2.83, 0.5, count=3)
        f = notch_fe(0.75, 0.45, 2.83, 0.5, count=3, n_r=3, n_backbone=28, n_cut=16, n_lead=10, n_notch=6, n_web=6)
        print(f"\nmesh: tube1 row of 3, middle notch K {c.middle_nmm_per_rad:.2f} ({c.dofs} dofs) -> "
              f"{f.middle_nmm_per_rad:.2f} ({f.dofs} dofs), end notch {c.per_notch_nmm_per_rad[-1]:.2f} -> "
              f"{f.per_notch_nmm_per_rad[-1]:.2f}, closure {c.closure_deg:.2f} -> {f.closure_deg:.2f} deg")
        for n in (3, 7):
            r = notch_fe(0.75, 0.45, 2.83, 0.5, count=n)
            print(f"row length: tube1, {n} notches: middle notch K {r.middle_nmm_per_rad:.2f}, end notch "
                  f"{r.per_notch_nmm_per_rad[-1]:.2f}, row mean {r.stiffness_nmm_per_rad:.2f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
