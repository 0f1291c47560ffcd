"""G-code dialects as data: one frozen :class:`Dialect` per machine, one emitter for all.

``linuxcnc`` (``.ngc``)
    A LinuxCNC rotary stage: X along the tube (mm), A rotary (deg), Z focus (mm).
    ``A = degrees(y / r_o)``, A = 0 at y = 0. Cutting moves in inverse-time mode
    (G93, F = 1 / minutes of the move), so every move, pure rotary ones
    included, runs at the scan speed on the outer surface. The beam is gated by
    digital output 0 with ``M62 P0`` / ``M63 P0`` (switched in step with the
    start of the next move, LinuxCNC's motion-synchronised output; rs274
    prints ``SET_MOTION_OUTPUT_BIT(0)`` / ``CLEAR_MOTION_OUTPUT_BIT(0)``);
    ``M65 P0`` switches it off at once in the preamble and postamble. Laser
    power (W) and pulse frequency (kHz) go to analog outputs 0 and 1 with
    ``M68 E0 Q..`` / ``M68 E1 Q..`` when they change.
``grbl`` (``.nc``)
    A flat-bed GRBL 1.1 laser for an unrolled test cut on a sheet: X = x,
    Y = y (mm), Z focus; G94 feed in mm/min; beam ``M4 S..`` (dynamic power;
    S = W x ``spindle_per_watt``, S1000 = 10 W by default) / ``M5``.

Z is the focus height relative to the outer surface: ``Z = -focus_offset``
(a defocus 0.1 mm into the material is Z = -0.1).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Literal


@dataclass(frozen=True)
class Dialect:
    """A G-code post-processor, as data.

    Attributes
    ----------
    name, suffix, description : str
        Key, file suffix (with the dot) and one-line description.
    rotary : bool
        True: the second axis is rotary, ``degrees(y / r_o)``; False: flat, ``y`` mm.
    axes : tuple[str, str, str]
        Letters of the axial, circumferential and focus axes.
    preamble, postamble : tuple[str, ...]
        Lines before the first and after the last pass (comments written in
        this dialect's style are added by the emitter).
    laser_on, laser_off : str
        Beam gate; ``laser_on`` may use ``{power_w}``, ``{frequency_khz}``, ``{spindle}``.
    settings : tuple[str, ...]
        Lines written before a pass whose power/frequency differ from the
        previous pass (same fields as ``laser_on``).
    feed_mode : {"inverse_time", "units_per_minute"}
        G93 (F = 1/min of each cutting move) or G94 (F per move in the units
        the controller applies it to: XYZ mm/min, or deg/min for a pure rotary move).
    decimals, feed_decimals : int
        Fixed decimals of coordinates (mm, deg) and of F.
    comment : {"paren", "semicolon"}
        ``(text)`` or ``; text``.
    spindle_per_watt : float
        S value per watt for ``{spindle}``.
    """

    name: str
    suffix: str
    description: str
    rotary: bool
    axes: tuple[str, str, str]
    preamble: tuple[str, ...]
    postamble: tuple[str, ...]
    laser_on: str
    laser_off: str
    settings: tuple[str, ...] = ()
    feed_mode: Literal["inverse_time", "units_per_minute"] = "inverse_time"
    decimals: int = 6
    feed_decimals: int = 3
    comment: Literal["paren", "semicolon"] = "paren"
    spindle_per_watt: float = 0.0

    def comment_line(self, text: str) -> str:
        """``text`` as a comment line (parentheses removed from paren comments)."""
        if self.comment == "paren":
            return "(" + text.replace("(", "[").replace(")", "]") + ")"
        return "; " + text

    def fields(self, power_w: float, frequency_khz: float) -> dict:
        return {"power_w": power_w, "frequency_khz": frequency_khz, "spindle": power_w * self.spindle_per_watt}


LINUXCNC = Dialect(
    name="linuxcnc",
    suffix=".ngc",
    description="LinuxCNC rotary stage: X mm along the tube, A deg, Z focus; G93; gate M62/M63 P0",
    rotary=True,
    axes=("X", "A", "Z"),
    preamble=("G21 G90 G17 G40 G49 G80", "G64 P0.001", "M65 P0", "G93", "G0 Z0"),
    postamble=("M65 P0", "G94", "M2"),
    laser_on="M62 P0",
    laser_off="M63 P0",
    settings=("M68 E0 Q{power_w:.3f}", "M68 E1 Q{frequency_khz:.3f}"),
    feed_mode="inverse_time",
    comment="paren",
)

GRBL = Dialect(
    name="grbl",
    suffix=".nc",
    description="GRBL 1.1 flat-bed laser, unrolled test cut: X = x, Y = y mm, Z focus; G94; M4 S/M5",
    rotary=False,
    axes=("X", "Y", "Z"),
    preamble=("G21 G90 G17 G94", "M5", "G0 Z0"),
    postamble=("M5", "M2"),
    laser_on="M4 S{spindle:.0f}",
    laser_off="M5",
    feed_mode="units_per_minute",
    comment="semicolon",
    spindle_per_watt=100.0,
)

DIALECTS: dict[str, Dialect] = {d.name: d for d in (LINUXCNC, GRBL)}


def get_dialect(name: str) -> Dialect:
    """The dialect called ``name`` (``KeyError`` lists the known ones)."""
    try:
        return DIALECTS[name]
    except KeyError:
        raise KeyError(f"unknown dialect {name!r}; known: {', '.join(DIALECTS)}") from None
