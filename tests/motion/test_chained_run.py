"""Chained passes on LinuxCNC's motion controller (issue 21): a short job in CI (about 15 s)."""
from __future__ import annotations

import numpy as np

from camtube.design.source import DrawingOptions, load_source
from camtube.machine.bound import time_optimal_s
from camtube.machine.motion_time import estimate_program
from camtube.motion import linuxcnc as lc
from camtube.motion.analysis import JobGeometry, analyse
from camtube.plan import plan_job
from tests.conftest import ROOT
from tests.motion.test_dose import write_job
from tests.motion.test_linuxcnc import require_linuxcnc


def test_a_chained_curved_drawing_meets_the_target_on_a_fast_stage(tmp_path):
    """The slotted drawing, 8 notches x 2 focus levels x 2 drill passes chained (16 groups, 32 passes), on the
    air-bearing demonstration profile: one gate-on per group, the links inside, the dose uniform, the run
    within 3 % of the estimate and within 1.3 x the lower bound (the issue's target for curved drawings)."""
    require_linuxcnc()
    loaded = load_source(ROOT / "examples" / "curved" / "slotted.dxf", ["process.repeats=1", "process.drill_passes=2"],
                         DrawingOptions(outer_radius_mm=0.8))
    job = plan_job(loaded.pattern, ordering="chained")
    assert job.packed.pass_link.sum() == 16
    profile, ngc, jf = write_job(tmp_path, job, "linuxcnc-path-airbearing")
    assert ngc.read_text().count("M62 P0") == 16
    est = estimate_program(ngc.read_text(), profile).total_s
    rec = lc.run_program(ngc, profile)
    r = analyse(rec, JobGeometry.from_job_file(jf), profile, estimate_s=est)
    assert abs(r.estimate_error) < 0.03
    assert r.run_time_s < 1.3 * r.lower_bound_s and r.run_time_s < 1.05 * time_optimal_s(job, profile)
    assert r.dose_share >= 0.99 and np.all(rec.rate_khz[~rec.gate] == 0.0)
    # the beam-on path: the passes plus the links (0.12 mm here), within 0.1 % either way
    assert r.link_length_mm > 0 and abs(r.path_length_error) < 0.001 and abs(r.length_error) < 0.001
    assert r.max_outside_mm <= 0.001
    # each group's stretch follows its passes and links within the path tolerance, every vertex reached
    assert r.max_path_dev_mm <= profile.path_tolerance_mm and r.max_vertex_miss_mm <= profile.path_tolerance_mm
