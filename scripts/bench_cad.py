"""Benchmark of the CAD stage: prints timings and ratios to the targets (issue 4).

    python scripts/bench_cad.py

Targets, for a 200-notch pattern (tube1 with notch.count=200):

- STEP (build123d solid + STEP text) in under 5 s;
- STL preview (manifold3d mesh + binary STL) in under 1 s.

The one-off import of build123d/OCCT (several seconds) is reported separately
and not counted. Also prints, for information, the kerf simulation, the
verification and the volume errors of the presets.
"""
from __future__ import annotations

import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))

from benchutil import best_of  # noqa: E402


TARGET_STEP_S = 5.0
TARGET_STL_S = 1.0


def main() -> int:
    from camtube.cad.ascut import simulate
    from camtube.cad.mesh import design_mesh, stl_bytes, tube_mesh
    from camtube.cad.verify import analytic_volume_mm3, verify
    from camtube.design.loader import load
    from camtube.plan import plan_job

    print("== CAD stage ==")
    for name in ("tube1", "tube2", "tube3"):
        p = load(ROOT / "patterns" / f"{name}.yaml").pattern
        m = design_mesh(p)
        ana = analytic_volume_mm3(p)
        rep = verify(p, design_mesh=m)
        phi = [c for c in rep.checks if c.name.endswith("].phi")]
        worst = max(abs(c.measured / c.expected - 1) for c in phi)
        print(f"{name}: STL watertight {m.is_watertight}, volume {m.volume:.5f} vs analytic {ana:.5f} mm^3 "
              f"(error {m.volume / ana - 1:+.2e}); phi measured {phi[0].measured:.4f} deg vs "
              f"{phi[0].expected:.4f} deg (worst rel. error {worst:.1e})")

    n = 200
    p = load(ROOT / "patterns" / "tube1.yaml", [f"notch.count={n}", f"tube.length={1.5 + n * 1.0 + 1.0}"]).pattern
    print(f"\n200-notch pattern: {len(p.notches)} notches, {len(p.cuts)} cuts, L = {p.tube.length_mm} mm")

    t_stl, data = best_of(lambda: stl_bytes(design_mesh(p)))
    print(f"STL preview (mesh + STL bytes):   {t_stl:7.3f} s  target {TARGET_STL_S:.1f} s  "
          f"ratio {t_stl / TARGET_STL_S:.2f}  ({len(data) / 1e6:.1f} MB)")

    t0 = time.perf_counter()
    import build123d  # noqa: F401  (one-off import cost, not part of the target)
    t_imp = time.perf_counter() - t0
    from camtube.cad.solid import design_solid, step_bytes

    t_step, step = best_of(lambda: step_bytes(design_solid(p), "bench.step"), repeat=2)
    print(f"STEP (solid + STEP text):         {t_step:7.3f} s  target {TARGET_STEP_S:.1f} s  "
          f"ratio {t_step / TARGET_STEP_S:.2f}  ({len(step) / 1e6:.1f} MB; build123d import {t_imp:.1f} s not counted)")

    job = plan_job(p)
    t_sim, a = best_of(lambda: simulate(job), repeat=1)
    t_mesh, am = best_of(lambda: tube_mesh(p.tube.outer_radius_mm, p.tube.inner_radius_mm, p.tube.length_mm,
                                           [a.removed]), repeat=1)
    m = design_mesh(p)
    t_ver, rep = best_of(lambda: verify(p, design_mesh=m, ascut=a, ascut_mesh=am), repeat=1)
    print(f"kerf simulation ({len(job.passes)} passes):  {t_sim:7.3f} s")
    print(f"as-cut mesh:                      {t_mesh:7.3f} s")
    print(f"verification ({len(rep.checks)} checks):     {t_ver:7.3f} s  -> {'PASS' if rep.passed else 'FAIL'}")
    ok = t_stl < TARGET_STL_S and t_step < TARGET_STEP_S
    print("targets met" if ok else "TARGETS MISSED")
    return 0 if ok and math.isfinite(t_stl) else 1


if __name__ == "__main__":
    sys.exit(main())
