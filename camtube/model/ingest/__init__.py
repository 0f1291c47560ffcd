"""From a bench's raw instrument logs to a measurement file (``camtube model ingest``).

Modules, in the order data flows through them: :mod:`.ndi` (the NDI tracker's CSV export),
:mod:`.series` (the DAQ's and the motor's time-series logs and the bench map that says how to read them),
:mod:`.poses` (bend angle from the coils' orientations), :mod:`.clock` (offset and drift of each clock
against the tracker's), :mod:`.cycles` (cycles from the stroke), :mod:`.merge` (units and signs checked,
everything on the tracker's frames) and :mod:`.report` (a one-page HTML report with figures).
"""
from __future__ import annotations
