"""Benchmark of `camtube model diagnose`: 20,000 rows, every built-in candidate; target < 10 s.

Also prints, for each hidden-effect case of tests/model/test_diagnose.py, the rank of the hidden
effect, the final RMSE over the noise floor and the recovered parameters.

Run: ``python scripts/bench_diagnose.py``
"""
from __future__ import annotations

from benchutil import ROOT, best_of

from camtube.design.loader import load_pattern
from camtube.model.diagnose import diagnose
from camtube.model.predict import model_for_pattern, pattern_values
from camtube.model.truth import Hidden, simulate

TARGET_S = 10.0


def main() -> None:
    p = load_pattern(ROOT / "patterns" / "tube2.yaml")
    sim = simulate(p, Hidden(slack_mm=0.08, play_mm=0.06, joint_friction_nmm=0.05), n_samples=2, n_cycles=50,
                   rate_hz=20.0, seed=1)
    model = model_for_pattern(p)
    t, d = best_of(lambda: diagnose(model, sim.data, ("E_t",), pattern_values(p)), repeat=2)
    print(f"diagnose {len(sim.data)} rows, {len(d.candidates)} candidates, recommended {list(d.recommended)}: "
          f"{t:.2f} s (target {TARGET_S:g} s, ratio {t / TARGET_S:.2f}); "
          + ", ".join(f"{k} {v:.2f} s" for k, v in d.seconds.items()))
    print(f"  RMSE {d.waterfall[0].rmse_deg:.3f} -> {d.final.rmse_deg:.3f} deg; noise floor {d.noise_floor_deg:.3f} "
          f"(sensor {sim.sensor_floor_deg:.3f})")

    import sys

    sys.path.insert(0, str(ROOT))
    from tests.model.test_diagnose import CASES, _run

    print(f"{'case':<18} {'first':<13} {'rank':>4}  {'recommended':<24} {'RMSE/floor':>10} {'RMSE/sensor':>11}  "
          "params (fitted vs true)")
    for cid, tube, hidden, want, truth in CASES:
        _, s, dg = _run(tube, hidden)
        names = [c.effect for c in dg.candidates]
        rank = min(names.index(w) + 1 for w in want if w in names)
        prm = ", ".join(f"{n} {dg.final.params[n]:.4g} vs {v:g}" for n, (v, _) in truth.items())
        print(f"{cid:<18} {names[0]:<13} {rank:>4}  {','.join(dg.recommended):<24} "
              f"{dg.final.rmse_deg / dg.noise_floor_deg:10.2f} {dg.final.rmse_deg / s.sensor_floor_deg:11.2f}  {prm}")
    for tube in ("tube1", "tube2", "tube3"):
        _, s, dg = _run(tube, Hidden(joint_friction_nmm=0.05), seed=11)
        print(f"control-{tube:<10} recommended {list(dg.recommended)}; RMSE/floor "
              f"{dg.final.rmse_deg / dg.noise_floor_deg:.2f}")


if __name__ == "__main__":
    main()
