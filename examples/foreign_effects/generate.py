"""Measurements with physics camtube's effect library does not ship (an independent simulator, numpy only).

This script knows nothing of camtube's model code: it has its own time-stepping
joint simulation and its own CSV writer. It writes camtube's measurement format
(``sample, cycle, time_s, stroke_mm, force_N, angle_deg``).

The joint
---------
A motor pulls the tendon with a triangular stroke ``x_m(t)`` (0 -> max -> 0 at
``speed`` mm/s, ``cycles`` times). The stroke that reaches the tendon is
``x = x_m + e_drive(x_m) + e_osc(t) - set``. Each time step solves, for the
joint angle ``theta`` (rad) and the tension ``T`` (N),

* length:  ``x = L_kin(theta) + C T``, ``L_kin = integral of a(theta) dtheta``,
  ``C = L0 / (E_t pi r_t^2)``,
* moment:  ``T a(theta) = K (theta - theta_0)``,

by Newton's method from the previous step (the tendon cannot push: where
``x < L_kin(theta_0)`` it is slack, ``T = 0``, ``theta = theta_0``). The
measured force is ``T - T_tare + noise``, the measured angle
``deg(theta) + noise``.

Effects (``--effect``; each one alone, or ``none`` for a control)
-----------------------------------------------------------------
``drive``        periodic error of the lead screw: ``e_drive = A sin(2 pi x_m / P + phi)``
                 (``amp_mm``, ``period_mm``, ``phase_rad``)
``arm``          moment arm that changes with the bend angle: ``a = a_0 (1 + beta theta)``
                 (``beta_per_rad``)
``set``          permanent set in the first cycle: above a yield tension (``yield_frac`` of the
                 first cycle's peak) the tendon stretches plastically and its compliance grows,
                 in proportion to the largest tension of the first cycle; later cycles keep both
                 (``set_mm`` and the relative softening ``soften`` reached at the peak)
``oscillation``  slow oscillation of the tendon length in time (temperature):
                 ``e_osc = A sin(2 pi t / P + phi)`` (``amp_mm``, ``period_s``, ``phase_rad``)
``rest_moment``  a bending moment at rest (a pre-bent tube held straight by the tendon) with the
                 load cell tared at rest (``moment_Nmm``): the tare hides the pretension
``none``         a control

Samples differ in joint stiffness (``--stiffness-spread``) and, with
``--param-spread``, in the effect's size. Seeds and every parameter are
arguments, so a fresh held-out batch can be made later.

Run::

    python examples/foreign_effects/generate.py --effect drive -o drive.csv
    python examples/foreign_effects/generate.py --effect drive --param period_mm=0.7 --seed 7 -o d7.csv

The truth (effect, parameters per sample, noise floor) is printed as JSON and
returned by :func:`simulate` for tests.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

EFFECTS = ("none", "drive", "arm", "set", "oscillation", "rest_moment")

#: Default parameters of each effect (sized to leave the base model at a few times the noise floor).
DEFAULTS: dict[str, dict[str, float]] = {
    "none": {},
    "drive": {"amp_mm": 0.02, "period_mm": 0.5, "phase_rad": 0.4},
    "arm": {"beta_per_rad": 0.6},
    "set": {"set_mm": 0.1, "soften": 0.2, "yield_frac": 0.5},
    "oscillation": {"amp_mm": 0.03, "period_s": 37.0, "phase_rad": 1.0},
    "rest_moment": {"moment_Nmm": 1.5},
}

#: The variable each effect's residual follows first, and the period's unit (for tests and reports).
TRUTH_VARIABLE = {"drive": "stroke", "arm": "angle", "set": "first_cycle", "oscillation": "time"}


@dataclass(frozen=True)
class Joint:
    """A notched-tube joint and its test rig (defaults: tube2 of camtube's patterns).

    Attributes
    ----------
    arm_mm : float
        Moment arm at zero bend, mm.
    stiffness_nmm_per_rad : float
        Bending stiffness K, N mm/rad.
    tendon_length_mm, tendon_modulus_gpa, tendon_radius_mm : float
        L0, E_t and r_t of the tendon.
    max_stroke_mm, speed_mm_s, rate_hz : float
        Triangle stroke peak, motor speed and sampling rate.
    """

    arm_mm: float = 1.0472
    stiffness_nmm_per_rad: float = 7.143
    tendon_length_mm: float = 70.0
    tendon_modulus_gpa: float = 28.0
    tendon_radius_mm: float = 0.04
    max_stroke_mm: float = 2.5
    speed_mm_s: float = 0.5
    rate_hz: float = 40.0

    @property
    def compliance_mm_per_N(self) -> float:
        return self.tendon_length_mm / (self.tendon_modulus_gpa * 1e3 * math.pi * self.tendon_radius_mm**2)


@dataclass(frozen=True)
class Truth:
    """What :func:`simulate` hid: per-sample parameters and the sensor floor."""

    effect: str
    params: dict = field(default_factory=dict)       # sample -> {name: value}
    noise_angle_deg: float = 0.25
    noise_force_N: float = 0.005
    sensor_floor_deg: float = 0.0
    seed: int = 0

    def as_dict(self) -> dict:
        return {"effect": self.effect, "params": self.params, "noise_angle_deg": self.noise_angle_deg,
                "noise_force_N": self.noise_force_N, "sensor_floor_deg": self.sensor_floor_deg,
                "seed": self.seed, "follows": TRUTH_VARIABLE.get(self.effect)}


def triangle(j: Joint, cycles: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Time (s), motor stroke (mm), cycle number of ``cycles`` triangles 0 -> max -> 0."""
    period = 2.0 * j.max_stroke_mm / j.speed_mm_s
    m = max(int(round(period * j.rate_hz)), 8)
    t1 = np.arange(m) * (period / m)
    s1 = j.max_stroke_mm - np.abs(j.max_stroke_mm - j.speed_mm_s * t1)
    t = (np.arange(cycles)[:, None] * period + t1[None, :]).ravel()
    return t, np.tile(s1, cycles), np.repeat(np.arange(1, cycles + 1), m)


def _solve(x: float, theta: float, a0: float, beta: float, k: float, c: float, theta0: float) -> float:
    """Joint angle (rad) for tendon stroke ``x``: ``L_kin(th) + C K (th - th0) / a(th) = x``, th >= th0."""

    def h(th: float) -> tuple[float, float]:
        a = a0 * (1.0 + beta * th)
        lk = a0 * (th + 0.5 * beta * th * th)
        g = lk + c * k * (th - theta0) / a - x
        dg = a + c * k * (a - (th - theta0) * a0 * beta) / (a * a)
        return g, dg

    g0, _ = h(theta0)
    if g0 >= 0.0:
        return theta0  # slack tendon: the joint rests
    th = max(theta, theta0)
    for _ in range(30):
        g, dg = h(th)
        step = g / dg
        th = max(th - step, theta0)
        if abs(step) < 1e-13:
            break
    return th


def simulate_sample(j: Joint, effect: str, p: dict, k: float, cycles: int,
                    rng: np.random.Generator, noise_angle_deg: float, noise_force_N: float) -> dict:
    """One sample's rows (dict of arrays) with ``effect`` and parameters ``p``."""
    t, xm, cyc = triangle(j, cycles)
    c = j.compliance_mm_per_N
    a0 = j.arm_mm
    beta = p.get("beta_per_rad", 0.0) if effect == "arm" else 0.0
    theta0 = -p["moment_Nmm"] / k if effect == "rest_moment" else 0.0
    drive = (p["amp_mm"] * np.sin(2 * math.pi * xm / p["period_mm"] + p["phase_rad"])
             if effect == "drive" else np.zeros_like(xm))
    osc = (p["amp_mm"] * np.sin(2 * math.pi * t / p["period_s"] + p["phase_rad"])
           if effect == "oscillation" else np.zeros_like(xm))
    # the first cycle's peak tension without the set, to scale the plastic stretch
    t_peak_ref = None
    if effect == "set":
        th = _solve(float(xm.max()), 0.0, a0, beta, k, c, theta0)
        t_peak_ref = k * (th - theta0) / (a0 * (1.0 + beta * th))
    theta = np.empty_like(xm)
    tension = np.empty_like(xm)
    th, peak, set_mm, c_now = theta0, 0.0, 0.0, c
    for i in range(xm.size):          # time stepping: the set depends on the history of the tension
        x = xm[i] + drive[i] + osc[i] - set_mm
        th = _solve(float(x), th, a0, beta, k, c_now, theta0)
        tn = k * (th - theta0) / (a0 * (1.0 + beta * th))
        theta[i], tension[i] = th, tn
        if effect == "set" and cyc[i] == 1:
            peak = max(peak, tn)
            y = p["yield_frac"] * t_peak_ref
            progress = max(peak - y, 0.0) / (t_peak_ref - y)
            set_mm = p["set_mm"] * progress
            c_now = c * (1.0 + p["soften"] * progress)
    tare = 0.0
    if effect == "rest_moment":   # tared at rest (x = 0): the pretension of the tendon holding the bend
        th_rest = _solve(0.0, theta0, a0, beta, k, c, theta0)
        tare = k * (th_rest - theta0) / a0
    n = xm.size
    return {"cycle": cyc, "time": t, "stroke": xm,
            "force": tension - tare + rng.normal(0.0, noise_force_N, n),
            "angle": np.degrees(theta) + rng.normal(0.0, noise_angle_deg, n)}


def simulate(effect: str = "none", params: dict | None = None, *, samples: int = 2, cycles: int = 50,
             seed: int = 0, joint: Joint = Joint(), noise_angle_deg: float = 0.25, noise_force_N: float = 0.005,
             stiffness_spread: float = 0.1, param_spread: float = 0.0) -> tuple[dict, Truth]:
    """Simulate ``samples`` samples with one foreign ``effect``.

    Parameters
    ----------
    effect : str
        One of :data:`EFFECTS`.
    params : dict, optional
        Effect parameters overriding :data:`DEFAULTS`.
    samples, cycles, seed : int
    joint : Joint
    noise_angle_deg, noise_force_N : float
        Gaussian sensor noise (deg, N).
    stiffness_spread : float
        Relative spread of K between samples (uniform +-).
    param_spread : float
        Relative spread of the effect's size (amplitudes, set, beta, moment) between samples.

    Returns
    -------
    rows : dict of (n,) arrays
        ``sample`` (str), ``cycle``, ``time``, ``stroke``, ``force``, ``angle``.
    truth : Truth
    """
    if effect not in EFFECTS:
        raise ValueError(f"unknown effect {effect!r}; choose one of {', '.join(EFFECTS)}")
    base = dict(DEFAULTS[effect])
    unknown = set(params or {}) - set(base)
    if unknown:
        raise ValueError(f"effect {effect!r} has no parameter(s) {sorted(unknown)}; it has {sorted(base)}")
    base.update(params or {})
    rng = np.random.default_rng(seed)
    cols: dict[str, list] = {k: [] for k in ("sample", "cycle", "time", "stroke", "force", "angle")}
    per: dict[str, dict] = {}
    for s in range(samples):
        name = f"S{s + 1}"
        k = joint.stiffness_nmm_per_rad * (1.0 + stiffness_spread * rng.uniform(-1.0, 1.0))
        p = dict(base)
        if param_spread:
            f = 1.0 + param_spread * rng.uniform(-1.0, 1.0)
            for key in ("amp_mm", "beta_per_rad", "set_mm", "soften", "moment_Nmm"):
                if key in p:
                    p[key] *= f
        per[name] = {kk: round(float(v), 9) for kk, v in p.items()}
        per[name]["stiffness_nmm_per_rad"] = round(float(k), 6)
        rows = simulate_sample(joint, effect, p, k, cycles, rng, noise_angle_deg, noise_force_N)
        cols["sample"].append(np.full(rows["stroke"].size, name, dtype=object))
        for key in ("cycle", "time", "stroke", "force", "angle"):
            cols[key].append(rows[key])
    out = {k: np.concatenate(v) for k, v in cols.items()}
    floor = math.hypot(noise_angle_deg, math.degrees(joint.compliance_mm_per_N / joint.arm_mm) * noise_force_N)
    return out, Truth(effect, per, noise_angle_deg, noise_force_N, floor, seed)


def to_csv(rows: dict) -> str:
    """camtube's measurement CSV text (header ``sample,cycle,time_s,stroke_mm,force_N,angle_deg``)."""
    lines = ["sample,cycle,time_s,stroke_mm,force_N,angle_deg"]
    for s, c, t, x, f, a in zip(rows["sample"], rows["cycle"], rows["time"], rows["stroke"], rows["force"],
                                rows["angle"]):
        lines.append(f"{s},{int(c)},{t:.4f},{x:.6f},{f:.6f},{a:.5f}")
    return "\n".join(lines) + "\n"


def _parse_params(items: list[str]) -> dict:
    out = {}
    for it in items:
        key, sep, val = it.partition("=")
        if not sep:
            raise SystemExit(f"--param {it!r}: expected NAME=VALUE")
        out[key.strip()] = float(val)
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--effect", default="none", choices=EFFECTS)
    ap.add_argument("--param", action="append", default=[], metavar="NAME=VALUE",
                    help="effect parameter (see the module docstring); repeatable")
    ap.add_argument("-o", "--output", required=True, metavar="OUT.csv")
    ap.add_argument("--samples", type=int, default=2)
    ap.add_argument("--cycles", type=int, default=50)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--noise-angle", type=float, default=0.25, metavar="DEG")
    ap.add_argument("--noise-force", type=float, default=0.005, metavar="N")
    ap.add_argument("--stiffness-spread", type=float, default=0.1)
    ap.add_argument("--param-spread", type=float, default=0.0)
    ap.add_argument("--max-stroke", type=float, default=Joint.max_stroke_mm, metavar="MM")
    ap.add_argument("--rate", type=float, default=Joint.rate_hz, metavar="HZ")
    ap.add_argument("--truth", metavar="TRUTH.json", help="also write the hidden truth as JSON")
    a = ap.parse_args(argv)
    try:
        rows, truth = simulate(a.effect, _parse_params(a.param), samples=a.samples, cycles=a.cycles, seed=a.seed,
                               joint=Joint(max_stroke_mm=a.max_stroke, rate_hz=a.rate),
                               noise_angle_deg=a.noise_angle, noise_force_N=a.noise_force,
                               stiffness_spread=a.stiffness_spread, param_spread=a.param_spread)
    except ValueError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    Path(a.output).write_text(to_csv(rows), encoding="utf-8")
    text = json.dumps(truth.as_dict(), indent=2, sort_keys=True)
    if a.truth:
        Path(a.truth).write_text(text + "\n", encoding="utf-8")
    print(f"wrote {a.output}: {rows['stroke'].size} rows")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
