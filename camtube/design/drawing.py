"""Design input from a drawing (DXF): the cuts a CAD user drew, or a refusal naming the entity.

How a drawing is read (``docs/dxf.md`` has the long version):

1. Entities of the model space are walked; block references (INSERT, MINSERT
   arrays, nested, scaled, rotated, mirrored) are expanded with ezdxf's own
   ``virtual_entities`` (entities on layer ``0`` inside a block take the
   INSERT's layer, as in AutoCAD).
2. Each entity's layer maps to a role (:data:`DEFAULT_ROLES`, overridden by
   ``DrawingOptions.layers``): ``notch``, ``hole``, ``slit`` or ``ignore``.
3. Every curve (LINE, ARC, CIRCLE, ELLIPSE, SPLINE, LWPOLYLINE / POLYLINE with
   bulges) becomes an ``ezdxf.path`` and is flattened to chords within
   :data:`camtube.tol.TOL.chord`; units follow ``$INSUNITS`` (or
   ``DrawingOptions.units`` for a unitless drawing). An entity beyond
   :data:`MAX_ENTITY_MM` or :data:`MAX_COORD_MM` is refused (set aside on an
   ignored layer) before it is flattened; a curve on an ignored layer is never
   flattened.
4. Loose open pieces on one layer are chained into loops with
   ``ezdxf.edgeminer`` (ends within :data:`camtube.tol.TOL.gap`).
5. The tube outline -- the smallest axis-aligned rectangle, on any layer, that
   encloses every cut -- sets the origin and checks (or gives) ``r_o`` and ``L``.
6. Pieces split at the seam are rejoined; each closed loop on a notch / hole
   layer is a cut (a drawn rectangle stays a plain rectangle), each open path on
   a slit layer a slit; the design rules run with messages naming the entity.

Every entity ends up imported, set aside by an explicit rule (annotation, ignored,
hidden or non-plotting layer, the outline), or refused with a :class:`~camtube.errors.PatternError`.
"""
from __future__ import annotations

import math
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Sequence

from camtube.design.loader import Loaded, apply_overrides, build_settings, parse_override
from camtube.design.pattern import Cut, Pattern, drawn, sort_cuts
from camtube.errors import Issue, PatternError
from camtube.inputfile import refuse_device
from camtube.tol import TOL

ROLES = ("notch", "hole", "slit", "ignore")

#: Layer-name prefix (upper case) -> role; the first match wins. Any other layer is ``notch``.
DEFAULT_ROLES: tuple[tuple[str, str], ...] = (
    ("NOTCH", "notch"),
    ("HOLE", "hole"),
    ("SLIT", "slit"),
    ("CONSTRUCTION", "ignore"),
    ("DEFPOINTS", "ignore"),
)
DEFAULT_OTHER_ROLE = "notch"

#: ``$INSUNITS`` code -> (name, mm per drawing unit). 0 (unitless) needs ``DrawingOptions.units``.
INSUNITS: dict[int, tuple[str, float]] = {
    1: ("inch", 25.4), 2: ("foot", 304.8), 4: ("mm", 1.0), 5: ("cm", 10.0), 6: ("m", 1000.0),
    8: ("microinch", 25.4e-6), 9: ("mil", 0.0254), 13: ("um", 1e-3), 14: ("dm", 100.0),
}
#: Names accepted for ``DrawingOptions.units`` -> mm per unit.
UNIT_NAMES: dict[str, float] = {
    "mm": 1.0, "cm": 10.0, "dm": 100.0, "m": 1000.0, "um": 1e-3, "micron": 1e-3, "inch": 25.4, "in": 25.4,
    "foot": 304.8, "ft": 304.8, "mil": 0.0254,
}

#: Entities that are never cut: set aside wherever they are (counted in the summary).
ANNOTATIONS = frozenset({
    "TEXT", "MTEXT", "ATTRIB", "ATTDEF", "DIMENSION", "ARC_DIMENSION", "LARGE_RADIAL_DIMENSION", "LEADER",
    "MULTILEADER", "MLEADER", "TOLERANCE", "POINT", "IMAGE", "WIPEOUT",
    "VIEWPORT", "XLINE", "RAY", "ACAD_TABLE", "UNDERLAY", "PDFUNDERLAY", "DWFUNDERLAY", "DGNUNDERLAY",
})
#: Filled areas: set aside when each of their boundaries is drawn as a cut too; refused on a cut layer otherwise.
FILLS = frozenset({"HATCH", "MPOLYGON", "SOLID", "TRACE"})
CURVES = frozenset({"LINE", "ARC", "CIRCLE", "ELLIPSE", "SPLINE", "LWPOLYLINE", "POLYLINE", "HELIX"})

#: Wall assumed when the drawing's process settings do not give ``tube.inner_radius`` (mm).
DEFAULT_WALL_MM = 0.3


# ---------------------------------------------------------------- what was drawn
@dataclass
class _Entity:
    """One drawn entity (a block's entity once per INSERT copy) and what became of it."""

    dxftype: str
    handle: str
    layer: str
    via: str = ""          # "in block B of INSERT #H" for block content
    status: str = ""       # imported | outline | aside:<reason> | refused

    def describe(self) -> str:
        where = f" {self.via}" if self.via else ""
        return f"{self.dxftype} #{self.handle}{where} on layer {self.layer}"


@dataclass
class _Piece:
    """A flattened path in mm (drawing coordinates scaled to mm, origin not yet moved)."""

    points: list[tuple[float, float]]
    closed: bool
    entities: list[_Entity]
    layer: str
    role: str

    def describe(self) -> str:
        if len(self.entities) == 1:
            return self.entities[0].describe()
        kinds: dict[str, int] = {}
        for e in self.entities:
            kinds[e.dxftype] = kinds.get(e.dxftype, 0) + 1
        what = " + ".join(f"{n} {t}s" if n > 1 else f"1 {t}" for t, n in sorted(kinds.items()))
        handles = ", ".join(f"#{e.handle}" for e in self.entities[:6]) + (", ..." if len(self.entities) > 6 else "")
        return f"{what} ({handles}) on layer {self.layer}"

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        xs = [p[0] for p in self.points]
        ys = [p[1] for p in self.points]
        return min(xs), min(ys), max(xs), max(ys)


@dataclass
class _Reading:
    file: str
    factor: float                     # mm per drawing unit
    unit: str
    roles: dict[str, str]             # upper-case layer -> role (explicit overrides)
    hidden: dict[str, str]            # upper-case names of layers not shown or not printed -> why they are set aside
    frozen: set[str] = field(default_factory=set)   # upper-case names of frozen layers (hide a block reference whole)
    entities: list[_Entity] = field(default_factory=list)
    pieces: list[_Piece] = field(default_factory=list)
    issues: list[Issue] = field(default_factory=list)
    inserts: int = 0
    joined: list[_Piece] = field(default_factory=list)
    fills: list[tuple[_Entity, list[list[tuple[float, float]]]]] = field(default_factory=list)

    def role(self, layer: str) -> str:
        up = layer.upper()
        if up in self.roles:
            return self.roles[up]
        if up in self.hidden:
            return "ignore"
        for prefix, role in DEFAULT_ROLES:
            if up.startswith(prefix):
                return role
        return DEFAULT_OTHER_ROLE

    def refuse(self, what: str, message: str, fix: str, allowed: str = "", entities: Iterable[_Entity] = ()) -> None:
        for e in entities:
            e.status = "refused"
        self.issues.append(Issue(what, message, None, allowed, fix, self.file))

    def at(self, x_mm: float, y_mm: float) -> str:
        """A point as the user finds it in the drawing (drawing units)."""
        return f"({x_mm / self.factor:.6g}, {y_mm / self.factor:.6g}) {self.unit}"


# ---------------------------------------------------------------- entry point
def load_drawing(path: str | os.PathLike, overrides: Iterable[str], options) -> Loaded:
    """Read a DXF drawing into a validated pattern (see the module docstring).

    Parameters
    ----------
    path : path
        The ``*.dxf`` file.
    overrides : iterable of str
        ``KEY=VALUE`` (``--set``) for the ``name``, ``tube``, ``process``,
        ``tendon`` and ``rules`` sections; ``process=FILE.yaml`` takes the process
        from a process file (relative to the working directory or the drawing).
    options : camtube.design.source.DrawingOptions
        Outer radius, length, units and layer roles given by the user.

    Returns
    -------
    Loaded
        The pattern (cuts in ``x, angle`` order), design warnings, the entity
        each cut came from (``origins``) and a one-line ``summary``.

    Raises
    ------
    PatternError
        The drawing cannot be read as the user meant it, or breaks a design
        rule; every issue names the entity (type, handle, layer) and the fix.
    """
    file = str(path)
    overrides = list(overrides)
    raw = _settings_raw(overrides, file, Path(path).parent)
    ro_opt = _agree("outer radius", options.outer_radius_mm, raw.get("tube", {}).get("outer_radius"), file)
    len_opt = _agree("length", options.length_mm, raw.get("tube", {}).get("length"), file)

    doc = _read_document(path, file)
    factor, unit = _units(doc, options.units, file, path)
    layer_names = _layer_names(doc)
    roles = _layer_roles(options.layers, layer_names, file)
    rd = _Reading(file, factor, unit, roles, _hidden_layers(doc),
                  {layer.dxf.name.upper() for layer in doc.layers if layer.is_frozen()})

    for entity in doc.modelspace():
        _walk(rd, entity, "", "")
    _close_and_chain(rd)
    _check_fills(rd)
    outline, ro, length = _find_outline(rd, ro_opt, len_opt)
    if rd.issues:
        raise PatternError(rd.issues)

    cuts, origins, seam_joined = _cuts(rd, outline, ro, length)
    lost = [e.describe() for e in rd.entities if not e.status]
    if lost:  # every path above gives each entity a fate; one without is a bug, never a silent drop
        raise RuntimeError(f"{file}: entities not accounted for: {', '.join(lost[:5])}")
    if rd.issues:
        raise PatternError(rd.issues)
    if not cuts:
        raise PatternError([Issue("cuts", "the drawing has no cuts" + _set_aside_note(rd), None,
                                  "closed outlines on notch/hole layers, open paths on slit layers",
                                  _no_cuts_fix(rd), file)])

    tube_raw = raw.setdefault("tube", {})
    tube_raw["outer_radius"], tube_raw["length"] = ro, length
    warnings: list[Issue] = []
    if tube_raw.get("inner_radius") is None:
        ri = ro - min(DEFAULT_WALL_MM, 0.5 * ro)
        tube_raw["inner_radius"] = ri
        warnings.append(Issue("tube.inner_radius", f"not given: the wall is assumed {ro - ri:g} mm (r_i = {ri:g} mm) "
                              "for the CAD model and the closure warnings; the cut does not depend on it", None, "",
                              "pass --set tube.inner_radius=R", file))
    tube, process, tendon, rules = build_settings(raw, file)
    order = sorted(range(len(cuts)), key=lambda k: (cuts[k].x_mm, cuts[k].angle_deg, cuts[k].kind))
    pattern = Pattern(name=str(raw.get("name") or Path(path).stem), tube=tube, cuts=sort_cuts(cuts),
                      process=process, tendon=tendon, rules=rules, source=file)
    origins = [origins[k] for k in order]

    from camtube.design import rules as design_rules

    errors, rule_warnings = design_rules.check(pattern, origins, file)
    widths = [c.width_mm for c in pattern.cuts if c.kind != "slit"]
    if process.kerf_mm and widths and process.kerf_mm >= min(widths) / 2:
        errors.append(Issue("process.kerf", "kerf is as wide as half the narrowest cut", process.kerf_mm,
                            f"< {min(widths) / 2:g} mm", "check the kerf width", file))
    if errors:
        raise PatternError(errors)
    summary = _summary(rd, pattern, outline, seam_joined, ro_opt is None, len_opt is None)
    return Loaded(pattern, tuple(warnings + list(rule_warnings)), tuple(origins), summary)


# ---------------------------------------------------------------- settings
def _settings_raw(overrides: list[str], file: str, folder: Path) -> dict:
    """The tube/process/tendon/rules raw data given by ``--set`` (a ``process=FILE`` first)."""
    bad = []
    plain = []
    process_file = None
    for item in overrides:
        key, value = parse_override(item)
        top = key.split(".")[0]
        if top in ("notch", "cuts", "holes"):
            bad.append(Issue(key, "a drawing's cuts come from the drawing", None, "name, tube.*, process.*, "
                             "tendon.*, rules.*", "edit the drawing instead", file))
        elif key == "process" and isinstance(value, str):
            process_file = value
        else:
            plain.append(item)
    if bad:
        raise PatternError(bad)
    raw: dict = {}
    if process_file is not None:
        from camtube.design.loader import find_process_file, read_process_file

        # as given (from the working directory), else beside the drawing or shipped, as a YAML pattern's process:
        found = Path(process_file) if Path(process_file).is_file() else find_process_file(process_file, folder,
                                                                                              file, None)
        raw["process"] = read_process_file(found)
    return apply_overrides(raw, plain, file)


def _agree(what: str, option, value, file: str):
    for v in (option, value):
        # (a bool is an int: `--set tube.outer_radius=true` was a tube of 1 mm, where a YAML pattern refuses it)
        if v is not None and not (isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(float(v))
                                  and float(v) > 0):
            raise PatternError([Issue(f"tube.{what.replace(' ', '_')}", f"the {what} must be a positive number", v,
                                      "> 0 mm", "pass a positive number of mm", file)])
    if option is not None and value is not None and abs(float(option) - float(value)) > TOL.zero:
        raise PatternError([Issue(f"tube.{what.replace(' ', '_')}", f"the {what} is given twice, differently",
                                  f"{option:g} and {value:g}", "one value", "give it once", file)])
    v = option if option is not None else value
    return float(v) if v is not None else None


def _read_document(path, file: str):
    import ezdxf

    try:
        refuse_device(path)
        return ezdxf.readfile(str(path))
    except OSError as exc:
        if Path(path).is_file():
            raise PatternError([Issue("file", f"not a valid DXF file ({exc})", None, "a DXF file (R12 or later)",
                                      "save the drawing as DXF again from your CAD program", file)]) from None
        raise PatternError([Issue("file", f"cannot read the drawing: {exc.strerror or exc}", file,
                                  "a readable DXF file", "check the path", file)]) from None
    except ezdxf.DXFError as exc:
        # (on one line: ezdxf's message may quote the bad tag with its line break)
        raise PatternError([Issue("file", f"not a valid DXF file: {' '.join(str(exc).split())}", None,
                                  "a DXF file (R12 or later)",
                                  "save the drawing as DXF again from your CAD program", file)]) from None
    except StopIteration:   # ezdxf's tag reader runs out of tags: the file ends inside a section
        raise PatternError([Issue("file", "not a valid DXF file: it ends inside a section (cut short: a copy or "
                                  "download that did not finish?)", None, "a whole DXF file (R12 or later)",
                                  "save the drawing as DXF again from your CAD program", file)]) from None
    except (ValueError, IndexError, KeyError, TypeError, AttributeError, UnicodeError, OverflowError) as exc:
        # a damaged file ezdxf's reader fails on without a DXFError of its own (inf as a whole number: OverflowError)
        why = " ".join(str(exc).split())[:120] or type(exc).__name__
        raise PatternError([Issue("file", f"not a valid DXF file ({type(exc).__name__}: {why})", None,
                                  "a DXF file (R12 or later)", "save the drawing as DXF again from your CAD program",
                                  file)]) from None


def _declares_units(path) -> bool:
    """Whether the file itself holds ``$INSUNITS``: ezdxf gives a file without a HEADER section (as scripts and old
    CAM exporters write) its default header, whose unit is m; such a drawing is unitless, as one saying 0."""
    try:
        return b"$INSUNITS" in Path(path).read_bytes()
    except OSError:
        return True


def _units(doc, given: str | None, file: str, path=None) -> tuple[float, str]:
    declared = path is None or _declares_units(path)
    try:
        code = int(doc.header.get("$INSUNITS", 0) or 0) if declared else 0
    except (ValueError, OverflowError, TypeError):
        raise PatternError([Issue("$INSUNITS", "the drawing's unit code is not a whole number", doc.header.get(
            "$INSUNITS"), "mm, inch, ... ", "pass --units mm (or inch, um, ...), or set the drawing's units",
            file)]) from None
    if given is not None:
        name = given.strip().lower()
        if name not in UNIT_NAMES:
            raise PatternError([Issue("--units", "unknown unit", given, ", ".join(UNIT_NAMES),
                                      "use one of the names listed", file)])
        if code in INSUNITS and abs(INSUNITS[code][1] - UNIT_NAMES[name]) > 1e-12:
            raise PatternError([Issue("--units", f"the drawing says its units are {INSUNITS[code][0]} ($INSUNITS = "
                                      f"{code}), not {name}", given, INSUNITS[code][0],
                                      "drop --units, or fix $INSUNITS in the drawing (UNITS command)", file)])
        return UNIT_NAMES[name], name
    if code in INSUNITS:
        return INSUNITS[code][1], INSUNITS[code][0]
    if not declared:
        raise PatternError([Issue("$INSUNITS", "the drawing does not say its unit (no $INSUNITS in the file: DXF R12, or "
                                  "no HEADER section): its size is unknown", None, "mm, inch, ... ",
                                  "pass --units mm (or inch, um, ...), or save the drawing with its units from a CAD "
                                  "program", file)])
    if code == 0:
        raise PatternError([Issue("$INSUNITS", "the drawing is unitless ($INSUNITS = 0): its size is unknown", 0,
                                  "mm, inch, ... ", "pass --units mm (or inch, um, ...), or set the drawing's units",
                                  file)])
    raise PatternError([Issue("$INSUNITS", "unsupported drawing unit", code, ", ".join(n for n, _ in INSUNITS.values()),
                              "save the drawing in mm or inch, or pass --units", file)])


def _layer_names(doc) -> dict[str, str]:
    """Upper-case name -> name of every layer of the drawing: those of its layer table and those its entities are
    on (model space and blocks), which a DXF written by a script or an old program need not list in the table."""
    names = {layer.dxf.name.upper(): layer.dxf.name for layer in doc.layers}
    for block in doc.blocks:
        if block.name.upper().startswith("*PAPER_SPACE"):
            continue
        for e in block:
            name = e.dxf.get("layer", "0")
            names.setdefault(str(name).upper(), str(name))
    return names


def _layer_roles(pairs, layer_names: dict[str, str], file: str) -> dict[str, str]:
    out: dict[str, str] = {}
    issues = []
    for name, role in pairs:
        if role not in ROLES:
            issues.append(Issue(f"--layer {name}={role}", "unknown layer role", role, " | ".join(ROLES),
                                "use notch, hole, slit or ignore", file))
            continue
        if name.upper() not in layer_names:
            import difflib

            near = difflib.get_close_matches(name, list(layer_names.values()), n=1, cutoff=0.5)
            issues.append(Issue(f"--layer {name}={role}", "the drawing has no such layer (not in its layer "
                                "table, no entity on it)", name, "its layers " + ", ".join(sorted(layer_names.values())),
                                f"did you mean '{near[0]}'?" if near else "name one of the drawing's layers (case "
                                "does not matter), or drop this --layer", file))
            continue
        out[name.upper()] = role
    if issues:
        raise PatternError(issues)
    return out


# ---------------------------------------------------------------- walking the entities
#: Most copies one INSERT (a MINSERT array) may place: more than a pattern may have notches (100000).
MAX_INSERT_COPIES = 100_000
#: Deepest nesting of blocks in blocks followed (CAD programs nest a few levels).
MAX_BLOCK_DEPTH = 64
#: Scales an INSERT may give its block along X and Y (magnitude; negative mirrors): a block drawn in um or m and
#: placed in a mm drawing is scaled 1e-3 or 1e3, a unit square scaled to a cut by the cut's size; 0 flattens the
#: block to a line or a point (and ezdxf's placing of it divides by zero).
INSERT_SCALE_RANGE = (1e-9, 1e9)
#: Largest size (mm, across in x or y) of one drawn entity: five times the longest tube a pattern may have
#: (``tube.length`` <= 2000 mm; ``2 pi r_o`` <= 314 mm). Checked on the entity's control points before it is
#: flattened: a CIRCLE of radius 1e9 mm flattened to :data:`TOL.chord` took 4 GB, one of 1e12 mm all the memory
#: there was; one of this size stays under 1e5 points.
MAX_ENTITY_MM = 10_000.0
#: Farthest an entity may lie from the drawing's origin (mm, in x or y): within it a float64 coordinate resolves
#: 1.5e-8 mm, finer than :data:`TOL.merge`; a drawing at 1e15 mm resolves 0.125 mm, and its outline read as
#: r_o = 0.9947 mm for 1.
MAX_COORD_MM = 1e8


def _walk(rd: _Reading, entity, via: str, insert_layer: str, blocks: tuple[str, ...] = ()) -> None:
    t = entity.dxftype()
    layer = entity.dxf.get("layer", "0")
    if via and layer == "0":
        layer = insert_layer
    if t == "INSERT":
        rd.inserts += 1
        here = f"INSERT #{entity.dxf.handle}" if entity.dxf.handle else "INSERT"
        name = entity.dxf.name
        block = entity.block()

        def unplaced() -> _Entity:
            """This INSERT as an entity of the reading (one whose block is not placed)."""
            ent = _Entity("INSERT", entity.dxf.handle or "-", layer, via)
            rd.entities.append(ent)
            return ent

        if entity.dxf.get("invisible", 0):   # (CAD programs show neither it nor its block's entities)
            unplaced().status = "aside:invisible entity"
            return
        if layer.upper() in rd.frozen and layer.upper() not in rd.roles:
            # a block reference on a frozen layer is not shown at all, whatever its entities' layers (one that is only
            # off hides its layer-0 entities, which take its layer); its block's notches were cut
            unplaced().status = "aside:hidden layer"
            return
        if block is None or block.block.is_xref:
            what = "an external reference (XREF)" if block is not None else "a block missing from the drawing"
            _refuse_if_cut(rd, unplaced(), rd.role(layer), f"places {what} {name!r}: its content is not in this file",
                           "bind the XREF into the drawing (XREF > Bind) and save again")
            return
        if name in blocks or len(blocks) >= MAX_BLOCK_DEPTH:
            ent = unplaced()
            why = (f"places block {name!r} inside itself ({' > '.join(blocks + (name,))})" if name in blocks
                   else f"nests blocks more than {MAX_BLOCK_DEPTH} deep ({' > '.join(blocks[:3])} > ...)")
            rd.refuse(ent.describe(), why, "redefine the block without placing itself in it, or explode it in CAD",
                      entities=[ent])
            return
        if entity.mcount > MAX_INSERT_COPIES:
            ent = unplaced()
            rd.refuse(ent.describe(), f"places block {name!r} {entity.mcount} times (an array of "
                      f"{entity.dxf.get('row_count', 1)} x {entity.dxf.get('column_count', 1)})",
                      "check the array's row and column counts", f"at most {MAX_INSERT_COPIES} copies", entities=[ent])
            return
        lo, hi = INSERT_SCALE_RANGE
        bad = [(axis, float(entity.dxf.get(f"{axis}scale", 1.0))) for axis in "xy"]
        bad = [(axis, v) for axis, v in bad if not (math.isfinite(v) and lo <= abs(v) <= hi)]
        if bad:
            axis, v = bad[0]
            why = ("flattens it to a line or a point" if v == 0 else "is not a finite number" if not math.isfinite(v)
                   else "makes it too small to cut" if abs(v) < lo else "makes it too large for any tube")
            _refuse_if_cut(rd, unplaced(), rd.role(layer), f"scales block {name!r} by {v:g} along {axis.upper()} "
                           f"({axis}scale), which {why}", "set the INSERT's X and Y scale to the block's size in the "
                           "drawing (e.g. 1) in CAD, or delete the INSERT", f"|scale| {lo:g} to {hi:g}")
            return
        copies = list(entity.multi_insert()) if entity.mcount > 1 else [entity]
        for k, ins in enumerate(copies):
            tag = f"in block {name} of {here}" + (f" (copy {k + 1} of {len(copies)})" if len(copies) > 1 else "")
            if via:
                tag += f", {via}"
            skipped: list = []
            for sub in ins.virtual_entities(skipped_entity_callback=lambda e, why: skipped.append((e, why))):
                _walk(rd, sub, tag, layer, blocks + (name,))
            for sub, why in skipped:
                ent = _Entity(sub.dxftype(), "-", layer if sub.dxf.get("layer", "0") == "0" else sub.dxf.layer, tag)
                rd.entities.append(ent)
                _refuse_if_cut(rd, ent, rd.role(ent.layer), f"cannot place this block entity: {why}",
                               "explode the block in CAD (EXPLODE), or scale it uniformly")
        for att in getattr(entity, "attribs", []):
            ent = _Entity("ATTRIB", att.dxf.handle or "-", layer, via)
            ent.status = "aside:annotation"
            rd.entities.append(ent)
        return
    ent = _Entity(t, entity.dxf.handle or "-", layer, via)
    rd.entities.append(ent)
    role = rd.role(layer)
    if entity.dxf.get("invisible", 0):
        # (flag 60 = 1: CAD programs do not show it; it was cut as any other)
        ent.status = "aside:invisible entity"
        return
    if t in ANNOTATIONS:
        ent.status = "aside:annotation"
        return
    if t in FILLS:
        if role == "ignore":
            ent.status = "aside:ignored layer"
        else:
            _fill(rd, entity, ent)
        return
    if t in CURVES:
        bad = _damaged_number(entity)
        if bad:
            # (an inf vertex was dropped by ezdxf's path, the notch cut as a triangle; an inf arc angle made the arc
            # vanish as "zero length": both with exit 0)
            _refuse_if_cut(rd, ent, role, f"{bad} is not a finite number (nan or inf)",
                           "redraw or delete it (the file may be damaged: export it again)")
            return
    if t == "LWPOLYLINE" and role != "ignore" and (entity.dxf.get("const_width", 0.0) or any(
            w0 or w1 for _, _, w0, w1 in entity.get_points("xyse"))) or \
            t == "POLYLINE" and role != "ignore" and _polyline_width(entity):
        rd.refuse(ent.describe(), "is a polyline with a width: the drawing shows a band, camtube would cut its "
                  "centre line", "set the polyline's width to 0 (draw the cut's outline instead)", entities=[ent])
        return
    if t not in CURVES:
        _refuse_if_cut(rd, ent, role, f"a {t} cannot be read as a cut", "explode it into lines, arcs or polylines, or "
                       "move it to a CONSTRUCTION layer", "LINE, ARC, CIRCLE, ELLIPSE, SPLINE, (LW)POLYLINE")
        return
    if t == "SPLINE" and role != "ignore" and entity.control_point_count() == 0:
        rd.refuse(ent.describe(), "is a SPLINE given by fit points only: its shape depends on the CAD program that "
                  "draws it", "save the drawing so the spline has control points, or convert it to a polyline",
                  entities=[ent])
        return
    if t == "SPLINE" and entity.dxf.degree == 1:
        _control_polygon(rd, entity, ent, layer, role)
        return
    if t == "POLYLINE" and entity.dxf.get("flags", 0) & 4:
        # PEDIT Spline: the frame's control points and the curve's fit points in one list of vertices (read as one
        # ring, "the outline crosses itself"); CAD programs show the fit points' curve, which is what is cut
        _spline_fit_polyline(rd, entity, ent, layer, role)
        return
    if t in ("CIRCLE", "ARC"):
        # a radius of nan was dropped without a word (the drawing then 'has no cuts'), a negative one cut as its size
        r = float(entity.dxf.get("radius", 0.0))
        if not (math.isfinite(r) and r >= 0.0):
            _refuse_if_cut(rd, ent, role, f"has a radius of {r:g}, not a number >= 0 (the file may be damaged)",
                           "redraw it with its radius, or export the drawing again")
            return
    _flatten(rd, entity, ent, layer, role)


def _refuse_if_cut(rd: _Reading, ent: _Entity, role: str, message: str, fix: str, allowed: str = "") -> None:
    """Refuse ``ent`` on a cut layer; on an ignored one it is set aside (nothing of it is cut)."""
    if role == "ignore":
        ent.status = "aside:ignored layer"
    else:
        rd.refuse(ent.describe(), message, fix, allowed, entities=[ent])


def _finite(v) -> bool:
    try:
        return all(math.isfinite(float(c)) for c in (v if hasattr(v, "__iter__") else (v,)))
    except (TypeError, ValueError):
        return True   # (not a number: a name, a handle)


def _damaged_number(entity) -> str:
    """What of ``entity`` holds a number that is not finite (a damaged file), in words, or "" (its DXF attributes, and
    a polyline's vertices, a spline's points, knots and weights: ezdxf's path drops what it cannot place)."""
    for name, value in entity.dxfattribs().items():
        if name == "radius":
            continue   # (a circle's or arc's radius has its own line: not a number >= 0)
        if isinstance(value, (int, float)) and not isinstance(value, bool) or hasattr(value, "__iter__") and \
                not isinstance(value, str):
            if not _finite(value):
                return f"its {name.replace('_', ' ')} ({name})"
    t = entity.dxftype()
    if t == "LWPOLYLINE":
        if not all(_finite(p) for p in entity.get_points("xyb")):
            return "one of its vertices"
    elif t == "POLYLINE":
        if not all(_finite(v.dxf.location) and _finite(v.dxf.get("bulge", 0.0)) for v in entity.vertices):
            return "one of its vertices"
    elif t == "SPLINE":
        for what, values in (("one of its control points", entity.control_points),
                             ("one of its fit points", entity.fit_points), ("one of its knots", entity.knots),
                             ("one of its weights", entity.weights)):
            if not all(_finite(v) for v in values):
                return what
    return ""


def _polyline_width(entity) -> bool:
    """An old-style POLYLINE drawn with a width (its default widths, or a vertex's)."""
    if entity.dxf.get("default_start_width", 0.0) or entity.dxf.get("default_end_width", 0.0):
        return True
    return any(v.dxf.get("start_width", 0.0) or v.dxf.get("end_width", 0.0) for v in entity.vertices)


def _spline_fit_polyline(rd: _Reading, entity, ent: _Entity, layer: str, role: str) -> None:
    """A POLYLINE smoothed by PEDIT Spline (flag 4): its fit vertices (vertex flag 8), the curve CAD programs show;
    its frame's control points (vertex flag 16) are left out."""
    fit = [tuple(v.dxf.location) for v in entity.vertices if v.dxf.get("flags", 0) & 8]
    if len(fit) < 2:
        _refuse_if_cut(rd, ent, role, "is a spline-fit POLYLINE (PEDIT Spline) without its fit points",
                       "convert it to a plain polyline or a SPLINE in CAD (PEDIT > Decurve, or SPLINE > Object)")
        return
    if _beyond_any_tube(rd, ent, layer, role, fit):
        return
    _vertex_piece(rd, ent, layer, role, fit, bool(entity.is_closed))


def _vertex_piece(rd: _Reading, ent: _Entity, layer: str, role: str, vertices, flagged_closed: bool) -> None:
    """The piece through ``vertices`` (drawing units), closed when flagged so or when it ends where it began; a path
    of one point set aside as of zero length, a closed one of two refused or set aside (:func:`_no_area`)."""
    pts = _dedupe([(v[0] * rd.factor, v[1] * rd.factor) for v in vertices])
    closed = flagged_closed or (len(pts) > 2 and _isclose(pts[0], pts[-1], TOL.gap))
    if closed and len(pts) > 1 and _isclose(pts[0], pts[-1], TOL.gap):
        pts = pts[:-1]
    if len(pts) < 2 or (closed and len(pts) < 3):
        if not _no_area(rd, ent, layer, role, pts):
            ent.status = "aside:zero length"
        return
    rd.pieces.append(_Piece(pts, closed, [ent], layer, role))


def _control_polygon(rd: _Reading, entity, ent: _Entity, layer: str, role: str) -> None:
    """A degree-1 SPLINE is its control polygon (closed when the spline is flagged closed or ends where it began)."""
    cps = [tuple(v) for v in entity.control_points]
    if _not_finite(rd, ent, [c for v in cps for c in v]) or _beyond_any_tube(rd, ent, layer, role, cps):
        return
    zs = [v[2] if len(v) > 2 else 0.0 for v in cps]
    if max(zs) - min(zs) > TOL.gap / rd.factor:
        rd.refuse(ent.describe(), "is not drawn in the XY plane (its z varies by "
                  f"{(max(zs) - min(zs)) * rd.factor:.4g} mm)", "flatten the drawing (FLATTEN) to the XY plane",
                  entities=[ent])
        return
    _vertex_piece(rd, ent, layer, role, cps, bool(entity.closed))


def _not_finite(rd: _Reading, ent: _Entity, coords: Sequence[float]) -> bool:
    """Refuse ``ent`` when one of its coordinates is not a finite number (nan, inf: a damaged file, or one written
    by a program that failed); True when refused."""
    if all(math.isfinite(float(c)) for c in coords):
        return False
    rd.refuse(ent.describe(), "has a coordinate that is not a finite number (nan or inf)",
              "redraw or delete it (the file may be damaged: export it again)", entities=[ent])
    return True


def _no_area(rd: _Reading, ent: _Entity, layer: str, role: str, pts: list[tuple[float, float]]) -> bool:
    """A closed path of two points farther apart than :data:`TOL.gap` (a rectangle 0 wide, a polyline drawn out
    and back) has a length but no area: refused on a cut layer, as a closed outline of three or more points with no
    area is in :func:`_cuts` (not set aside as of zero length); set aside on an ignored layer. True when handled."""
    if len(pts) != 2 or _isclose(pts[0], pts[1], TOL.gap):
        return False
    if role == "ignore":
        _set_aside_on_ignored(rd, ent, layer)
    else:
        rd.refuse(ent.describe(), "the closed outline encloses no area", "delete it or redraw it", entities=[ent])
    return True


def _aside_by_layer(rd: _Reading) -> dict[str, tuple[str, int]]:
    """Layers whose entities were set aside as hidden or not plotted: ``name -> (why, count)``, in drawing order."""
    out: dict[str, tuple[str, int]] = {}
    for e in rd.entities:
        why = e.status.removeprefix("aside:")
        if e.status.startswith("aside:") and why in ("hidden layer", "non-plotting layer"):
            out[e.layer] = (why, out.get(e.layer, (why, 0))[1] + 1)
    return out


def _set_aside_note(rd: _Reading) -> str:
    """``" (N entities on the hidden layer X were set aside)"``, or "" when none were."""
    aside = _aside_by_layer(rd)
    if not aside:
        return ""
    return " (" + "; ".join(f"{n} {'entity' if n == 1 else 'entities'} on the {why} {name} set aside"
                            for name, (why, n) in aside.items()) + ")"


def _no_cuts_fix(rd: _Reading) -> str:
    """The fix of a drawing without cuts: cut the layers set aside as hidden or not plotted, when there are some."""
    aside = _aside_by_layer(rd)
    if not aside:
        return "draw the cuts, or map their layer with --layer NAME=notch|hole|slit"
    return ("to cut them, map the layer: " + ", ".join(f"--layer {name}=notch" for name in aside)
            + " (or hole, slit), or switch it on and let it plot in the CAD program")


def _hidden_layers(doc) -> dict[str, str]:
    """Upper-case names of the layers a CAD program neither shows nor prints -> the reason they are set aside:
    switched off or frozen ("hidden layer"), or not plotted ("non-plotting layer": DXF group 290 = 0, where a drafter
    keeps construction and reference geometry; the beam cuts what the drawing prints)."""
    out = {}
    for layer in doc.layers:
        if layer.is_off() or layer.is_frozen():
            out[layer.dxf.name.upper()] = "hidden layer"
        elif not layer.dxf.get("plot", 1):
            out[layer.dxf.name.upper()] = "non-plotting layer"
    return out


def _why_ignored(rd: _Reading, layer: str) -> str:
    """Why an entity of ``layer`` (role ``ignore``) is set aside: the layer is hidden or not plotted (and not
    mapped to a role by the user), or its name says so."""
    up = layer.upper()
    return rd.hidden[up] if up in rd.hidden and up not in rd.roles else "ignored layer"


def _set_aside_on_ignored(rd: _Reading, ent: _Entity, layer: str) -> None:
    ent.status = f"aside:{_why_ignored(rd, layer)}"


def _beyond_any_tube(rd: _Reading, ent: _Entity, layer: str, role: str, xy: Sequence[tuple[float, float]]) -> bool:
    """Refuse ``ent`` (set it aside on an ignored layer) when its control points ``xy`` (drawing units, finite) span
    more than :data:`MAX_ENTITY_MM` or lie farther than :data:`MAX_COORD_MM` from the origin: checked before it is
    flattened, which for such a curve takes gigabytes. True when refused or set aside."""
    if not xy:
        return False
    xs = [float(v[0]) * rd.factor for v in xy]
    ys = [float(v[1]) * rd.factor for v in xy]
    x0, x1, y0, y1 = min(xs), max(xs), min(ys), max(ys)
    size = max(x1 - x0, y1 - y0)
    far = max(abs(x0), abs(x1), abs(y0), abs(y1))
    if size <= MAX_ENTITY_MM and far <= MAX_COORD_MM:
        return False
    if role == "ignore":
        _set_aside_on_ignored(rd, ent, layer)
        return True
    in_units = "" if rd.unit == "mm" else " (units {unit}: check $INSUNITS or --units)".format(unit=rd.unit)
    if size > MAX_ENTITY_MM:
        what = f"is {size:.4g} mm across{in_units}, far larger than any tube"
        fix = "redraw it at the tube's size, or delete it (or move it to a CONSTRUCTION layer)"
    else:
        where = "(%.4g, %.4g)" % ((x0, y0) if abs(x0) + abs(y0) >= abs(x1) + abs(y1) else (x1, y1))
        what = (f"lies at {where} mm{in_units}, too far from the origin for a tube drawing (coordinates that large "
                "lose precision)")
        fix = "move the drawing near the origin (MOVE in CAD), or delete the entity"
    rd.refuse(ent.describe(), what, fix, f"at most {MAX_ENTITY_MM:g} mm across and within {MAX_COORD_MM:g} mm of "
              "the origin", [ent])
    return True


def _unclamped_spline_path(entity, tolerance: float):
    """The path of a SPLINE whose knot vector is not clamped (a uniform or periodic spline, as some CAD programs write a
    closed one), or None for a clamped one. Such a spline is defined on its knots ``t_p .. t_n`` only (p its degree,
    n its count of control points); ``ezdxf.path.make_path`` and ``BSpline.flattening`` run it over every knot, through
    the region where it is not defined: a slit drawn at y = 10.2 mm was cut up to y = 23.7 mm, a closed spline read as
    open. Sampled here on its domain until every chord lies within ``tolerance`` of the curve (drawing units)."""
    import numpy as np
    from ezdxf import path as ezpath

    knots = [float(k) for k in entity.knots]
    deg = int(entity.dxf.degree)
    n_cp = entity.control_point_count()
    if len(knots) != n_cp + deg + 1 or deg < 2:
        return None
    if len(set(knots[:deg + 1])) == 1 and len(set(knots[-deg - 1:])) == 1:
        return None   # clamped: make_path reads it right
    lo, hi = knots[deg], knots[n_cp]
    if not hi > lo:
        return None
    bs = entity.construction_tool()
    n = 16 * max(1, n_cp - deg)
    for _ in range(12):
        ts = np.linspace(lo, hi, n + 1)
        pts = np.array([tuple(v) for v in bs.points(ts)], float)
        mid = np.array([tuple(v) for v in bs.points((ts[:-1] + ts[1:]) / 2.0)], float)
        a, b, m = pts[:-1, :2], pts[1:, :2], mid[:, :2]
        ab = b - a
        length = np.hypot(ab[:, 0], ab[:, 1])
        cross = np.abs(ab[:, 0] * (m[:, 1] - a[:, 1]) - ab[:, 1] * (m[:, 0] - a[:, 0]))
        dev = np.where(length > 0, cross / np.maximum(length, 1e-300), np.hypot(*(m - a).T))
        if float(np.max(dev)) <= tolerance:
            break
        n *= 2
    # (closed or not as its ends lie: :func:`_flatten` joins ends within the gap tolerance, as for any curve)
    return ezpath.from_vertices([tuple(v) for v in pts])


def _flatten(rd: _Reading, entity, ent: _Entity, layer: str, role: str) -> None:
    from ezdxf import path as ezpath

    try:
        p = None
        if entity.dxftype() == "SPLINE":
            p = _unclamped_spline_path(entity, TOL.chord / rd.factor)
        if p is None:
            p = ezpath.make_path(entity, segments=16, level=8)
    except (TypeError, ValueError, ArithmeticError) as exc:
        # (an ELLIPSE of axis ratio 0: ezdxf divides by its minor axis, ZeroDivisionError)
        why = str(exc) or type(exc).__name__
        if entity.dxftype() == "ELLIPSE" and not float(entity.dxf.get("ratio", 1.0)):
            why = "an ellipse of axis ratio 0, a line"
        _refuse_if_cut(rd, ent, role, f"cannot be read as a curve ({why})", "redraw it as a polyline")
        return
    distance = TOL.chord / rd.factor
    found = False
    cvs = p.control_vertices()
    if _not_finite(rd, ent, [c for v in cvs for c in v]) or _beyond_any_tube(rd, ent, layer, role, cvs):
        return
    if role == "ignore" and p.has_curves:  # a curve is never the outline (a rectangle): set aside, not flattened
        _set_aside_on_ignored(rd, ent, layer)
        return
    for sub in (p.sub_paths() if p.has_sub_paths else [p]):
        vs = list(sub.flattening(distance, segments=4))
        if len(vs) < 2:
            continue
        zs = [v.z for v in vs]
        if max(zs) - min(zs) > TOL.gap / rd.factor:
            rd.refuse(ent.describe(), "is not drawn in the XY plane (its z varies by "
                      f"{(max(zs) - min(zs)) * rd.factor:.4g} mm)", "flatten the drawing (FLATTEN) to the XY plane",
                      entities=[ent])
            return
        pts = _dedupe([(v.x * rd.factor, v.y * rd.factor) for v in vs])
        if len(pts) < 2:
            continue
        closed = bool(sub.is_closed) or _isclose(pts[0], pts[-1], TOL.gap)
        if closed and _isclose(pts[0], pts[-1], TOL.gap):
            pts = pts[:-1]
        if closed and len(pts) < 3:
            if _no_area(rd, ent, layer, role, pts):
                return
            continue
        rd.pieces.append(_Piece(pts, closed, [ent], layer, role))
        found = True
    if not found:
        ent.status = "aside:zero length"


def _fill(rd: _Reading, entity, ent: _Entity) -> None:
    """Remember a filled area's boundary loops (mm); checked against the drawn cuts in :func:`_check_fills`."""
    from ezdxf import path as ezpath

    try:
        paths = list(ezpath.from_hatch(entity)) if entity.dxftype() in ("HATCH", "MPOLYGON") else \
            [ezpath.make_path(entity)]
    except (TypeError, ValueError):
        paths = []
    cvs = [v for p in paths for v in p.control_vertices()]
    if _not_finite(rd, ent, [c for v in cvs for c in v]) or _beyond_any_tube(rd, ent, ent.layer, rd.role(ent.layer),
                                                                                cvs):
        return
    loops = []
    for p in paths:
        for sub in (p.sub_paths() if p.has_sub_paths else [p]):
            pts = [(v.x * rd.factor, v.y * rd.factor) for v in sub.flattening(TOL.chord / rd.factor, segments=4)]
            if len(pts) >= 3:
                loops.append(_dedupe(pts))
    rd.fills.append((ent, loops))


def _check_fills(rd: _Reading) -> None:
    """A fill on a cut layer is set aside if every boundary of it is drawn as a closed piece; else refused."""
    from shapely.geometry import Polygon

    closed = [Polygon(p.points) for p in rd.pieces if p.closed and len(p.points) >= 3]
    for ent, loops in rd.fills:
        ok = bool(loops)
        for loop in loops:
            f = Polygon(loop)
            tol = TOL.gap * max(f.length, 1.0)
            if not any(abs(f.area - g.area) <= tol and f.symmetric_difference(g).area <= tol for g in closed
                       if g.is_valid and f.is_valid):
                ok = False
                break
        if ok:
            ent.status = "aside:fill of a drawn outline"
        else:
            rd.refuse(ent.describe(), f"a filled area ({ent.dxftype}) whose boundary is not drawn as a closed outline",
                      "draw the cut's outline (e.g. HATCHEDIT > recreate boundary), or move the fill to a "
                      "CONSTRUCTION layer", entities=[ent])


def _isclose(a, b, tol: float) -> bool:
    return math.hypot(a[0] - b[0], a[1] - b[1]) <= tol


def _dedupe(pts: list[tuple[float, float]]) -> list[tuple[float, float]]:
    out = [pts[0]]
    for p in pts[1:]:
        if not _isclose(p, out[-1], TOL.merge):
            out.append(p)
    return out


def _refuse_open_copies(rd: _Reading) -> None:
    """An open piece on a cut layer drawn twice (the same points, either way round): refused naming both, and the copy
    left out of the chaining (a LINE pasted twice in a notch of four LINEs read as three open paths, "close the
    outline"; a slit pasted twice as "a closed outline on a slit layer")."""
    seen: dict[tuple, _Piece] = {}
    copies: dict[str, list[tuple[_Piece, _Piece]]] = {}   # layer -> (copy, first)
    for p in rd.pieces:
        if p.closed or p.role == "ignore":
            continue
        key = tuple((round(x / TOL.gap), round(y / TOL.gap)) for x, y in p.points)
        first = seen.get((p.layer, key)) or seen.get((p.layer, key[::-1]))
        if first is None:
            seen[(p.layer, key)] = p
        else:
            copies.setdefault(p.layer, []).append((p, first))
    for layer, pairs in copies.items():
        p, first = pairs[0]
        if len(pairs) == 1:
            rd.refuse(f"{p.describe()} and {first.describe()}", "the same path drawn twice (pasted twice?)",
                      "delete one of the two", entities=p.entities)
            continue
        # an outline of LINEs pasted twice: one line for the copy, not one a LINE
        handles = [f"#{e.handle}" for c, _ in pairs for e in c.entities]
        shown = ", ".join(handles[:8]) + (", ..." if len(handles) > 8 else "")
        rd.refuse(f"{p.describe()} and {first.describe()}, and {len(pairs) - 1} more on layer {layer}",
                  f"{len(pairs)} paths drawn twice (pasted twice?)", f"delete the copies ({shown})",
                  entities=[e for c, _ in pairs for e in c.entities])
    gone = {id(c) for pairs in copies.values() for c, _ in pairs}
    rd.pieces = [p for p in rd.pieces if id(p) not in gone]


def _close_and_chain(rd: _Reading) -> None:
    """Chain the open pieces of each layer with ezdxf.edgeminer: into loops (outlines), and, on a slit
    layer, pieces drawn end to end into one open path (a slit broken at a point, a zig-zag of LINEs)."""
    from ezdxf import edgeminer as em
    from ezdxf.math import Vec3

    _refuse_open_copies(rd)
    by_layer: dict[str, list[_Piece]] = {}
    for p in rd.pieces:
        if not p.closed:
            by_layer.setdefault(p.layer, []).append(p)
    for layer, pieces in sorted(by_layer.items()):
        edges = [em.make_edge(Vec3(p.points[0]), Vec3(p.points[-1]), length=1.0, payload=k)
                 for k, p in enumerate(pieces)]
        deposit = em.Deposit(edges, gap_tol=TOL.gap)
        chains = sorted(em.find_all_simple_chains(deposit), key=lambda ch: min(e.payload for e in ch))
        consumed: set[int] = set()
        for chain in chains:
            if len(chain) < 2:
                continue
            is_loop = em.is_loop(chain, gap_tol=TOL.gap)
            pts: list[tuple[float, float]] = []
            for e in chain:
                seg = pieces[e.payload].points
                seg = list(reversed(seg)) if e.is_reverse else list(seg)
                pts.extend(seg if not pts else seg[1:])
            if is_loop and _isclose(pts[0], pts[-1], TOL.gap):
                pts = pts[:-1]
            ents = [pieces[e.payload].entities[0] for e in chain]
            joined = _Piece(_dedupe(pts), is_loop, ents, layer, pieces[0].role)
            if is_loop:
                rd.joined.append(joined)
            rd.pieces.append(joined)  # an open chain is one open path (refused or set aside as one)
            consumed.update(e.payload for e in chain)
        rd.pieces = [p for p in rd.pieces if not any(p is pieces[k] for k in consumed)]


# ---------------------------------------------------------------- the tube outline
def _rectangle(piece: _Piece) -> tuple[float, float, float, float] | None:
    """Bounds of a closed piece if it is an axis-aligned rectangle (within TOL.gap), else None."""
    if not piece.closed or len(piece.points) < 3:
        return None
    x0, y0, x1, y1 = piece.bounds
    if x1 - x0 <= TOL.gap or y1 - y0 <= TOL.gap:
        return None
    for x, y in piece.points:
        on_x = abs(x - x0) <= TOL.gap or abs(x - x1) <= TOL.gap
        on_y = abs(y - y0) <= TOL.gap or abs(y - y1) <= TOL.gap
        if not (on_x or on_y):
            return None
    # every corner of the box drawn (a chamfered or notched corner has its vertices on the box's edges, and a small
    # chamfer's missing area is within the area test below: it was cut square, the beam outside the drawn corner)
    for cx, cy in ((x0, y0), (x1, y0), (x1, y1), (x0, y1)):
        if not any(abs(x - cx) <= TOL.gap and abs(y - cy) <= TOL.gap for x, y in piece.points):
            return None
    from shapely.geometry import Polygon

    area = Polygon(piece.points).area
    if abs(area - (x1 - x0) * (y1 - y0)) > TOL.gap * (x1 - x0 + y1 - y0):
        return None
    return x0, y0, x1, y1


def _largest_rectangle_with_a_cut_outside(pieces, cut_pieces, bounds):
    """``(rectangle, a cut outside it)`` when the largest drawn rectangle holds at least one other cut (or lies on a
    layer that is not cut, or is four times the size of every other cut) but not all of them (a cut drawn past a
    correctly drawn outline), else None."""
    rects = [(p, _rectangle(p)) for p in pieces]
    rects = [(p, box) for p, box in rects if box is not None]
    if not rects:
        return None
    p, (x0, y0, x1, y1) = max(rects, key=lambda r: (r[1][2] - r[1][0]) * (r[1][3] - r[1][1]))
    inside, outside = [], []
    for q, bb in zip(cut_pieces, bounds):
        if q is p:
            continue
        ok = bb[0] >= x0 - TOL.gap and bb[2] <= x1 + TOL.gap and y0 - TOL.gap <= 0.5 * (bb[1] + bb[3]) <= y1 + TOL.gap
        (inside if ok else outside).append(q)
    # (a rectangle on a layer that is not cut is the outline even when no cut lies inside it: the one cut drawn past
    # its end was "no tube outline found")
    area = (x1 - x0) * (y1 - y0)
    larger = all(area >= 4.0 * (bb[2] - bb[0]) * (bb[3] - bb[1]) for q, bb in zip(cut_pieces, bounds) if q is not p)
    return (p, outside[0]) if outside and (inside or p.role == "ignore" or larger) else None


def _overshooting_frame(pieces) -> list:
    """Two horizontal and two vertical straight open pieces (2 points each) on one layer that cross one another near
    their ends, each running on past the crossings (by more than :data:`TOL.gap`, less than a fifth of its length): a
    rectangle drawn with its LINEs extended past the corners. The four pieces, or []."""
    def straight(p, axis):
        if p.closed or len(p.points) != 2:
            return False
        (xa, ya), (xb, yb) = p.points
        return abs(ya - yb) <= TOL.gap < abs(xa - xb) if axis == "h" else abs(xa - xb) <= TOL.gap < abs(ya - yb)

    by_layer: dict[str, tuple[list, list]] = {}
    for p in pieces:
        for axis, k in (("h", 0), ("v", 1)):
            if straight(p, axis):
                by_layer.setdefault(p.layer, ([], []))[k].append(p)
    for hs, vs in by_layer.values():
        if len(hs) < 2 or len(vs) < 2 or len(hs) * len(vs) > 400:
            continue
        for i, h0 in enumerate(hs):
            for h1 in hs[i + 1:]:
                for j, v0 in enumerate(vs):
                    for v1 in vs[j + 1:]:
                        frame = [h0, h1, v0, v1]
                        if _crossing_frame(h0, h1, v0, v1):
                            return frame
    return []


def _crossing_frame(h0, h1, v0, v1) -> bool:
    ys = sorted((h0.points[0][1], h1.points[0][1]))
    xs = sorted((v0.points[0][0], v1.points[0][0]))
    if ys[1] - ys[0] <= TOL.gap or xs[1] - xs[0] <= TOL.gap:
        return False
    for h in (h0, h1):
        lo, hi = sorted(x for x, _ in h.points)
        if not (lo < xs[0] - TOL.gap and hi > xs[1] + TOL.gap and max(xs[0] - lo, hi - xs[1]) < 0.2 * (hi - lo)):
            return False
    for v in (v0, v1):
        lo, hi = sorted(y for _, y in v.points)
        if not (lo < ys[0] - TOL.gap and hi > ys[1] + TOL.gap and max(ys[0] - lo, hi - ys[1]) < 0.2 * (hi - lo)):
            return False
    return True


def _overshoot(p, frame) -> float:
    """How far the straight piece ``p`` of ``frame`` runs on past the frame's crossing lines."""
    hs = [q for q in frame if abs(q.points[0][1] - q.points[1][1]) <= TOL.gap]
    vs = [q for q in frame if q not in hs]
    if p in hs:
        lo, hi = sorted(x for x, _ in p.points)
        xs = sorted(q.points[0][0] for q in vs)
        return max(xs[0] - lo, hi - xs[1])
    lo, hi = sorted(y for _, y in p.points)
    ys = sorted(q.points[0][1] for q in hs)
    return max(ys[0] - lo, hi - ys[1])


def _find_outline(rd: _Reading, ro: float | None, length: float | None):
    """The tube outline piece (or None), and r_o and L (checked against it, or taken from it)."""
    cut_pieces = [p for p in rd.pieces if p.role != "ignore"]
    if not cut_pieces:
        return None, ro or 1.0, length or 1.0  # nothing to cut: refused as such by the caller
    frame = _overshooting_frame(rd.pieces)
    if frame and frame[0].role == "ignore":
        # construction lines that cross: a frame only where no closed rectangle is drawn as big as it (the outline)
        xs = sorted(q.points[0][0] for q in frame[2:])
        ys = sorted(q.points[0][1] for q in frame[:2])
        if any(box is not None and box[0] <= xs[0] + TOL.gap and box[2] >= xs[1] - TOL.gap
               and box[1] <= ys[0] + TOL.gap and box[3] >= ys[1] - TOL.gap for box in map(_rectangle, rd.pieces)):
            frame = []
    if frame:
        # (four LINEs extended past the corners, as CAD leaves them: no closed outline, and a notch was named "the tube
        # outline" with a LINE "outside it")
        over = max(_overshoot(p, frame) for p in frame)
        rd.refuse(", ".join(p.describe() for p in frame), f"cross one another near their ends instead of meeting (they "
                  f"run on past the corners by up to {over:.4g} mm): a frame of four lines that is not a closed outline",
                  "trim them at the corners in CAD (TRIM, or FILLET with radius 0), so that their ends meet",
                  entities=[e for p in frame for e in p.entities])
        return None, ro or 1.0, length or 1.0
    import numpy as np

    # per cut piece: x range and the y of its centre (a cut may cross the seam line drawn whole)
    b = np.array([q.bounds for q in cut_pieces], dtype=float)
    xs0, xs1, yc = b[:, 0], b[:, 2], 0.5 * (b[:, 1] + b[:, 3])
    index = {id(q): k for k, q in enumerate(cut_pieces)}
    groups: list[tuple[tuple[float, float, float, float], list[_Piece]]] = []  # rectangles drawn twice: one group
    for p in rd.pieces:
        box = _rectangle(p)
        if box is None:
            continue
        x0, y0, x1, y1 = box
        # pieces around this rectangle (a frame, a larger outline) do not stop it being the outline
        keep = ~((b[:, 0] <= x0 + TOL.gap) & (b[:, 2] >= x1 - TOL.gap) & (b[:, 1] <= y0 + TOL.gap)
                 & (b[:, 3] >= y1 - TOL.gap))
        if id(p) in index:
            keep[index[id(p)]] = False
        if not keep.any():
            continue
        inside = bool(np.all((xs0[keep] >= x0 - TOL.gap) & (xs1[keep] <= x1 + TOL.gap)
                             & (yc[keep] >= y0 - TOL.gap) & (yc[keep] <= y1 + TOL.gap)))
        if not inside:
            continue
        for g_box, members in groups:
            if all(abs(u - v) <= TOL.gap for u, v in zip(g_box, box)):
                members.append(p)
                break
        else:
            groups.append((box, [p]))
    if not groups:
        missing = [w for w, v in (("--outer-radius", ro), ("--length", length)) if v is None]
        if not missing:  # a rectangle of the tube's size that does not hold every cut: never guess the origin
            for p in rd.pieces:
                box = _rectangle(p)
                if box is not None and abs(box[3] - box[1] - 2.0 * math.pi * ro) <= TOL.outline \
                        and abs(box[2] - box[0] - length) <= TOL.outline:
                    out = next((q for q, bb in zip(cut_pieces, b) if q is not p and (
                        bb[0] < box[0] - TOL.gap or bb[2] > box[2] + TOL.gap
                        or not box[1] - TOL.gap <= 0.5 * (bb[1] + bb[3]) <= box[3] + TOL.gap)), None)
                    where = f"; {out.describe()} lies outside it" if out is not None else ""
                    rd.refuse(p.describe(), f"is the size of the tube outline but does not enclose every cut{where}",
                              "move the cut inside the outline (or delete it), or the outline around the cuts",
                              entities=p.entities)
                    return None, ro, length
        if missing:
            largest = _largest_rectangle_with_a_cut_outside(rd.pieces, cut_pieces, b)
            if largest is not None:
                p, out = largest
                rd.refuse(p.describe(), "would be the tube outline (the largest rectangle drawn) but "
                          f"{out.describe()} lies outside it", "move that cut inside the outline (or delete it), or "
                          "pass " + " and ".join(missing) + " if the tube is not this rectangle",
                          entities=p.entities + out.entities)
                return None, ro, length
            rd.refuse("tube outline", "no tube outline found (an axis-aligned rectangle L x 2 pi r_o around every cut)",
                      "draw the unrolled tube outline (any layer), or pass " + " and ".join(missing))
        return None, ro, length

    def fits(box) -> bool:
        ok_r = ro is None or abs(box[3] - box[1] - 2.0 * math.pi * ro) <= TOL.outline
        ok_l = length is None or abs(box[2] - box[0] - length) <= TOL.outline
        return ok_r and ok_l

    if ro is not None or length is not None:
        matching = [g for g in groups if fits(g[0])]
        # none fits: the largest is the outline the user drew, and the mismatch is reported on it
        groups = matching or [max(groups, key=lambda g: (g[0][2] - g[0][0]) * (g[0][3] - g[0][1]))]
    if len(groups) > 1:
        names = "; ".join(f"{g[1][0].describe()} ({(g[0][2] - g[0][0]):.4g} x {(g[0][3] - g[0][1]):.4g} mm)"
                          for g in groups)
        rd.refuse("tube outline", f"{len(groups)} nested rectangles could each be the tube outline: {names}",
                  "pass --outer-radius (and --length) to say which, or delete the extra rectangle "
                  "(a cut drawn around another cut is refused anyway)",
                  entities=[p for g in groups for p in g[1]])
        return None, ro, length
    (x0, y0, x1, y1), members = groups[0]
    piece = members[0]
    h, w = y1 - y0, x1 - x0
    desc = piece.describe()
    if ro is not None and abs(h - 2.0 * math.pi * ro) > TOL.outline:
        drawn_h = f"{h / rd.factor:.6g} {rd.unit} = " if rd.unit != "mm" else ""
        rd.refuse(desc, f"the tube outline is {drawn_h}{h:.4f} mm high, i.e. 2 pi x "
                  f"{h / (2 * math.pi):.4f} mm, but the outer radius {ro:g} mm needs 2 pi r_o = "
                  f"{2 * math.pi * ro:.4f} mm", f"pass --outer-radius {h / (2 * math.pi):.4f} (or omit it), or redraw "
                  "the outline", f"height 2 pi r_o within {TOL.outline:g} mm", piece.entities)
    if length is not None and abs(w - length) > TOL.outline:
        rd.refuse(desc, f"the tube outline is {w:.4f} mm long, but the tube length given is {length:g} mm",
                  f"pass --length {w:.4f} (or omit it), or redraw the outline", f"length within {TOL.outline:g} mm",
                  piece.entities)
    for extra in members[1:]:  # the outline drawn twice (copy/paste, or on two layers)
        for e in extra.entities:
            e.status = "aside:outline drawn again"
    rd.pieces = [p for p in rd.pieces if not any(p is m for m in members[1:])]
    for e in piece.entities:
        e.status = "outline"
    rd.pieces = [p for p in rd.pieces if p is not piece]
    return piece, h / (2.0 * math.pi) if ro is None else ro, w if length is None else length


# ---------------------------------------------------------------- cuts
def _cuts(rd: _Reading, outline: _Piece | None, ro: float, length: float):
    """Cuts (and their entity descriptions) from the remaining pieces, in the tube frame."""
    from shapely.geometry import LineString, Polygon
    from shapely.validation import explain_validity

    from camtube.design.contour import Contour, merge_seam_polygons

    ox, oy = (outline.bounds[0], outline.bounds[1]) if outline is not None else (0.0, 0.0)
    circ = 2.0 * math.pi * ro
    contours: list[Contour] = []
    owners: list[_Piece] = []
    for p in rd.pieces:
        if p.role == "ignore":
            why = _why_ignored(rd, p.layer)
            for e in p.entities:
                e.status = e.status or f"aside:{why}"
            continue
        pts = [(x - ox, y - oy) for x, y in p.points]
        desc = p.describe()
        if p.role == "slit":
            if p.closed:
                rd.refuse(desc, "a closed outline on a slit layer (a slit is an open path the beam follows)",
                          f"draw the slit as an open path, or map the layer to notch (--layer {p.layer}=notch) "
                          "to cut out the area", entities=p.entities)
                continue
            if len(pts) >= 3 and not LineString(pts).is_simple:
                # (accepted: the beam passed the crossing twice, where two crossing slits are refused as overlapping;
                # three points that run back over themselves too)
                rd.refuse(desc, "the slit crosses or runs back over itself (the beam would pass there twice)",
                          "redraw it as a path that does not cross itself, or as separate slits that meet end to end",
                          entities=p.entities)
                continue
            contours.append(Contour(tuple(pts), "slit", len(contours), False))
            owners.append(p)
            continue
        if not p.closed:
            (xa, ya), (xb, yb) = p.points[0], p.points[-1]
            rd.refuse(desc, f"an open path on a {p.role} layer: its ends {rd.at(xa, ya)} and {rd.at(xb, yb)} are "
                      f"{math.hypot(xa - xb, ya - yb):.4g} mm apart (joined only within {TOL.gap:g} mm)",
                      f"close the outline in CAD (snap the ends, JOIN), or map the layer to slit "
                      f"(--layer {p.layer}=slit) if it is a kerf path", "closed outlines", p.entities)
            continue
        if len(pts) < 3:  # two LINEs drawn over each other chain into a loop of two points
            rd.refuse(desc, "the closed outline encloses no area", "delete it or redraw it", entities=p.entities)
            continue
        poly = Polygon(pts)
        if not poly.is_valid:
            rd.refuse(desc, f"the outline crosses itself ({explain_validity(poly)}, drawing origin moved to the "
                      "outline corner)", "redraw it as a simple closed outline", entities=p.entities)
            continue
        if poly.area <= TOL.gap * TOL.gap:
            rd.refuse(desc, "the closed outline encloses no area", "delete it or redraw it", entities=p.entities)
            continue
        if poly.exterior.is_ccw is False:
            pts = pts[::-1]
        contours.append(Contour(tuple(pts), p.role, len(contours)))
        owners.append(p)
    merged = merge_seam_polygons(contours, circ, TOL.gap)
    cuts: list[Cut] = []
    origins: list[str] = []
    seam_joined = 0
    for con, idx in merged:
        ents = [e for k in idx for e in owners[k].entities]
        for e in ents:
            e.status = "imported"
        if len(idx) > 1:
            seam_joined += 1
            desc = " + ".join(owners[k].describe() for k in idx) + " (joined at the seam)"
        else:
            desc = owners[idx[0]].describe()
        cuts.append(_to_cut(con, ro))
        origins.append(desc)
    return cuts, origins, seam_joined


def _to_cut(con, ro: float) -> Cut:
    """A plain rectangle cut if the contour is one (within TOL.gap), else a drawn cut."""
    x0, y0, x1, y1 = con.bounds
    if con.closed and _rectangle(_Piece(list(con.points), True, [], "", "")) is not None:
        angle_deg = math.degrees(0.5 * (y0 + y1) / ro) % 360.0
        return Cut(con.kind, 0.5 * (x0 + x1), x1 - x0, y1 - y0, angle_deg)
    return drawn(con.kind, con.points, ro)


# ---------------------------------------------------------------- the summary line
def _plural(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if n == 1 else ("es" if word.endswith(("ch", "s")) else "s"))


def _summary(rd: _Reading, pattern: Pattern, outline: _Piece | None, seam_joined: int,
             radius_from_outline: bool, length_from_outline: bool) -> str:
    counts = [(len(pattern.notches), "notch"), (len(pattern.holes), "hole"), (len(pattern.slits), "slit")]
    parts = [_plural(n, w) for n, w in counts if n]
    what = parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]
    notes = []
    if outline is not None:
        t = pattern.tube
        given = []
        if radius_from_outline:
            given.append(f"r_o = {t.outer_radius_mm:.4g} mm")
        if length_from_outline:
            given.append(f"L = {t.length_mm:.4g} mm")
        notes.append(f"outline {outline.describe()}" + (f" gives {' and '.join(given)}" if given else " checked"))
    else:
        notes.append("no outline: origin at the drawing's origin")
    notes.append(f"units {rd.unit}")
    if rd.inserts:
        notes.append(f"{_plural(rd.inserts, 'INSERT')} expanded")
    joined = [p for p in rd.joined if any(e.status == "imported" for e in p.entities)]
    if joined:
        n_ent = sum(len(p.entities) for p in joined)
        notes.append(f"{n_ent} loose entities joined into {_plural(len(joined), 'loop')}")
    if seam_joined:
        notes.append(f"{_plural(seam_joined, 'cut')} rejoined at the seam")
    aside: dict[str, int] = {}
    for e in rd.entities:
        if e.status.startswith("aside:"):
            aside[e.status[6:]] = aside.get(e.status[6:], 0) + 1
    if aside:
        notes.append("set aside: " + ", ".join(f"{n} ({why})" for why, n in sorted(aside.items())))
    return f"imported {what} from {_plural(len(rd.entities), 'entity').replace('entitys', 'entities')} " \
           f"({'; '.join(notes)})"
