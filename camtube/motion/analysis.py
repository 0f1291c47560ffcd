"""What a recorded run did, measured against the job it was made from.

The beam model: LinuxCNC's motion controller writes the commanded position and
the outputs (gate, pulse rate) of a servo cycle together, and the stage moves to
that position while they are in force (causality: no drive moves towards a position
not yet written): the beam is on while the stage moves from sample ``k - 1`` to
sample ``k`` exactly when the gate is set at sample ``k``. From rest (every gate
switch under exact stop) the gate opens in the cycle of a cut's first step and closes
in the cycle of the next move's first step, so the beam-on path is exactly the
cutting moves; switched at speed (over-travel), LinuxCNC switches it with the step
that reaches the move's start, one step early. Kept samples
are joined by straight lines: the recorder drops only cycles on straight,
constant-speed stretches with a steady gate. All lengths are on the outer
surface of the tube (``y = radians(A) r_o`` for a rotary stage), mm.

Figures (:class:`MotionReport`):

- run time (first to last cycle with motion) against the estimate and the lower bound;
- beam-on path length against the job's cut length;
- share of the beam-on path run within +-5 % of the scan speed;
- dose: share of the beam-on path that gets within +-5 % of the nominal pulses per mm
  (``1000 frequency_khz / scan_speed``): from the recorded pulse rate of a distance-gated
  profile (the rate commanded at sample ``k`` is in force from ``k - 1`` to ``k``), or, for a
  time-gated one, the set frequency over the recorded speed;
- farthest beam-on position outside the design cut regions (the tube is periodic in y);
- largest distance from a drawn corner (every vertex of a pass path that is a true corner of the
  drawing, :func:`camtube.machine.bound.design_corners`: every vertex of a rectangle, none of a
  slot or an ellipse; matched by focus level) to the beam-on path at that focus;
- each stretch of the beam-on path against its own pass (the k-th stretch with the gate open is the
  k-th beam-on run: a pass, or a chain of passes joined by beam-on links, ``chained`` ordering): the
  farthest sample from the run's commanded path (its passes' paths and the links between them), and
  the farthest vertex of that path (on a curve: a point of the drawn curve) from the stretch (curves
  followed within the path tolerance).

The beam-on path is compared with the job's cut length (the passes' paths) and, where passes are
chained, with the cut length plus the links (``link_length_mm``): the links are beam-on path the
passes do not have, stated apart.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from camtube.errors import DataError
from camtube.inputfile import parse_json, read_input_text

SPEED_BAND = 0.05


@dataclass(frozen=True, eq=False)
class JobGeometry:
    """The parts of a job the analysis compares a run with.

    Attributes
    ----------
    name : str
    outer_radius_mm, scan_speed_mm_s, cut_length_mm : float
    regions : list of (k, 2) float
        Design cut regions (unwrapped unrolled frame, mm).
    corners : (c, 3) float
        The vertices of the pass paths that are true corners of the drawing: x, y (mm), focus
        offset into the material (mm).
    paths : tuple of ((k, 2) float, bool, float)
        Every distinct pass path (vertices, closed, focus offset mm).
    pass_paths : tuple of int
        Per pass, its index in ``paths``.
    pass_link : tuple of bool
        Per pass, entered from the pass before by a beam-on link (a chain is one beam-on run).
    link_length_mm : float
        Total length of the links (beam-on path that is not part of ``cut_length_mm``).
    estimate_s, lower_bound_s : float
        The job's time estimate and lower bound (s), NaN if unknown.
    """

    name: str
    outer_radius_mm: float
    scan_speed_mm_s: float
    cut_length_mm: float
    regions: tuple
    corners: np.ndarray
    estimate_s: float
    lower_bound_s: float
    frequency_khz: float = math.nan
    paths: tuple = ()
    pass_paths: tuple = ()
    pass_link: tuple = ()
    link_length_mm: float = 0.0

    @classmethod
    def from_job(cls, job, estimate_s: float = math.nan) -> "JobGeometry":
        """From a planned :class:`~camtube.plan.job.Job`."""
        from camtube.machine.bound import design_corners, true_corner_flags

        drawn = design_corners(job)
        rows = []
        for p in job.passes:
            pts = np.asarray(p.contour.points, float)
            keep = true_corner_flags(pts, drawn, p.offset_mm)
            rows.append(np.column_stack([pts[keep], np.full(int(keep.sum()), p.focus_offset_mm)]))
        corners = np.concatenate(rows) if rows else np.zeros((0, 3))
        pk = job.packed
        seen = sorted({(int(g), float(z)) for g, z in zip(pk.pass_geom.tolist(), pk.pass_z.tolist())})
        paths = tuple((np.asarray(pk.path_points(g), float), bool(pk.geom_closed[g]), z) for g, z in seen)
        index = {(g, z): k for k, (g, z) in enumerate(seen)}
        order = tuple(index[(int(g), float(z))] for g, z in zip(pk.pass_geom.tolist(), pk.pass_z.tolist()))
        return cls(job.name, float(job.outer_radius_mm), float(job.process.scan_speed_mm_s),
                   float(job.cut_length_mm), tuple(np.asarray(c.points, float) for c in job.design), corners,
                   float(estimate_s), float(job.cut_length_mm / job.process.scan_speed_mm_s),
                   float(job.process.frequency_khz), paths, order, tuple(bool(v) for v in pk.pass_link.tolist()),
                   float(job.link_length_mm))

    @classmethod
    def from_job_file(cls, path: str | os.PathLike) -> "JobGeometry":
        """From a job file (``NAME.job.json``, ``camtube.job/2``), expanded into its passes by
        :func:`camtube.export.jobfile.read_job`; the estimate is the file's ``summary.total_time_s``."""
        from camtube.export.jobfile import read_job

        try:
            d = parse_json(read_input_text(path))
        except OSError as exc:
            raise DataError(f"{path}: cannot read the job file: {exc.strerror}; fix: give the NAME.job.json written "
                            "next to the G-code") from None
        except ValueError as exc:
            raise DataError(f"{path}: not a camtube job file ({exc}); give the NAME.job.json written next to "
                            "the G-code") from None
        job = read_job(d) if isinstance(d, dict) else read_job(path)
        try:
            estimate_s = float(d["summary"]["total_time_s"])
        except (KeyError, TypeError, ValueError):
            estimate_s = math.nan
        return cls.from_job(job, estimate_s)


@dataclass(frozen=True)
class MotionReport:
    """Figures of one run (s, mm, mm/s); see the module docstring."""

    name: str
    machine: str
    run_time_s: float
    estimate_s: float
    lower_bound_s: float
    beam_on_time_s: float
    beam_on_length_mm: float
    cut_length_mm: float
    scan_speed_mm_s: float
    speed_share: float
    median_speed_mm_s: float
    max_outside_mm: float
    max_corner_miss_mm: float
    corners: int
    samples: int
    wall_s: float
    dose_share: float = math.nan
    nominal_pulses_per_mm: float = math.nan
    distance_gated: bool = False
    max_path_dev_mm: float = math.nan
    max_vertex_miss_mm: float = math.nan
    link_length_mm: float = 0.0

    @property
    def estimate_error(self) -> float:
        """estimate / run time - 1."""
        return self.estimate_s / self.run_time_s - 1.0

    @property
    def length_error(self) -> float:
        """beam-on length / cut length - 1 (the links of chained passes count against it)."""
        return self.beam_on_length_mm / self.cut_length_mm - 1.0

    @property
    def path_length_error(self) -> float:
        """beam-on length / (cut length + links) - 1: the beam-on path against every beam-on move commanded."""
        return self.beam_on_length_mm / (self.cut_length_mm + self.link_length_mm) - 1.0

    def table(self) -> str:
        """Plain-text table of the figures."""
        rows = [
            ("job / machine", f"{self.name} / {self.machine}", ""),
            ("run time (LinuxCNC)", f"{self.run_time_s:.3f}", f"s (real time {self.wall_s:.1f} s)"),
            ("estimate", f"{self.estimate_s:.3f}", f"s ({100 * self.estimate_error:+.2f} % of the run time)"),
            ("lower bound", f"{self.lower_bound_s:.3f}", f"s (run time / lower bound "
                                                        f"{self.run_time_s / self.lower_bound_s:.3f})"),
            ("beam-on time", f"{self.beam_on_time_s:.3f}", "s"),
            ("beam-on path", f"{self.beam_on_length_mm:.4f}", f"mm ({100 * self.length_error:+.3f} % of the "
                                                              f"cut length {self.cut_length_mm:.4f} mm"
                                                              + (f"; links {self.link_length_mm:.4f} mm, "
                                                                 f"{100 * self.path_length_error:+.3f} % of cut "
                                                                 "length + links)" if self.link_length_mm > 0
                                                                 else ")")),
            ("within +-5 % of scan speed", f"{100 * self.speed_share:.2f}", f"% of the beam-on path (scan "
                                                                            f"{self.scan_speed_mm_s:g} mm/s, median "
                                                                            f"{self.median_speed_mm_s:.2f})"),
            ("dose within +-5 %", f"{100 * self.dose_share:.2f}", f"% of the beam-on path (nominal "
                                                                 f"{self.nominal_pulses_per_mm:.1f} pulses/mm, "
                                                                 + ("distance-gated rate recorded)" if self.distance_gated
                                                                    else "time-gated: set frequency / speed)")),
            ("beam on outside cut regions", f"{1000 * self.max_outside_mm:.3f}", "um at most"),
            ("own pass: path, vertices", f"{1000 * self.max_path_dev_mm:.3f}, {1000 * self.max_vertex_miss_mm:.3f}",
             "um at most (each beam-on stretch against its own pass: samples from the path, the path's vertices "
             "from the beam)"),
            ("drawn corner missed by", f"{1000 * self.max_corner_miss_mm:.3f}", f"um at most ({self.corners} "
                                                                                "corners)"),
        ]
        w = max(len(r[0]) for r in rows)
        return "\n".join(f"{a:<{w}}  {b} {c}".rstrip() for a, b, c in rows)

    def as_dict(self) -> dict:
        d = dict(self.__dict__)
        d.update(estimate_error=self.estimate_error, length_error=self.length_error,
                 path_length_error=self.path_length_error)
        return d


def _surface(rec, ro: float, rotary: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    y = np.radians(rec.circ) * ro if rotary else rec.circ
    return rec.axial, y, -rec.focus


def _outside_mm(px: np.ndarray, py: np.ndarray, regions, circ: float) -> float:
    """Largest distance (mm) of the points from the union of the regions, periodic in y with period ``circ``."""
    import shapely

    if len(px) == 0:
        return 0.0
    polys = [shapely.Polygon(np.column_stack([r[:, 0], r[:, 1] + k * circ])) for r in regions for k in (-1, 0, 1, 2)]
    union = shapely.union_all(polys)
    shapely.prepare(union)
    yy = np.mod(py, circ)
    pts = np.unique(np.round(np.column_stack([px, yy]), 9), axis=0)
    inside = shapely.contains_xy(union, pts[:, 0], pts[:, 1])
    out = pts[~inside]
    if len(out) == 0:
        return 0.0
    return float(shapely.distance(union, shapely.points(out)).max())


def _seg_dist(p: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    L2 = np.einsum("ij,ij->i", ab, ab)
    t = np.where(L2 > 0, np.einsum("ij,ij->i", p - a, ab) / np.where(L2 > 0, L2, 1.0), 0.0)
    t = np.clip(t, 0.0, 1.0)
    q = a + ab * t[:, None]
    return np.hypot(*(p - q).T)


def _corner_miss_mm(corners: np.ndarray, a: np.ndarray, b: np.ndarray, fz: np.ndarray, circ: float) -> float:
    """Largest distance from a corner to the nearest beam-on segment (a -> b) at the corner's focus."""
    from scipy.spatial import cKDTree

    if len(corners) == 0:
        return 0.0
    worst = 0.0
    shift = np.floor(a[:, 1] / circ) * circ  # bring every segment near [0, C) by whole turns
    a = a - np.column_stack([np.zeros(len(a)), shift])
    b = b - np.column_stack([np.zeros(len(b)), shift])
    for f in np.unique(np.round(corners[:, 2], 6)):
        segs = np.flatnonzero(np.abs(fz - f) < 1e-4)
        cs = corners[np.abs(corners[:, 2] - f) < 1e-6][:, :2]
        cs = np.unique(np.round(np.column_stack([cs[:, 0], np.mod(cs[:, 1], circ)]), 9), axis=0)
        if len(segs) == 0:
            return math.inf
        sa, sb = a[segs], b[segs]
        ends = np.concatenate([sa, sb])
        owner = np.concatenate([np.arange(len(sa)), np.arange(len(sa))])
        tree = cKDTree(ends)
        best = np.full(len(cs), np.inf)
        k = min(8, len(ends))
        for dy in (-circ, 0.0, circ):
            q = cs + [0.0, dy]
            _, idx = tree.query(q, k=k)
            idx = idx.reshape(len(cs), k)
            for j in range(k):
                s = owner[idx[:, j]]
                best = np.minimum(best, _seg_dist(q, sa[s], sb[s]))
        worst = max(worst, float(best.max()))
    return worst


def _beam_runs(geom) -> list[tuple[int, ...]]:
    """The beam-on runs of a job: per run, the indices (into ``geom.paths``) of its passes' paths in order."""
    runs: list[list[int]] = []
    link = geom.pass_link or (False,) * len(geom.pass_paths)
    for k, linked in zip(geom.pass_paths, link):
        if linked and runs:
            runs[-1].append(k)
        else:
            runs.append([k])
    return [tuple(r) for r in runs]


def _own_pass_mm(rec_x, rec_y, gate, geom) -> tuple[float, float]:
    """(farthest beam-on sample from its own pass's path, farthest vertex of a pass's path from its own beam-on
    path), mm: the k-th stretch of samples with the gate open is the k-th beam-on run, a pass or a chain of
    linked passes, whose path is its passes' paths joined by the links (NaN if the counts differ)."""
    import shapely

    g = gate[1:].astype(np.int8)  # the gate of sample k + 1 is that of the step k -> k + 1
    edges = np.flatnonzero(np.diff(np.concatenate(([0], g, [0]))))
    starts, ends = edges[::2], edges[1::2]  # the beam is on from sample s to sample e (gate set at s + 1 .. e)
    runs = _beam_runs(geom)
    if len(starts) != len(runs) or not runs:
        return math.nan, math.nan
    dev = miss = 0.0
    lines = {}
    for s, e, k in zip(starts.tolist(), ends.tolist(), runs):
        pts = np.column_stack([rec_x[s:e + 1], rec_y[s:e + 1]])
        line = lines.get(k)
        if line is None:
            rings = []
            for j in k:
                pp, closed, _ = geom.paths[j]
                rings.append(np.vstack([pp, pp[:1]]) if closed else pp)
            line = lines[k] = shapely.LineString(np.concatenate(rings))  # a link joins each ring to the next
        dev = max(dev, float(shapely.distance(line, shapely.points(pts)).max()))
        beam = shapely.LineString(pts) if len(pts) > 1 else shapely.Point(pts[0])
        miss = max(miss, float(shapely.distance(beam, shapely.points(np.asarray(line.coords))).max()))
    return dev, miss


def analyse(rec, geom: JobGeometry, profile, estimate_s: float | None = None) -> MotionReport:
    """Measure a :class:`~camtube.motion.linuxcnc.Recording` against the job it ran.

    Parameters
    ----------
    rec : Recording
    geom : JobGeometry
    profile : MachineProfile
        The profile the run used (rotary or flat).
    estimate_s : float, optional
        The estimate to compare with (default: the job's).
    """
    ro = geom.outer_radius_mm
    circ = 2.0 * math.pi * ro if profile.rotary else math.inf
    x, y, z = _surface(rec, ro, profile.rotary)
    on = rec.gate[1:]  # step k -> k + 1 runs with the gate (and pulse rate) of sample k + 1
    dx, dy = np.diff(x), np.diff(y)
    seg = np.hypot(dx, dy)
    dt = np.diff(rec.cycle) * rec.period_s
    lo = seg[on]
    length = float(lo.sum())
    speed = lo / dt[on]
    v = geom.scan_speed_mm_s
    within = np.abs(speed / v - 1.0) <= SPEED_BAND
    share = float(lo[within].sum() / length) if length > 0 else 0.0
    if length > 0:  # length-weighted median speed
        order = np.argsort(speed)
        c = np.cumsum(lo[order])
        median = float(speed[order][np.searchsorted(c, 0.5 * c[-1])])
    else:
        median = 0.0
    ia = np.flatnonzero(on)
    a = np.column_stack([x[ia], y[ia]])
    b = np.column_stack([x[ia + 1], y[ia + 1]])
    if profile.rotary:
        pts = np.unique(np.concatenate([a, b]), axis=0)
        outside = _outside_mm(pts[:, 0], pts[:, 1], geom.regions, circ)
        miss = _corner_miss_mm(geom.corners, a, b, z[ia], circ)
    else:
        big = 1e9
        pts = np.unique(np.concatenate([a, b]), axis=0)
        outside = _outside_mm(pts[:, 0], pts[:, 1], geom.regions, big)
        miss = _corner_miss_mm(geom.corners, a, b, z[ia], big)
    path_dev, vertex_miss = _own_pass_mm(x, y, rec.gate, geom)
    est = geom.estimate_s if estimate_s is None else float(estimate_s)
    nominal = 1000.0 * geom.frequency_khz / v
    rate = getattr(rec, "rate_khz", None)
    with np.errstate(divide="ignore", invalid="ignore"):
        if rate is not None:  # pulses fired over each beam-on interval per mm moved
            ppmm = 1000.0 * rate[1:][on] * dt[on] / lo
        else:  # time gating: the set frequency, whatever the speed
            ppmm = 1000.0 * geom.frequency_khz / speed
    good = np.abs(ppmm / nominal - 1.0) <= SPEED_BAND
    dose_share = float(lo[good].sum() / length) if length > 0 else 0.0
    return MotionReport(geom.name, profile.name, rec.run_time_s, est, geom.lower_bound_s, float(dt[on].sum()),
                        length, geom.cut_length_mm, v, share, median, outside, miss, len(geom.corners), len(rec),
                        rec.wall_s, dose_share, nominal, rate is not None, path_dev, vertex_miss,
                        geom.link_length_mm)
