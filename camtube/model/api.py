"""The joint model as a base plus named, composable effects.

The base model (the source paper)::

    L_t = L_kin + L_el,   L_kin = arm * theta,   L_el = F L0 / (E_t pi r_t^2)
    => theta = (stroke - F L0 / (E_t pi r_t^2)) / arm,   arm = ybar + r_i - r_t

An :class:`Effect` is a named term that changes one *stage* of this chain.
The stages, in the order :meth:`JointModel.predict` runs them:

``force``
    the force signal before it is used (load-cell zero, ...):
    ``apply(ctx, force_N, p) -> force_N``
``stroke``
    the stroke that reaches the tendon, from the motor stroke's history
    (slack, backlash/play, creep over cycles, ...): ``apply(ctx, stroke_mm, p) -> stroke_mm``
``elongation``
    the tendon's force-elongation law (toe region, viscoelasticity, series
    compliance, ...): ``apply(ctx, elongation_mm, p) -> elongation_mm``;
    ``ctx.force_N`` is the (corrected) force
``kinematics``
    tendon length change -> joint angle (chords, hard stop, geometry
    corrections, ...): ``apply(ctx, theta_rad, p) -> theta_rad``;
    ``ctx.l_kin_mm`` is the kinematic length change, ``ctx.geometry`` the joint geometry
``angle``
    the measured angle (sensor bias, ...): ``apply(ctx, angle_deg, p) -> angle_deg``

Each effect's parameter values arrive in ``p`` keyed by the parameter's short
name. Effects are registered by name (:func:`register`); a user's effect in
their own ``.py`` file is registered the same way (:func:`load_effect_file`).
"""
from __future__ import annotations

import importlib.util
import math
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np

from camtube.design.geometry import JointGeometry
from camtube.model.dataset import Dataset

STAGES = ("force", "stroke", "elongation", "kinematics", "angle")


@dataclass(frozen=True)
class Param:
    """A named model parameter.

    Attributes
    ----------
    name : str
        Short name inside its effect (``deadband_mm``); the model-wide name is
        ``effect.name`` (``slack.deadband_mm``); base parameters have no prefix.
    unit : str
        Unit, e.g. ``mm``, ``GPa``, ``deg``, ``s``.
    lo, hi : float
        Bounds for fitting.
    init : float | Callable[[Dataset, "Context"], float]
        Initial value, or a function of the data giving one.
    doc : str
        Physical meaning.
    """

    name: str
    unit: str
    lo: float
    hi: float
    init: float | Callable = 0.0
    doc: str = ""

    def initial(self, data: Dataset, ctx: "Context") -> float:
        v = self.init(data, ctx) if callable(self.init) else float(self.init)
        return float(min(max(v, self.lo), self.hi))


@dataclass
class Context:
    """What an effect may read while the model runs.

    Attributes
    ----------
    data : Dataset
        The rows being predicted (stroke, force, time, cycle, sample, ...).
    geometry : JointGeometry
        Geometry of the joint's notches (``moment_arm_mm``, ``phi_rad``, ...).
    n_notches : int
        Number of notches in the joint.
    tendon_length_mm, tendon_area_mm2 : float
        L0 and pi r_t^2.
    modulus_gpa : float
        Current E_t.
    force_N : (n,) float
        Force after the ``force`` stage.
    stroke_mm : (n,) float
        Stroke after the ``stroke`` stage.
    l_kin_mm : (n,) float
        Kinematic length change (stroke - elongation), set before ``kinematics``.
    arm_mm : float
        Moment arm in use (geometry's arm times ``arm_scale``), set before ``kinematics``.
    direction : (n,) int
        +1 loading, -1 unloading (from the measured stroke).
    """

    data: Dataset
    geometry: JointGeometry
    n_notches: int
    tendon_length_mm: float
    tendon_area_mm2: float
    modulus_gpa: float
    force_N: np.ndarray | None = None
    stroke_mm: np.ndarray | None = None
    l_kin_mm: np.ndarray | None = None
    direction: np.ndarray | None = None
    arm_mm: float = 0.0
    cache: dict = field(default_factory=dict)

    @property
    def compliance_mm_per_N(self) -> float:
        """Base tendon compliance L0 / (E_t pi r_t^2) in mm/N (E_t in GPa = 1e3 N/mm^2)."""
        return self.tendon_length_mm / (self.modulus_gpa * 1e3 * self.tendon_area_mm2)


@dataclass(frozen=True)
class Effect:
    """A named physical effect added to the base model.

    Attributes
    ----------
    name : str
        Registry name (``slack``); used on the command line (``--effects slack``).
    stage : str
        One of :data:`STAGES`.
    params : tuple[Param, ...]
    apply : Callable[[Context, ndarray, dict[str, float]], ndarray]
        The stage transform.
    meaning : str
        One sentence: the physics.
    signature : str
        The residual pattern it explains, in words.
    family : str
        Effects of one family cannot be told apart from each other by the data
        alone (the diagnosis reports them together).
    """

    name: str
    stage: str
    params: tuple[Param, ...]
    apply: Callable[[Context, np.ndarray, dict], np.ndarray]
    meaning: str = ""
    signature: str = ""
    family: str = ""

    def __post_init__(self):
        if self.stage not in STAGES:
            raise ValueError(f"effect {self.name!r}: stage must be one of {STAGES}, not {self.stage!r}")


_REGISTRY: dict[str, Effect] = {}


def register(effect: Effect, replace_existing: bool = False) -> Effect:
    """Add ``effect`` to the registry (built-in and user effects alike)."""
    if effect.name in _REGISTRY and not replace_existing and _REGISTRY[effect.name] is not effect:
        raise ValueError(f"an effect named {effect.name!r} is already registered")
    _REGISTRY[effect.name] = effect
    return effect


def registry() -> Mapping[str, Effect]:
    """Every registered effect by name (built-ins are loaded on first use)."""
    _load_builtins()
    return dict(_REGISTRY)


def get_effect(name: str) -> Effect:
    reg = registry()
    if name not in reg:
        import difflib

        hint = difflib.get_close_matches(name, list(reg), n=1)
        raise KeyError(f"unknown effect {name!r}" + (f"; did you mean {hint[0]!r}?" if hint else "")
                       + f" (known: {', '.join(sorted(reg))})")
    return reg[name]


def load_effect_file(path: str | Path) -> list[str]:
    """Import a user's ``.py`` file; every :class:`Effect` it registers or defines at module level is registered.

    Returns the names of the effects the file added.
    """
    path = Path(path)
    before = set(_REGISTRY)
    spec = importlib.util.spec_from_file_location(f"camtube_user_effect_{path.stem}", path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot import effect file {path}")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    for v in vars(mod).values():
        if isinstance(v, Effect) and v.name not in _REGISTRY:
            register(v)
    return sorted(set(_REGISTRY) - before)


_BUILTINS_LOADED = False


def _load_builtins() -> None:
    global _BUILTINS_LOADED
    if not _BUILTINS_LOADED:
        _BUILTINS_LOADED = True
        try:
            importlib.import_module("camtube.model.effects")
        except ModuleNotFoundError as exc:
            if exc.name != "camtube.model.effects":
                raise


#: Base parameters (no prefix). ``E_t`` is fitted by default.
BASE_PARAMS: tuple[Param, ...] = (
    Param("E_t", "GPa", 0.5, 500.0, 28.0, "tendon Young's modulus"),
    Param("L0", "mm", 1.0, 10000.0, 70.0, "unloaded tendon length"),
    Param("arm_scale", "", 0.3, 3.0, 1.0, "factor on the moment arm ybar + r_i - r_t"),
)


@dataclass(frozen=True)
class JointModel:
    """Base model plus effects, for one joint geometry.

    Parameters are addressed by full name: base ``E_t``, ``L0``,
    ``arm_scale``; effect ``<effect>.<param>``.
    """

    geometry: JointGeometry
    n_notches: int = 1
    tendon_radius_mm: float = 0.04
    effects: tuple[Effect, ...] = ()

    def with_effects(self, effects: Sequence[Effect | str]) -> "JointModel":
        effs = tuple(get_effect(e) if isinstance(e, str) else e for e in effects)
        return replace(self, effects=effs)

    @property
    def param_specs(self) -> dict[str, Param]:
        """Full name -> :class:`Param` of every parameter, base first."""
        out = {p.name: p for p in BASE_PARAMS}
        for e in self.effects:
            for p in e.params:
                out[f"{e.name}.{p.name}"] = p
        return out

    def context(self, data: Dataset, values: Mapping[str, float]) -> Context:
        return Context(
            data=data,
            geometry=self.geometry,
            n_notches=self.n_notches,
            tendon_length_mm=float(values.get("L0", 70.0)),
            tendon_area_mm2=math.pi * self.tendon_radius_mm**2,
            modulus_gpa=float(values.get("E_t", 28.0)),
            direction=data.direction,
        )

    def initial_values(self, data: Dataset, base: Mapping[str, float] | None = None) -> dict[str, float]:
        """Initial value of every parameter (``base`` overrides, e.g. L0 from the pattern)."""
        vals = {p.name: float(p.init) for p in BASE_PARAMS}
        vals.update(base or {})
        ctx = self.context(data, vals)
        for name, spec in self.param_specs.items():
            if name not in vals:
                vals[name] = spec.initial(data, ctx)
        return vals

    def predict(self, data: Dataset, values: Mapping[str, float]) -> np.ndarray:
        """Model joint angle (deg), shape ``(n,)``, from measured stroke and force."""
        ctx = self.context(data, values)
        by_stage: dict[str, list[Effect]] = {s: [] for s in STAGES}
        for e in self.effects:
            by_stage[e.stage].append(e)

        def params_of(e: Effect) -> dict[str, float]:
            return {p.name: float(values[f"{e.name}.{p.name}"]) for p in e.params}

        force = np.asarray(data.force_N, float)
        for e in by_stage["force"]:
            force = e.apply(ctx, force, params_of(e))
        ctx.force_N = force
        stroke = np.asarray(data.stroke_mm, float)
        for e in by_stage["stroke"]:
            stroke = e.apply(ctx, stroke, params_of(e))
        ctx.stroke_mm = stroke
        elong = force * ctx.compliance_mm_per_N
        for e in by_stage["elongation"]:
            elong = e.apply(ctx, elong, params_of(e))
        l_kin = stroke - elong
        ctx.l_kin_mm = l_kin
        arm = self.geometry.moment_arm_mm * float(values.get("arm_scale", 1.0))
        ctx.arm_mm = arm
        theta = l_kin / arm
        for e in by_stage["kinematics"]:
            theta = e.apply(ctx, theta, params_of(e))
        angle = np.degrees(theta)
        for e in by_stage["angle"]:
            angle = e.apply(ctx, angle, params_of(e))
        return angle
