"""Model parameters: the declaration of one (:class:`Param`) and one set of values (:class:`Parameters`).

In the spirit of lmfit's ``Parameters``: a fit takes one :class:`Parameters`
value (every parameter's name, value, whether it varies, bounds, unit,
per-sample scope) and returns another with standard errors filled in. It
replaces the parallel dicts of fitted names, fixed values, initial values and
bounds.

Names
-----
Base parameters have no prefix (``E_t``, ``L0``, ``arm_scale``); an effect's
parameter is ``<effect>.<param>`` (``slack.deadband_mm``). A per-sample copy
adds ``@<sample>``: ``slack.deadband_mm@S2`` is sample ``S2``'s value; the
shared name then stands for the samples that have no copy of their own.

The tendon defaults and compliance are written here once:
:data:`DEFAULT_L0_MM`, :data:`DEFAULT_E_T_GPA`, :func:`tendon_compliance_mm_per_N`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Callable, Iterable, Iterator, Mapping

import numpy as np

from camtube.design.geometry import tendon_compliance_mm_per_N  # noqa: F401  (written once, in design)

#: Unloaded tendon length (mm) when neither the pattern nor the user gives one.
DEFAULT_L0_MM = 70.0
#: Tendon Young's modulus (GPa) when neither the pattern nor the user gives one (the paper's fibre).
DEFAULT_E_T_GPA = 28.0


@dataclass(frozen=True)
class Param:
    """The declaration of a model parameter (what an effect says about it).

    Attributes
    ----------
    name : str
        Short name inside its effect (``deadband_mm``); the model-wide name is
        ``effect.name`` (``slack.deadband_mm``); base parameters have no prefix.
    unit : str
        Unit, e.g. ``mm``, ``GPa``, ``deg``, ``s``.
    lo, hi : float
        Bounds for fitting.
    init : float | Callable[[Dataset, Context], float]
        Initial value, or a function of the data giving one.
    doc : str
        Physical meaning.
    log : bool
        The parameter is a scale (a time constant, a length over decades): start
        grids are log-spaced (needs ``lo > 0``).
    starts : tuple[float, ...]
        Explicit start values for the multi-start fit (default: a grid over ``lo``-``hi``).
    kind : str
        What the data must resolve: ``time`` (between a few sample intervals and
        the record), ``length`` (within the stroke span), ``modulus`` (a
        plausible E_t), ``sharp`` (a scale whose lower bound is the law's sharp limit, a switch within a
        row: a fit on it is that limit when a decade above it reads the same), or ``""`` (nothing checked).
    """

    name: str
    unit: str
    lo: float
    hi: float
    init: float | Callable = 0.0
    doc: str = ""
    log: bool = False
    starts: tuple = ()
    kind: str = ""

    def at_sharp_limit(self, value: float) -> bool:
        """``value`` is this parameter's sharp limit: a parameter of kind ``sharp`` on (within 1e-6 of) its lower
        bound."""
        return self.kind == "sharp" and float(value) <= self.lo * (1.0 + 1e-6)

    def initial(self, data, ctx) -> float:
        v = self.init(data, ctx) if callable(self.init) else float(self.init)
        return float(min(max(v, self.lo), self.hi))

    def grid(self, n: int = 3) -> tuple[float, ...]:
        """``n`` start values across the bounds (log-spaced for a :attr:`log` parameter), or :attr:`starts`."""
        if self.starts:
            return tuple(float(min(max(s, self.lo), self.hi)) for s in self.starts)
        lo, hi = float(self.lo), float(self.hi)
        if not (math.isfinite(lo) and math.isfinite(hi)) or n < 1:
            return ()
        q = (np.arange(n) + 0.5) / n
        if self.log and lo > 0:
            return tuple(float(v) for v in np.exp(np.log(lo) + q * (np.log(hi) - np.log(lo))))
        return tuple(float(v) for v in lo + q * (hi - lo))


@dataclass(frozen=True)
class Parameter:
    """One parameter's value in a :class:`Parameters` set.

    Attributes
    ----------
    name : str
        Full name (``E_t``, ``slack.deadband_mm``, ``slack.deadband_mm@S2``).
    value : float
    vary : bool
        Fitted (True) or held (False).
    lo, hi : float
        Bounds.
    unit : str
    stderr : float
        Standard error after a fit (NaN before; inf when the data cannot see it).
    sample : str | None
        The sample a per-sample copy belongs to (None: shared).
    log : bool
        Start grids are log-spaced.
    starts : tuple[float, ...]
        Explicit start values for multi-start fits.
    kind : str
        See :attr:`Param.kind`.
    """

    name: str
    value: float
    vary: bool = False
    lo: float = -math.inf
    hi: float = math.inf
    unit: str = ""
    stderr: float = math.nan
    sample: str | None = None
    log: bool = False
    starts: tuple = ()
    kind: str = ""

    @property
    def base_name(self) -> str:
        """The name without its ``@sample`` suffix."""
        return self.name.split("@", 1)[0]

    def grid(self, n: int = 3) -> tuple[float, ...]:
        return Param(self.base_name, self.unit, self.lo, self.hi, self.value, log=self.log,
                     starts=self.starts).grid(n)

    def on_bound(self, rel: float = 1e-6) -> bool:
        span = self.hi - self.lo if math.isfinite(self.hi - self.lo) else max(abs(self.value), 1.0)
        return self.value - self.lo <= rel * span or self.hi - self.value <= rel * span


def split_name(name: str) -> tuple[str, str | None]:
    """``'slack.deadband_mm@S2'`` -> ``('slack.deadband_mm', 'S2')``; no ``@`` -> ``(name, None)``."""
    base, sep, smp = name.partition("@")
    return base, (smp if sep else None)


@dataclass(frozen=True)
class Parameters:
    """An ordered, immutable set of :class:`Parameter` by full name (see the module docstring).

    Operations return new sets: :meth:`set` (change fields of one),
    :meth:`with_values`, :meth:`per_sample` (add per-sample copies).
    """

    items: tuple = ()
    _index: dict = field(default=None, compare=False, repr=False)

    def __post_init__(self):
        object.__setattr__(self, "_index", {p.name: p for p in self.items})

    @classmethod
    def of(cls, params: Iterable[Parameter]) -> "Parameters":
        seen = {}
        for p in params:
            seen[p.name] = p
        return cls(tuple(seen.values()))

    # mapping-like access
    def __getitem__(self, name: str) -> Parameter:
        return self._index[name]

    def __contains__(self, name: object) -> bool:
        return name in self._index

    def __iter__(self) -> Iterator[str]:
        return iter(self._index)

    def __len__(self) -> int:
        return len(self.items)

    def get(self, name: str, default=None):
        return self._index.get(name, default)

    @property
    def names(self) -> tuple[str, ...]:
        return tuple(self._index)

    @property
    def values(self) -> dict[str, float]:
        """``{name: value}`` of every parameter (what :meth:`JointModel.predict` takes)."""
        return {p.name: float(p.value) for p in self.items}

    @property
    def varying(self) -> tuple[str, ...]:
        """Names of the fitted parameters, in order."""
        return tuple(p.name for p in self.items if p.vary)

    @property
    def stderr(self) -> dict[str, float]:
        return {p.name: float(p.stderr) for p in self.items if p.vary}

    @property
    def per_sample_names(self) -> tuple[str, ...]:
        return tuple(p.name for p in self.items if p.sample is not None)

    def set(self, name: str, **changes) -> "Parameters":
        """A copy with ``name``'s fields changed (``value=``, ``vary=``, ``lo=``, ...)."""
        new = replace(self._index[name], **changes)
        return Parameters(tuple(new if p.name == name else p for p in self.items))

    def with_values(self, values: Mapping[str, float], stderr: Mapping[str, float] | None = None) -> "Parameters":
        """A copy with new values (and standard errors) for the names given; other names unchanged."""
        se = stderr or {}
        out = []
        for p in self.items:
            ch = {}
            if p.name in values:
                ch["value"] = float(values[p.name])
            if p.name in se:
                ch["stderr"] = float(se[p.name])
            out.append(replace(p, **ch) if ch else p)
        return Parameters(tuple(out))

    def per_sample(self, names: Iterable[str], samples: Iterable[str]) -> "Parameters":
        """Add a per-sample copy ``name@S`` of each ``name`` for each sample (same value, bounds, vary).

        The shared parameter is then held (every sample has its own copy).
        """
        samples = list(samples)
        out = []
        for p in self.items:
            if p.name in set(names):
                out.append(replace(p, vary=False))
                out += [replace(p, name=f"{p.name}@{s}", sample=s) for s in samples]
            else:
                out.append(p)
        return Parameters.of(out)

    def for_sample(self, sample: str) -> dict[str, float]:
        """Values as seen by one sample: each ``name@sample`` overrides ``name``; other samples' copies dropped."""
        vals = {}
        for p in self.items:
            if p.sample is None:
                vals.setdefault(p.name, float(p.value))
            elif p.sample == sample:
                vals[p.base_name] = float(p.value)
        return vals


def values_for_sample(values: Mapping[str, float], sample: str) -> dict[str, float]:
    """Like :meth:`Parameters.for_sample` for a plain ``{name: value}`` dict."""
    out = {k: float(v) for k, v in values.items() if "@" not in k}
    suffix = f"@{sample}"
    for k, v in values.items():
        if k.endswith(suffix):
            out[k[: -len(suffix)]] = float(v)
    return out
