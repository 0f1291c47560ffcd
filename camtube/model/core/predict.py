"""Joint angle from the tendon stroke alone: what a pattern will do before it is cut.

The paper's model ``L_t = arm theta + F L0 / (E_t pi r_t^2)`` needs the
tendon force. Without a measurement, the force follows from the joint's
bending stiffness: the backbone of each notch (length ``h``, second moment
``I``, polyimide modulus ``E_pi``) bends like a short beam, the ``n``
notches act in series, so the joint stiffness is

    K = 1 / sum_i (h_i / (E_pi I_i))   (= E_pi I / (n h) for equal notches), N mm/rad

and the moment balance ``F arm = K theta`` closes the model:

    theta = L / (arm + K C / arm),   C = L0 / (E_t pi r_t^2)  (mm/N)

``E_pi`` is 2.5 GPa by default (a typical polyimide); a stiffness fitted to
measured force and angle (:func:`stiffness_from_data`) can be used instead.
This module also builds the :class:`~camtube.model.core.model.JointModel` of a
pattern (:func:`model_for_pattern`) and its base parameter values
(:func:`pattern_values`), which the fit and the CLI share.
"""
from __future__ import annotations

import math
from typing import Mapping, Sequence

import numpy as np

from camtube.design.geometry import MATERIAL_MODULUS_GPA, notches_by_direction, pattern_geometry
from camtube.design.pattern import Pattern
from camtube.model.core.model import Effect, JointModel
from camtube.model.core.params import tendon_compliance_mm_per_N
from camtube.model.data.dataset import Dataset

#: Default Young's modulus of polyimide (GPa) for the bending stiffness.
POLYIMIDE_MODULUS_GPA = MATERIAL_MODULUS_GPA["polyimide"]


def model_for_pattern(pattern: Pattern, effects: Sequence[Effect | str] = (), registry=None) -> JointModel:
    """The :class:`JointModel` of ``pattern`` (first notch's geometry, notch count, tendon radius).

    ``effects`` are objects or names looked up in ``registry`` (default: the built-ins).
    """
    geo = pattern_geometry(pattern)
    model = JointModel(geometry=geo.first, n_notches=len(geo.notches),
                       tendon_radius_mm=pattern.tendon.radius_mm)
    if not effects:
        return model
    if registry is None and any(isinstance(e, str) for e in effects):
        from camtube.model.core.registry import builtin_registry

        registry = builtin_registry()
    return model.with_effects(effects, registry)


def pattern_compliance_mm_per_N(pattern: Pattern, modulus_gpa: float | None = None) -> float:
    """Tendon compliance C = L0 / (E_t pi r_t^2) (mm/N) of ``pattern`` (E_t from the pattern unless given)."""
    e_t = pattern.tendon.modulus_gpa if modulus_gpa is None else modulus_gpa
    return tendon_compliance_mm_per_N(pattern.tendon.length_mm, e_t, pattern.tendon.radius_mm)


def pattern_values(pattern: Pattern) -> dict[str, float]:
    """Base parameter values taken from the pattern: ``E_t`` (GPa), ``L0`` (mm), ``arm_scale`` = 1."""
    return {"E_t": float(pattern.tendon.modulus_gpa), "L0": float(pattern.tendon.length_mm),
            "arm_scale": 1.0}


def joint_stiffness_nmm_per_rad(pattern: Pattern, modulus_gpa: float = POLYIMIDE_MODULUS_GPA) -> float:
    """Bending stiffness K (N mm/rad) of the whole joint: notches' backbones in series.

    Parameters
    ----------
    pattern : Pattern
    modulus_gpa : float
        Tube material's Young's modulus (GPa); 2.5 for polyimide.
    """
    geo = pattern_geometry(pattern)
    e = modulus_gpa * 1e3  # N/mm^2
    flex = sum(g.notch_width_mm / (e * g.second_moment_mm4) for g in geo.notches)  # rad/(N mm)
    return 1.0 / flex


def stroke_only_angle_rad(
    stroke_mm: np.ndarray,
    arm_mm: float,
    stiffness_nmm_per_rad: float,
    compliance_mm_per_N: float,
) -> np.ndarray:
    """Closed-form angle of the base model from stroke alone.

    ``theta = L / (arm + K C / arm)``; negative strokes (slack tendon) give 0.

    Parameters
    ----------
    stroke_mm : (n,) float
        Tendon stroke past the slack, mm.
    arm_mm : float
        Moment arm ybar + r_i - r_t, mm.
    stiffness_nmm_per_rad : float
        Joint bending stiffness K.
    compliance_mm_per_N : float
        Tendon compliance C = L0 / (E_t pi r_t^2).

    Returns
    -------
    (n,) float
        Joint angle, rad.
    """
    s = np.clip(np.asarray(stroke_mm, float), 0.0, None)
    return s / (arm_mm + stiffness_nmm_per_rad * compliance_mm_per_N / arm_mm)


def predict_from_stroke(
    model: JointModel,
    values: Mapping[str, float],
    stroke_mm: np.ndarray,
    stiffness_nmm_per_rad: float,
    *,
    tol_N: float = 1e-9,
) -> tuple[np.ndarray, np.ndarray]:
    """Angle and force from stroke alone for any model (base plus effects).

    Solves ``F arm = K theta(stroke, F)`` row by row: closed form for the base
    model, vectorised bisection on F otherwise (each row's force is treated as
    independent, so history effects see the solved force only at the end).

    Parameters
    ----------
    model : JointModel
    values : dict
        Full parameter values (``E_t``, ``L0``, ...).
    stroke_mm : (n,) float
        Tendon stroke, mm (rows in time order if effects use history).
    stiffness_nmm_per_rad : float
        Joint bending stiffness K.

    Returns
    -------
    angle_deg : (n,) float
    force_N : (n,) float
    """
    stroke = np.asarray(stroke_mm, float)
    n = stroke.shape[0]
    arm = model.geometry.moment_arm_mm * float(values.get("arm_scale", 1.0))
    k = float(stiffness_nmm_per_rad)
    if not model.effects:
        c = model.compliance_mm_per_N(values)
        theta = stroke_only_angle_rad(stroke, arm, k, c)
        return np.degrees(theta), k * theta / arm

    def data_with(force: np.ndarray) -> Dataset:
        return Dataset(np.full(n, "s", dtype=object), np.ones(n, int), np.arange(n, dtype=float),
                       stroke, force, np.zeros(n))

    # g(F) = F - K theta(F) / arm is increasing in F; bracket [0, F_hi]
    f_lo = np.zeros(n)
    f_hi = np.full(n, k * max(float(np.max(np.abs(stroke), initial=0.0)), 1e-6) / arm**2 * 10.0 + 1.0)
    for _ in range(80):
        mid = 0.5 * (f_lo + f_hi)
        th = np.radians(model.predict(data_with(mid), values))
        g = mid - k * th / arm
        f_hi = np.where(g > 0, mid, f_hi)
        f_lo = np.where(g > 0, f_lo, mid)
        if float(np.max(f_hi - f_lo, initial=0.0)) < tol_N:
            break
    force = 0.5 * (f_lo + f_hi)
    return model.predict(data_with(force), values), force


def stiffness_from_data(data: Dataset, arm_mm: float) -> float:
    """Joint stiffness K (N mm/rad) from measured force and angle, least squares through 0.

    ``F arm = K theta``: ``K = arm sum(F theta) / sum(theta^2)``.
    """
    th = np.radians(np.asarray(data.angle_deg, float))
    f = np.asarray(data.force_N, float)
    den = float(np.dot(th, th))
    if den <= 0:
        raise ValueError("the data have no joint angle: stiffness is undefined")
    return arm_mm * float(np.dot(f, th)) / den


def design_summary(pattern: Pattern, steps: int = 5,
                   modulus_gpa: float = POLYIMIDE_MODULUS_GPA) -> str:
    """Text table of the predicted stroke-angle curve up to ``rules.max_stroke`` (for ``camtube design``).

    A pattern that bends several ways (bidirectional, multi-direction) has one tendon per
    direction, each pulling only its own notches: one table per direction.
    """
    groups = notches_by_direction(pattern)
    if len(groups) == 1:
        return _direction_summary(pattern, steps, modulus_gpa, "")
    return "".join(_direction_summary(pattern.with_cuts(cuts), steps, modulus_gpa, f", notches at {ang:g} deg")
                   for ang, cuts in groups)


def _direction_summary(pattern: Pattern, steps: int, modulus_gpa: float, label: str) -> str:
    geo = pattern_geometry(pattern)
    g = geo.first
    model = model_for_pattern(pattern)
    vals = pattern_values(pattern)
    k = joint_stiffness_nmm_per_rad(pattern, modulus_gpa)
    c = model.compliance_mm_per_N(vals)
    smax = float(pattern.rules.max_stroke_mm)
    strokes = np.linspace(0.0, smax, steps + 1)
    ang, force = predict_from_stroke(model, vals, strokes, k)
    closure_deg = math.degrees(geo.total_closure_angle_rad)
    lines = [
        "",
        f"predicted stroke-angle{label} (base model, stroke only: E_pi {modulus_gpa:g} GPa, "
        f"E_t {vals['E_t']:g} GPa, L0 {vals['L0']:g} mm)",
        f"  joint stiffness K = E_pi I / (n h): {k:.3f} N mm/rad; tendon compliance {c:.4f} mm/N; "
        f"{100 * (k * c / g.moment_arm_mm**2) / (1 + k * c / g.moment_arm_mm**2):.0f}% of the stroke "
        "stretches the tendon",
        f"  {'stroke mm':>10}  {'angle deg':>9}  {'force N':>8}  {'strain':>7}",
    ]
    for s, a, f in zip(strokes, ang, force):
        strain = g.strain_at(math.radians(a) / len(geo.notches))
        flag = ("  notches closed" if a > closure_deg
                else f"  strain > {pattern.rules.max_strain:g}" if strain > pattern.rules.max_strain else "")
        lines.append(f"  {s:10.3f}  {a:9.2f}  {f:8.3f}  {strain:7.4f}{flag}")
    return "\n".join(lines)
