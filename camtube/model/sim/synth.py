"""Synthetic measurements from the base model, so a new user can try the fit loop at once.

What the generator does (per sample, all lengths mm, forces N, angles deg):

* stroke: ``n_cycles`` triangles 0 -> ``max_stroke`` -> 0 at a constant
  lead-screw speed, sampled at ``rate_hz`` (an EM tracker's rate);
* tendon slack: the first ``slack_mm`` of stroke moves nothing (deadband);
* angle and force from the closed base model with a joint bending stiffness
  (:func:`camtube.model.core.predict.stroke_only_angle_rad`):
  ``theta = s / (arm + K C / arm)``, ``F = K theta / arm``,
  ``s = max(stroke - slack, 0)``; each sample's stiffness is the
  pattern's ``K`` times a factor drawn from ``1 +- stiffness_spread``;
* noise: Gaussian, ``noise_angle_deg`` on the angle (EM tracker, ~0.25 deg)
  and ``noise_force_N`` on the force (small load cell, ~5 mN).

No hysteresis, creep or first-cycle effect: this is the paper's model plus
sensor noise, so fitting it returns the generating ``E_t`` and an RMSE at the
noise floor ``sqrt(sigma_angle^2 + (deg(C / arm) sigma_F)^2)``
(:func:`noise_floor_deg`). Deterministic for a given ``seed``.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from camtube.design.geometry import pattern_geometry
from camtube.design.pattern import Pattern
from camtube.errors import DataError
from camtube.model.data.dataset import Dataset
from camtube.model.core.predict import (
    POLYIMIDE_MODULUS_GPA, joint_stiffness_nmm_per_rad, pattern_compliance_mm_per_N, stroke_only_angle_rad,
)


def triangle_stroke(max_stroke_mm: float, speed_mm_s: float, rate_hz: float,
                    n_cycles: int, dwell_s: float = 0.0) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time (s), stroke (mm) and cycle (1-based) of ``n_cycles`` triangles 0 -> max -> 0.

    Each cycle ramps up and down at ``speed_mm_s`` and then rests ``dwell_s`` at 0.
    Returns arrays of shape ``(n_cycles * m,)``, ``m = round(period * rate)``
    samples per cycle (at least 6); each cycle starts at stroke 0.
    """
    ramp = max_stroke_mm / speed_mm_s
    period = 2.0 * ramp + dwell_s
    m = max(int(round(period * rate_hz)), 6)
    t1 = np.arange(m) / m * period
    s1 = np.clip(max_stroke_mm - np.abs(max_stroke_mm - speed_mm_s * t1), 0.0, None)
    s1[t1 > 2.0 * ramp] = 0.0
    time = (np.arange(n_cycles)[:, None] * period + t1[None, :]).ravel()
    stroke = np.tile(s1, n_cycles)
    cycle = np.repeat(np.arange(1, n_cycles + 1), m)
    return time, stroke, cycle


#: Largest sensor noise a synthetic file may have (a standard deviation): more is no measurement (``model fit`` refuses
#: such readings) but a typing error.
MAX_NOISE_ANGLE_DEG = 10.0
MAX_NOISE_FORCE_N = 1.0
#: Most rows one synthetic file may have (about 100 MB of CSV); more is a typing error, not a data set.
MAX_ROWS = 2_000_000


def rows_per_cycle(max_stroke_mm: float, speed_mm_s: float, rate_hz: float, dwell_s: float = 0.0) -> int:
    """Rows of one triangle cycle (see :func:`triangle_stroke`), computed without allocating them."""
    return max(int(round((2.0 * max_stroke_mm / speed_mm_s + dwell_s) * rate_hz)), 6)


def check_arguments(n_samples: int, n_cycles: int, noise_angle_deg: float, noise_force_N: float, *,
                    modulus_gpa: float | None, max_stroke_mm: float, speed_mm_s: float, rate_hz: float,
                    slack_mm: float, stiffness_spread: float = 0.1, dwell_s: float = 0.0, seed: int = 0) -> None:
    """Refuse generator settings that make no physical sense or an absurd file.

    Raises
    ------
    DataError
        Naming the setting (with its command-line option), the value and the allowed range.
    """
    from camtube.model.core.model import BASE_PARAMS

    e_lo, e_hi = next((p.lo, p.hi) for p in BASE_PARAMS if p.name == "E_t")

    def bad(name: str, value, allowed: str) -> DataError:
        return DataError(f"{name} = {value!r}: allowed {allowed}; fix: give a value in that range")

    checks = (
        (n_samples >= 1, "samples (--samples)", n_samples, ">= 1"),
        (n_cycles >= 1, "cycles (--cycles)", n_cycles, ">= 1"),
        (math.isfinite(noise_angle_deg) and 0 <= noise_angle_deg <= MAX_NOISE_ANGLE_DEG, "angle noise (--noise-angle)",
         noise_angle_deg, f"0..{MAX_NOISE_ANGLE_DEG:g} deg (a standard deviation)"),
        (math.isfinite(noise_force_N) and 0 <= noise_force_N <= MAX_NOISE_FORCE_N, "force noise (--noise-force)",
         noise_force_N, f"0..{MAX_NOISE_FORCE_N:g} N (a standard deviation)"),
        (math.isfinite(speed_mm_s) and speed_mm_s > 0, "stroke speed (--speed)", speed_mm_s, "> 0 mm/s"),
        (math.isfinite(rate_hz) and rate_hz > 0, "sampling rate (--rate)", rate_hz, "> 0 Hz"),
        (math.isfinite(max_stroke_mm) and max_stroke_mm > 0, "peak stroke (rules.max_stroke)", max_stroke_mm,
         "> 0 mm"),
        (math.isfinite(slack_mm) and 0 <= slack_mm < max_stroke_mm, "slack (--slack)", slack_mm,
         f"0 <= slack < the peak stroke {max_stroke_mm:g} mm"),
        (modulus_gpa is None or (math.isfinite(modulus_gpa) and e_lo <= modulus_gpa <= e_hi),
         "tendon modulus (--modulus)", modulus_gpa, f"{e_lo:g}..{e_hi:g} GPa (the range a fit takes E_t in)"),
        (0 <= stiffness_spread < 1, "stiffness spread", stiffness_spread, "0 <= spread < 1"),
        (seed is None or 0 <= seed < 2 ** 63, "random seed (--seed)", seed, "a whole number 0 <= seed < 2**63"),
    )
    for ok, name, value, allowed in checks:
        if not ok:
            raise bad(name, value, allowed)
    m = rows_per_cycle(max_stroke_mm, speed_mm_s, rate_hz, dwell_s)
    rows = m * n_cycles * n_samples
    if m < 12:
        m = int(round((2.0 * max_stroke_mm / speed_mm_s + dwell_s) * rate_hz))   # (as sampled: not the floor of 6)
        raise DataError(f"sampling rate (--rate) = {rate_hz!r}: only {m} rows per cycle "
                        f"({2 * max_stroke_mm / speed_mm_s:g} s); allowed: at least 12 rows per cycle, "
                        f"i.e. --rate >= {12 * speed_mm_s / (2 * max_stroke_mm):.3g} Hz at --speed {speed_mm_s:g}; "
                        "fix: raise --rate or lower --speed")
    if rows > MAX_ROWS:
        raise DataError(f"{n_samples} sample(s) x {n_cycles} cycles x {m} rows per cycle = {rows:,} rows: "
                        f"allowed at most {MAX_ROWS:,}; fix: lower --rate, --cycles or --samples, or raise --speed")


def noise_floor_deg(pattern: Pattern, noise_angle_deg: float = 0.25, noise_force_N: float = 0.005,
                    modulus_gpa: float | None = None) -> float:
    """RMSE (deg) a perfect base model leaves on noisy data: ``sqrt(sa^2 + (deg(C/arm) sF)^2)``."""
    g = pattern_geometry(pattern).first
    e_t = pattern.tendon.modulus_gpa if modulus_gpa is None else modulus_gpa
    c = pattern_compliance_mm_per_N(pattern, e_t)
    return math.hypot(noise_angle_deg, math.degrees(c / g.moment_arm_mm) * noise_force_N)


def synthesize(
    pattern: Pattern,
    n_samples: int = 2,
    n_cycles: int = 50,
    noise_angle_deg: float = 0.25,
    noise_force_N: float = 0.005,
    seed: int = 0,
    *,
    modulus_gpa: float | None = None,
    max_stroke_mm: float | None = None,
    speed_mm_s: float = 0.5,
    rate_hz: float = 40.0,
    slack_mm: float = 0.05,
    stiffness_nmm_per_rad: float | None = None,
    stiffness_spread: float = 0.1,
) -> Dataset:
    """A synthetic measurement :class:`Dataset` of ``pattern`` from the base model.

    Parameters
    ----------
    pattern : Pattern
        Geometry, tendon (E_t, L0, r_t) and ``rules.max_stroke``.
    n_samples, n_cycles : int
        Samples ``"1"``, ``"2"``, ... each with cycles 1..n_cycles.
    noise_angle_deg, noise_force_N : float
        Standard deviations of the Gaussian sensor noise.
    seed : int
        Seed of :func:`numpy.random.default_rng`.
    modulus_gpa : float, optional
        Tendon E_t used to generate (default: the pattern's).
    max_stroke_mm : float, optional
        Peak stroke (default: ``pattern.rules.max_stroke``).
    speed_mm_s, rate_hz : float
        Lead-screw speed and sampling rate.
    slack_mm : float
        Tendon slack at the start of every cycle.
    stiffness_nmm_per_rad : float, optional
        Joint stiffness K (default: E_pi I / (n h) with E_pi = 2.5 GPa).
    stiffness_spread : float
        Relative spread of K between samples (uniform in +- spread).

    Returns
    -------
    Dataset
        ``n_samples * n_cycles * m`` rows; ``extra`` is empty.
    """
    smax = pattern.rules.max_stroke_mm if max_stroke_mm is None else max_stroke_mm
    check_arguments(n_samples, n_cycles, noise_angle_deg, noise_force_N, modulus_gpa=modulus_gpa,
                    max_stroke_mm=smax, speed_mm_s=speed_mm_s, rate_hz=rate_hz, slack_mm=slack_mm,
                    stiffness_spread=stiffness_spread, seed=seed)
    rng = np.random.default_rng(seed)
    g = pattern_geometry(pattern).first
    e_t = pattern.tendon.modulus_gpa if modulus_gpa is None else modulus_gpa
    c = pattern_compliance_mm_per_N(pattern, e_t)
    k0 = (joint_stiffness_nmm_per_rad(pattern, POLYIMIDE_MODULUS_GPA)
          if stiffness_nmm_per_rad is None else stiffness_nmm_per_rad)
    time, stroke, cycle = triangle_stroke(smax, speed_mm_s, rate_hz, n_cycles)
    arm = g.moment_arm_mm
    cols: dict[str, list[np.ndarray]] = {k: [] for k in ("sample", "cycle", "time", "stroke", "force", "angle")}
    for i in range(n_samples):
        k = k0 * (1.0 + stiffness_spread * rng.uniform(-1.0, 1.0))
        theta = stroke_only_angle_rad(stroke - slack_mm, arm, k, c)
        force = k * theta / arm
        m = stroke.shape[0]
        cols["sample"].append(np.full(m, str(i + 1), dtype=object))
        cols["cycle"].append(cycle)
        cols["time"].append(time)
        cols["stroke"].append(stroke)
        cols["force"].append(force + rng.normal(0.0, noise_force_N, m))
        cols["angle"].append(np.degrees(theta) + rng.normal(0.0, noise_angle_deg, m))
    cat = {k: np.concatenate(v) for k, v in cols.items()}
    return Dataset(cat["sample"], cat["cycle"].astype(int), cat["time"], cat["stroke"],
                   cat["force"], cat["angle"])


def to_csv(dataset: Dataset) -> str:
    """The CSV text of ``dataset`` (see :func:`camtube.model.data.format_csv`)."""
    from camtube.model.data.csvfile import format_csv

    return format_csv(dataset)


def write(dataset: Dataset, path: str | Path) -> Path:
    """Write ``dataset`` as CSV to ``path`` atomically; returns the path."""
    from camtube.io import write_atomic

    return write_atomic(path, to_csv(dataset))
