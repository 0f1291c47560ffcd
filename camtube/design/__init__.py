"""Design stage: pattern data model, YAML and drawing (DXF) input, design rules, joint geometry, unrolled contours.

Owns: :class:`Tube`, :class:`Cut` (notches, square holes, drawn outlines and
slits), :class:`Process`, :class:`Tendon`, :class:`Pattern`; the YAML schema and
loader; the drawing reader (:mod:`camtube.design.drawing`); the design rules;
the geometry of a notched section; and the unrolled contours every other stage
starts from. :func:`camtube.design.source.load_source` is the one entry point.
"""
from __future__ import annotations

from camtube.design.contour import Contour, cut_contours, outline, sheet_contours, split_at_seam
from camtube.design.generate import notch_row, uan
from camtube.design.geometry import JointGeometry, beam_depth_mm, joint_geometry, pattern_geometry
from camtube.design.loader import Loaded, load, load_pattern
from camtube.design.pattern import Cut, Pattern, Process, RepeatRule, Rules, Tendon, Tube, hole, notch

__all__ = [
    "Contour", "Cut", "JointGeometry", "Loaded", "Pattern", "Process", "RepeatRule", "Rules", "Tendon", "Tube",
    "beam_depth_mm", "cut_contours", "hole", "joint_geometry", "load", "load_pattern", "notch", "notch_row",
    "outline", "pattern_geometry", "sheet_contours", "split_at_seam", "uan",
]
