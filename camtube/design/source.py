"""Design input: a pattern from a YAML file or from a drawing (DXF), one entry point.

Every stage downstream sees the same :class:`~camtube.design.loader.Loaded`
(a validated :class:`~camtube.design.pattern.Pattern` plus its warnings), whatever
the input was. The CLI and the orchestration in :mod:`camtube.pipeline` call
:func:`load_source` and nothing else of the loaders.
"""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable

from camtube.design.loader import Loaded, load


@dataclass(frozen=True)
class DrawingOptions:
    """How to read a drawing (ignored for a YAML pattern).

    Attributes
    ----------
    outer_radius_mm : float | None
        Tube outer radius r_o; ``None``: taken from the drawing's tube outline.
    length_mm : float | None
        Tube length L; ``None``: taken from the drawing's tube outline.
    units : str | None
        Drawing units when ``$INSUNITS`` is unset (``mm``, ``inch``, ``um``, ...).
    layers : tuple[tuple[str, str], ...]
        ``(layer name, role)`` overrides of the layer -> role table
        (roles ``notch``, ``hole``, ``slit``, ``ignore``).
    """

    outer_radius_mm: float | None = None
    length_mm: float | None = None
    units: str | None = None
    layers: tuple[tuple[str, str], ...] = field(default_factory=tuple)


def is_drawing(path: str | os.PathLike) -> bool:
    """True when ``path`` names a DXF drawing (by its suffix)."""
    return Path(path).suffix.lower() == ".dxf"


def load_source(path: str | os.PathLike, overrides: Iterable[str] = (),
                drawing: DrawingOptions | None = None) -> Loaded:
    """Load a pattern YAML or a DXF drawing into a validated pattern.

    Parameters
    ----------
    path : path
        ``*.yaml`` / ``*.yml`` pattern, or ``*.dxf`` drawing.
    overrides : iterable of str
        ``KEY=VALUE`` pairs (``--set``), applied to the YAML, or to the
        process / tube / rules of a drawing.
    drawing : DrawingOptions, optional
        How to read a drawing.

    Raises
    ------
    PatternError
        The input is invalid or breaks a design rule; the message names the
        file, line or entity, and the fix.
    """
    if is_drawing(path):
        from camtube.design.drawing import load_drawing

        return load_drawing(path, overrides, drawing or DrawingOptions())
    return load(path, overrides)
