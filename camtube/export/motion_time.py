"""Moved to :mod:`camtube.machine.motion_time` (the machine in one place); this path warns and goes next release."""
from __future__ import annotations

import warnings

from camtube.machine.motion_time import *  # noqa: F401,F403
from camtube.machine.motion_time import (  # noqa: F401
    estimate_machine_moves, estimate_program, job_estimate, job_motion_s, slow_job_warning, trajectory_time,
)

warnings.warn("camtube.export.motion_time moved to camtube.machine.motion_time; import it from there",
              FutureWarning, stacklevel=2)
