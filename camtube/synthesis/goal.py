"""The goal file: what the joint must do, on which stock, within which limits.

A goal YAML is read once into a frozen :class:`Goal`; every key is checked against
:data:`GOAL_SCHEMA` (unknown keys get a "did you mean"), and every problem names the file,
the line, the key, the allowed range and the fix. Lengths mm, angles deg, forces N.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from camtube.design.loader import Reader, check_name
from camtube.design.pattern import Tendon, Tube
from camtube.design.schema import INF, POS, Field
from camtube.errors import Issue, PatternError
from camtube.yamltext import line_map, read_yaml_file

_BEND_ROW = (
    ("angle_deg", Field("float", "deg", "bending direction: rotary angle of the notch centres", 180.0, -360.0, 720.0)),
    ("bend_deg", Field("float", "deg", "bend of this direction at the design stroke", ..., 0.0, 360.0, True)),
    ("stroke_mm", Field("float", "mm", "tendon stroke (motor side) at which the bend is reached", ..., **POS)),
)

_ARC_ROW = (
    ("length_mm", Field("float", "mm", "arc length of this piece of the centre line", ..., **POS)),
    ("bend_deg", Field("float", "deg", "turn of the tangent over the piece (constant curvature)", ..., 0.0, 360.0,
                       True)),
    ("towards_deg", Field("float", "deg", "rotary angle (in the tube's own frame) the piece bends towards: its "
                          "notches' angle and its tendon's side", ..., -360.0, 720.0)),
    ("stroke_mm", Field("float", "mm", "stroke of this piece's tendon at which the shape is reached", ..., **POS)),
)

#: Every key of a goal file.
GOAL_SCHEMA: dict = {
    "name": Field("str", "", "name of the written pattern (defaults to the goal file's name)", None),
    "tube": {
        "outer_radius": Field("float", "mm", "outer radius r_o of the stock", ..., 0.0, 50.0, True),
        "inner_radius": Field("float", "mm", "inner radius r_i (< r_o)", ..., 0.0, 50.0, True),
        "material": Field("choice", "", "tube material", "polyimide",
                          choices=("polyimide", "pebax", "nitinol", "other")),
        "modulus_gpa": Field("float", "GPa", "Young's modulus of the tube (default: 2.5 for polyimide)", None, 0.001,
                             1000.0),
        "hinge": Field("choice", "", "notch stiffness: fe_row (h plus a root length that shrinks with the webs to "
                       "the neighbours, fitted to FE runs of notches in rows: within 7 % of the FE), beam (E I / h, the "
                       "paper's: 1.3-4.6 x too stiff) or fe_fit (h plus a lone notch's root length: 11-45 % too soft in "
                       "a row); see docs/design.md", "fe_row", choices=("fe_row", "beam", "fe_fit")),
    },
    "tendon": {
        "radius": Field("float", "mm", "tendon radius r_t", 0.04, **POS),
        "length": Field("float", "mm", "unloaded tendon length L0", 70.0, **POS),
        "modulus_gpa": Field("float", "GPa", "tendon Young's modulus E_t (within the range a fit takes it in)", 28.0,
                             0.5, 500.0),
        "material": Field("str", "", "tendon material", "UHMWPE"),
        "friction": Field("float", "", "capstan friction coefficient on the notch edges", 0.0, 0.0, 2.0),
    },
    "goal": {
        "bends": Field("rows", "", "one target per bending direction (required unless goal.centerline)", (),
                       row=_BEND_ROW),
        "centerline": Field("rows", "", "3-D centre line from the base: circular pieces, each in its own plane with its "
                            "own tendon (one piece per direction)", (), row=_ARC_ROW),
        "distribution": Field("str", "", "how the bend is shared by the notches: uniform, tip_first, base_first, "
                              "or a list of per-notch shares from the tip", "uniform"),
        "tip_ratio": Field("float", "", "tip_first/base_first: bend of the end notch over the other end's", 3.0,
                           1.0, 100.0, True),
        "curve": Field("floats", "deg/mm", "planar curvature profile, samples evenly spaced from the tip over "
                       "curve_length (one bend only)", (), 0.0, INF, True),
        "curve_length": Field("float", "mm", "length of the joint the curve covers", None, **POS),
        "notches": Field("int_or_auto", "", "notches per direction ('auto': from max_notch_bend_deg)", "auto", 1, 200),
        "layout": Field("choice", "", "several directions: alternate their notches or put them one after the "
                        "other (the first bend nearest the tip)", "alternate", choices=("alternate", "sequential")),
        "max_notch_bend_deg": Field("float", "deg", "largest bend of one notch ('auto' notch count)", 6.0, 0.0,
                                    45.0, True),
        # (>= 1 um: the pattern is written to 0.1 um, and a web of 1e-12 mm was written as a spacing of 0)
        "web": Field("float", "mm", "web between notches (edge to edge)", 0.3, 0.001),
        "first_offset": Field("float", "mm", "tip to the first notch (room for the anchor holes)", 1.5, **POS),
        "base_length": Field("float", "mm", "plain tube kept beyond the last notch", 1.5, 0.0),
    },
    "limits": {
        "max_strain": Field("float", "", "backbone strain limit at the design stroke (at most 1: no tube's backbone "
                            "bends back from more)", 0.03, 1e-4, 1.0),
        "max_force_N": Field("float", "N", "largest tendon force the motor gives", 5.0, **POS),
        "max_length": Field("float", "mm", "longest joint (first notch's tip edge to the last notch's base edge)",
                            20.0, **POS),
        "min_web": Field("float", "mm", "smallest material bridge between two cuts", 0.1, 0.0),
        "min_backbone_arc": Field("float", "mm", "smallest backbone arc 2 pi r_o - s", 0.3, 0.0),
        "min_feature": Field("float", "mm", "smallest notch width the process cuts", 0.05, **POS),
    },
    "process": Field("str", "", "process of the written pattern: a process file name or a mapping of "
                     "pattern process keys", "femto-polyimide.yaml"),
}

DISTRIBUTIONS = ("uniform", "tip_first", "base_first")


@dataclass(frozen=True)
class BendTarget:
    """One direction's target: ``bend_deg`` at ``stroke_mm`` of its tendon, notches at ``angle_deg``."""

    angle_deg: float
    bend_deg: float
    stroke_mm: float

    def scaled(self, bend: float = 1.0, stroke: float = 1.0) -> "BendTarget":
        return BendTarget(self.angle_deg, self.bend_deg * bend, self.stroke_mm * stroke)


@dataclass(frozen=True)
class Arc:
    """One piece of a 3-D centre-line goal: ``length_mm`` of constant curvature turning the tangent by
    ``bend_deg`` towards the rotary angle ``towards_deg`` of the tube's own frame, reached at ``stroke_mm``
    of its tendon."""

    length_mm: float
    bend_deg: float
    towards_deg: float
    stroke_mm: float

    @property
    def target(self) -> BendTarget:
        return BendTarget(self.towards_deg % 360.0, self.bend_deg, self.stroke_mm)


@dataclass(frozen=True)
class Limits:
    """Limits the design must keep (mm, N)."""

    max_strain: float = 0.03
    max_force_N: float = 5.0
    max_length_mm: float = 20.0
    min_web_mm: float = 0.1
    min_backbone_arc_mm: float = 0.3
    min_feature_mm: float = 0.05


@dataclass(frozen=True)
class Goal:
    """A parsed goal file.

    Attributes
    ----------
    tube : Tube
        The stock (its length is set by the design).
    tube_modulus_gpa : float or None
    tendon : Tendon
    bends : tuple[BendTarget, ...]
        One per direction (distinct angles).
    distribution : str or tuple[float, ...]
        ``uniform``, ``tip_first``, ``base_first``, or per-notch shares from the tip.
    tip_ratio : float
    curve_deg_per_mm : tuple[float, ...]
        Curvature samples from the tip (empty: no curve).
    centerline : tuple[Arc, ...]
        3-D centre line from the base (empty: none); ``bends`` then holds one target per piece.
    curve_length_mm : float or None
    notches : int or None
        Notches per direction (None: automatic).
    layout : {"alternate", "sequential"}
    max_notch_bend_deg, web_mm, first_offset_mm, base_length_mm : float
    limits : Limits
    process : str or dict
        What the written pattern's ``process:`` holds.
    name, source : str
    """

    tube: Tube
    tube_modulus_gpa: float | None
    tendon: Tendon
    bends: tuple[BendTarget, ...]
    distribution: str | tuple[float, ...] = "uniform"
    tip_ratio: float = 3.0
    curve_deg_per_mm: tuple[float, ...] = ()
    curve_length_mm: float | None = None
    notches: int | None = None
    layout: str = "alternate"
    max_notch_bend_deg: float = 6.0
    web_mm: float = 0.3
    first_offset_mm: float = 1.5
    base_length_mm: float = 1.5
    limits: Limits = field(default_factory=Limits)
    process: object = "femto-polyimide.yaml"
    hinge: str = "fe_row"
    centerline: tuple["Arc", ...] = ()
    name: str = "goal"
    source: str | None = None

    def with_bends(self, bends) -> "Goal":
        from dataclasses import replace

        return replace(self, bends=tuple(bends))


def _sections(r: Reader, raw: dict, name: str) -> dict:
    """One section's values; a section that is not a mapping, or a missing one with required keys: one issue
    for the section, not one per key (its keys are then not reported one by one)."""
    spec = GOAL_SCHEMA[name]
    body = raw.get(name)
    required = [k for k, f in spec.items() if f.default is ...]
    if body is None and required:
        r.issue(name, "required section is missing", None, "a mapping with " + ", ".join(required),
                f"add e.g. '{name}: {{" + ", ".join(f"{k}: <value>" for k in required) + "}'")
        r.broken.add(name)
    if body is None:
        body = {}
    if not isinstance(body, dict):
        r.issue(name, "expected a mapping", body, "key: value pairs", f"indent the keys under '{name}:'")
        r.broken.add(name)
        body = {}
    r.check_keys(body, spec, name)
    out = {}
    for k, f in spec.items():
        if k == "distribution" and isinstance(body.get(k), list):
            out[k] = r.convert(body[k], Field("floats", "", "", (), 0.0, INF, True), f"{name}.{k}")
        else:
            out[k] = r.value(body, k, f, f"{name}.{k}")
    return out


#: A share of goal.distribution must be at least this fraction of the largest: a notch given less bends next to nothing.
MIN_SHARE = 0.01


def build_goal(raw: dict, file: str | None = None, lines: dict[str, int] | None = None,
               name: str | None = None) -> Goal:
    """Validate raw goal data; raises :class:`~camtube.errors.PatternError` listing every problem."""
    lines = lines or {}
    r = Reader(file, lines)
    r.check_keys(raw, GOAL_SCHEMA, "")
    tube = _sections(r, raw, "tube")
    tendon = _sections(r, raw, "tendon")
    goal = _sections(r, raw, "goal")
    lim = _sections(r, raw, "limits")
    process = raw.get("process", GOAL_SCHEMA["process"].default)
    if not isinstance(process, (str, dict)):
        r.issue("process", "expected a process file name or a mapping", process,
                "a name such as femto-polyimide.yaml, or process keys", "write e.g. 'process: femto-polyimide.yaml'")
    check_name(r, raw.get("name"))
    if r.issues:
        raise PatternError(r.issues)
    if not tube["inner_radius"] < tube["outer_radius"]:
        r.issue("tube.inner_radius", "inner radius must be smaller than the outer radius", tube["inner_radius"],
                f"< tube.outer_radius = {tube['outer_radius']:g} mm", "check r_i and r_o (radii, not diameters)")
    elif not tendon["radius"] < tube["inner_radius"]:
        # (the design rules refuse such a pattern; here the solver searched on and named the force instead)
        r.issue("tendon.radius", "the tendon is thicker than the tube's lumen (it runs inside the tube)",
                tendon["radius"], f"< tube.inner_radius = {tube['inner_radius']:g} mm",
                "check r_t (a radius, not a diameter) and r_i")
    bends = goal["bends"] or ()
    arcs = goal["centerline"] or ()
    if arcs:
        _check_centerline(r, goal, arcs, bends)
        bends = tuple({"angle_deg": a["towards_deg"], "bend_deg": a["bend_deg"], "stroke_mm": a["stroke_mm"]}
                      for a in arcs)
    elif not bends:
        r.issue("goal.bends", "needs at least one target", None, "a list of {angle_deg, bend_deg, stroke_mm}",
                "add e.g. '- {angle_deg: 180, bend_deg: 60, stroke_mm: 1.5}' (or a 3-D goal.centerline)")
    for i, b in enumerate(bends):
        if tendon.get("length") is not None and b["stroke_mm"] >= tendon["length"]:
            # (was "a notch must bend 6.00 deg, more than 0.75 of its closure angle; fix: ... give more stroke")
            key = f"goal.centerline[{i}].stroke_mm" if arcs else f"goal.bends[{i}].stroke_mm"
            r.issue(key, f"is as long as the tendon or longer (tendon.length = {tendon['length']:g} mm): the motor "
                    "cannot draw in more tendon than there is", b["stroke_mm"], f"< {tendon['length']:g} mm",
                    "give the stroke in mm (a few mm for these joints), or the tendon's length")
    seen: dict[float, int] = {}
    for i, b in enumerate(() if arcs else bends):
        a = round(b["angle_deg"] % 360.0, 6)
        if a in seen:
            r.issue(f"goal.bends[{i}].angle_deg", f"direction {b['angle_deg']:g} deg is already goal.bends[{seen[a]}]",
                    b["angle_deg"], "one target per direction", "merge the two targets or change the angle")
        seen[a] = i
    dist = goal["distribution"]
    if isinstance(dist, str) and dist not in DISTRIBUTIONS:
        from camtube.yamltext import closest

        m = closest(dist, DISTRIBUTIONS)
        r.issue("goal.distribution", "not an allowed choice", dist, "uniform, tip_first, base_first or a list of "
                "positive shares", f"did you mean '{m}'?" if m else "use uniform")
    if isinstance(dist, tuple) and not dist:
        r.issue("goal.distribution", "an empty list of shares", [], "uniform, tip_first, base_first or a list of "
                "positive shares, one per notch from the tip", "leave it out for uniform, or give the shares")
    elif isinstance(dist, tuple):
        if len(bends) > 1:
            r.issue("goal.distribution", "a list of shares needs a single bend", None, "one entry in goal.bends",
                    "use uniform or tip_first for several directions")
        if goal["notches"] not in (None, "auto") and goal["notches"] != len(dist):
            r.issue("goal.notches", f"disagrees with the {len(dist)} shares of goal.distribution", goal["notches"],
                    f"{len(dist)} or auto", "remove goal.notches (the list sets the count)")
        top = max(dist)
        small = [i for i, v in enumerate(dist) if not v >= MIN_SHARE * top]
        if top > 0 and small:
            # (a share of 1e-9: "a notch must bend 0.00 deg, more than 0.75 of its closure angle", a notch that bends
            # nothing, narrower than any cut)
            r.issue("goal.distribution", f"share {small[0] + 1} (from the tip) is {dist[small[0]]:g}, under "
                    f"{MIN_SHARE:.0%} of the largest ({top:g}): that notch would bend next to nothing, narrower than "
                    "any cut", list(dist), f"every share >= {MIN_SHARE:g} x the largest",
                    "leave that notch out (fewer shares) or give it a share of its own")
    curve = goal["curve"]
    if curve and not arcs:  # with a centre line: one issue, from _check_centerline
        if len(bends) > 1:
            r.issue("goal.curve", "a planar curve needs a single bend", None, "one entry in goal.bends",
                    "remove the other bends")
        if len(curve) < 2 or sum(curve) <= 0:
            r.issue("goal.curve", "needs at least two samples and some curvature", list(curve),
                    "two or more curvatures > 0 deg/mm", "list the curvature from the tip")
        if goal["curve_length"] is None:
            r.issue("goal.curve_length", "required with goal.curve", None, "a length > 0 mm",
                    "add 'curve_length: <mm>' (the joint length the curve covers)")
        elif bends and len(curve) >= 2:
            xs = [goal["curve_length"] * i / (len(curve) - 1) for i in range(len(curve))]
            total = sum(0.5 * (curve[i] + curve[i + 1]) * (xs[i + 1] - xs[i]) for i in range(len(curve) - 1))
            if abs(total - bends[0]["bend_deg"]) > 0.5:
                r.issue("goal.bends[0].bend_deg", f"disagrees with the curve's total bend {total:.2f} deg",
                        bends[0]["bend_deg"], f"{total:.2f} deg (the integral of goal.curve over goal.curve_length)",
                        f"set bend_deg: {total:.2f} or rescale the curve")
        if isinstance(dist, tuple) or dist != "uniform":
            r.issue("goal.distribution", "the curve sets the distribution", dist, "uniform (or leave it out)",
                    "remove goal.distribution")
    if goal["notches"] in (None, "auto") and not isinstance(dist, tuple):  # ceil(bend / max_notch_bend_deg) notches
        most = max((b["bend_deg"] for b in bends), default=0.0)
        hi = GOAL_SCHEMA["goal"]["notches"].hi
        if most / goal["max_notch_bend_deg"] > hi:
            r.issue("goal.max_notch_bend_deg", f"asks for {most / goal['max_notch_bend_deg']:.4g} notches for a bend "
                    f"of {most:g} deg, more than the {hi:g} a direction may have", goal["max_notch_bend_deg"],
                    f">= {most / hi:.4g} deg", f"raise it to {math.ceil(most / hi * 1e4) / 1e4:g} deg or more, or "
                    "give goal.notches")
    written = raw.get("goal") if isinstance(raw.get("goal"), dict) else {}
    if "tip_ratio" in written and dist not in ("tip_first", "base_first"):   # (dropped without a word)
        r.issue("goal.tip_ratio", f"is given, but goal.distribution is {dist if isinstance(dist, str) else 'a list'}: "
                "the ratio would not be used", goal["tip_ratio"], "tip_ratio with distribution tip_first or base_first",
                "set distribution: tip_first (or base_first), or delete tip_ratio")
    if "max_notch_bend_deg" in written and goal["notches"] not in (None, "auto") and not isinstance(dist, tuple):
        # (notches: 3 for 60 deg wrote 20 deg per notch, ten times the maximum given, without a word)
        most = max((b["bend_deg"] for b in bends), default=0.0)
        if most / goal["notches"] > goal["max_notch_bend_deg"] * (1.0 + 1e-9):
            r.issue("goal.notches", f"gives {most / goal['notches']:.3g} deg per notch for a bend of {most:g} deg, more "
                    f"than goal.max_notch_bend_deg = {goal['max_notch_bend_deg']:g} deg", goal["notches"],
                    f">= {math.ceil(most / goal['max_notch_bend_deg'] - 1e-9)} notches, or auto",
                    "give more notches, or notches: auto (the count from max_notch_bend_deg)")
    if lim["min_web"] > goal["web"]:
        r.issue("goal.web", "is thinner than limits.min_web", goal["web"], f">= {lim['min_web']:g} mm",
                "raise goal.web")
    if r.issues:
        raise PatternError(r.issues)
    return Goal(
        tube=Tube(tube["outer_radius"], tube["inner_radius"], 1.0, tube["material"]),
        tube_modulus_gpa=tube["modulus_gpa"],
        tendon=Tendon(tendon["radius"], tendon["length"], tendon["modulus_gpa"], tendon["material"],
                      tendon["friction"]),
        bends=tuple(BendTarget(b["angle_deg"] % 360.0, b["bend_deg"], b["stroke_mm"]) for b in bends),
        distribution=dist, tip_ratio=goal["tip_ratio"], curve_deg_per_mm=tuple(curve),
        curve_length_mm=goal["curve_length"], notches=None if goal["notches"] == "auto" else goal["notches"], layout=goal["layout"],
        max_notch_bend_deg=goal["max_notch_bend_deg"], web_mm=goal["web"], first_offset_mm=goal["first_offset"],
        base_length_mm=goal["base_length"],
        limits=Limits(lim["max_strain"], lim["max_force_N"], lim["max_length"], lim["min_web"],
                      lim["min_backbone_arc"], lim["min_feature"]),
        process=process, hinge=tube["hinge"],
        centerline=tuple(Arc(a["length_mm"], a["bend_deg"], a["towards_deg"] % 360.0, a["stroke_mm"]) for a in arcs),
        name=raw.get("name") or name or "goal", source=file)


def _check_centerline(r: Reader, goal: dict, arcs, bends) -> None:
    """The 3-D centre line's own rules (each problem: one issue naming the key and the fix)."""
    if bends:
        r.issue("goal.bends", "goal.centerline sets the bends (one per piece)", None, "goal.bends or goal.centerline",
                "remove goal.bends (each piece's towards_deg, bend_deg and stroke_mm are its target)")
    if goal["curve"]:
        r.issue("goal.curve", "a planar curve and a 3-D centre line cannot both be followed", None,
                "goal.curve or goal.centerline", "remove goal.curve (a planar piece is one goal.centerline row)")
    dist = goal["distribution"]
    if isinstance(dist, tuple) or dist != "uniform":
        r.issue("goal.distribution", "each piece of goal.centerline has constant curvature", dist,
                "uniform (or leave it out)", "remove goal.distribution; split a piece to vary its curvature")
    seen: dict[float, int] = {}
    for i, a in enumerate(arcs):
        d = round(a["towards_deg"] % 360.0, 6)
        if d in seen:
            r.issue(f"goal.centerline[{i}].towards_deg", f"direction {a['towards_deg']:g} deg is already "
                    f"goal.centerline[{seen[d]}] (each piece has its own tendon)", a["towards_deg"],
                    "a different rotary angle for every piece", "merge the two pieces or turn one of them")
        seen[d] = i


def load_goal(path: str | os.PathLike) -> Goal:
    """Read and validate a goal YAML file (every failure: a :class:`PatternError` naming file, line and key)."""
    raw, text = read_yaml_file(path, "goal", "check the path of the goal YAML")
    file = str(path)
    if raw is None:  # an empty file (or only comments): one line, not one per missing key
        raise PatternError([Issue("<top>", "the goal file is empty", None, "sections " + ", ".join(GOAL_SCHEMA),
                                  "write at least 'tube:' and 'goal:' (e.g. start from "
                                  "examples/goals/01-tube1-uniform-60.yaml)", file, 1)])
    if not isinstance(raw, dict):
        raise PatternError([Issue("<top>", "a goal file must be a mapping of sections", None,
                                  "sections " + ", ".join(GOAL_SCHEMA), "start the file with 'tube:'", file, 1)])
    return build_goal(raw, file, line_map(text), name=Path(path).stem)


def goal_process(goal: Goal):
    """The :class:`~camtube.design.pattern.Process` the written pattern will use (validated).

    A process file name is looked up beside the goal file, then among the shipped presets.
    """
    from camtube.design.loader import PRESETS_DIR, build_settings, read_process_file

    proc = goal.process
    if isinstance(proc, str):
        here = Path(goal.source).parent if goal.source else Path(".")
        for cand in (here / proc, here / f"{proc}.yaml", PRESETS_DIR / proc, PRESETS_DIR / f"{proc}.yaml"):
            if cand.is_file():
                proc = read_process_file(cand)
                break
        else:
            raise PatternError([Issue("process", "names a process file that is not there", goal.process,
                                      "a process YAML beside the goal or a shipped one (femto-polyimide.yaml)",
                                      "put the file beside the goal or write the process keys under 'process:'",
                                      goal.source)])
    raw = {"tube": {"outer_radius": goal.tube.outer_radius_mm, "inner_radius": goal.tube.inner_radius_mm,
                    "length": 1.0}, "process": proc}
    return build_settings(raw, goal.source)[1]


def shares_from_tip(goal: Goal, n: int) -> tuple[float, ...]:
    """Target share of each of ``n`` notches of one direction, from the tip (sums to 1)."""
    d = goal.distribution
    if goal.curve_deg_per_mm:
        k = goal.curve_deg_per_mm
        w = []
        for i in range(n):
            u = (i + 0.5) / n * (len(k) - 1)
            j = min(int(math.floor(u)), len(k) - 2)
            w.append(k[j] + (u - j) * (k[j + 1] - k[j]))
    elif isinstance(d, tuple):
        w = list(d)
    elif d == "uniform" or n == 1:
        w = [1.0] * n
    else:
        ratio = goal.tip_ratio if d == "tip_first" else 1.0 / goal.tip_ratio
        w = [ratio + (1.0 - ratio) * i / (n - 1) for i in range(n)]
    tot = sum(w)
    return tuple(x / tot for x in w)
