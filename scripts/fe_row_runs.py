"""Row FE runs for the ``fe_row`` hinge: rows of five equal notches, each notch's own stiffness, kept in JSON.

    python scripts/fe_row_runs.py train                 # the 20 training runs (seed 1) -> scripts/data/fe_row_train.json
    python scripts/fe_row_runs.py heldout --seed 7 -n 8 # a held-out batch (drawn after the model was settled)
    python scripts/fe_row_runs.py fit                   # fit HINGE_ROW's coefficients to the training file, print them

Each run is :func:`camtube.joint.fe.notch_fe` with ``count=5``: a row of five equal notches at the run's web,
between two leads of plain tube 2 r_o long (clamped base, pure moment on the far face). The geometry is a Latin
hypercube (scipy.stats.qmc) over the outer radius r_o 0.5-1.5 mm, the wall ratio r_i/r_o 0.5-0.8, the backbone
angle phi 1.2-4.3 rad (the notch's arc is ``s = r_o (2 pi - phi)``), the notch width h 0.2-1.0 mm and the web
(edge to edge) 0.2-1.5 mm. Kept per run: the inputs, every notch's own stiffness (N mm/rad, base to far end:
the middle one, index 2, is a notch inside a pattern; the last one has plain tube on its far side), the row's
mean, the middle notch's closure angle, the unknowns and the seconds. ``fit`` needs no FE: it reads the file.
None of the FE table's notches (the presets and the tip-first design) can be drawn: their values are fixed,
the draws are continuous.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

DATA = ROOT / "scripts" / "data"
#: (name, low, high) of each drawn input.
SPACE = (("outer_radius_mm", 0.5, 1.5), ("wall_ratio", 0.5, 0.8), ("phi_rad", 1.2, 4.3), ("width_mm", 0.2, 1.0),
         ("web_mm", 0.2, 1.5))
COUNT = 5


def draw(n: int, seed: int) -> list[dict]:
    from scipy.stats import qmc

    u = qmc.LatinHypercube(d=len(SPACE), seed=seed).random(n)
    out = []
    for row in u:
        v = {name: round(float(lo + (hi - lo) * x), 4) for (name, lo, hi), x in zip(SPACE, row)}
        v["inner_radius_mm"] = round(v["outer_radius_mm"] * v.pop("wall_ratio"), 4)
        v["arc_mm"] = round(v["outer_radius_mm"] * (2.0 * math.pi - v["phi_rad"]), 4)
        out.append(v)
    return out


def run(v: dict) -> dict:
    from camtube.joint.fe import notch_fe

    t0 = time.perf_counter()
    r = notch_fe(v["outer_radius_mm"], v["inner_radius_mm"], v["arc_mm"], v["width_mm"], count=COUNT,
                 web_mm=v["web_mm"])
    return dict(v, per_notch_nmm_per_rad=[round(float(k), 5) for k in r.per_notch_nmm_per_rad],
                row_mean_nmm_per_rad=round(r.stiffness_nmm_per_rad, 5), beam_nmm_per_rad=round(r.model_stiffness_nmm_per_rad, 5),
                closure_deg=round(r.closure_deg, 4), model_closure_deg=round(r.model_closure_deg, 4), dofs=r.dofs,
                seconds=round(time.perf_counter() - t0, 1))


def batch(name: str, n: int, seed: int) -> int:
    DATA.mkdir(parents=True, exist_ok=True)
    path = DATA / f"fe_row_{name}.json"
    runs = []
    for i, v in enumerate(draw(n, seed)):
        r = run(v)
        runs.append(r)
        print(f"{i:2d} r_o {r['outer_radius_mm']:.3f} r_i {r['inner_radius_mm']:.3f} phi {r['phi_rad']:.2f} "
              f"h {r['width_mm']:.3f} web {r['web_mm']:.3f}: middle {r['per_notch_nmm_per_rad'][2]:.3f}, "
              f"end {r['per_notch_nmm_per_rad'][-1]:.3f}, beam {r['beam_nmm_per_rad']:.3f} N mm/rad "
              f"({r['seconds']:.0f} s)", flush=True)
        path.write_text(json.dumps({"set": name, "seed": seed, "count": COUNT, "runs": runs}, indent=1) + "\n")
    print(f"wrote {path.relative_to(ROOT)}")
    return 0


def points(path: Path) -> list[dict]:
    """Per run two notches: the middle one (webs on both sides) and the far-end one (a web and plain tube)."""
    from camtube.design.geometry import joint_geometry

    out = []
    for i, r in enumerate(json.loads(path.read_text())["runs"]):
        ro, ri, s, h, w = (r[k] for k in ("outer_radius_mm", "inner_radius_mm", "arc_mm", "width_mm", "web_mm"))
        g = joint_geometry(ro, ri, s, h)
        for k, webs in ((COUNT // 2, (w, w)), (COUNT - 1, (w, math.inf))):
            out.append(dict(run=i, notch=k, ro=ro, ri=ri, phi=g.phi_rad, h=h, webs=webs,
                            ei=2.5e3 * g.second_moment_mm4, fe=r["per_notch_nmm_per_rad"][k]))
    return out


def predict(p, a, b: float) -> float:
    from camtube.joint.forward import row_extra_mm

    return p["ei"] / (p["h"] + row_extra_mm(p["ro"], p["ri"], p["phi"], p["webs"], a, b))


def fit(pts: list[dict]):
    """``(a0, a1, a2), b`` of the least squares in log stiffness."""
    from scipy.optimize import least_squares

    res = least_squares(lambda v: [math.log(predict(p, v[:3], v[3]) / p["fe"]) for p in pts],
                        [0.2, 0.1, 0.5, 1.0], bounds=([-5, -5, -5, 0.05], [5, 5, 5, 10]))
    return tuple(float(x) for x in res.x[:3]), float(res.x[3])


def errors(pts, a, b) -> list[float]:
    return [predict(p, a, b) / p["fe"] - 1.0 for p in pts]


def summary(label: str, pts, a, b) -> str:
    e = errors(pts, a, b)
    mid = [x for x, p in zip(e, pts) if p["notch"] == COUNT // 2]
    end = [x for x, p in zip(e, pts) if p["notch"] != COUNT // 2]
    return (f"{label}: middle notch |err| max {100 * max(map(abs, mid)):.1f} %, rms "
            f"{100 * math.sqrt(sum(x * x for x in mid) / len(mid)):.1f} %; end notch max {100 * max(map(abs, end)):.1f} %, "
            f"rms {100 * math.sqrt(sum(x * x for x in end) / len(end)):.1f} %")


def do_fit(check: list[str]) -> int:
    from camtube.joint.forward import HINGE_ROW

    pts = points(DATA / "fe_row_train.json")
    a, b = fit(pts)
    print(f"fitted: a = ({a[0]:.4f}, {a[1]:.4f}, {a[2]:.4f}), b = {b:.4f}  (HINGE_ROW: a = {HINGE_ROW['a']}, b = {HINGE_ROW['b']})")
    a, b = HINGE_ROW["a"], HINGE_ROW["b"]  # what the code uses (rounded)
    print(summary(f"training ({len(pts) // 2} runs, HINGE_ROW)", pts, a, b))
    runs = sorted({p["run"] for p in pts})
    loo = []
    for j in runs:  # leave one run out: refit without it, predict its two notches
        aj, bj = fit([p for p in pts if p["run"] != j])
        loo += [(p, predict(p, aj, bj) / p["fe"] - 1.0) for p in pts if p["run"] == j]
    mid = [e for p, e in loo if p["notch"] == COUNT // 2]
    print(f"leave one run out: middle notch |err| max {100 * max(map(abs, mid)):.1f} %, "
          f"rms {100 * math.sqrt(sum(x * x for x in mid) / len(mid)):.1f} %")
    for name in check:
        path = DATA / f"fe_row_{name}.json"
        print(summary(f"{name} ({path.relative_to(ROOT)})", points(path), a, b))
        for p, e in zip(points(path), errors(points(path), a, b)):
            print(f"  run {p['run']} notch {p['notch']}: r_o {p['ro']:.3f} r_i {p['ri']:.3f} phi {p['phi']:.2f} "
                  f"h {p['h']:.3f} web {p['webs'][0]:.3f}: FE {p['fe']:.3f}, fe_row {predict(p, a, b):.3f} ({100 * e:+.1f} %)")
    return 0


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=("train", "heldout", "fit"))
    ap.add_argument("-n", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--check", action="append", default=[], help="fit: also the errors on this set (e.g. heldout_7)")
    a = ap.parse_args()
    if a.what == "train":
        return batch("train", a.n, a.seed)
    if a.what == "heldout":
        return batch(f"heldout_{a.seed}", a.n, a.seed)
    return do_fit(a.check)


if __name__ == "__main__":
    raise SystemExit(main())
