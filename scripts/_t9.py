from benchutil import ROOT
from camtube.design.loader import load_pattern
from camtube.model.sim.truth import Hidden, simulate
from camtube.model.diagnose.instruments import check_instruments
p = load_pattern(ROOT / "patterns/tube2.yaml")
for jf in (0.0, 0.05):
  for rate in (10.0, 50.0):
    sim = simulate(p, Hidden(joint_friction_nmm=jf), seed=100, rate_hz=rate)
    ins = check_instruments(sim.data)
    print(jf, rate, round(ins.lag.lag_ms,1), round(ins.lag.se_ms,1), round(ins.lag.fall,4), ins.lag.applied_ms)
