"""The rows of a CSV log: its header line and the data lines after it, with their line numbers."""
from __future__ import annotations

import csv
import io
from dataclasses import dataclass

from camtube.errors import DataError


@dataclass(frozen=True, eq=False)
class Table:
    """A CSV file's header and data rows.

    Attributes
    ----------
    header : list of str
        The first non-blank line's cells, stripped.
    header_line : int
        Its 1-based line number.
    rows : list of list of str
        The data rows after it (blank lines left out).
    lines : list of int
        Each row's 1-based line number.
    """

    header: list[str]
    header_line: int
    rows: list[list[str]]
    lines: list[int]


def read_table(text: str, source: str, *, comments: bool = False) -> Table | None:
    """Split ``text`` into its header and data rows; None when it holds no line at all.

    ``comments``: lines whose first cell starts with ``#`` are left out too.

    Raises
    ------
    DataError
        The text is not valid CSV (naming ``source:line``).
    """
    reader = csv.reader(io.StringIO(text))
    header: list[str] | None = None
    hline = 0
    rows: list[list[str]] = []
    lines: list[int] = []
    try:
        for rec in reader:
            if not rec or not any(c.strip() for c in rec) or (comments and rec[0].lstrip().startswith("#")):
                continue
            if header is None:
                header, hline = [c.strip() for c in rec], reader.line_num
                continue
            rows.append(rec)
            lines.append(reader.line_num)
    except csv.Error as exc:
        raise DataError(f"{source}:{reader.line_num}: not valid CSV ({exc})") from None
    return None if header is None else Table(header, hline, rows, lines)
