"""The joint model as a base plus named, composable effects.

The base model (the source paper)::

    L_t = L_kin + L_el,   L_kin = arm * theta,   L_el = F L0 / (E_t pi r_t^2)
    => theta = (stroke - F L0 / (E_t pi r_t^2)) / arm,   arm = ybar + r_i - r_t

An :class:`Effect` is a named term that changes one *stage* of this chain
(or several: see below). The stages, in the order :meth:`JointModel.predict` runs them:

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
    ``ctx.l_kin_mm`` is the kinematic length change (mm, the natural input:
    ``theta = l_kin / arm`` for the base model), ``ctx.arm_mm`` the arm, ``ctx.geometry`` the joint geometry
``angle``
    the measured angle (sensor bias, ...): ``apply(ctx, angle_deg, p) -> angle_deg``

Each effect's parameter values arrive in ``p`` keyed by the parameter's short
name. An effect on several stages gives ``stage`` as a tuple and ``apply`` as a
``{stage: function}`` mapping; its functions share the parameters.

Effects are looked up by name in an explicit :class:`~camtube.model.core.registry.Registry`
(built-ins plus the effects of the files a command loads); nothing here is process-wide state.

Per-sample parameters (``slack.deadband_mm@S2``): :meth:`JointModel.predict`
runs each sample with its own values (every effect already runs per sample).
"""
from __future__ import annotations

import inspect
import math
import numbers
import struct
from dataclasses import dataclass, field, replace
from functools import cached_property
from collections.abc import Callable, Mapping, Sequence

import numpy as np

from camtube.design.geometry import JointGeometry
from camtube.errors import CamtubeError
from camtube.model.core.params import (
    DEFAULT_E_T_GPA, DEFAULT_L0_MM, Param, Parameter, Parameters, split_name, tendon_compliance_mm_per_N,
    values_for_sample,
)
from camtube.model.data.dataset import Dataset


class FitError(CamtubeError, ValueError):
    """A model could not be set up, evaluated or fitted (unknown parameter, no data, broken effect)."""


STAGES = ("force", "stroke", "elongation", "kinematics", "angle")


@dataclass
class Context:
    """What an effect may read while the model runs (one sample's rows, or all rows).

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

    Ready-made signals (properties, per sample, computed on first use):
    ``first_cycle`` (n,) bool, rows of each sample's first cycle;
    ``peak_force_N`` (n,) float, the largest force so far;
    ``time_since_reversal_s`` (n,) float, time since the stroke last changed direction.
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

    @property
    def first_cycle(self) -> np.ndarray:
        """(n,) bool: rows in each sample's first cycle."""
        out = np.zeros(len(self.data), bool)
        cyc = np.asarray(self.data.cycle)
        for _, sl in self.data.sample_slices():
            out[sl] = cyc[sl] == cyc[sl].min()
        return out

    @property
    def peak_force_N(self) -> np.ndarray:
        """(n,) float: the largest force (after the ``force`` stage) so far, per sample."""
        f = np.asarray(self.force_N if self.force_N is not None else self.data.force_N, float)
        out = np.empty_like(f)
        for _, sl in self.data.sample_slices():
            out[sl] = np.maximum.accumulate(f[sl])
        return out

    @property
    def time_since_reversal_s(self) -> np.ndarray:
        """(n,) float: time (s) since the direction of motion last changed (since the start for the first run)."""
        t = np.asarray(self.data.time_s, float)
        d = self.data.direction
        out = np.empty_like(t)
        for _, sl in self.data.sample_slices():
            dd, ts = d[sl], t[sl]
            start = np.zeros(dd.size, int)
            if dd.size:
                change = np.flatnonzero(np.diff(dd)) + 1
                start[change] = change
                np.maximum.accumulate(start, out=start)
            out[sl] = ts - ts[start]
        return out


def _identifier(text) -> str:
    """``'lead screw!'`` -> ``'lead_screw'``: a suggestion for a name that is not an identifier."""
    import re

    s = re.sub(r"\W+", "_", str(text)).strip("_") or "my_effect"
    return s if s.isidentifier() else f"e_{s}"


@dataclass(frozen=True)
class Effect:
    """A named physical effect added to the base model.

    Attributes
    ----------
    name : str
        Registry name (``slack``); used on the command line (``--effects slack``).
    stage : str | tuple[str, ...]
        One of :data:`STAGES`, or several (then ``apply`` maps each stage to its function).
    params : tuple[Param, ...]
    apply : Callable[[Context, ndarray, dict[str, float]], ndarray] | Mapping[str, Callable]
        The stage transform (or one per stage).
    meaning : str
        One sentence: the physics.
    signature : str
        The residual pattern it explains, in words.
    family : str
        Effects of one family cannot be told apart from each other by the data
        alone (the diagnosis reports them together).
    history : bool
        The effect depends on the history of the motion (play, creep,
        viscoelasticity): it needs whole cycles in both directions to be identified.
    source : str
        The file that defined it (empty for built-ins); named in error messages.
    off : dict
        Parameter values (short names) at which the effect does nothing, e.g. ``{"creep_mm": 0.0}``. With
        them the diagnosis can fit the effect in some samples only (held off in the others); empty: it
        cannot.
    check : Callable[[Dataset, ndarray], str] | None
        An optional test of the fitted form against its signature: ``check(data, predicted_deg)`` returns why
        the data contradict the form (empty when they do not), e.g. a hard stop where the measured angle keeps
        rising. A reason makes the diagnosis refuse the candidate, whatever its gain. A check that also takes a
        keyword ``effects`` gets the fitted model's effects (a tuple of :class:`Effect`, this one included): what
        the rest of the model already explains (a taut tendon at rest that a drive effect holds).
    pure : bool
        Its functions are pure: the output depends on the signal, ``p`` and the context only (no state of
        their own, ``ctx.cache`` unused) and the input signal is not modified. The model then keeps the
        signals between the stages of recent evaluations and starts a new one from the last stage whose
        inputs are equal to the bit (:func:`_checkpoints`; speed only). The built-ins are pure; default False.
    """

    name: str
    stage: str | tuple
    params: tuple[Param, ...]
    apply: Callable[[Context, np.ndarray, dict], np.ndarray] | Mapping
    meaning: str = ""
    signature: str = ""
    family: str = ""
    history: bool = False
    source: str = ""
    off: Mapping = field(default_factory=dict, compare=False)
    check: Callable | None = field(default=None, compare=False)
    pure: bool = field(default=False, compare=False)

    def __post_init__(self):
        # names are written NAME.param (and NAME.param@SAMPLE) on the command line: identifiers only
        if not (isinstance(self.name, str) and self.name.isidentifier()):
            raise ValueError(f"effect {self.name!r}: the name is not a Python identifier (letters, digits and _, "
                             "not starting with a digit; it is written NAME.param on the command line); fix: e.g. "
                             f"name={_identifier(self.name)!r}")
        for q in self.params:
            if not (isinstance(q.name, str) and q.name.isidentifier()):
                raise ValueError(f"effect {self.name!r}: parameter {q.name!r} is not a Python identifier (it is "
                                 f"written {self.name}.PARAM on the command line); fix: e.g. "
                                 f"Param({_identifier(q.name)!r}, ...)")
        for st in self.stages:
            if st not in STAGES:
                raise ValueError(f"effect {self.name!r}: stage must be one of {STAGES}, not {st!r}")
        if isinstance(self.apply, Mapping):
            missing = [st for st in self.stages if st not in self.apply]
            if missing:
                raise ValueError(f"effect {self.name!r}: apply has no function for stage(s) {', '.join(missing)}")
        elif len(self.stages) > 1:
            raise ValueError(f"effect {self.name!r} acts on {len(self.stages)} stages: give apply as "
                             "{stage: function}")
        seen = set()
        for q in self.params:
            if q.name in seen:  # the fit would hold one value under the name for both
                raise ValueError(f"effect {self.name!r}: two parameters are named {q.name!r}; fix: give each Param "
                                 "a name of its own")
            seen.add(q.name)
            _check_param_values(self.name, q)
            if q.lo != q.lo or q.hi != q.hi:  # NaN: every comparison with it is false, no bound would hold
                raise ValueError(f"effect {self.name!r}: parameter {q.name!r} has a NaN bound (lo {q.lo:g}, hi "
                                 f"{q.hi:g}); fix: give numbers (Param(name, unit, lo, hi, init))")
            if q.lo > q.hi:
                raise ValueError(f"effect {self.name!r}: parameter {q.name!r} has lo {q.lo:g} > hi {q.hi:g}; "
                                 "fix: swap them (Param(name, unit, lo, hi, init))")
            if not callable(q.init) and not (q.lo <= float(q.init) <= q.hi):
                # (a start outside the bounds was clipped to one, and the fit then said the parameter "ended on its
                # bound")
                raise ValueError(f"effect {self.name!r}: parameter {q.name!r} starts at {float(q.init):g}, outside its "
                                 f"bounds {q.lo:g}..{q.hi:g}; fix: give a start within them (Param(name, unit, lo, hi, "
                                 "init))")
        unknown = [k for k in self.off if k not in {p.name for p in self.params}]
        if unknown:
            raise ValueError(f"effect {self.name!r}: off names unknown parameter(s) {', '.join(unknown)}")

    @property
    def stages(self) -> tuple[str, ...]:
        return (self.stage,) if isinstance(self.stage, str) else tuple(self.stage)

    def function(self, stage: str) -> Callable:
        return self.apply[stage] if isinstance(self.apply, Mapping) else self.apply

    def full_names(self) -> tuple[str, ...]:
        return tuple(f"{self.name}.{p.name}" for p in self.params)


def _check_param_values(effect: str, q: Param) -> None:
    """A Param's bounds numbers, its ``init`` a finite number or a function, its ``starts`` finite numbers: a user's
    effect file writes these, and a wrong one is refused here (the loader names its file and line), not as a
    traceback in a fit. (A nan bound and lo > hi: :class:`Effect`'s own checks, after this.)"""
    def number(x) -> bool:
        return isinstance(x, numbers.Real) and not isinstance(x, bool)

    where = f"effect {effect!r}: parameter {q.name!r}"
    if not (number(q.lo) and number(q.hi)):
        raise ValueError(f"{where}: lo and hi must be numbers, got {q.lo!r} and {q.hi!r}; fix: give numbers "
                         "(Param(name, unit, lo, hi, init))")
    if not (callable(q.init) or (number(q.init) and math.isfinite(float(q.init)))):
        raise ValueError(f"{where}: init must be a finite number or a function of the data, got {q.init!r}")
    if not (isinstance(q.starts, (tuple, list)) and all(number(v) and math.isfinite(float(v)) for v in q.starts)):
        raise ValueError(f"{where}: starts must be a tuple of finite numbers, got {q.starts!r}")


#: Base parameters (no prefix). ``E_t`` is fitted by default.
BASE_PARAMS: tuple[Param, ...] = (
    Param("E_t", "GPa", 0.5, 500.0, DEFAULT_E_T_GPA, "tendon Young's modulus", log=True, kind="modulus"),
    Param("L0", "mm", 1.0, 10000.0, DEFAULT_L0_MM, "unloaded tendon length", log=True),
    Param("arm_scale", "", 0.3, 3.0, 1.0, "factor on the moment arm ybar + r_i - r_t"),
)


def _user_line(effect: Effect, stage: str, exc: BaseException | None = None) -> str:
    """``:LINE`` in the effect's own file: the deepest traceback frame there, else the stage function's ``def``."""
    fn = effect.function(stage)
    code = getattr(fn, "__code__", None)
    line = _user_line_of({effect.source, getattr(code, "co_filename", None)}, exc) if exc is not None else ""
    return line or (f":{code.co_firstlineno}" if code is not None else "")


def user_raised(exc: BaseException) -> str:
    """What a user's code raised, for a one-line message: ``called sys.exit()`` for a ``SystemExit``, else
    ``TYPE: MESSAGE`` (any ``BaseException`` but ``KeyboardInterrupt``, which the caller lets through as an
    interrupt), its message on one line."""
    if isinstance(exc, SystemExit):
        return "called sys.exit()"
    text = " ".join(str(exc).split())
    return f"{type(exc).__name__}: {text}" if text else type(exc).__name__


def _user_line_of(files: str | set, exc: BaseException) -> str:
    """``:LINE`` of the deepest frame of ``exc``'s traceback in the effect's file (``files``: its name, or the names
    it may go by) ("" when none is there)."""
    import traceback

    names = ({files} if isinstance(files, str) else set(files)) - {None, ""}
    frames = [f for f in traceback.extract_tb(exc.__traceback__) if f.filename in names]
    return f":{frames[-1].lineno}" if frames else ""


def _call(effect: Effect, stage: str, ctx: Context, signal: np.ndarray, p: dict) -> np.ndarray:
    """Run one effect's stage function; a broken effect gets a message naming it, its file, the line and the problem."""
    def where(exc: BaseException | None = None) -> str:
        if not effect.source:
            return f"effect {effect.name!r}"
        return f"effect {effect.name!r} ({effect.source}{_user_line(effect, stage, exc)})"

    if effect.source:
        # a user's effect gets its input read-only: one that changed it in place (``s -= k``) changed the array the
        # model holds for every later effect and evaluation (a slack refit went from 0.30 to 20 deg, exit 0)
        signal = signal.view()
        signal.flags.writeable = False
    try:
        out = effect.function(stage)(ctx, signal, p)
    except KeyError as exc:
        raise FitError(f"{where(exc)}, stage {stage}: asked for parameter {exc.args[0]!r}, but its params are "
                       f"{', '.join(repr(q.name) for q in effect.params) or 'none'}; fix: use one of those names "
                       "or add a Param of that name") from None
    except (FitError, KeyboardInterrupt):  # (Ctrl-C and SIGTERM stay an interrupt, wherever they arrive)
        raise
    except BaseException as exc:  # noqa: BLE001 - a user's effect may raise anything: report it with its line
        if not effect.source:
            raise
        if isinstance(exc, ValueError) and "read-only" in str(exc):
            raise FitError(f"{where(exc)}, stage {stage}: changes the {stage} array it is given in place (the model "
                           "keeps that array for the effects after it); fix: return a new array at that line "
                           "(s = s - k, not s -= k)") from None
        what = user_raised(exc)
        raise FitError(f"{where(exc)}, stage {stage}: {what}; fix: correct the effect's function at that "
                       "line") from None
    shape_fix = f"fix: return one number per row (an array shaped like the {stage} signal it was given)"
    if np.iscomplexobj(out):
        raise FitError(f"{where()}, stage {stage}: returned complex numbers; {shape_fix}")
    try:
        out = np.asarray(out, float)
    except (TypeError, ValueError):
        raise FitError(f"{where()}, stage {stage}: returned {type(out).__name__} {_short(out)}, not numbers; "
                       f"{shape_fix}") from None
    if out.shape != signal.shape:
        raise FitError(f"{where()}, stage {stage}: returned shape {out.shape}, expected {signal.shape} "
                       f"(one value per row); {shape_fix}")
    return out


def _short(value) -> str:
    """``repr(value)``, cut to 40 characters (a user's wrong return value, in a one-line message)."""
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


def check_reads_chain(effect: Effect) -> bool:
    """Whether ``effect``'s check takes the fitted model's effects (keyword ``effects``): its verdict may change
    with the rest of the chain."""
    if effect.check is None:
        return False
    try:
        return "effects" in inspect.signature(effect.check).parameters
    except (TypeError, ValueError):  # a builtin or a callable without a signature: two arguments
        return False


def form_problem(effect: Effect, data, predicted_deg: np.ndarray, effects: Sequence[Effect] = ()) -> str:
    """Why ``data`` contradict ``effect``'s fitted form (its ``check``; empty when they do not, or it has none).

    ``effects``: the fitted model's effects, given to a check that takes them (keyword ``effects``).
    A broken check in a user's file gets one line naming the effect, its file and the problem."""
    if effect.check is None:
        return ""
    takes = check_reads_chain(effect)
    try:
        reason = effect.check(data, predicted_deg, effects=tuple(effects)) if takes else \
            effect.check(data, predicted_deg)
    except KeyboardInterrupt:
        raise
    except BaseException as exc:  # noqa: BLE001 - a user's check may raise anything: report it with its file
        if not effect.source:
            raise
        raise FitError(f"effect {effect.name!r} ({effect.source}{_user_line_of(effect.source, exc)}), check: "
                       f"{user_raised(exc)}; fix: correct the check function at that line") from None
    if reason is not None and not isinstance(reason, str):
        raise FitError(f"effect {effect.name!r}{f' ({effect.source})' if effect.source else ''}, check: returned "
                       f"{type(reason).__name__}, expected a string (empty when the form holds)")
    return reason or ""


@dataclass(frozen=True)
class JointModel:
    """Base model plus effects, for one joint geometry.

    Parameters are addressed by full name: base ``E_t``, ``L0``,
    ``arm_scale``; effect ``<effect>.<param>``; per sample ``<name>@<sample>``.
    """

    geometry: JointGeometry
    n_notches: int = 1
    tendon_radius_mm: float = 0.04
    effects: tuple[Effect, ...] = ()

    def with_effects(self, effects: Sequence[Effect | str], registry=None) -> "JointModel":
        """The model with ``effects``: :class:`Effect` objects, or names looked up in ``registry``.

        The model knows no table of effects itself (the registry sits above it and the built-in
        effects above that): pass ``registry`` (e.g. :func:`camtube.model.core.registry.builtin_registry`)
        to give effects by name.
        """
        names = [e for e in effects if isinstance(e, str)]
        if names and registry is None:
            raise FitError(f"effects by name ({', '.join(names)}) need a registry to look them up in; "
                           "fix: pass registry=builtin_registry() or the Effect objects")
        effs = tuple(registry.get_effect(e) if isinstance(e, str) else e for e in effects)
        return replace(self, effects=effs)

    @property
    def param_specs(self) -> dict[str, Param]:
        """Full name -> :class:`Param` of every parameter, base first."""
        out = {p.name: p for p in BASE_PARAMS}
        for e in self.effects:
            for p in e.params:
                out[f"{e.name}.{p.name}"] = p
        return out

    def spec(self, name: str) -> Param:
        """The :class:`Param` of a full name (per-sample names share their base's)."""
        return self.param_specs[split_name(name)[0]]

    def effect_names(self) -> tuple[str, ...]:
        return tuple(e.name for e in self.effects)

    def context(self, data: Dataset, values: Mapping[str, float]) -> Context:
        return Context(
            data=data,
            geometry=self.geometry,
            n_notches=self.n_notches,
            tendon_length_mm=float(values.get("L0", DEFAULT_L0_MM)),
            tendon_area_mm2=math.pi * self.tendon_radius_mm**2,
            modulus_gpa=float(values.get("E_t", DEFAULT_E_T_GPA)),
            direction=data.direction,
        )

    def compliance_mm_per_N(self, values: Mapping[str, float]) -> float:
        """Base tendon compliance (mm/N) at ``values`` (L0, E_t)."""
        return tendon_compliance_mm_per_N(values.get("L0", DEFAULT_L0_MM), values.get("E_t", DEFAULT_E_T_GPA),
                                          self.tendon_radius_mm)

    def initial_values(self, data: Dataset, base: Mapping[str, float] | None = None) -> dict[str, float]:
        """Initial value of every parameter (``base`` overrides, e.g. L0 from the pattern)."""
        vals = {p.name: float(p.init) for p in BASE_PARAMS}
        vals.update(base or {})
        ctx = self.context(data, vals)
        for name, spec in self.param_specs.items():
            if name not in vals:
                vals[name] = self._initial(name, spec, data, ctx)
        return vals

    def _initial(self, name: str, spec, data: Dataset, ctx) -> float:
        """``spec.initial``; a user's init function that raises or gives no finite number: one line naming the
        parameter and its effect's file."""
        def source() -> str:   # (looked up only for the message: this runs for every parameter of every fit)
            eff = next((e for e in self.effects if name.startswith(e.name + ".")), None)
            return eff.source if eff is not None else ""

        try:
            v = spec.initial(data, ctx)
        except KeyboardInterrupt:
            raise
        except BaseException as exc:  # noqa: BLE001 - a user's init function may raise anything: report it with its file
            if not source():
                raise
            raise FitError(f"parameter {name!r} ({source()}{_user_line_of(source(), exc)}): its init function "
                           f"raised {user_raised(exc)}; "
                           "fix: correct the function, or give a number") from None
        if not math.isfinite(v):
            src = source()
            raise FitError(f"parameter {name!r}{f' ({src})' if src else ''}: its init gave {v}, not a finite "
                           "number; fix: make init give a value between lo and hi") from None
        return v

    def per_sample_names(self, names: Sequence[str]) -> list[str]:
        """``names`` (``--per-sample``) as full parameter names: a full name as it is, an effect's name for all its
        parameters, in order.

        Raises
        ------
        FitError
            For a name that is neither (with a "did you mean" hint).
        """
        specs = self.param_specs
        out = []
        for nm in names:
            if nm in specs:
                out.append(nm)
            elif nm in self.effect_names():
                out += [f"{nm}.{p.name}" for p in next(e for e in self.effects if e.name == nm).params]
            else:
                raise unknown_parameter(nm, list(specs) + list(self.effect_names()), "--per-sample")
        return out

    def make_params(
        self,
        data: Dataset,
        fit: Sequence[str] = ("E_t",),
        fixed: Mapping[str, float] | None = None,
        *,
        initial: Mapping[str, float] | None = None,
        bounds: Mapping[str, tuple[float, float]] | None = None,
        per_sample: Sequence[str] = (),
    ) -> Parameters:
        """The :class:`Parameters` of this model: ``fit`` names vary, the others are held.

        Parameters
        ----------
        data : Dataset
            For data-dependent initial values and the sample names of per-sample copies.
        fit : sequence of str
            Full names to fit (a ``name@S`` entry makes that one per-sample copy).
        fixed : dict
            Values of held parameters and starting values of fitted ones.
        initial : dict
            Starting values (win over ``fixed``).
        bounds : dict
            ``{name: (lo, hi)}`` overriding the declarations.
        per_sample : sequence of str
            Full names (or effect names: all their parameters) fitted per sample.

        Raises
        ------
        FitError
            For an unknown name (with a "did you mean" hint).
        """
        specs = self.param_specs
        known = list(specs)
        fixed = dict(fixed or {})
        initial = dict(initial or {})
        bounds = dict(bounds or {})
        ps = self.per_sample_names(per_sample)
        samples = data.samples
        for option, names in (("--fit", fit), ("--fix", fixed), ("--init", initial), ("bounds", bounds)):
            for nm in names:
                base, smp = split_name(nm)
                if base not in specs:
                    raise unknown_parameter(base, known, option)
                if smp is not None and smp not in samples:
                    raise FitError(f"{option} {nm}: the data have no sample {smp!r} (samples: {', '.join(samples)}); "
                                   "fix: use NAME@SAMPLE with one of these samples")
        start = self.initial_values(data, base={k: v for k, v in fixed.items() if "@" not in k})
        start.update({k: float(v) for k, v in initial.items() if "@" not in k})
        want = {split_name(n)[0] for n in fit}
        items = []
        for name, sp in specs.items():
            lo, hi = bounds.get(name, (sp.lo, sp.hi))
            items.append(Parameter(name, float(start[name]), name in want and name not in ps, float(lo), float(hi),
                                   sp.unit, log=sp.log, starts=tuple(sp.starts), kind=sp.kind))
        out = Parameters(tuple(items))
        if ps:
            out = out.per_sample(ps, samples)
            out = Parameters(tuple(replace(p, vary=p.name.split("@")[0] in want) if p.sample else p
                                   for p in out.items))
        # explicit name@S entries in fit: per-sample copies of those only
        single = [n for n in fit if "@" in n and n not in out]
        for n in single:
            base, smp = split_name(n)
            p = out[base]
            out = Parameters.of(list(out.items) + [replace(p, name=n, sample=smp, vary=True)])
        # a per-sample copy given in ``fixed`` is held there (an effect off in that sample), unless it is
        # named in ``fit``; a start value in ``initial`` does not move a held copy
        held = {k for k in fixed if "@" in k and k not in fit}
        out = out.with_values({k: v for k, v in fixed.items() if k in out and "@" in k})
        out = out.with_values({k: v for k, v in initial.items() if k in out and "@" in k and k not in held})
        for k in fixed:
            if "@" in k and k not in out:
                base = split_name(k)[0]
                raise FitError(f"parameter {k!r} is held for one sample, but {base!r} is not fitted per sample: add "
                               f"--per-sample {base.split('.')[0]} (or hold it for every sample with --fix {base}=VALUE)")
            if "@" in k and k not in fit:
                out = out.set(k, vary=False)
        for name, (lo, hi) in bounds.items():
            if name in out:
                out = out.set(name, lo=float(lo), hi=float(hi))
        return out

    def predict(self, data: Dataset, values: Mapping[str, float] | Parameters) -> np.ndarray:
        """Model joint angle (deg), shape ``(n,)``, from measured stroke and force.

        ``values``: ``{full name: value}`` or a :class:`Parameters`; per-sample
        entries (``name@S``) override ``name`` for sample ``S``.
        """
        if isinstance(values, Parameters):
            values = values.values
        if any("@" in k for k in values):
            out = np.empty(len(data))
            for smp, sl, sub in sample_views(data):
                out[sl] = self._predict(sub, values_for_sample(values, smp))
            return out
        return self._predict(data, values)

    def _predict(self, data: Dataset, values: Mapping[str, float]) -> np.ndarray:
        ctx = self.context(data, values)
        seq, pure = self._chain

        def params_of(e: Effect) -> dict[str, float]:
            try:
                return {p.name: float(values[f"{e.name}.{p.name}"]) for p in e.params}
            except KeyError as exc:
                raise FitError(f"no value for parameter {exc.args[0]!r} of effect {e.name!r}") from None

        kept = None
        if pure:
            try:
                kept = _Checkpoints(self, data, values, [params_of(e) for _, e in seq])
            except FitError:  # a missing value: raised where the chain asks for it, as without the cache
                kept = None
        start, signal = (0, None) if kept is None else kept.resume(ctx)
        first_stage = STAGES.index(seq[start - 1][0]) if start else 0
        for si in range(first_stage, len(STAGES)):
            st = STAGES[si]
            if not (start and si == first_stage):
                signal = self._enter(st, ctx, signal, values)
            for k in range(start, len(seq)):
                if seq[k][0] != st:
                    break
                e = seq[k][1]
                signal = _call(e, st, ctx, signal, kept.params[k] if kept is not None else params_of(e))
                start = k + 1
                if kept is not None:
                    kept.save(k, ctx, signal)
        if kept is not None and kept.holds(signal):
            return signal.copy()   # an array the model keeps is never handed out
        return signal

    @cached_property
    def _chain(self) -> tuple:
        """``(seq, pure)``: the effects in the order they run, ``(stage, effect)``, stage by stage and in the
        model's order within a stage; whether they are all pure (then :class:`_Checkpoints` keeps their signals)."""
        seq = tuple((st, e) for st in STAGES for e in self.effects if st in e.stages)
        return seq, bool(seq) and all(e.pure for _, e in seq)

    def _enter(self, stage: str, ctx: Context, signal, values: Mapping[str, float]) -> np.ndarray:
        """The signal ``stage`` starts from, given the one the stage before ended with (and the context)."""
        data = ctx.data
        if stage == "force":
            return np.asarray(data.force_N, float)
        if stage == "stroke":
            ctx.force_N = signal
            return np.asarray(data.stroke_mm, float)
        if stage == "elongation":
            ctx.stroke_mm = signal
            return ctx.force_N * ctx.compliance_mm_per_N
        if stage == "kinematics":
            l_kin = ctx.stroke_mm - signal
            ctx.l_kin_mm = l_kin
            arm = self.geometry.moment_arm_mm * float(values.get("arm_scale", 1.0))
            ctx.arm_mm = arm
            return l_kin / arm
        return np.degrees(signal)


# speed: the signals between the stages of recent evaluations of pure effects, kept per Dataset

#: Evaluations whose stage signals are kept per Dataset (the most recently used): a finite-difference
#: Jacobian steps one parameter (or one parameter's per-sample copies) at a time from one point, so the stages
#: before the stepped effect see the same inputs as at that point.
CHECKPOINTS_KEPT = 4


class _Checkpoints:
    """The kept stage signals of a Dataset for one evaluation of ``model`` at ``values``.

    The signal after effect ``k`` of the chain (and the context's force, stroke, kinematic length and arm at
    that moment) depends on the data, the model (geometry, notches, tendon radius, the effects), the base
    values the context carries (E_t, L0; the arm's scale from the kinematics stage on) and the parameters of
    effects ``0 .. k``: nothing else, when every effect is pure. These inputs are laid out as one vector of
    floats in chain order, compared to the bit (their IEEE bit patterns) with the kept evaluations'; the
    longest equal prefix gives the last effect whose output can be taken as it was (the same computation
    gives the same numbers).
    """

    __slots__ = ("model", "params", "bits", "ends", "states", "kept")

    def __init__(self, model: "JointModel", data: Dataset, values: Mapping[str, float], params: list[dict]):
        self.model = model
        self.params = params
        vec = [float(values.get("E_t", DEFAULT_E_T_GPA)), float(values.get("L0", DEFAULT_L0_MM))]
        ends = []
        arm_added = False
        for (st, e), p in zip(model._chain[0], params):
            if not arm_added and st in ("kinematics", "angle"):
                vec.append(float(values.get("arm_scale", 1.0)))
                arm_added = True
            vec.extend(p[q.name] for q in e.params)
            ends.append(len(vec))
        if not arm_added:   # the angle depends on the arm even when no effect comes after it
            vec.append(float(values.get("arm_scale", 1.0)))
        self.bits = struct.unpack(f"{len(vec)}q", struct.pack(f"{len(vec)}d", *vec))
        self.ends = ends
        self.states: list = [None] * len(ends)
        kept = data.cache.get("model.checkpoints")
        if kept is None:
            kept = data.cache.set("model.checkpoints", [])
        self.kept = kept

    def resume(self, ctx: Context) -> tuple:
        """``(k, signal)``: effects ``0 .. k-1`` already done, ``signal`` their output (the context set as it
        was then; the stages after effect ``k - 1`` still to run); ``(0, None)``: nothing kept matches. This
        evaluation joins the kept ones as the most recent."""
        best, best_k = None, 0
        bits, ends = self.bits, self.ends
        for other in self.kept:
            ob = other.bits
            # E_t first: its step, and every trial point of a fit, differ there (speed: nothing more to compare)
            if ob[0] != bits[0] or len(ob) != len(bits):
                continue
            if other.model is not self.model and other.model != self.model:
                continue   # equal models (dataclass equality) run the same effects
            if ob == bits:
                k = len(ends)
            else:
                k = 0
                for e in ends:
                    if ob[:e] != bits[:e]:
                        break
                    k += 1
            while k and other.states[k - 1] is None:
                k -= 1
            if k and k >= best_k:
                best, best_k = other, k
        kept = self.kept
        if best is not None:
            self.states[:best_k] = best.states[:best_k]
            kept.remove(best)
            kept.append(best)        # most recently used last
        kept.append(self)
        if len(kept) > CHECKPOINTS_KEPT:
            del kept[0]
        if best is None:
            return 0, None
        signal, ctx.force_N, ctx.stroke_mm, ctx.l_kin_mm, ctx.arm_mm = best.states[best_k - 1]
        return best_k, signal

    def save(self, k: int, ctx: Context, signal: np.ndarray) -> None:
        self.states[k] = (signal, ctx.force_N, ctx.stroke_mm, ctx.l_kin_mm, ctx.arm_mm)

    def holds(self, signal: np.ndarray) -> bool:
        """Whether ``signal`` is one of the kept arrays (an effect may hand back its input unchanged)."""
        return any(s is not None and s[0] is signal for s in self.states)


# speed: per-sample views of a Dataset, cached on it (per-sample parameters run the model sample by sample)


def sample_views(data: Dataset) -> list:
    """``(sample, slice, sub-dataset)`` of each sample, cached per Dataset (fits evaluate the same rows often)."""
    hit = data.cache.get("model.sample_views")
    if hit is None:
        hit = [(smp, sl, data.take(np.arange(sl.start, sl.stop))) for smp, sl in data.sample_slices()]
        data.cache.set("model.sample_views", hit)
    return hit


def unknown_parameter(name: str, known: Sequence[str], option: str = "") -> FitError:
    """The error for a parameter name the model does not have (``option``: where it was given, e.g. ``--fit``)."""
    import difflib

    hint = difflib.get_close_matches(name, list(known), n=1)
    return FitError((f"{option} {name}: " if option else "") + f"unknown model parameter {name!r}" + (f"; did you mean {hint[0]!r}?" if hint else "")
                    + f" (this model has: {', '.join(known)}); fix: use one of these names (an effect's as NAME.param), "
                    "or add its effect with --effects")
