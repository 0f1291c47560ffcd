"""Measurement data in memory: one row per instant, several samples and cycles.

Loading and validating CSV files lives in :mod:`camtube.model.data`; this
module only holds the value type every model function takes.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np

#: Column of :attr:`Dataset.extra` that carries the stroke speed (mm/s) of the full record into a thinned copy.
SPEED_COLUMN = "stroke_speed_mm_s"
#: Column of :attr:`Dataset.extra` that carries the smoothed force (N) of the full record into a thinned copy.
FORCE_SMOOTHED_COLUMN = "force_smoothed_N"
#: Window (s) of the centred running mean :attr:`Dataset.force_smoothed_N`: long enough to average the load
#: cell's white noise over several rows at 25-100 Hz, short against a ramp.
FORCE_SMOOTHING_S = 0.1


class Cache:
    """Derived data of one value, computed once and kept with it (the way trimesh's ``caching.Cache`` sits on a
    mesh): the direction of motion, sample slices, monotone runs, windows, per-sample views ...

    The value that owns it is immutable (a :class:`Dataset`'s arrays are not modified after construction), so
    nothing is ever invalidated: a new value (``take``, ``with_angle``) gets a new, empty cache. Keys are
    strings named by the module that computes the entry (``"history.segments"``).
    """

    __slots__ = ("_data",)

    def __init__(self) -> None:
        self._data: dict[str, Any] = {}

    def get(self, key: str, default: Any = None) -> Any:
        return self._data.get(key, default)

    def set(self, key: str, value: Any) -> Any:
        """Store ``value`` under ``key``; returns it."""
        self._data[key] = value
        return value

    def get_or(self, key: str, compute: Callable[[], Any]) -> Any:
        """The entry under ``key``, computed by ``compute()`` and stored the first time."""
        try:
            return self._data[key]
        except KeyError:
            return self.set(key, compute())

    def __contains__(self, key: str) -> bool:
        return key in self._data

    def __len__(self) -> int:
        return len(self._data)

    def clear(self) -> None:
        self._data.clear()

    def __repr__(self) -> str:
        return f"Cache({sorted(self._data)})"


def at_bottom(stroke_mm: np.ndarray) -> np.ndarray:
    """(n,) bool: the rows of one sample's stroke at the bottom of its span (within 0.1 % of it): the motor at rest at
    zero (a rest, or the rows before the first pull)."""
    s = np.asarray(stroke_mm, float)
    lo, hi = float(np.min(s)), float(np.max(s))
    return s <= lo + 1e-3 * (hi - lo) + 1e-12


def rest_runs(data: "Dataset", sl: slice, min_rows: int = 6) -> list[np.ndarray]:
    """Rows (indices into ``data``) of each rest of one sample (``sl``): the later half of each run of at least
    ``min_rows`` rows at the bottom of the stroke (:func:`at_bottom`), where the tendon has gone slack (or is held)
    and the guide has let go."""
    s = data.stroke_mm[sl]
    if s.size < 2:
        return []
    idx = np.flatnonzero(at_bottom(s)) + sl.start
    runs = np.split(idx, np.flatnonzero(np.diff(idx) > 1) + 1) if idx.size else []
    return [r[r.size // 2:] for r in runs if r.size >= min_rows]


@dataclass(frozen=True, eq=False)
class Rests:
    """One sample's rests (:func:`rest_runs`) as the load cell read them: ``runs`` (rows of each), the median time
    and force of each (``time_s``, ``force_N``), and the cell's row-to-row noise there (``row_noise_N``:
    ``1.4826 MAD(diff force) / sqrt 2`` over the rests' rows; 0 without rows)."""

    runs: list
    time_s: np.ndarray
    force_N: np.ndarray
    row_noise_N: float


def rest_noise(x: np.ndarray, runs: list) -> float:
    """A signal's row-to-row noise over the rests' rows: ``1.4826 MAD(diff x) / sqrt 2`` of the changes within each
    run of ``runs`` (0 without rows). ``x`` (n,): the whole record's values (``runs`` index it)."""
    steps = np.concatenate([np.diff(x[r]) for r in runs]) if runs else np.zeros(0)
    return float(1.4826 * np.median(np.abs(steps - np.median(steps))) / math.sqrt(2.0)) if steps.size else 0.0


def rests_of(data: "Dataset", sl: slice) -> Rests:
    """:class:`Rests` of one sample (``sl``) of ``data``."""
    runs = rest_runs(data, sl)
    f, t = np.asarray(data.force_N, float), np.asarray(data.time_s, float)
    return Rests(runs, np.array([float(np.median(t[r])) for r in runs]),
                 np.array([float(np.median(f[r])) for r in runs]), rest_noise(f, runs))


def recently_used(store: dict, key: Any, compute: Callable[[], Any], limit: int) -> Any:
    """``store[key]``, computed by ``compute()`` the first time; ``store`` keeps the ``limit`` most recently used
    entries (a dict keeps its order: the most recently used last, the least recently used dropped first)."""
    value = store.pop(key, None)
    if value is None:
        value = compute()
    store[key] = value
    if len(store) > limit:
        del store[next(iter(store))]
    return value


@dataclass(frozen=True, eq=False)
class Dataset:
    """Tendon stroke, force and joint angle over time.

    Rows are ordered by sample, then time. All arrays have shape ``(n,)``.

    Attributes
    ----------
    sample : (n,) str (object array)
        Sample id of each row.
    cycle : (n,) int
        Actuation cycle number (1-based).
    time_s : (n,) float
        Time (s), non-decreasing per sample, from any origin (:attr:`elapsed_s`: since the sample's first row).
    stroke_mm : (n,) float
        Tendon stroke (motor side), mm.
    force_N : (n,) float
        Tendon force (load cell), N.
    angle_deg : (n,) float
        Measured joint angle, deg.
    extra : dict[str, (n,) array]
        Extra CSV columns, kept as read.
    cache : Cache
        Derived data computed once per Dataset (speed: fits evaluate the model hundreds of times on the same
        rows); not part of the value (not compared, not passed on by ``take`` or ``dataclasses.replace``).
    taken_from : tuple or None
        ``(record, rows)`` when :meth:`take` made it: :meth:`rows_of_record`.
    """

    sample: np.ndarray
    cycle: np.ndarray
    time_s: np.ndarray
    stroke_mm: np.ndarray
    force_N: np.ndarray
    angle_deg: np.ndarray
    extra: dict = field(default_factory=dict)
    cache: Cache = field(default_factory=Cache, init=False, compare=False, repr=False)
    #: ``(record, rows)`` when :meth:`take` made this Dataset (see :meth:`rows_of_record`); not part of the value
    taken_from: tuple | None = field(default=None, init=False, compare=False, repr=False)

    def __len__(self) -> int:
        return int(self.stroke_mm.shape[0])

    @property
    def samples(self) -> list[str]:
        """Sample ids in order of first appearance."""
        _, idx = np.unique(self.sample, return_index=True)
        return [str(self.sample[i]) for i in sorted(idx)]

    def sample_slices(self) -> list[tuple[str, slice]]:
        """``(sample, slice)`` of each sample's contiguous rows, in order (computed once per Dataset; a new list
        each call)."""
        hit = self.cache.get("dataset.slices")
        if hit is not None:
            return list(hit)
        out = []
        n = len(self)
        if n:
            change = np.flatnonzero(self.sample[1:] != self.sample[:-1]) + 1
            starts = np.concatenate(([0], change))
            ends = np.concatenate((change, [n]))
            for s, e in zip(starts, ends):
                out.append((str(self.sample[s]), slice(int(s), int(e))))
        self.cache.set("dataset.slices", tuple(out))
        return out

    @property
    def direction(self) -> np.ndarray:
        """(n,) int: +1 while the stroke grows (loading), -1 while it shrinks (unloading).

        Taken from the sign of the stroke's change, carried over pauses; the
        first row of a sample takes the sign of the first real change.
        Computed once per Dataset (the arrays are not modified after construction;
        the cached copy is read-only).
        """
        hit = self.cache.get("dataset.direction")
        if hit is not None:
            return hit
        d = self._direction()
        d.setflags(write=False)
        return self.cache.set("dataset.direction", d)

    def _direction(self) -> np.ndarray:
        d = np.zeros(len(self), dtype=int)
        for _, sl in self.sample_slices():
            s = self.stroke_mm[sl]
            if len(s) < 2:
                d[sl] = 1
                continue
            ds = np.diff(s)
            sg = np.sign(ds).astype(int)
            # forward-fill zeros (pauses) with the last non-zero sign
            idx = np.where(sg != 0, np.arange(len(sg)), 0)
            np.maximum.accumulate(idx, out=idx)
            sg = sg[idx]
            first = sg[np.flatnonzero(sg)[0]] if np.any(sg) else 1
            sg = np.where(sg == 0, first, sg)
            d[sl] = np.concatenate(([sg[0]], sg))
        return d

    @property
    def stroke_speed_mm_s(self) -> np.ndarray:
        """(n,) float: the stroke's speed (mm/s, + loading): each row's step over its time step, per sample; 0
        where the stroke does not move (a dwell, a rest: :attr:`direction` keeps the last motion's sign there);
        the first row takes the second's. A column ``stroke_speed_mm_s`` in :attr:`extra` wins: a thinned copy
        carries the speed of the full record there (:meth:`with_full_rate_columns`), since steps between kept rows
        average over the dropped ones. Computed once per Dataset, read-only."""
        if SPEED_COLUMN in self.extra:
            return self.extra[SPEED_COLUMN]
        hit = self.cache.get("dataset.stroke_speed")
        if hit is not None:
            return hit
        out = np.zeros(len(self))
        for _, sl in self.sample_slices():
            ss, ts = self.stroke_mm[sl], self.time_s[sl]
            if ss.size < 2:
                continue
            ds, dt = np.diff(ss), np.diff(ts)
            v = np.where(dt > 0.0, ds / np.where(dt > 0.0, dt, 1.0), 0.0)
            out[sl] = np.concatenate((v[:1], v))
        out.setflags(write=False)
        return self.cache.set("dataset.stroke_speed", out)

    @property
    def elapsed_s(self) -> np.ndarray:
        """(n,) float: the time since each sample's first row (s), computed once per Dataset. The clock's origin is no
        part of the physics: a logger counting from when it was switched on, Unix time, a second sample logged after
        the first. A sample whose first row is at 0 s reads its ``time_s`` unchanged."""
        hit = self.cache.get("dataset.elapsed")
        if hit is None:
            t = np.asarray(self.time_s, float)
            out = t.copy()
            for _, sl in self.sample_slices():
                if t[sl.start] != 0.0:
                    out[sl] = t[sl] - t[sl.start]
            out.setflags(write=False)
            hit = self.cache.set("dataset.elapsed", out)
        return hit

    def median_steps_s(self, positive: bool = False) -> tuple[float, ...]:
        """Each sample's median time step (s), in the order of :meth:`sample_slices` (0.0 for a sample of fewer than
        two rows, or with no positive step when ``positive``). ``positive``: over the steps above zero only (a
        record whose repeated stamps are still in it). Computed once per Dataset: the sampling the laws, the noise
        floor's row spacing and the instruments' windows all read."""
        key = "dataset.median_steps_pos" if positive else "dataset.median_steps"
        hit = self.cache.get(key)
        if hit is None:
            t = np.asarray(self.time_s, float)
            steps = []
            for _, sl in self.sample_slices():
                dt = np.diff(t[sl])
                if positive:
                    dt = dt[dt > 0]
                steps.append(float(np.median(dt)) if dt.size else 0.0)
            hit = self.cache.set(key, tuple(steps))
        return hit

    @property
    def force_smoothed_N(self) -> np.ndarray:
        """(n,) float: the measured force, a centred running mean over :data:`FORCE_SMOOTHING_S` per sample (the
        rows within half the window on either side, by the sample's median time step). A column
        ``force_smoothed_N`` in :attr:`extra` wins: a thinned copy carries the full record's there
        (:meth:`with_full_rate_columns`). Computed once per Dataset, read-only."""
        if FORCE_SMOOTHED_COLUMN in self.extra:
            return self.extra[FORCE_SMOOTHED_COLUMN]
        hit = self.cache.get("dataset.force_smoothed")
        if hit is not None:
            return hit
        f = np.asarray(self.force_N, float)
        out = f.copy()
        for (_, sl), h in zip(self.sample_slices(), self.median_steps_s()):
            x = f[sl]
            half = int(round(FORCE_SMOOTHING_S / h)) // 2 if h > 0 else 0
            if half == 0:
                continue
            csum = np.concatenate(([0.0], np.cumsum(x)))
            i = np.arange(x.size)
            lo, hi = np.clip(i - half, 0, x.size), np.clip(i + half + 1, 0, x.size)
            out[sl] = (csum[hi] - csum[lo]) / (hi - lo)
        out.setflags(write=False)
        return self.cache.set("dataset.force_smoothed", out)

    def with_full_rate_columns(self) -> "Dataset":
        """This Dataset with the signals a thinned copy must take from the full record as columns (kept by
        :meth:`take`): the stroke speed and the smoothed force."""
        return Dataset(self.sample, self.cycle, self.time_s, self.stroke_mm, self.force_N, self.angle_deg,
                       {**self.extra, SPEED_COLUMN: self.stroke_speed_mm_s,
                        FORCE_SMOOTHED_COLUMN: self.force_smoothed_N})

    def with_speed_of(self, record: "Dataset", rows: np.ndarray) -> "Dataset":
        """This Dataset with the stroke speed of ``record`` at ``rows`` (one per row of this one) as the column
        :data:`SPEED_COLUMN`: the rows set aside between two rows kept still had a sound stroke and time, and the
        speed read across their gap would average a ramp's end, a dwell and the next ramp's start into one step.
        Keeps the record this one was taken from (:meth:`rows_of_record`)."""
        out = Dataset(self.sample, self.cycle, self.time_s, self.stroke_mm, self.force_N, self.angle_deg,
                      {**self.extra, SPEED_COLUMN: record.stroke_speed_mm_s[rows]})
        object.__setattr__(out, "taken_from", self.taken_from)
        return out

    def take(self, mask: np.ndarray) -> "Dataset":
        """Rows where ``mask`` (bool or index array) selects (the copy knows them: :meth:`rows_of_record`)."""
        out = Dataset(
            self.sample[mask], self.cycle[mask], self.time_s[mask], self.stroke_mm[mask],
            self.force_N[mask], self.angle_deg[mask], {k: v[mask] for k, v in self.extra.items()},
        )
        record, rows = self.rows_of_record()
        object.__setattr__(out, "taken_from", (record, rows[mask]))
        return out

    def rows_of_record(self) -> tuple["Dataset", np.ndarray]:
        """``(record, rows)``: the Dataset this one was taken from by :meth:`take` (through any number of takes:
        a thinned copy, one sample's rows) and the indices of this one's rows in it; ``(self, arange)`` for one
        that was not taken. A signal that needs every row of the record (a crossing between two kept rows) is
        computed on the record and indexed."""
        return self.taken_from if self.taken_from is not None else (self, np.arange(len(self)))

    def with_angle(self, angle_deg: np.ndarray) -> "Dataset":
        return Dataset(self.sample, self.cycle, self.time_s, self.stroke_mm, self.force_N,
                       np.asarray(angle_deg, float), self.extra)

    def with_force(self, force_N: np.ndarray) -> "Dataset":
        return Dataset(self.sample, self.cycle, self.time_s, self.stroke_mm, np.asarray(force_N, float),
                       self.angle_deg, self.extra)
