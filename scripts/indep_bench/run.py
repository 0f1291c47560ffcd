"""Diagnose batches of the independent bench simulator (:mod:`sim`, written without reading camtube's code) and score
them by issue 19's acceptance.

    python scripts/indep_bench/run.py first OUTDIR    # the batch that found the samples' stiffness and the wandering zero
    python scripts/indep_bench/run.py fresh OUTDIR    # the fresh batch drawn once those were settled (h01-h14)
    python scripts/indep_bench/run.py fresh2 OUTDIR   # the second fresh batch (g01-g14), drawn after toe_soft, play_held
    python scripts/indep_bench/run.py score OUTDIR    # score what is in OUTDIR again

Each file: two samples of about 30,000 rows, 25-100 Hz, 50 cycles; ``NAME.csv`` with ``NAME.truth.json`` (the
mechanisms and their parameters, the true floors), then ``camtube model diagnose`` (one core, ``CAMTUBE_WORKERS=1``)
into ``NAME.json`` and ``NAME.out``. The score: a control recommends nothing and leaves nothing unexplained; a
mechanism of a library family (``FAM``) is recommended first and the final RMSE is within 1.15x the true floor
(without the rows set aside); two samples of different mechanisms show both families, one first; a drift or a lag
(no family) gets nothing of a wrong family and is found (a lag corrected, a drift named as time or re-zeroed).
Results and when each batch was run: docs/diagnose.md ("An independent bench simulator").
"""
from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(HERE))

import sim  # noqa: E402

#: (name, tube, dominant, weak mechanisms, the second sample's dominant or None, spread of E_t between the samples)
FIRST = [
    ("f01_control", "tube1", None, [], None, 0.0), ("f02_control", "tube3", None, [], None, 0.0),
    ("f03_toe", "tube2", "toe", ["capstan"], None, 0.0), ("f04_slack", "tube1", "slack", ["creep"], None, 0.0),
    ("f05_lostmotion", "tube2", "lost_motion", ["toe"], None, 0.0),
    ("f06_creep", "tube3", "creep", ["fz_drift"], None, 0.0), ("f07_relax", "tube2", "relaxation", ["lag"], None, 0.0),
    ("f08_capstan", "tube1", "capstan", ["slack"], None, 0.0), ("f09_fzdrift", "tube2", "fz_drift", ["toe"], None, 0.0),
    ("f10_lag", "tube3", "lag", ["creep"], None, 0.0), ("f11_azdrift", "tube1", "az_drift", ["slack"], None, 0.0),
    ("f12_mix_toe_slack", "tube2", "toe", [], "slack", 0.0),
    ("f13_mix_creep_lost", "tube3", "creep", [], "lost_motion", 0.0),
    ("f14_mix_capstan_relax", "tube1", "capstan", [], "relaxation", 0.0),
]
FIRST_SEED = 2001
FRESH = [
    ("h01_control", "tube2", None, [], None, 0.0), ("h02_control_et", "tube1", None, [], None, 0.06),
    ("h03_toe", "tube3", "toe", ["slack"], None, 0.0), ("h04_slack", "tube2", "slack", ["capstan"], None, 0.05),
    ("h05_lostmotion", "tube1", "lost_motion", ["creep"], None, 0.0),
    ("h06_creep", "tube2", "creep", ["relaxation"], None, 0.05),
    ("h07_relax", "tube3", "relaxation", ["fz_drift"], None, 0.0),
    ("h08_capstan", "tube2", "capstan", ["toe"], None, 0.05), ("h09_fzdrift", "tube1", "fz_drift", ["slack"], None, 0.0),
    ("h10_lag", "tube2", "lag", ["slack"], None, 0.05), ("h11_azdrift", "tube3", "az_drift", ["creep"], None, 0.0),
    ("h12_mix_slack_creep", "tube1", "slack", [], "creep", 0.0),
    ("h13_mix_relax_capstan", "tube2", "relaxation", [], "capstan", 0.05),
    ("h14_mix_toe_lost", "tube3", "toe", [], "lost_motion", 0.0),
]
FRESH_SEED = 7001
#: Drawn once toe_soft, play_held, the per-sample tries by family and the samples' stiffness on the first chain were
#: settled (the session of 2026-12-08): new seeds, other tubes and pairings, two weak mechanisms in one file.
FRESH2 = [
    ("g01_control_et", "tube3", None, [], None, 0.03), ("g02_control", "tube1", None, [], None, 0.0),
    ("g03_toe", "tube1", "toe", ["creep"], None, 0.03), ("g04_slack", "tube3", "slack", ["toe"], None, 0.0),
    ("g05_lostmotion", "tube2", "lost_motion", ["capstan"], None, 0.03),
    ("g06_creep", "tube1", "creep", ["slack", "fz_drift"], None, 0.0),
    ("g07_relax", "tube2", "relaxation", ["creep"], None, 0.0),
    ("g08_capstan", "tube3", "capstan", ["relaxation"], None, 0.03),
    ("g09_fzdrift", "tube3", "fz_drift", ["creep"], None, 0.0), ("g10_lag", "tube1", "lag", ["toe"], None, 0.0),
    ("g11_azdrift", "tube2", "az_drift", ["slack"], None, 0.03),
    ("g12_mix_lost_toe", "tube1", "lost_motion", [], "toe", 0.0),
    ("g13_mix_creep_relax", "tube3", "creep", [], "relaxation", 0.0),
    ("g14_mix_capstan_slack", "tube2", "capstan", [], "slack", 0.03),
]
FRESH2_SEED = 9001
BATCHES = {"first": (FIRST, FIRST_SEED), "fresh": (FRESH, FRESH_SEED), "fresh2": (FRESH2, FRESH2_SEED)}

#: The effects of the library that are the right answer for each mechanism (empty: none is).
FAM = {"toe": {"toe", "toe_shape", "toe_soft"}, "slack": {"slack"},
       "lost_motion": {"slack", "play", "play_held", "carriage_hold", "carriage_gap"},
       "creep": {"creep", "creep_load", "viscoelastic"}, "relaxation": {"relaxation", "relaxation2"},
       "capstan": {"friction", "capstan"}, "fz_drift": set(), "lag": set(), "az_drift": set(), None: set()}


def run_batch(batch: str, outdir: Path) -> None:
    specs, seed0 = BATCHES[batch]
    outdir.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, CAMTUBE_WORKERS="1", PYTHONPATH=str(ROOT))
    for i, (name, tube, dom, weak, dom2, et_var) in enumerate(specs):
        out = outdir / f"{name}.csv"
        truth = sim.make_file(str(out), tube, seed0 + i, dom, weak, dom2=dom2, et_var=et_var)
        t0 = time.perf_counter()
        with open(outdir / f"{name}.out", "w") as fo:
            rc = subprocess.run([sys.executable, "-m", "camtube", "model", "diagnose", str(out), "--pattern", tube,
                                 "--json", str(outdir / f"{name}.json")], stdout=fo, stderr=subprocess.STDOUT,
                                env=env).returncode
        truth.update(diag_seconds=time.perf_counter() - t0, diag_rc=rc, et_var=et_var)
        (outdir / f"{name}.truth.json").write_text(json.dumps(truth, indent=1))
        print(name, tube, truth["rate"], "rc", rc, f"{truth['diag_seconds']:.1f} s", flush=True)


def score(outdir: Path) -> int:
    rows = []
    for tf in sorted(outdir.glob("*.truth.json")):
        t = json.loads(tf.read_text())
        name = tf.name[:-len(".truth.json")]
        dj, out = outdir / f"{name}.json", outdir / f"{name}.out"
        if not dj.exists():
            print(f"{name}: no diagnosis (exit {t.get('diag_rc')})")
            continue
        d, txt = json.loads(dj.read_text()), out.read_text()
        rec = [r if isinstance(r, str) else r["effect"] for r in d["recommended"]]
        doms = [t["dominant"]["S1"]] + ([t["dominant"]["S2"]] if t["dominant"]["S2"] != t["dominant"]["S1"] else [])
        allowed = set().union(*[FAM[m] for m in doms + t["weak"]])
        after = d["final"]["rmse_deg"] if rec else d["base"]["rmse_deg"]
        ratio = after / t["floor_no_spikes"]
        ins = d["instruments"]
        un = d.get("unexplained") or {}
        follows = un.get("follows", [])
        rezeroed = any(v.get("rezeroed") for v in (ins.get("load_cell_zero") or {}).values())
        wrong = [e for e in rec if e not in allowed and e != "rest_angle"]
        dom = doms[0]
        if dom is None:
            ok = not rec and not un
        elif len(doms) == 2:
            a, b = FAM[doms[0]], FAM[doms[1]]
            ok = bool(rec) and rec[0] in a | b and any(e in a for e in rec) and any(e in b for e in rec) and ratio <= 1.15
        elif FAM[dom]:
            ok = bool(rec) and rec[0] in FAM[dom] and ratio <= 1.15
        else:
            if dom == "lag":
                lag = ins.get("lag_applied_ms") or 0
                true_lag = max(t["samples"][s]["params"].get("lag_ms", 0) for s in ("S1", "S2"))
                found = (lag > 0 and abs(lag - true_lag) < 0.3 * true_lag) or bool(ins.get("lag_per_sample"))
            elif dom == "fz_drift":
                found = "time" in follows or rezeroed
            else:
                found = "time" in follows
            ok = not wrong and found
        m = re.search(r"set aside counted: RMSE ([\d.]+) -> ([\d.]+) deg", txt)
        rows.append((name, t["tube"], int(t["rate"]), "/".join(str(x) for x in doms), ",".join(rec) or "-",
                     d.get("explanation") or "-", ratio, ok, float(m.group(2)) / t["floor_with_spikes"] if m else float("nan"),
                     d["noise_floor_deg"] / t["floor_no_spikes"]))
    print("| file | tube | Hz | dominant | recommended | label | final / true floor | w/ artefacts | floor est / true | right |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, tube, rate, dom, rec, label, ratio, ok, ratio_all, fl in rows:
        print(f"| {name} | {tube} | {rate} | {dom} | {rec} | {label} | {ratio:.2f} | {ratio_all:.2f} | {fl:.2f} | "
              f"{'RIGHT' if ok else 'wrong'} |")
    right = sum(r[7] for r in rows)
    floors = sum(abs(r[9] - 1.0) <= 0.2 for r in rows)
    print(f"\n{right} of {len(rows)} right; the noise floor within 20 % of the true one in {floors} of {len(rows)}")
    return 0


def main(argv: list[str]) -> int:
    if len(argv) != 2 or argv[0] not in (*BATCHES, "score"):
        print(__doc__, file=sys.stderr)
        return 2
    outdir = Path(argv[1])
    if argv[0] != "score":
        run_batch(argv[0], outdir)
    return score(outdir)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
