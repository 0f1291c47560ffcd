from benchutil import ROOT
from camtube.design.loader import load_pattern
from camtube.model.sim.truth import Hidden, simulate
from camtube.model.diagnose.instruments import check_instruments
p = load_pattern(ROOT / "patterns/tube1.yaml")
sim = simulate(p, Hidden(), n_samples=2, n_cycles=12, seed=8, dwell_s=2.0)
ins = check_instruments(sim.data)
print("\n".join(ins.lines()))
