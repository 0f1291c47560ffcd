"""The pattern YAML schema: every key, its type, unit, range, default and meaning.

This table is the single source of truth for the loader (validation, "did you
mean" hints, ``--set`` overrides) and for the schema section of the README
(``camtube schema`` prints it as Markdown).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

INF = math.inf


@dataclass(frozen=True)
class Field:
    """One YAML key.

    ``kind``: ``float``, ``int``, ``str``, ``choice``, ``floats`` (list of
    float), ``int_or_auto``, ``rows`` (list of mappings, see ``row``).
    ``lo``/``hi`` bound numbers; ``lo_open``/``hi_open`` make a bound strict.
    ``default`` of ``...`` means required.
    """

    kind: str
    unit: str = ""
    doc: str = ""
    default: object = ...
    lo: float = -INF
    hi: float = INF
    lo_open: bool = False
    hi_open: bool = False
    choices: tuple[str, ...] = ()
    row: tuple[tuple[str, "Field"], ...] = ()

    def allowed(self) -> str:
        if self.kind == "choice":
            return "one of " + ", ".join(self.choices)
        if self.kind == "str":
            return "text"
        if self.kind in ("rows",):
            return "a list of mappings with keys " + ", ".join(k for k, _ in self.row)
        lo = "" if self.lo == -INF else f"{'>' if self.lo_open else '>='} {self.lo:g}"
        hi = "" if self.hi == INF else f"{'<' if self.hi_open else '<='} {self.hi:g}"
        rng = " and ".join(p for p in (lo, hi) if p)
        what = {
            "float": "a finite number",
            "int": "a whole number",
            "floats": "a list of finite numbers",
            "int_or_auto": "'auto' or a whole number",
        }[self.kind]
        unit = f" {self.unit}" if self.unit else ""
        return f"{what}{(' ' + rng) if rng else ''}{unit}"


POS = dict(lo=0.0, lo_open=True)

_HOLE_ROW = (
    ("x", Field("float", "mm", "axial centre of the hole from the tip", ..., 0.0, INF, True)),
    ("size", Field("float", "mm", "side of the square hole", 0.3, **POS)),
    ("angle_deg", Field("float", "deg", "rotary angle of the hole centre", 180.0, -360.0, 720.0)),
)
_CUT_ROW = (
    ("x", Field("float", "mm", "axial centre of the notch from the tip", ..., 0.0, INF, True)),
    ("width", Field("float", "mm", "axial width h", ..., **POS)),
    ("arc", Field("float", "mm", "arc s on the outer surface", ..., **POS)),
    ("angle_deg", Field("float", "deg", "rotary angle of the notch centre", 180.0, -360.0, 720.0)),
)
#: Most repeats of the focus+defocus group: 12x the paper's deepest cut (8 repeats for a beam depth of 1.64 mm;
#: 4 and 6 for 0.98 and 1.11 mm through a 0.3 mm polyimide wall). More cut nothing a tube on a rotary stage holds,
#: and they only made the plan slow (1000 repeats of a curved drawing: minutes and gigabytes; bug 12).
MAX_REPEATS = 100

_RULE_ROW = (
    # (a beam crosses at most the diameter of the largest tube, 2 x 50 mm)
    ("max_depth", Field("float", "mm", "largest beam depth this row covers", ..., 0.0, 100.0, True)),
    ("repeats", Field("int", "", "repeats of the focus+defocus group", ..., 1, MAX_REPEATS)),
)

SCHEMA: dict[str, dict[str, Field]] | dict = {
    "name": Field("str", "", "pattern name (defaults to the file name)", None),
    "tube": {
        # (upper bounds far above any tube a rotary stage holds: a radius of 1e103 mm overflowed the geometry, a
        # length of 1e7 mm wrote a preview of 227 MB)
        "outer_radius": Field("float", "mm", "outer radius r_o", ..., 0.0, 50.0, True),
        "inner_radius": Field("float", "mm", "inner radius r_i (< r_o)", ..., 0.0, 50.0, True),
        "length": Field("float", "mm", "length of the modelled segment from the tip", ..., 0.0, 2000.0, True),
        "material": Field("choice", "", "tube material (sets the strain limit's meaning)", "polyimide",
                          choices=("polyimide", "pebax", "nitinol", "other")),
    },
    "notch": {
        "layout": Field("choice", "", "uan: all notches at angle_deg; bidirectional: alternate "
                        "angle_deg and angle_deg+180; directions: cycle through directions_deg",
                        "uan", choices=("uan", "bidirectional", "directions")),
        "count": Field("int", "", "number of notches n", ..., 0, 100000),
        "width": Field("float", "mm", "axial notch width h (required unless 'widths' is given)", None, **POS),
        "spacing": Field("float", "mm", "web c between adjacent notches, edge to edge (required unless "
                         "'spacings' is given)", None, **POS),
        "arc": Field("float", "mm", "notch arc s on the outer surface (required unless 'arcs' is given)",
                     None, **POS),
        "first_offset": Field("float", "mm", "tip to the tip-side edge of the first notch", ..., 0.0),
        "angle_deg": Field("float", "deg", "rotary angle of the (first) notch centre", 180.0, -360.0, 720.0),
        "directions_deg": Field("floats", "deg", "with layout: directions, the centre angle of "
                                "successive notches, repeated", ()),
        "widths": Field("floats", "mm", "per-notch width h, one per notch from the tip (replaces 'width')",
                        (), **POS),
        "arcs": Field("floats", "mm", "per-notch arc s, one per notch from the tip (replaces 'arc')", (), **POS),
        "spacings": Field("floats", "mm", "per-gap web c, count - 1 values from the tip (replaces 'spacing')",
                          (), **POS),
        "angles_deg": Field("floats", "deg", "per-notch centre angle, one per notch from the tip (replaces "
                            "layout, angle_deg and directions_deg)", (), -360.0, 720.0),
    },
    "holes": Field("rows", "", "square tendon holes", (), row=_HOLE_ROW),
    "cuts": Field("rows", "", "extra notches placed by hand", (), row=_CUT_ROW),
    "tendon": {
        "radius": Field("float", "mm", "tendon radius r_t", 0.04, **POS),
        "length": Field("float", "mm", "unloaded tendon length L0", 70.0, **POS),
        "modulus_gpa": Field("float", "GPa", "tendon Young's modulus E_t (initial value for fits; within the range a "
                             "fit takes it in)", 28.0, 0.5, 500.0),
        "material": Field("str", "", "tendon material", "UHMWPE"),
        "friction": Field("float", "", "capstan friction coefficient of the tendon on the notch edges "
                          "(forward model)", 0.0, 0.0, 2.0),
    },
    # Process bounds (issue: fuzz E2): the range a femtosecond micromachining lab works in (the paper's process:
    # 2.0 W, 60 kHz, 25 mm/s, drill offset 0.005 mm, defocus 0.1 mm), so that no value writes a meaningless or
    # unsafe job. The lower bounds of power and frequency keep their G-code values (M68 Q.. with 3 decimals)
    # within 1 % of the value, as camtube.machine.kinematics.FEED_ROUNDING asks of the feeds, and the dose
    # (M68 Q<1000 frequency / speed> pulses per mm) away from Q0.000000; a too slow scan speed is refused per
    # machine (camtube.machine.kinematics.check_feeds), a defocus below the tube per tube (design.rules).
    "process": {
        # 50 mW (a tight focus on polyimide) to 100 W (the strongest femtosecond machining lasers)
        "power_w": Field("float", "W", "average laser power", 2.0, 0.05, 100.0),
        # 100 Hz (high-energy amplifiers) to 100 MHz (oscillator rates)
        "frequency_khz": Field("float", "kHz", "pulse repetition frequency", 60.0, 0.1, 100000.0),
        # up to 2 m/s, beyond any stage pair a tube is cut on (a linear motor's top speed)
        "scan_speed_mm_s": Field("float", "mm/s", "cutting speed on the outer surface", 25.0, 0.0, 2000.0, True),
        # deep UV (the 5th harmonic, 206 nm) to mid-infrared OPAs
        "wavelength_nm": Field("float", "nm", "laser wavelength", 1030.0, 100.0, 20000.0),
        # 0 (every cut of a group on one line) to 0.1 mm, twenty times the paper's step and several kerfs
        "drill_offset": Field("float", "mm", "step between the cuts of a drill group", 0.005, 0.0, 0.1),
        "drill_passes": Field("int", "", "cuts per drill group", 4, 1, 100),
        # at most the diameter of the largest tube (2 x 50 mm); design.rules refuses a focus below the tube itself
        "defocus": Field("float", "mm", "second focus level, into the material (at most the tube's outer "
                          "diameter 2 r_o)", 0.1, 0.0, 100.0),
        "repeats": Field("int_or_auto", "", "repeats of the focus+defocus group; auto uses repeat_rule",
                         "auto", 1, MAX_REPEATS),
        "repeat_rule": Field("rows", "", "beam depth -> repeats; first row with depth <= max_depth wins",
                             ({"max_depth": 1.0, "repeats": 4}, {"max_depth": 1.3, "repeats": 6},
                              {"max_depth": 2.0, "repeats": 8}), row=_RULE_ROW),
        # a kerf wider than 1 mm is no laser's; design.rules also keeps it below half the narrowest cut
        "kerf": Field("float", "mm", "kerf width for compensation (0 = off)", 0.0, 0.0, 1.0),
        "rapid_speed_mm_s": Field("float", "mm/s", "laser-off traverse speed (time estimate)", 50.0, 0.1, 10000.0),
        "focus_speed_mm_s": Field("float", "mm/s", "Z focus move speed (time estimate)", 5.0, 0.01, 1000.0),
        # 36 s to six weeks
        "max_time_h": Field("float", "h", "warn when the estimated laser time of a job exceeds this", 8.0, 0.01,
                            1000.0),
    },
    "rules": {
        "min_backbone_arc": Field("float", "mm", "smallest backbone arc 2 pi r_o - s allowed", 0.3, 0.0),
        "min_web": Field("float", "mm", "smallest material bridge between two cuts", 0.1, 0.0),
        "max_strain": Field("float", "", "backbone strain limit of the tube material (warning; at most 1: no tube's "
                            "backbone bends back from more)", 0.03, 1e-4, 1.0),
        "max_stroke": Field("float", "mm", "largest tendon stroke the joint is driven to", 2.0, **POS),
    },
}


def iter_fields():
    """Yield ``(dotted_key, Field)`` for every key of the schema (rows expanded as key[].sub)."""
    for sec, body in SCHEMA.items():
        if isinstance(body, Field):
            yield sec, body
            for k, f in body.row:
                yield f"{sec}[].{k}", f
        else:
            for k, f in body.items():
                yield f"{sec}.{k}", f
                for rk, rf in f.row:
                    yield f"{sec}.{k}[].{rk}", rf


def markdown() -> str:
    """The schema as a Markdown table (for the README)."""
    lines = ["| key | type / allowed | default | meaning |", "|---|---|---|---|"]
    for key, f in iter_fields():
        d = "required" if f.default is ... else ("" if f.default in (None, ()) else f"`{f.default}`")
        if f.kind == "rows" and f.default not in ((), ...):
            d = "see below"
        lines.append(f"| `{key}` | {f.allowed()} | {d} | {f.doc} |")
    return "\n".join(lines)
