"""Synthesis stage: from a goal (bend at a stroke, distribution, curve or 3-D centre line, limits) to a notch pattern.

It owns the goal file (:mod:`~camtube.synthesis.goal`), the solver that chooses per-notch
arcs and widths under the forward model of :mod:`camtube.joint` (:mod:`~camtube.synthesis.solve`),
the report and the pattern YAML writer (:mod:`~camtube.synthesis.report`), the 3-D centre line a goal
draws and how closely a pattern follows it (:mod:`~camtube.synthesis.centerline`), and the independent
re-simulation of a written pattern from its job's cut geometry (:mod:`~camtube.synthesis.check`).
"""
from __future__ import annotations
