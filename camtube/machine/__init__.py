"""The machine, in one place: what it can do, how a job maps onto its axes, and how long it takes.

- :mod:`~camtube.machine.profile`: machine profiles (``camtube/machine/profiles/*.yaml``): axis
  limits, blending, corner strategy, laser I/O and gating (time or distance), G-code style;
  :func:`load_profile` reads a shipped profile by name or any profile file;
- :mod:`~camtube.machine.kinematics`: the job's unrolled moves in the machine's axes, rounded as
  printed (the wrap to a rotary axis), and the check that its feeds can be written;
- :mod:`~camtube.machine.corners`: corner strategies that add moves (over-travel);
- :mod:`~camtube.machine.motion_time`: the motion-aware time estimate (LinuxCNC's planner:
  trapezoids, collinear joins, blend arcs) and the slow-job warning;
- :mod:`~camtube.machine.bound`: the time-optimal bound that stops at every true corner.

:class:`MachineProfile` is the frozen value the emitter (:mod:`camtube.export`) and the motion
runner (:mod:`camtube.motion`) take.
"""
from __future__ import annotations

from camtube.machine.profile import (
    DEFAULT_MACHINE, MACHINES_DIR, AxisLimits, MachineProfile, load_profile, profile_names, read_profile,
)

__all__ = ["DEFAULT_MACHINE", "MACHINES_DIR", "AxisLimits", "MachineProfile", "load_profile", "profile_names",
           "read_profile"]
