"""Proof on a real motion controller: run a job in LinuxCNC (headless, real time) and measure what it did.

:mod:`camtube.motion.linuxcnc` writes a configuration from a machine profile, runs the program in
LinuxCNC's motion controller and records the commanded axes and the laser gate every servo cycle;
:mod:`camtube.motion.analysis` measures the recording against the job (run time, beam-on length,
speed uniformity, beam outside the cut regions, missed corners); :mod:`camtube.commands.motion` is
``camtube motion`` and ``camtube machines``.
"""
