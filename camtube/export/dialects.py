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

The shipped dialects are built from the machine profiles ``machines/linuxcnc-rotary.yaml``
and ``machines/grbl-flat.yaml`` (:func:`dialect_from_profile`); a profile of your own
gives a dialect the same way.

Z is the focus height relative to the outer surface: ``Z = -focus_offset``
(a defocus 0.1 mm into the material is Z = -0.1).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from camtube.fmt import one_line


@dataclass(frozen=True)
class Dialect:
    """A G-code post-processor, as data: the codes of one G-code family for one machine profile.

    Everything that describes the machine (axes, rotary or flat, decimals, comment style, feed
    mode, S per watt, suffix) is read from :attr:`profile`, never stored twice; the dialect holds
    only the lines and codes the emitter writes.

    Attributes
    ----------
    name : str
        Key of the G-code family (``linuxcnc``, ``grbl``).
    profile : MachineProfile
        The machine the G-code is for (limits, blending, corner strategy, axes, number format).
    preamble, postamble : tuple[str, ...]
        Lines before the first and after the last pass (comments written in
        this dialect's style are added by the emitter).
    laser_on, laser_off : str
        Beam gate; ``laser_on`` may use ``{power_w}``, ``{frequency_khz}``, ``{spindle}``.
    settings : tuple[str, ...]
        Lines written before a pass whose settings differ from the previous pass (same fields
        as ``laser_on``, and ``{pulses_per_mm}``, ``{outer_radius_mm}``).
    blend_on, blend_off : str | None
        ``blend`` corner strategy: the lines written before the first beam-on move of a pass
        (``G64 P<tol>``) and before its last (``G61``, so the machine stops where the gate closes);
        None otherwise.
    """

    name: str
    profile: Any
    preamble: tuple[str, ...]
    postamble: tuple[str, ...]
    laser_on: str
    laser_off: str
    settings: tuple[str, ...] = ()
    blend_on: str | None = None
    blend_off: str | None = None

    # ---- read from the profile
    @property
    def suffix(self) -> str:
        """File suffix, with the dot."""
        return self.profile.suffix

    @property
    def description(self) -> str:
        return self.profile.description

    @property
    def rotary(self) -> bool:
        """True: the second axis is rotary, ``degrees(y / r_o)``; False: flat, ``y`` mm."""
        return self.profile.rotary

    @property
    def axes(self) -> tuple[str, str, str]:
        """Letters of the axial, circumferential and focus axes."""
        return self.profile.axes

    @property
    def feed_mode(self) -> str:
        """``inverse_time`` (G93) or ``units_per_minute`` (G94)."""
        return self.profile.feed_mode

    @property
    def decimals(self) -> int:
        return self.profile.decimals

    @property
    def feed_decimals(self) -> int:
        return self.profile.feed_decimals

    @property
    def comment(self) -> str:
        """``paren`` ``(text)`` or ``semicolon`` ``; text``."""
        return self.profile.comment

    @property
    def spindle_per_watt(self) -> float:
        """S value per watt for ``{spindle}``."""
        return self.profile.s_per_watt

    @property
    def uses_speed(self) -> bool:
        """True when a settings line depends on the pass's scan speed (the pulses per mm)."""
        return any("pulses_per_mm" in x for x in self.settings)

    def comment_line(self, text: str) -> str:
        """``text`` as one comment line (parentheses removed from paren comments). A line break or another control
        character in it (a pattern's name, a profile's description) becomes a space: a comment never ends its line,
        so no text a user gives can become a G-code line (``M3 S1000`` after a line break in a name)."""
        text = one_line(text)
        if self.comment == "paren":
            return "(" + text.replace("(", "[").replace(")", "]") + ")"
        return "; " + text

    def fields(self, power_w: float, frequency_khz: float, speed_mm_s: float = 0.0,
               outer_radius_mm: float = 0.0) -> dict:
        """Values of the format fields of ``laser_on`` and ``settings`` for one pass's settings.

        ``pulses_per_mm`` = pulses per mm of path at the scan speed (1/mm, the dose of a
        distance-gated laser), ``outer_radius_mm`` the tube's (mm).
        """
        ppmm = 1000.0 * frequency_khz / speed_mm_s if speed_mm_s > 0 else 0.0
        return {"power_w": power_w, "frequency_khz": frequency_khz, "spindle": power_w * self.spindle_per_watt,
                "pulses_per_mm": ppmm, "outer_radius_mm": outer_radius_mm}


def blending_line(profile) -> str | None:
    """The G-code line that sets ``profile.blending`` (None: leave the controller's own).

    Under the ``blend`` corner strategy the program starts in exact stop; the emitter switches to
    the tolerance for the beam-on moves of each pass (:attr:`Dialect.blend_on`).
    """
    if profile.blending == "exact_stop" or profile.corner_strategy == "blend":
        return "G61"
    if profile.blending == "controller":
        return None
    return tolerance_line(profile)


def tolerance_line(profile) -> str:
    """``G64 P<profile.blending>`` in fixed-point notation (``G64 P0.001``; rs274ngc reads no exponent, so
    ``{:g}``'s ``P1e-09`` would not be a tolerance of 1 nm)."""
    from camtube.fmt import fixed

    return f"G64 P{fixed(profile.blending)}"


def dialect_from_profile(profile) -> Dialect:
    """The :class:`Dialect` of a :class:`~camtube.machine.MachineProfile` (preamble, gate, settings, style).

    ``linuxcnc``: G93 inverse time, gate ``M62``/``M63 P<gate_output>`` (``M65`` at once in the
    preamble and postamble), power and frequency on ``M68 E<power_output>``/``E<frequency_output>``.
    ``grbl``: G94, beam ``<spindle> S<W x s_per_watt>`` / ``M5``.
    """
    ax, ay, az = profile.axes
    blend = blending_line(profile)
    common = dict(name=profile.dialect, profile=profile)
    if profile.dialect == "linuxcnc":
        g = profile.gate_output
        settings = tuple(line for out, line in ((profile.power_output, "M68 E{} Q{{power_w:.3f}}"),
                                                (profile.frequency_output, "M68 E{} Q{{frequency_khz:.3f}}"),
                                                (profile.dose_output, "M68 E{} Q{{pulses_per_mm:.6f}}"),
                                                (profile.radius_output, "M68 E{} Q{{outer_radius_mm:.6f}}"))
                         if out is not None for line in [line.format(out)])
        pre = ("G21 G90 G17 G40 G49 G80",) + ((blend,) if blend else ()) + (f"M65 P{g}", "G93", f"G0 {az}0")
        blend = (tolerance_line(profile), "G61") if profile.corner_strategy == "blend" else (None, None)
        return Dialect(preamble=pre, postamble=(f"M65 P{g}", "G94", "M2"), laser_on=f"M62 P{g}",
                       laser_off=f"M63 P{g}", settings=settings, blend_on=blend[0], blend_off=blend[1], **common)
    pre = ("G21 G90 G17 G94",) + ((blend,) if blend else ()) + ("M5", f"G0 {az}0")
    return Dialect(preamble=pre, postamble=("M5", "M2"), laser_on=f"{profile.spindle} S{{spindle:.0f}}",
                   laser_off="M5", **common)


def _shipped(name: str) -> Dialect:
    from camtube.machine.profile import load_profile

    return dialect_from_profile(load_profile(name))


LINUXCNC = _shipped("linuxcnc-rotary")
GRBL = _shipped("grbl-flat")

DIALECTS: dict[str, Dialect] = {d.name: d for d in (LINUXCNC, GRBL)}


def get_dialect(name: str) -> Dialect:
    """The dialect called ``name`` (``KeyError`` lists the known ones)."""
    try:
        return DIALECTS[name]
    except KeyError:
        raise KeyError(f"unknown dialect {name!r}; known: {', '.join(DIALECTS)}") from None
