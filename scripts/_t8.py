from benchutil import ROOT
import bench_diagnose as BD
from camtube.design.loader import load_pattern
from camtube.model.sim.truth import simulate
from camtube.model.diagnose.instruments import check_instruments
for k, (name, tube, hidden, *_r) in enumerate(BD.TUNE):
    p = load_pattern(ROOT / "patterns" / f"{tube}.yaml")
    sim = simulate(p, hidden, seed=100 + k)
    ins = check_instruments(sim.data)
    print(name, ins.n_aside, round(ins.lag.lag_ms,1), round(ins.lag.se_ms,1), ins.lag.applied_ms)
