from benchutil import ROOT
from camtube.model.data import read_measurements
from camtube.model.diagnose.instruments import check_instruments
import sys
m = read_measurements(sys.argv[1]); ins = check_instruments(m.data); print(ins.lines()[-1])
