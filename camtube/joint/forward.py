"""Notch-by-notch forward model: tendon stroke -> per-notch angles, force, strain and tip pose.

Model (lengths mm, forces N, angles rad unless named ``_deg``)
---------------------------------------------------------------
Each bending direction (the rotary angle its notches share) has its own tendon, anchored at
the tip, that pulls only its own notches (as in :func:`camtube.design.geometry.bends_at_stroke`).
Along one tendon, notches are taken from the base (large ``x``) to the tip:

* notch ``i`` is a short beam: its backbone sector (arc ``s_i``, width ``h_i``) has second
  moment ``I_i`` about its own neutral axis, stiffness ``k_i = E I_i / h_i`` (N mm/rad), and the
  tendon, ``arm_i = ybar_i + r_i - r_t`` from that axis, bends it by ``theta_i = T_i arm_i / k_i``;
* the notch closes (contact) at ``h_i / (r_o + ybar_i)``: it then stops bending;
* capstan friction: the tendon wraps each notch's edges by the notch's angle, so the tension
  reaching the next notch is ``T_{i+1} = T_i exp(-mu theta_i)``;
* the stroke is ``slack + sum_i arm_i theta_i + elongation(F)``, with the elastic elongation
  ``F L0 / (E_t pi r_t^2)`` (plus a toe region and a series compliance when calibrated).

Each backbone beam is longer than ``h`` by the root length the finite-element model of a notch in its row
shows (:mod:`camtube.joint.fe`): the default hinge ``fe_row`` (:data:`HINGE_ROW`) shortens a lone notch's root by
the webs to its neighbours (the notches of its own direction); ``beam`` is the paper's ``h`` and ``fe_fit`` a lone
notch's root (:data:`HINGE_FE_POLY`).
For a given stroke the motor-side force ``F`` is the root of that (monotone) stroke equation.
The tip pose follows by chaining the notch rotations, each about its backbone's neutral axis.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from camtube.design.geometry import (
    MATERIAL_MODULUS_GPA, joint_geometry, notches_by_direction, tendon_compliance_mm_per_N,
)
from camtube.design.pattern import Pattern
from camtube.errors import CamtubeError
from camtube.inputfile import parse_json, read_input_text

#: Tube modulus (GPa) when the material has no entry in MATERIAL_MODULUS_GPA.
FALLBACK_MODULUS_GPA = 2.5

#: ``hinge="fe_fit"``: the backbone bends over ``h + r_o * poly(phi)`` instead of ``h``. The cubic (highest
#: power first) was fitted to ten finite-element runs of :mod:`camtube.joint.fe` (tubes r_o/r_i 0.75/0.45,
#: 0.85/0.55, 1.25/0.75; phi 1.1-4.3 rad; h 0.3-0.8 mm), none of them a preset notch: the extra length hardly
#: depends on h, and peaks near phi = 3 (a half-tube backbone) at about one outer radius. Those runs were of a notch
#: *alone*; in a pattern the webs are shorter than that root length and a notch in its row is 16-55 % stiffer, so
#: ``fe_fit`` is 16-35 % too soft there, and it ignores the wall ratio (17-21 % too stiff on thin walls): the FE of a
#: notch in a row lies between ``beam`` and ``fe_fit`` (docs/design.md); ``fe_row`` (below) is the default.
HINGE_FE_POLY = (-0.0737, 0.5155, -0.8976, 1.0071)

#: ``hinge="fe_row"``: the backbone bends over ``h + r_o A (tanh(w_1 / (B r_o)) + tanh(w_2 / (B r_o))) / 2``,
#: ``w_1, w_2`` the webs (edge to edge, as cut) to the neighbouring notches on either side (a side without a
#: neighbour: plain tube, tanh = 1), ``A = a0 + a1 phi + a2 r_i / r_o`` the root length of a lone notch
#: over r_o and ``B r_o`` the decay length of a root into the tube (a shear-lag root whose far end is the web's
#: middle, the plane of symmetry between two notches: its compliance is ``tanh(w / 2 lambda)`` of the
#: unbounded root's). Fitted by ``python scripts/fe_row_runs.py fit`` to the 20 training runs of
#: scripts/data/fe_row_train.json (rows of five, a Latin hypercube over r_o, r_i / r_o, phi, h and the web; the
#: middle and the far-end notch of each); checked against the FE table's notches and held-out rows (docs/design.md).
#: Not for notches on alternate sides (two directions interleaved): there the FE row is several times softer than
#: this (or any) hinge says (``scripts/fe_notch_table.py --alternating``).
HINGE_ROW = {"a": (0.151, 0.113, 0.689), "b": 1.32}
HINGES = ("beam", "fe_fit", "fe_row")


def hinge_extra_mm(outer_radius_mm: float, phi_rad: float, hinge: str = "beam", *,
                   inner_radius_mm: float | None = None, webs_mm=(math.inf, math.inf)) -> float:
    """Extra bending length (mm) of a notch's backbone beyond its width h (0 for the plain beam model).

    ``fe_row`` needs ``inner_radius_mm`` and the webs (mm, edge to edge, as cut) to the neighbouring notches on
    either side (``math.inf``: plain tube on that side; the default, a lone notch).
    """
    return hinge_root_mm(outer_radius_mm, phi_rad, hinge, inner_radius_mm) * hinge_side_factor(
        outer_radius_mm, webs_mm, hinge)


def hinge_root_mm(outer_radius_mm: float, phi_rad: float, hinge: str = "beam",
                  inner_radius_mm: float | None = None) -> float:
    """The extra bending length (mm) of a lone notch (plain tube on both sides)."""
    if hinge == "beam":
        return 0.0
    if hinge == "fe_fit":
        return outer_radius_mm * max(float(np.polyval(HINGE_FE_POLY, phi_rad)), 0.0)
    if hinge != "fe_row":
        raise ValueError(f"unknown hinge model {hinge!r}; one of {', '.join(HINGES)}")
    if inner_radius_mm is None:
        raise ValueError("the fe_row hinge needs the inner radius")
    return row_extra_mm(outer_radius_mm, inner_radius_mm, phi_rad, (math.inf, math.inf), HINGE_ROW["a"],
                        HINGE_ROW["b"])


def hinge_side_factor(outer_radius_mm: float, webs_mm, hinge: str = "beam") -> float:
    """The share (0..1] of the lone notch's root length left by the webs to its neighbours (1 but for ``fe_row``)."""
    if hinge != "fe_row":
        return 1.0
    return _sides(outer_radius_mm, webs_mm, HINGE_ROW["b"])


def _sides(outer_radius_mm: float, webs_mm, b: float) -> float:
    sides = [math.tanh(max(w, 0.0) / (b * outer_radius_mm)) if math.isfinite(w) else 1.0 for w in webs_mm]
    return sum(sides) / len(sides)


def row_extra_mm(outer_radius_mm: float, inner_radius_mm: float, phi_rad: float, webs_mm, a, b: float) -> float:
    """The ``fe_row`` root length (mm) with coefficients ``a = (a0, a1, a2)`` and ``b`` (see :data:`HINGE_ROW`)."""
    root = a[0] + a[1] * phi_rad + a[2] * inner_radius_mm / outer_radius_mm
    return outer_radius_mm * max(root, 0.0) * _sides(outer_radius_mm, webs_mm, b)


def row_webs_mm(x_mm, width_mm) -> list[tuple[float, float]]:
    """Per notch (in the order given, along the tube) the webs (mm, edge to edge) to the previous and the next
    notch of the row; ``math.inf`` at the row's ends."""
    x, h = np.asarray(x_mm, float), np.asarray(width_mm, float)
    gaps = [abs(x[i + 1] - x[i]) - (h[i] + h[i + 1]) / 2.0 for i in range(len(x) - 1)]
    return [(gaps[i - 1] if i > 0 else math.inf, gaps[i] if i < len(gaps) else math.inf) for i in range(len(x))]


#: The schemas of the files a calibration is read from (``model fit --json``, ``model diagnose --json``).
CALIBRATION_SCHEMAS = ("camtube.fit/1", "camtube.diagnose/1")
#: The largest value of each base parameter a calibration may give (and its unit): the stiffest fibre's modulus, a
#: tendon of 10 m, an arm ten times the section's (an effect parameter's range is :data:`CALIBRATION_RANGE`).
CALIBRATION_MAX = {"E_t": (1000.0, "GPa"), "L0": (10_000.0, "mm"), "arm_scale": (10.0, "")}

#: The range a fit takes each effect parameter a calibration uses in, and its unit: the built-in effects' Param
#: bounds (``tests/joint/test_forward.py`` holds them to the registry's; this stage does not import the model's).
CALIBRATION_RANGE = {"slack.deadband_mm": (0.0, 10.0, "mm"), "toe.toe_mm": (0.0, 5.0, "mm"),
                     "kerf.kerf_mm": (-0.5, 0.5, "mm"), "series.compliance_mm_per_N": (0.0, 10.0, "mm/N"),
                     "friction.mu": (-0.9, 0.9, "")}

#: The smallest value of each base parameter a calibration may give (and its unit): the lower bounds a fit takes them in
#: (:data:`camtube.model.core.model.BASE_PARAMS`).
CALIBRATION_MIN = {"E_t": (0.5, "GPa"), "L0": (1.0, "mm"), "arm_scale": (0.3, "")}


@dataclass(frozen=True)
class Mechanics:
    """Physical constants of the forward model beyond the cut geometry.

    Attributes
    ----------
    tube_modulus_gpa : float or None
        Young's modulus of the tube (None: from the material, 2.5 GPa for polyimide).
    friction : float or None
        Capstan friction coefficient of the tendon on the notch edges (None: the pattern's
        ``tendon.friction``).
    tendon_modulus_gpa, tendon_length_mm : float or None
        E_t and L0 (None: the pattern's ``tendon``).
    slack_mm : float
        Stroke taken up before the tendon is taut.
    toe_mm : float
        Elongation over which the tendon's fibres straighten (0: linear tendon).
    series_compliance_mm_per_N : float
        Extra compliance in series with the tendon (sheath, fixture).
    arm_scale : float
        Factor on every moment arm.
    kerf_mm : float
        Overcut of the laser: each notch is cut this much wider than drawn, in arc and in width
        (a job planned without kerf compensation cuts its first pass on the design line).
    sheath_loss : float
        Fraction of the motor-side force lost before the joint (tendon-sheath friction while pulling).
    hinge : {"fe_row", "beam", "fe_fit"}
        How long a beam the backbone is: ``fe_row`` (the default: h plus a root length that shrinks with the
        webs to the neighbouring notches, :data:`HINGE_ROW`), ``beam`` (the paper's: the notch width h) or
        ``fe_fit`` (h plus the root length of a lone notch, :data:`HINGE_FE_POLY`).
    source : str
        Where the values came from (``defaults`` or a fit file).
    ignored : tuple[str, ...]
        Parameters of a calibration file the model does not use.
    """

    tube_modulus_gpa: float | None = None
    friction: float | None = None
    tendon_modulus_gpa: float | None = None
    tendon_length_mm: float | None = None
    slack_mm: float = 0.0
    toe_mm: float = 0.0
    series_compliance_mm_per_N: float = 0.0
    arm_scale: float = 1.0
    kerf_mm: float = 0.0
    sheath_loss: float = 0.0
    hinge: str = "fe_row"
    source: str = "defaults"
    ignored: tuple[str, ...] = ()

    def modulus_gpa(self, material: str) -> float:
        if self.tube_modulus_gpa is not None:
            return self.tube_modulus_gpa
        return MATERIAL_MODULUS_GPA.get(material, FALLBACK_MODULUS_GPA)

    def mu(self, pattern: Pattern) -> float:
        """The capstan friction coefficient used for ``pattern``."""
        return self.friction if self.friction is not None else pattern.tendon.friction

    def compliance_mm_per_N(self, pattern: Pattern) -> float:
        """Linear tendon compliance ``L0 / (E_t pi r_t^2)`` plus the series compliance (mm/N)."""
        td = pattern.tendon
        e_t = self.tendon_modulus_gpa if self.tendon_modulus_gpa is not None else td.modulus_gpa
        l0 = self.tendon_length_mm if self.tendon_length_mm is not None else td.length_mm
        return tendon_compliance_mm_per_N(l0, e_t, td.radius_mm) + self.series_compliance_mm_per_N

    def elongation_mm(self, force_N: float, pattern: Pattern) -> float:
        """Tendon elongation (mm) at motor-side force ``force_N`` (toe region, then linear)."""
        c = self.compliance_mm_per_N(pattern)
        f = max(force_N, 0.0)
        et = self.toe_mm
        if et > 0.0 and f < et / (2.0 * c):
            return math.sqrt(2.0 * et * c * f)
        return c * f + 0.5 * et

    @classmethod
    def from_fit_json(cls, path: str | Path, **base) -> "Mechanics":
        """Mechanics with the parameters of a ``camtube model fit --json`` or ``model diagnose --json`` file.

        Used: ``E_t``, ``L0``, ``arm_scale``, ``slack.deadband_mm``, ``toe.toe_mm``, ``kerf.kerf_mm``,
        ``series.compliance_mm_per_N``, ``friction.mu`` (as the sheath loss while pulling). Per-sample
        copies (``name@S``) are averaged. Other parameters are listed in :attr:`ignored`.

        Raises
        ------
        CamtubeError
            The file is unreadable, not JSON, or has no parameters.
        """
        p = Path(path)
        try:
            doc = parse_json(read_input_text(p))
        except OSError as exc:
            raise CamtubeError(f"{p}: cannot read the calibration: {exc.strerror}; fix: check the path") from None
        except (json.JSONDecodeError, UnicodeDecodeError) as exc:
            raise CamtubeError(f"{p}: the calibration is not JSON ({exc}); fix: pass the file written by "
                               "'camtube model fit --json' or 'camtube model diagnose --json'") from None
        schema = doc.get("schema") if isinstance(doc, dict) else None
        if schema is not None and schema not in CALIBRATION_SCHEMAS:   # (taken without a word)
            raise CamtubeError(f"{p}: schema {schema!r} is not a fit's ({' or '.join(CALIBRATION_SCHEMAS)}); fix: pass "
                               "the JSON of 'camtube model fit --json' or 'camtube model diagnose --json'")
        params = _fit_params(doc, p)
        if not params:
            raise CamtubeError(f"{p}: no fitted parameters found (expected 'params' or 'final.params' of a "
                               "camtube.fit/1 or camtube.diagnose/1 file); fix: pass the JSON of 'camtube model "
                               "fit --json' or 'camtube model diagnose --json'")
        used = {"E_t": "tendon_modulus_gpa", "L0": "tendon_length_mm", "arm_scale": "arm_scale",
                "slack.deadband_mm": "slack_mm", "toe.toe_mm": "toe_mm", "kerf.kerf_mm": "kerf_mm",
                "series.compliance_mm_per_N": "series_compliance_mm_per_N", "friction.mu": "sheath_loss"}
        # the physical range of each used value: a fitted value outside it is not a calibration of a joint
        positive = {"E_t": "GPa", "L0": "mm", "arm_scale": ""}
        values: dict[str, float] = dict(base)
        ignored = []
        for name, v in params.items():
            if name in used and (v <= 0.0 if name in positive else v < 0.0 and name != "friction.mu"):
                unit = positive.get(name, "")
                raise CamtubeError(f"{p}: parameter {name} = {v:g}{' ' + unit if unit else ''}: outside its physical "
                                   f"range ({'> 0' if name in positive else '>= 0'}); fix: pass the JSON of a fit "
                                   "whose parameters are physical (hold a parameter with --fix NAME=VALUE)")
            if name in CALIBRATION_MIN and v < CALIBRATION_MIN[name][0]:
                # (E_t = 1e-300 GPa was taken: the design then asked for 1e295 mm of tendon travel)
                low, unit = CALIBRATION_MIN[name]
                raise CamtubeError(f"{p}: parameter {name} = {v:g}{' ' + unit if unit else ''}: below any fit's (at "
                                   f"least {low:g}{' ' + unit if unit else ''}, the lower bound a fit takes it in); fix: "
                                   "pass the JSON of a fit whose parameters are physical")
            if name in CALIBRATION_MAX and v > CALIBRATION_MAX[name][0]:
                # (E_t = 1e300 GPa was taken: a tendon that does not stretch, the design computed without a word)
                top, unit = CALIBRATION_MAX[name]
                raise CamtubeError(f"{p}: parameter {name} = {v:g}{' ' + unit if unit else ''}: beyond any joint's "
                                   f"(at most {top:g}{' ' + unit if unit else ''}); fix: pass the JSON of a fit whose "
                                   "parameters are physical (hold a parameter with --fix NAME=VALUE)")
            bounds = CALIBRATION_RANGE.get(name)
            if bounds is not None and not bounds[0] <= v <= bounds[1]:
                # (friction.mu = 1.5 was designed with, a bend of 0 deg at 3 N; a kerf of 20 mm, a value in um, was
                # blamed on the goal's limits): no fit gives a value outside its effect's range
                lo, hi, unit = bounds
                u = f" {unit}" if unit else ""
                raise CamtubeError(f"{p}: parameter {name} = {v:g}{u}: outside the range a fit takes it in ({lo:g} to "
                                   f"{hi:g}{u}, its effect's), so it is no fit's value (another unit?); fix: pass the "
                                   "JSON of 'camtube model fit --json' or 'camtube model diagnose --json' as written")
            if name in used:
                values[used[name]] = v
            else:
                ignored.append(name)
        if values.get("sheath_loss", 0.0) < 0.0:  # a negative mu is a gain, not a loss: keep it at 0
            values["sheath_loss"] = 0.0
        return cls(**values, source=str(p), ignored=tuple(sorted(ignored)))


def _fit_params(doc, path: Path) -> dict[str, float]:
    """``{name: value}`` of a fit or diagnose JSON, per-sample copies averaged.

    Raises
    ------
    CamtubeError
        A parameter whose value is not a finite number (NaN, Infinity, null, text, true/false), naming ``path``
        and the key: it was skipped, so the joint was computed with the pattern's value instead.
    """
    if not isinstance(doc, dict):
        return {}
    if doc.get("success") is False:
        # (a fit that did not converge was designed with, without a word)
        raise CamtubeError(f"{path}: success: false: this fit did not converge ({str(doc.get('message', ''))[:80]}), so "
                           "its values are not estimates; fix: fit again until it converges (more --starts, fewer "
                           "parameters) and pass that JSON")
    where, block = "params", doc.get("params")
    if not isinstance(block, dict) and isinstance(doc.get("final"), dict):
        where, block = "final.params", doc["final"].get("params")
    if not isinstance(block, dict):
        return {}
    sums: dict[str, list[float]] = {}
    for name, entry in block.items():
        if isinstance(entry, dict) and entry.get("fitted") is False:
            # held in that fit (the pattern's L0 of 70 mm, say): not measured, so not a calibration; it overrode the
            # goal's tendon length of 200 mm, and the design's angles were those of a 70 mm tendon
            continue
        key = f"{where}.{name}" + (".value" if isinstance(entry, dict) else "")
        v = entry.get("value") if isinstance(entry, dict) else entry
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            got = ("no value" if isinstance(entry, dict) and "value" not in entry
                   else "got " + json.dumps(v, allow_nan=True)[:40])
            raise CamtubeError(f"{path}: {key}: not a finite number ({got}); fix: write the fitted value there, or "
                               "pass the JSON of 'camtube model fit --json' or 'camtube model diagnose --json' as "
                               "written")
        se = entry.get("stderr") if isinstance(entry, dict) else None
        if isinstance(entry, dict) and str(name).split("@")[0] in ("E_t", "L0", "arm_scale") and \
                isinstance(se, (int, float)) and \
                not isinstance(se, bool) and not (math.isfinite(se) and se <= abs(v)):
            # (E_t 28 +- 9e5 GPa, fitted beside L0: not an estimate, and it was designed with; an effect's value may be
            # near zero within its error, a slack of 0.00003 +- 0.0006 mm: the base parameters only)
            raise CamtubeError(f"{path}: {where}.{name}: {v:g} +- {se:g}: its standard error exceeds the value, so "
                               "the data did not determine it; fix: fit it again with the parameters it trades against "
                               "held (see the fit's correlations), and pass that JSON")
        sums.setdefault(str(name).split("@")[0], []).append(float(v))
    return {k: sum(v) / len(v) for k, v in sums.items()}


@dataclass(frozen=True, eq=False)
class NotchSet:
    """The notches of one bending direction, base to tip, with their mechanics.

    Attributes
    ----------
    angle_deg : float
        Direction (rotary angle of the notch centres).
    index : (n,) int
        Index of each notch in ``pattern.notches``.
    x_mm, width_mm, arc_mm : (n,) float
        Centre, axial width h and arc s, as cut (drawn + ``kerf_mm``).
    arm_mm : (n,) float
        Moment arm of the tendon about each backbone's neutral axis (times ``arm_scale``).
    ybar_mm : (n,) float
        Backbone centroid distance from the tube axis.
    stiffness_nmm_per_rad : (n,) float
        ``E I / L`` of each notch (``L`` its bending length).
    closure_rad : (n,) float
        Angle at which each notch closes.
    extreme_fibre_mm : (n,) float
        Largest distance of backbone material from the neutral axis.
    bending_length_mm : (n,) float
        Length over which each backbone bends (h, or more with a hinge model).
    """

    angle_deg: float
    index: np.ndarray
    x_mm: np.ndarray
    width_mm: np.ndarray
    arc_mm: np.ndarray
    arm_mm: np.ndarray
    ybar_mm: np.ndarray
    stiffness_nmm_per_rad: np.ndarray
    closure_rad: np.ndarray
    extreme_fibre_mm: np.ndarray
    bending_length_mm: np.ndarray

    def angles_at(self, tension_N: float, friction: float) -> np.ndarray:
        """Per-notch angles (rad, base to tip) when the tendon enters the joint at ``tension_N``."""
        out = np.empty(len(self.x_mm))
        t = max(tension_N, 0.0)
        for i in range(len(out)):
            th = min(t * self.arm_mm[i] / self.stiffness_nmm_per_rad[i], self.closure_rad[i])
            out[i] = th
            t *= math.exp(-friction * th)
        return out

    def strain(self, angles_rad: np.ndarray) -> np.ndarray:
        """Peak backbone strain of each notch at ``angles_rad``."""
        return self.extreme_fibre_mm * np.asarray(angles_rad) / self.bending_length_mm


def notch_set(tube, tendon_radius_mm: float, angle_deg: float, x_mm, width_mm, arc_mm,
              mechanics: Mechanics = Mechanics(), index=None, webs_mm=None) -> NotchSet:
    """A :class:`NotchSet` from per-notch arrays (base to tip): centres, widths h and arcs s (mm).

    ``mechanics.kerf_mm`` widens each arc and width (as cut); the arcs are kept inside ``(0, 2 pi r_o)``.
    ``webs_mm`` (the ``fe_row`` hinge): per notch the two webs (as cut) to its neighbours; by default from the
    centres and the as-cut widths of these notches (:func:`row_webs_mm`).
    """
    e = mechanics.modulus_gpa(tube.material) * 1e3  # N/mm^2
    circ = tube.circumference_mm
    geos = [joint_geometry(tube.outer_radius_mm, tube.inner_radius_mm,
                           min(max(float(s) + mechanics.kerf_mm, 1e-6), circ - 1e-6),
                           max(float(h) + mechanics.kerf_mm, 1e-6), tendon_radius_mm)
            for h, s in zip(width_mm, arc_mm)]
    n = len(geos)
    if webs_mm is None:
        webs_mm = row_webs_mm(x_mm, [g.notch_width_mm for g in geos])
    bend_len = np.array([g.notch_width_mm + hinge_extra_mm(g.outer_radius_mm, g.phi_rad, mechanics.hinge,
                                                           inner_radius_mm=g.inner_radius_mm, webs_mm=w)
                         for g, w in zip(geos, webs_mm)])
    return NotchSet(
        angle_deg=angle_deg,
        index=np.arange(n) if index is None else np.asarray(index, int),
        x_mm=np.asarray(x_mm, float),
        width_mm=np.array([g.notch_width_mm for g in geos]),
        arc_mm=np.array([g.arc_mm for g in geos]),
        arm_mm=np.array([g.moment_arm_mm * mechanics.arm_scale for g in geos]),
        ybar_mm=np.array([g.ybar_mm for g in geos]),
        stiffness_nmm_per_rad=np.array([e * g.second_moment_mm4 for g in geos]) / bend_len,
        closure_rad=np.array([g.closure_angle_rad for g in geos]),
        extreme_fibre_mm=np.array([g.extreme_fibre_mm for g in geos]),
        bending_length_mm=bend_len,
    )


def direction_notches(pattern: Pattern, mechanics: Mechanics = Mechanics()) -> list[NotchSet]:
    """The pattern's notches grouped by direction (sorted by angle), each base to tip."""
    index_of = {id(n): k for k, n in enumerate(pattern.notches)}
    out = []
    for ang, notches in notches_by_direction(pattern):
        ns = sorted(notches, key=lambda n: -n.x_mm)
        out.append(notch_set(pattern.tube, pattern.tendon.radius_mm, ang, [n.x_mm for n in ns],
                             [n.width_mm for n in ns], [n.arc_mm for n in ns], mechanics,
                             [index_of[id(n)] for n in ns]))
    return out


@dataclass(frozen=True, eq=False)
class DirectionState:
    """One tendon's state at its stroke.

    Attributes
    ----------
    angle_deg : float
        Bending direction.
    stroke_mm : float
        Motor-side tendon stroke.
    force_N : float
        Motor-side tendon force.
    notch_angles_rad : (n,) float
        Per-notch angles, base to tip (``notches.index`` maps them to the pattern).
    strain : (n,) float
        Per-notch peak backbone strain.
    closed : (n,) bool
        Notches that are closed (in contact).
    notches : NotchSet
    """

    angle_deg: float
    stroke_mm: float
    force_N: float
    notch_angles_rad: np.ndarray
    strain: np.ndarray
    closed: np.ndarray
    notches: NotchSet

    @property
    def bend_deg(self) -> float:
        """Sum of this direction's notch angles (deg)."""
        return math.degrees(float(np.sum(self.notch_angles_rad)))

    @property
    def shares(self) -> np.ndarray:
        """Each notch's share of the direction's bend, base to tip (sums to 1)."""
        tot = float(np.sum(self.notch_angles_rad))
        return self.notch_angles_rad / tot if tot > 0 else np.zeros_like(self.notch_angles_rad)


@dataclass(frozen=True, eq=False)
class JointState:
    """The whole joint at a set of strokes.

    Attributes
    ----------
    directions : tuple[DirectionState, ...]
    notch_angles_rad : (n,) float
        Angle of every notch of ``pattern.notches``, in pattern order.
    tip_position_mm : (3,) float
        Tip centre in the tube frame: origin at the base section (x = tube.length), ``z`` along the
        straight tube towards the tip, rotary angle 0 along ``+x``.
    tip_direction : (3,) float
        Unit tangent of the tube at the tip.
    centerline_mm : (m, 3) float
        Points of the tube's axis from the base to the tip.
    """

    directions: tuple[DirectionState, ...]
    notch_angles_rad: np.ndarray
    tip_position_mm: np.ndarray
    tip_direction: np.ndarray
    centerline_mm: np.ndarray

    @property
    def tip_angle_deg(self) -> float:
        """Angle between the tip direction and the straight tube's axis (deg)."""
        return math.degrees(math.acos(max(-1.0, min(1.0, float(self.tip_direction[2])))))

    @property
    def tip_plane_deg(self) -> float:
        """Azimuth of the tip direction (rotary angle towards which the tip points, deg in [0, 360))."""
        return math.degrees(math.atan2(self.tip_direction[1], self.tip_direction[0])) % 360.0

    @property
    def max_strain(self) -> float:
        return max((float(np.max(d.strain)) for d in self.directions if len(d.strain)), default=0.0)

    def direction(self, angle_deg: float) -> DirectionState:
        for d in self.directions:
            if abs((d.angle_deg - angle_deg + 180.0) % 360.0 - 180.0) < 1e-6:
                return d
        raise KeyError(f"no notches at {angle_deg:g} deg")


def _solve_force(ns: NotchSet, stroke_mm: float, pattern: Pattern, mech: Mechanics) -> float:
    """Motor-side force (N) at which the modelled stroke equals ``stroke_mm`` (brentq on a monotone function)."""
    from scipy.optimize import brentq

    eff = stroke_mm - mech.slack_mm
    if eff <= 0.0:
        return 0.0
    keep = 1.0 - mech.sheath_loss

    def stroke_of(f: float) -> float:
        th = ns.angles_at(f * keep, mech.mu(pattern))
        return float(ns.arm_mm @ th) + mech.elongation_mm(f, pattern) - eff

    hi = 1.0
    while stroke_of(hi) < 0.0:
        hi *= 2.0
        if hi > 1e9:
            raise CamtubeError("the joint cannot take up the stroke (no finite force found)")
    return float(brentq(stroke_of, 0.0, hi, xtol=1e-12, rtol=1e-12, maxiter=200))


def simulate(pattern: Pattern, strokes: float | Mapping[float, float],
             mechanics: Mechanics = Mechanics()) -> JointState:
    """The joint at the given tendon strokes.

    Parameters
    ----------
    pattern : Pattern
        At least one notch.
    strokes : float or {angle_deg: stroke_mm}
        Motor-side stroke of every tendon (one number: every direction), mm. Directions not
        named are not pulled.
    mechanics : Mechanics

    Returns
    -------
    JointState
    """
    if not pattern.notches:
        raise CamtubeError(f"{pattern.name}: the pattern has no notches; the joint does not bend")
    sets = direction_notches(pattern, mechanics)
    states = []
    all_angles = np.zeros(len(pattern.notches))
    for ns in sets:
        if isinstance(strokes, Mapping):
            stroke = next((float(v) for a, v in strokes.items()
                           if abs((float(a) - ns.angle_deg + 180.0) % 360.0 - 180.0) < 1e-6), 0.0)
        else:
            stroke = float(strokes)
        f = _solve_force(ns, stroke, pattern, mechanics)
        th = ns.angles_at(f * (1.0 - mechanics.sheath_loss), mechanics.mu(pattern))
        states.append(DirectionState(ns.angle_deg, stroke, f, th, ns.strain(th), th >= ns.closure_rad * (1 - 1e-9),
                                     ns))
        all_angles[ns.index] = th
    pts, tip_dir = centerline(pattern, all_angles, mechanics)
    return JointState(tuple(states), all_angles, pts[-1], tip_dir, pts)


def _rot(axis: np.ndarray, angle: float) -> np.ndarray:
    a = axis / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1.0 - math.cos(angle)) * (k @ k)


def centerline(pattern: Pattern, notch_angles_rad: np.ndarray, mechanics: Mechanics = Mechanics(),
               per_notch: int = 6) -> tuple[np.ndarray, np.ndarray]:
    """Tube axis from the base to the tip for given notch angles.

    Each notch bends by its angle about the neutral axis of its backbone (``ybar`` from the
    axis, opposite the notch), spread over ``per_notch`` steps across its width; the tube is
    straight elsewhere.

    Returns
    -------
    points : (m, 3) float
        Axis points (mm) in the tube frame of :class:`JointState`.
    tip_direction : (3,) float
    """
    t = pattern.tube
    notches = pattern.notches
    order = sorted(range(len(notches)), key=lambda k: -notches[k].x_mm)
    p = np.zeros(3)
    r = np.eye(3)  # columns: local x, y (rotary frame), z (towards the tip)
    pts = [p.copy()]
    pos = t.length_mm  # current axial coordinate (x from the tip)
    circ = t.circumference_mm
    for k in order:
        n = notches[k]
        theta = float(notch_angles_rad[k])
        start = n.x_mm + n.width_mm / 2.0
        p = p + r[:, 2] * (pos - start)
        pts.append(p.copy())
        arc = min(max(n.arc_mm + mechanics.kerf_mm, 1e-6), circ - 1e-6)
        g = joint_geometry(t.outer_radius_mm, t.inner_radius_mm, arc, n.width_mm + mechanics.kerf_mm,
                           pattern.tendon.radius_mm)
        a = math.radians(n.angle_deg)
        towards = r[:, 0] * math.cos(a) + r[:, 1] * math.sin(a)  # notch side, in the local section
        axis = np.cross(r[:, 2], towards)  # closing the notch turns the tip towards it
        step_len = n.width_mm / per_notch
        rot = _rot(axis, theta / per_notch)
        for _ in range(per_notch):
            q = p - towards * g.ybar_mm + r[:, 2] * (step_len / 2.0)  # neutral fibre, mid-step
            r = rot @ r
            towards = rot @ towards
            p = q + r[:, 2] * (step_len / 2.0) + towards * g.ybar_mm
            pts.append(p.copy())
        pos = n.x_mm - n.width_mm / 2.0
    p = p + r[:, 2] * pos
    pts.append(p.copy())
    return np.array(pts), r[:, 2].copy()


def stroke_table(pattern: Pattern, stroke_mm: float, mechanics: Mechanics = Mechanics()) -> str:
    """Text report of the joint at ``stroke_mm`` on every tendon, one tendon pulled at a time.

    Per direction: force, bend, largest strain, closed notches, then every notch's angle and
    strain; then the tip pose with all tendons at ``stroke_mm`` when there is one direction.
    """
    lines = [f"forward model at a tendon stroke of {stroke_mm:g} mm (notch by notch; friction mu "
             f"{mechanics.mu(pattern):g}, hinge {mechanics.hinge}, tube E {mechanics.modulus_gpa(pattern.tube.material):g} GPa, "
             f"mechanics: {mechanics.source}; notches cut {1000 * mechanics.kerf_mm:.0f} um wider than drawn)"]
    sets = direction_notches(pattern, mechanics)
    for ns in sets:
        st = simulate(pattern, {ns.angle_deg: stroke_mm}, mechanics)
        d = st.direction(ns.angle_deg)
        lines.append(f"tendon at {d.angle_deg:g} deg: force {d.force_N:.3f} N, bend {d.bend_deg:.2f} deg, "
                     f"largest strain {float(np.max(d.strain)):.4f}, {int(np.sum(d.closed))} of {len(d.closed)} "
                     f"notches closed; tip at ({st.tip_position_mm[0]:.3f}, {st.tip_position_mm[1]:.3f}, "
                     f"{st.tip_position_mm[2]:.3f}) mm pointing {st.tip_angle_deg:.2f} deg off the axis "
                     f"towards {st.tip_plane_deg:.1f} deg")
        lines.append("   notch     x mm   angle deg   share %   strain")
        for j in range(len(ns.x_mm)):
            lines.append(f"  {int(ns.index[j]):6d} {ns.x_mm[j]:8.3f} {math.degrees(d.notch_angles_rad[j]):11.3f} "
                         f"{100 * d.shares[j]:9.2f} {d.strain[j]:8.4f}" + ("  closed" if d.closed[j] else ""))
    return "\n".join(lines)
