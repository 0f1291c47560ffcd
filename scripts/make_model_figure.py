"""Figure for docs/model.md: synthetic tube 2 data (base model, 50 cycles x 2 samples) and its fit.

    python scripts/make_model_figure.py     # writes docs/img/model-fit-tube2.png
"""
from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))


def main() -> int:
    from camtube.design.loader import load_pattern
    from camtube.io import write_atomic
    from camtube.model.data import prepare, remove_deadband
    from camtube.model.core.fit import fit
    from camtube.model.report.plot import fit_png
    from camtube.model.core.predict import model_for_pattern, pattern_values
    from camtube.model.sim.synth import synthesize

    p = load_pattern(ROOT / "patterns" / "tube2.yaml")
    data = synthesize(p, seed=0)
    result = fit(model_for_pattern(p), prepare(data), ("E_t",), pattern_values(p))
    png = fit_png(result, remove_deadband(data),
                  title=f"tube2, synthetic: E_t = {result.params['E_t']:.2f} GPa, RMSE {result.rmse:.2f} deg")
    print(f"wrote {write_atomic(ROOT / 'docs' / 'img' / 'model-fit-tube2.png', png)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
