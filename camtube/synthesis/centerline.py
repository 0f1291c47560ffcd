"""The 3-D centre line a goal asks for, and how closely a pattern's forward model follows it.

A ``goal.centerline`` is a chain of circular pieces from the base, each turning the tangent by ``bend_deg``
over ``length_mm`` towards the rotary angle ``towards_deg`` of the tube's own frame (the frame the notches
are cut in, carried along by the bending: the tube does not twist). The solver cuts each piece as one
direction's notches at a uniform pitch (``length_mm`` over their count) with its own tendon, pieces one
after the other. Here the target is drawn in the frame of :class:`camtube.joint.forward.JointState`
(origin at the base section, ``z`` along the straight tube towards the tip, rotary angle 0 along ``+x``),
with the pattern's plain tube before and after the pieces, and compared with the forward model's centre
line with every tendon at its stroke. Lengths mm, angles deg.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from camtube.design.pattern import Pattern
from camtube.synthesis.goal import Goal

#: Spacing of the drawn target's points (mm).
STEP_MM = 0.02


def _rot(axis: np.ndarray, angle: float) -> np.ndarray:
    a = axis / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def piece_spans(goal: Goal, pattern: Pattern) -> list[tuple[float, float]]:
    """``(x_base, x_tip)`` of each piece along the straight tube (x from the tip, mm), in the goal's order.

    A piece is its direction's notch cells, centred on the notches at the piece's uniform pitch (the solver
    lengthens the cells by the axis's shortening, so a piece spans a little more than ``length_mm`` straight).
    """
    out = []
    for arc in goal.centerline:
        xs = sorted(n.x_mm for n in pattern.notches
                    if abs((n.angle_deg - arc.towards_deg + 180.0) % 360.0 - 180.0) < 1e-6)
        if not xs:
            raise ValueError(f"the pattern has no notches at {arc.towards_deg:g} deg")
        cell = (xs[-1] - xs[0]) / (len(xs) - 1) if len(xs) > 1 else arc.length_mm
        out.append((xs[-1] + cell / 2.0, xs[0] - cell / 2.0))
    return out


def target_points(goal: Goal, pattern: Pattern, step_mm: float = STEP_MM) -> np.ndarray:
    """(m, 3) points of the goal's centre line from the base section to the tip (mm), in the joint's frame.

    Only the plain tube before the first piece and after the last is taken from ``pattern``; the pieces are the
    goal's, back to back.
    """
    spans = piece_spans(goal, pattern)
    p = np.zeros(3)
    r = np.eye(3)
    pts = [p.copy()]

    def straight(length: float):
        nonlocal p
        for _ in range(max(int(math.ceil(length / step_mm)), 1)):
            p = p + r[:, 2] * (length / max(int(math.ceil(length / step_mm)), 1))
            pts.append(p.copy())

    straight(pattern.tube.length_mm - spans[0][0])  # plain tube before the first piece
    for arc in goal.centerline:  # the pieces back to back, as the goal draws them
        a = math.radians(arc.towards_deg)
        towards = r[:, 0] * math.cos(a) + r[:, 1] * math.sin(a)
        steps = max(int(math.ceil(arc.length_mm / step_mm)), 1)
        ds = arc.length_mm / steps
        rot = _rot(np.cross(r[:, 2], towards), math.radians(arc.bend_deg) / steps)
        for _ in range(steps):  # exact chords of the circle: half a step, turn, half a step
            p = p + r[:, 2] * (ds / 2.0)
            r = rot @ r
            p = p + r[:, 2] * (ds / 2.0)
            pts.append(p.copy())
    straight(spans[-1][1])  # plain tube from the last piece to the tip
    return np.array(pts)


@dataclass(frozen=True)
class Following:
    """How the forward model's centre line follows the goal's.

    Attributes
    ----------
    max_deviation_mm : float
        Largest distance from a point of the model's centre line to the target's.
    tip_error_mm : float
        Distance between the model's tip and the target's.
    tip_direction_error_deg : float
        Angle between the model's tip direction and the target's.
    length_mm : float
        Arc length of the target from the base section to the tip.
    model_tip_mm, target_tip_mm : (3,) float
    """

    max_deviation_mm: float
    tip_error_mm: float
    tip_direction_error_deg: float
    length_mm: float
    model_tip_mm: np.ndarray
    target_tip_mm: np.ndarray


def follow(goal: Goal, pattern: Pattern, mechanics) -> Following:
    """Simulate ``pattern`` with every piece's tendon at its stroke and compare its centre line with the goal's."""
    from camtube.joint.forward import centerline, simulate

    st = simulate(pattern, {b.angle_deg: b.stroke_mm for b in goal.bends}, mechanics)
    model, _ = centerline(pattern, st.notch_angles_rad, mechanics, per_notch=12)
    target = target_points(goal, pattern)
    # every model point against the target's segments
    a, b = target[:-1], target[1:]
    ab = b - a
    t = np.clip(np.einsum("mij,ij->mi", model[:, None, :] - a[None], ab) / np.maximum((ab * ab).sum(1), 1e-30),
                0.0, 1.0)
    near = a[None] + t[..., None] * ab[None]
    dev = np.linalg.norm(model[:, None, :] - near, axis=2).min(axis=1)
    t_dir = target[-1] - target[-2]
    cosang = float(np.dot(st.tip_direction, t_dir) / np.linalg.norm(t_dir))
    return Following(float(dev.max()), float(np.linalg.norm(st.tip_position_mm - target[-1])),
                     math.degrees(math.acos(max(-1.0, min(1.0, cosang)))),
                     float(np.linalg.norm(np.diff(target, axis=0), axis=1).sum()), st.tip_position_mm.copy(),
                     target[-1].copy())
