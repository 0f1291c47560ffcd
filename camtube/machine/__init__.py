"""Machine profiles (``machines/*.yaml``): axis limits, blending, laser I/O and G-code style of a machine.

:func:`load_profile` reads a shipped profile by name or any profile file;
:class:`MachineProfile` is the frozen value the planner, the emitter, the time
estimate (:mod:`camtube.machine.motion_time`) and the motion runner
(:mod:`camtube.motion`) take.
"""
from __future__ import annotations

from camtube.machine.profile import (
    DEFAULT_MACHINE, MACHINES_DIR, AxisLimits, MachineProfile, load_profile, profile_names, read_profile,
)

__all__ = ["DEFAULT_MACHINE", "MACHINES_DIR", "AxisLimits", "MachineProfile", "load_profile", "profile_names",
           "read_profile"]
