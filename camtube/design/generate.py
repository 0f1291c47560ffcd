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
    widths_mm: Sequence[float] = (),
    arcs_mm: Sequence[float] = (),
    spacings_mm: Sequence[float] = (),
    angles_deg: Sequence[float] = (),
) -> tuple[Cut, ...]:
    """A row of ``count`` notches of width h, web c and arc s.

    The first notch's tip-side edge lies ``first_offset_mm`` from the tip;
    notch i is centred at ``first_offset + h/2 + i (h + c)``. Per-notch lists, from the tip,
    replace the scalars where given: ``widths_mm`` and ``arcs_mm`` (``count`` values),
    ``spacings_mm`` (``count - 1`` webs) and ``angles_deg`` (``count`` centre angles, replacing
    the layout).
    """
    angles = ([a % 360.0 for a in angles_deg] if len(angles_deg) else
              notch_angles_deg(layout, count, angle_deg, directions_deg))
    widths = list(widths_mm) if len(widths_mm) else [width_mm] * count
    arcs = list(arcs_mm) if len(arcs_mm) else [arc_mm] * count
    webs = list(spacings_mm) if len(spacings_mm) else [spacing_mm] * max(count - 1, 0)
    out = []
    edge = first_offset_mm
    for i in range(count):
        out.append(notch(edge + widths[i] / 2.0, widths[i], arcs[i], angles[i]))
        if i < count - 1:
            edge += widths[i] + webs[i]
    return tuple(out)


def uan(n: int, h_mm: float, c_mm: float, s_mm: float, first_offset_mm: float, angle_deg: float = 180.0) -> tuple[Cut, ...]:
    """Unidirectional asymmetric notches: the paper's (n, h, c, s) plus the tip offset."""
    return notch_row(n, h_mm, c_mm, s_mm, first_offset_mm, angle_deg, "uan")
