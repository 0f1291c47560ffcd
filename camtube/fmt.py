"""One formatter for figures shown to people (shared by every report, header and warning).

:func:`format_duration_s` writes a duration as seconds with hours:minutes:seconds beside
it, so a long laser job reads at a glance (``908802 s (252:26:42)``).
"""
from __future__ import annotations

import math

#: Control characters (and Unicode's line and paragraph separators) as spaces: :func:`one_line`.
ONE_LINE = {**dict.fromkeys(range(32), " "), 127: " ", 0x85: " ", 0x2028: " ", 0x2029: " "}


def one_line(text: str) -> str:
    """``text`` with every line break and other control character as a space: text a user gives (a pattern's name,
    a profile's description) that is written into a one-line header (a G-code comment) stays on its line."""
    return str(text).translate(ONE_LINE)


def fixed(x: float, digits: int = 6) -> str:
    """``x`` in fixed-point notation with ``digits`` significant digits and no trailing zeros: what ``f"{x:g}"``
    writes, but never an exponent (rs274ngc, LinuxCNC's G-code reader, reads no exponents: ``G64 P1e-09`` would
    be P1 and an E word). Every number a G-code program holds is written so (or with a fixed ``.Nf``).

    >>> fixed(0.001), fixed(1e-9), fixed(1e9), fixed(2.0)
    ('0.001', '0.000000001', '1000000000', '2')
    """
    import numpy as np

    return np.format_float_positional(float(x), precision=digits, unique=False, fractional=False, trim="-")


def hms(seconds: float) -> str:
    """``h:mm:ss`` of ``seconds`` (rounded to the nearest second; hours are not wrapped at 24).

    >>> hms(908802)
    '252:26:42'
    """
    if not math.isfinite(seconds):
        return "-:--:--"
    s = int(round(abs(seconds)))
    h, rest = divmod(s, 3600)
    m, sec = divmod(rest, 60)
    return f"{'-' if seconds < 0 and s else ''}{h}:{m:02d}:{sec:02d}"


def format_duration_s(seconds: float) -> str:
    """A duration for people: seconds, then ``(h:mm:ss)``.

    Below 1000 s the seconds keep one decimal (``92.7 s (0:01:33)``); from 1000 s on
    they are whole (``908802 s (252:26:42)``).

    Parameters
    ----------
    seconds : float
        Duration in s.
    """
    if not math.isfinite(seconds):
        return f"{seconds} s"
    digits = 1 if abs(seconds) < 1000 else 0
    return f"{seconds:.{digits}f} s ({hms(seconds)})"
