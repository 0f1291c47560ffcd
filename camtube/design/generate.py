"""Notch-pattern generators: UAN, bidirectional and multi-direction layouts."""
from __future__ import annotations

from typing import Sequence

from camtube.design.pattern import Cut, notch


def notch_angles_deg(layout: str, count: int, angle_deg: float, directions_deg: Sequence[float] = ()) -> list[float]:
    """Centre angle of each of ``count`` notches for a layout.

    ``uan``: all at ``angle_deg``; ``bidirectional``: alternating ``angle_deg``
    and ``angle_deg + 180``; ``directions``: cycling through ``directions_deg``.
    """
    if layout == "uan":
        return [angle_deg % 360.0] * count
    if layout == "bidirectional":
        return [(angle_deg + 180.0 * (i % 2)) % 360.0 for i in range(count)]
    if layout == "directions":
        if not directions_deg:
            raise ValueError("layout 'directions' needs directions_deg")
        return [float(directions_deg[i % len(directions_deg)]) % 360.0 for i in range(count)]
    raise ValueError(f"unknown layout {layout!r}")


def notch_row(
    count: int,
    width_mm: float,
    spacing_mm: float,
    arc_mm: float,
    first_offset_mm: float,
    angle_deg: float = 180.0,
    layout: str = "uan",
    directions_deg: Sequence[float] = (),
) -> tuple[Cut, ...]:
    """A row of ``count`` notches of width h, web c and arc s.

    The first notch's tip-side edge lies ``first_offset_mm`` from the tip;
    notch i is centred at ``first_offset + h/2 + i (h + c)``.
    """
    angles = notch_angles_deg(layout, count, angle_deg, directions_deg)
    pitch = width_mm + spacing_mm
    return tuple(
        notch(first_offset_mm + width_mm / 2.0 + i * pitch, width_mm, arc_mm, a) for i, a in enumerate(angles)
    )


def uan(n: int, h_mm: float, c_mm: float, s_mm: float, first_offset_mm: float, angle_deg: float = 180.0) -> tuple[Cut, ...]:
    """Unidirectional asymmetric notches: the paper's (n, h, c, s) plus the tip offset."""
    return notch_row(n, h_mm, c_mm, s_mm, first_offset_mm, angle_deg, "uan")
