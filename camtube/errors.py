"""Errors and warnings that name the file, key, value, allowed range and fix."""
from __future__ import annotations

from dataclasses import dataclass


class CamtubeError(Exception):
    """Base of every error camtube raises on purpose (bad input, unsafe job)."""


@dataclass
class Issue:
    """One problem found in an input.

    Attributes
    ----------
    key : str
        Dotted key of the offending value (``notch.arc``) or a description of
        the location (``cut[3]``).
    message : str
        What is wrong.
    value : object
        The offending value (``None`` if not a single value).
    allowed : str
        The allowed range or set, in words, with units.
    fix : str
        What the user can do.
    file : str | None
        Source file, if known.
    line : int | None
        1-based line in the source file, if known.
    kind : str
        What kind of problem, for a program that acts on it (not printed): ``"holes_collide"`` (two holes
        overlap or leave too thin a web); empty for the rest.
    """

    key: str
    message: str
    value: object = None
    allowed: str = ""
    fix: str = ""
    file: str | None = None
    line: int | None = None
    kind: str = ""

    def __str__(self) -> str:
        where = self.file or ""
        if self.line is not None and where:
            where += f":{self.line}"
        parts = [f"{where}: {self.key}: {self.message}" if where else f"{self.key}: {self.message}"]
        if self.value is not None:
            parts.append(f"got {self.value!r}")
        if self.allowed:
            parts.append(f"allowed: {self.allowed}")
        if self.fix:
            parts.append(f"fix: {self.fix}")
        return "; ".join(parts)


class PatternError(CamtubeError):
    """A pattern (or process) failed to load or violates a design rule.

    Holds every :class:`Issue` found, not only the first.
    """

    def __init__(self, issues: list[Issue]):
        self.issues = list(issues)
        super().__init__("\n".join(_lines(self.issues)))


def _lines(issues: list[Issue]) -> list[str]:
    """One line per problem: issues of one key with one fix in one file (one mistake: ``notch.spacing`` too small
    made nine pairs of notches too close, nine lines) are said once, with how many more there are."""
    groups: dict[tuple, list[Issue]] = {}
    for i in issues:
        groups.setdefault((i.file, i.key, i.fix, i.allowed), []).append(i)
    out = []
    for same in groups.values():
        more = len(same) - 1
        out.append(str(same[0]) + (f" (and {more} more like it)" if more else ""))
    return out


class DataError(CamtubeError):
    """A measurement file is malformed (the message names the line)."""


class SafetyError(CamtubeError):
    """A job failed the laser safety check; nothing was written."""
