"""Measurement data: the :class:`Dataset` value, CSV files, and the selection of rows to compare.

Modules: :mod:`.dataset` (the value), :mod:`.csvfile` (load, validate, format), :mod:`.select`
(cycles, branch, deadband).

CSV format
----------
One row per instant, a header line with at least the columns
``sample, cycle, time_s, stroke_mm, force_N, angle_deg`` (any order; more
columns are kept in :attr:`Dataset.extra`). Several samples per file are
allowed; blank lines and lines starting with ``#`` are skipped. Rows of one
sample need not be contiguous (they are gathered by sample in order of first
appearance, keeping file order within a sample), but within a sample
``time_s`` must not decrease and ``cycle`` (a whole number >= 1) must not
decrease. Any violation, a missing column, a non-numeric, empty, NaN or
infinite cell raises :class:`~camtube.errors.DataError` naming the file and
line; nothing is returned half-loaded.

Selection (the paper compares the *last loading* cycle, slack removed)
----------------------------------------------------------------------
* :func:`select_cycles` with a spec: ``all``, ``last`` (each sample's last
  cycle), ``last20`` (each sample's last 20), ``5``, ``31-50``, ``2-``, ``-10``,
  or a comma list of these.
* :func:`select_branch`: ``loading`` (stroke growing, :attr:`Dataset.direction` +1),
  ``unloading`` (-1) or ``both``.
* :func:`remove_deadband`: per sample and cycle, the slack is the stroke at
  which the joint starts to move on loading (:func:`find_slack`); it is
  subtracted from that cycle's stroke and the rows inside the deadband are
  dropped.
* :func:`prepare` chains the three; its defaults are the paper's comparison.

API
---
``parse_csv(text, source="<csv>") -> Dataset``, ``load_csv(path) -> Dataset``,
``format_csv(data) -> str``, ``parse_cycles(spec) -> CycleSpec``,
``select_cycles(data, spec) -> Dataset``, ``select_branch(data, branch) -> Dataset``,
``find_slack(data, threshold_deg=None) -> dict[(sample, cycle), Slack]``,
``remove_deadband(data, threshold_deg=None) -> Dataset``,
``prepare(data, cycles="last", branch="loading", deadband=True) -> Dataset``.
"""
from __future__ import annotations

from camtube.model.data.csvfile import (
    COLUMNS, Measurements, check_fittable, check_row_count, format_csv, load_csv, parse_csv, read_measurements,
)
from camtube.model.data.dataset import Dataset
from camtube.model.data.select import (
    BRANCHES, CycleSpec, Slack, find_slack, parse_cycles, prepare, remove_deadband, select_branch, select_cycles,
)

__all__ = ["BRANCHES", "COLUMNS", "CycleSpec", "Dataset", "Measurements", "read_measurements", "Slack", "check_fittable", "check_row_count", "find_slack", "format_csv",
           "load_csv", "parse_csv", "parse_cycles", "prepare", "remove_deadband", "select_branch", "select_cycles"]
