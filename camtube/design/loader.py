"""Load a pattern YAML into a validated :class:`~camtube.design.pattern.Pattern`.

The YAML is parsed once, checked against :data:`camtube.design.schema.SCHEMA`
(unknown keys rejected with a "did you mean"), overridden by ``--set`` pairs,
built into plain values, and run through the design rules. Every error names
the file, the line, the key, the value, the allowed range and the fix; all
errors are reported together.
"""
from __future__ import annotations

import math
import os
import re
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Iterable

import yaml

from camtube.design import rules as design_rules
from camtube.design.generate import notch_row
from camtube.design.pattern import Pattern, Process, RepeatRule, Rules, Tendon, Tube, hole, notch, sort_cuts
from camtube.design.schema import SCHEMA, Field
from camtube.errors import Issue, PatternError
from camtube.fmt import one_line
from camtube.yamltext import NumberTooLongError, closest, line_map, parse_yaml, read_yaml_file

#: The shipped presets (package data): tube patterns and the process files they name.
PRESETS_DIR = Path(__file__).resolve().parent / "presets"


@dataclass(frozen=True)
class Loaded:
    """A loaded pattern with what the loader learnt about it.

    Attributes
    ----------
    pattern : Pattern
    warnings : list[Issue]
        Design warnings (closure angle, strain).
    origins : tuple[str, ...]
        YAML key each cut came from, parallel to ``pattern.cuts`` (for a
        drawing: the entity, e.g. ``LWPOLYLINE #2A on layer NOTCHES``).
    summary : str
        One line saying what was read (a drawing: what was imported from how
        many entities); empty for a YAML pattern.
    """

    pattern: Pattern
    warnings: tuple[Issue, ...]
    origins: tuple[str, ...]
    summary: str = ""


def _did_you_mean(word: str, options: Iterable[str]) -> str:
    m = closest(word, options)
    return f"did you mean '{m}'?" if m else "remove it"


def parse_override(item: str) -> tuple[str, Any]:
    """``'notch.count=20'`` -> ``('notch.count', 20)`` (value parsed as YAML)."""
    if "=" not in item:
        raise PatternError([Issue("--set", "expected KEY=VALUE", item, "e.g. notch.count=20",
                                  "write the key, an equals sign and the value")])
    key, _, value = item.partition("=")
    if not value.strip():
        # (an empty value parsed as null: "required key is missing; fix: add 'count:'" to the shipped preset file)
        raise PatternError([Issue(f"--set {key.strip()}=", "no value after the equals sign", item,
                                  f"e.g. {key.strip()}=VALUE", f"write the value: --set {key.strip()}=VALUE (an empty "
                                  "shell variable?)")])
    try:
        parsed = parse_yaml(value)
    except NumberTooLongError as exc:
        raise PatternError([Issue(key.strip(), "out of range in --set", f"a number of {exc.digits} digits",
                                  "the range `camtube schema` lists for the key",
                                  "bring it inside the allowed range")]) from None
    except yaml.YAMLError:
        parsed = value
    return key.strip(), parsed


def _is_index(part: str) -> bool:
    """True for a list index in a dotted --set key (``holes.0.x``): ASCII digits only (``'²'.isdigit()`` is true)."""
    return part.isascii() and part.isdigit()


def _past_end(key: str, idx: str, node: list, file: str | None = None) -> Issue:
    """``--set`` names an entry the list does not have (the pattern's file named, where it has one)."""
    top = key.split(".")[0]
    if not node:   # (was "allowed: 0..-1")
        return Issue(key, f"index {idx}, but the pattern has no {top} entries", None, "an index of an entry the "
                     "YAML gives", f"add the entry under '{top}:' in the YAML first", file)
    return Issue(key, f"index {idx} is past the end of the list", None, f"0..{len(node) - 1}",
                 "add the entry in the YAML first", file)


def _schema_node(parts: list[str]):
    node: Any = SCHEMA
    for p in parts:
        if isinstance(node, Field) and node.kind == "rows":
            if _is_index(p):
                node = dict(node.row)
                continue
            return None
        if not isinstance(node, dict) or p not in node:
            return None
        node = node[p]
    return node


def _merge(into: dict, update: dict) -> None:
    """``update``'s keys into ``into``, mappings into mappings (in place)."""
    for k, v in update.items():
        if isinstance(v, dict) and isinstance(into.get(k), dict):
            _merge(into[k], v)
        else:
            into[k] = v


def apply_overrides(raw: dict, overrides: Iterable[str], file: str | None = None) -> dict:
    """Return a copy of ``raw`` with ``key=value`` overrides applied.

    Keys are dotted paths (``notch.count``, ``process.repeats``,
    ``holes.0.x``); an unknown key is an error with a "did you mean". A mapping given for a section
    (``notch={count: 3}``) merges into it; a key given twice with different values is refused.
    """
    import copy

    raw = copy.deepcopy(raw) if raw else {}
    issues = []
    given: dict[str, str] = {}
    for item in overrides:
        key, value = parse_override(item)
        name = key.strip()
        if name in given and given[name] != item:
            # (--set notch.count=10 --set notch.count=3 cut 3 notches without a word; ingest --map refuses this too)
            issues.append(Issue(f"--set {name}", "given twice, with different values", item,
                                f"one --set {name}=VALUE", f"keep one of {given[name]!r} and {item!r}"))
            continue
        given[name] = item
        parts = key.split(".")
        if _schema_node(parts) is None:
            from camtube.design.schema import iter_fields

            known = [k for k, _ in iter_fields() if "[]" not in k]
            issues.append(Issue(key, "unknown key in --set", None, "a key of the pattern schema",
                                _did_you_mean(key, known), file))
            continue
        node = raw
        for depth, p in enumerate(parts[:-1]):
            if isinstance(node, list) and _is_index(p):
                if len(p) > 9 or int(p) >= len(node):
                    issues.append(_past_end(key, p, node, file))
                    node = None
                    break
                node = node[int(p)]
            elif isinstance(node, dict):
                if not isinstance(node.get(p), (dict, list)):
                    node[p] = [] if _is_index(parts[depth + 1]) else {}
                node = node[p]
            else:  # an entry the YAML gives as a scalar (holes: [0.75]): the check of the YAML names it
                node = None
                break
        if node is None:
            continue
        last = parts[-1]
        if isinstance(node, list) and _is_index(last):
            if len(last) > 9 or int(last) >= len(node):
                issues.append(_past_end(key, last, node, file))
                continue
            node[int(last)] = value
        elif isinstance(node, dict):
            if isinstance(value, dict) and isinstance(node.get(last), dict):
                # a mapping set on a section merges into it, as its keys set one by one would (--set 'notch={count:
                # 3}' replaced the section: four "required key is missing" lines at the preset's lines that hold them)
                _merge(node[last], value)
            else:
                node[last] = value
        # else: not a mapping in the YAML (holes: [[1, 2]]); the check of the YAML names the entry
    if issues:
        raise PatternError(issues)
    return raw


class _Reader:
    """Collects issues while converting raw YAML values to typed values."""

    def __init__(self, file: str | None, lines: dict[str, int]):
        self.file, self.lines, self.issues = file, lines, []
        self.broken: set[str] = set()  # sections that are not mappings: their keys are not reported one by one

    def issue(self, key, message, value=None, allowed="", fix=""):
        if any(key.startswith(b + ".") for b in self.broken):
            return
        self.issues.append(Issue(key, message, value, allowed, fix, self.file, self.lines.get(key)))

    def check_keys(self, mapping: dict, allowed: dict, prefix: str) -> None:
        for k in mapping:
            if k not in allowed:
                key = f"{prefix}.{k}" if prefix else str(k)
                self.issue(key, "unknown key", None, "one of " + ", ".join(allowed), _did_you_mean(str(k), allowed))

    def value(self, mapping: dict, name: str, f: Field, key: str):
        if name not in mapping or mapping[name] is None:
            if f.default is ...:
                self.issue(key, "required key is missing", None, f.allowed(), f"add '{name}: <value>'")
                return None
            return f.default
        v = mapping[name]
        return self.convert(v, f, key)

    def convert(self, v, f: Field, key: str):
        if f.kind == "str":
            return str(v)
        if f.kind == "choice":
            if v not in f.choices:
                self.issue(key, "not an allowed choice", v, f.allowed(), _did_you_mean(str(v), f.choices))
                return None
            return v
        if f.kind == "int_or_auto":
            if v == "auto":
                return None
            return self.number(v, f, key, integer=True)
        if f.kind == "floats":
            if not isinstance(v, (list, tuple)):
                self.issue(key, "expected a list", v, f.allowed(), "write e.g. [0, 90, 180, 270]")
                return ()
            before = len(self.issues)
            out = tuple(self.number(x, f, f"{key}[{i}]") for i, x in enumerate(v))
            if len(self.issues) > before + 1:  # one line for the list ([0, 0, 0]: one mistake, not three lines)
                first, more = self.issues[before], len(self.issues) - before - 1
                self.issues[before:] = [replace(first, message=f"{first.message} (and {more} more entr"
                                                f"{'y' if more == 1 else 'ies'} of {key})")]
            return out
        if f.kind == "rows":
            if not isinstance(v, list):
                self.issue(key, "expected a list of mappings", v, f.allowed(), "write one '- key: value' entry per item")
                return ()
            rows = []
            spec = dict(f.row)
            for i, item in enumerate(v):
                rk = f"{key}[{i}]"
                if not isinstance(item, dict):
                    self.issue(rk, "expected a mapping", item, f.allowed(), "write 'key: value' pairs")
                    continue
                self.check_keys(item, spec, rk)
                rows.append({n: self.value(item, n, rf, f"{rk}.{n}") for n, rf in f.row})
            return tuple(rows)
        return self.number(v, f, key, integer=(f.kind == "int"))

    def number(self, v, f: Field, key: str, integer: bool = False):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            self.issue(key, "expected a number", v, f.allowed(), "write a plain number (no units)")
            return None
        try:
            x = float(v)
        except OverflowError:  # an integer of hundreds of digits
            self.issue(key, "out of range", f"a number of {len(str(abs(v)))} digits", f.allowed(),
                       "bring it inside the allowed range")
            return None
        if not math.isfinite(x):
            self.issue(key, "must be finite", v, f.allowed(), "write a finite number")
            return None
        if integer and (isinstance(v, float) and not x.is_integer()):
            self.issue(key, "expected a whole number", v, f.allowed(), f"use {round(v)}")
            return None
        lo_bad = x <= f.lo if f.lo_open else x < f.lo
        hi_bad = x >= f.hi if f.hi_open else x > f.hi
        if lo_bad or hi_bad:
            fix = ("use a positive value" if lo_bad and f.lo == 0 and f.lo_open
                   else f"use a value {'<' if f.hi_open else '<='} {f.hi:g}" if hi_bad
                   else f"use a value {'>' if f.lo_open else '>='} {f.lo:g}")
            self.issue(key, "out of range", v, f.allowed(), fix)
            return None
        return int(x) if integer else x


#: The reader that turns raw YAML values into checked values (also used by other input files, e.g. goals).
Reader = _Reader


def _section(reader: _Reader, raw: dict, name: str) -> dict:
    body = raw.get(name)
    if body is None:
        body = {}
    if not isinstance(body, dict):
        reader.issue(name, "expected a mapping", body, "key: value pairs", f"indent the keys under '{name}:'")
        reader.broken.add(name)
        body = {}
    spec = SCHEMA[name]
    reader.check_keys(body, spec, name)
    return {k: reader.value(body, k, f, f"{name}.{k}") for k, f in spec.items()}


def read_yaml(path: str | os.PathLike, kind: str = "pattern") -> tuple[dict, dict[str, int], str]:
    """Read a YAML mapping; returns ``(raw, line_map, file)``; every failure names the file and line. ``kind``:
    ``pattern`` or ``process`` (a file a pattern's ``process:`` names), for the words of the messages."""
    file = str(path)
    raw, text = read_yaml_file(path, kind,
                               lambda: f"check the path, or give a preset name ({', '.join(preset_names())})"
                               if kind == "pattern" else "check the file the pattern's process: names")
    if raw is None:
        raw = {}
    if not isinstance(raw, dict):
        if kind == "process":
            raise PatternError([Issue("<top>", "a process file must be a mapping of process keys", None,
                                      "keys " + ", ".join(SCHEMA["process"]), "write one 'key: value' per line "
                                      "(power_w: 2.0, ...), with or without a top-level 'process:'", file, 1)])
        raise PatternError([Issue("<top>", "a pattern file must be a mapping of sections", None,
                                  "sections " + ", ".join(SCHEMA), "start the file with 'tube:'", file, 1)])
    return raw, line_map(text), file


def _process(proc: dict) -> Process:
    return Process(
        power_w=proc["power_w"], frequency_khz=proc["frequency_khz"], scan_speed_mm_s=proc["scan_speed_mm_s"],
        wavelength_nm=proc["wavelength_nm"], drill_offset_mm=proc["drill_offset"],
        drill_passes=proc["drill_passes"], defocus_mm=proc["defocus"],
        repeats=None if proc["repeats"] == "auto" else proc["repeats"],  # the schema default is the word
        repeat_rule=tuple(sorted((RepeatRule(x["max_depth"], x["repeats"]) for x in proc["repeat_rule"]),
                                 key=lambda q: q.max_depth_mm)),
        kerf_mm=proc["kerf"], rapid_speed_mm_s=proc["rapid_speed_mm_s"], focus_speed_mm_s=proc["focus_speed_mm_s"],
        max_time_h=proc["max_time_h"],
    )


#: Per-notch list key -> (the scalar it replaces, how many values it needs given the notch count).
_NOTCH_LISTS = {"widths": ("width", 0), "arcs": ("arc", 0), "spacings": ("spacing", -1), "angles_deg": (None, 0)}


def _check_notch_lists(r: _Reader, gen: dict, written: dict | None = None) -> None:
    """Each per-notch list has one value per notch (per gap for ``spacings``); a scalar is given or replaced.
    ``written``: the section as written (a list given empty is refused as a list of the wrong length is: it was
    taken as not given, so ``angles_deg: []`` cut every notch at ``angle_deg`` without a word)."""
    count = gen.get("count")
    written = written if isinstance(written, dict) else {}
    for key, (scalar, extra) in _NOTCH_LISTS.items():
        values = gen.get(key) or ()
        if count is not None:
            need = max(count + extra, 0)
            allowed = f"{need} values ({'one per gap between notches' if extra else 'one per notch'}, from the tip)"
            if values and len(values) != need:
                r.issue(f"notch.{key}", f"has {len(values)} values for notch.count = {count}", len(values), allowed,
                        f"give {need} values or set notch.count to match")
            elif need and isinstance(written.get(key), (list, tuple)) and not written[key]:
                r.issue(f"notch.{key}", f"is empty, for notch.count = {count}", [], allowed,
                        f"give {need} values, or delete the key" + (f" (notch.{scalar} then applies to every notch)"
                                                                   if scalar else ""))
        if (scalar and not values and gen.get(scalar) is None and not (scalar == "spacing" and count == 1)
                and not any(i.key == f"notch.{scalar}" for i in r.issues)):  # given but refused: said already
            r.issue(f"notch.{scalar}", "required key is missing", None, SCHEMA["notch"][scalar].allowed(),
                    f"add '{scalar}: <value>' or a per-notch list '{key}: [...]'")


def _check_unused_notch_keys(r: _Reader, written) -> None:
    """Refuse notch keys the pattern gives that its other keys leave unused (each was dropped without a word): a
    scalar beside the per-notch list that replaces it (``width: 0.5`` beside ``widths: [0.3, 0.4]``), and
    ``directions_deg`` under a layout that does not cycle through it."""
    if not isinstance(written, dict):
        return
    for key, scalar in (("widths", "width"), ("arcs", "arc"), ("spacings", "spacing"), ("angles_deg", "angle_deg")):
        if written.get(scalar) is not None and written.get(key):
            r.issue(f"notch.{scalar}", f"is given beside notch.{key}, which sets every notch's value: notch.{scalar} "
                    "would not be used", written[scalar], f"notch.{scalar} or notch.{key}", "delete one of the two")
    layout = written.get("layout", SCHEMA["notch"]["layout"].default)
    if written.get("directions_deg") and layout != "directions" and not written.get("angles_deg"):
        r.issue("notch.directions_deg", f"is given, but notch.layout is {layout!r}: the directions would not be used",
                written["directions_deg"], "directions_deg with layout: directions",
                "set layout: directions, or delete directions_deg")


def build_settings(raw: dict, file: str | None = None) -> tuple[Tube, Process, Tendon, Rules]:
    """The tube, process, tendon and rules sections of raw pattern data, validated.

    Used for inputs whose cuts come from elsewhere (a drawing). Raises
    :class:`~camtube.errors.PatternError` listing every problem.
    """
    r = _Reader(file, {})
    tube = _section(r, raw, "tube")
    tendon = _section(r, raw, "tendon")
    proc = _section(r, raw, "process")
    rl = _section(r, raw, "rules")
    check_name(r, raw.get("name"))
    if r.issues:
        raise PatternError(r.issues)
    return (Tube(tube["outer_radius"], tube["inner_radius"], tube["length"], tube["material"]), _process(proc),
            Tendon(tendon["radius"], tendon["length"], tendon["modulus_gpa"], tendon["material"],
                          tendon["friction"]),
            Rules(rl["min_backbone_arc"], rl["min_web"], rl["max_strain"], rl["max_stroke"]))


#: Characters a file name on Windows may not hold (besides '/' and '\\', refused as folders).
WINDOWS_RESERVED = '<>:"|?*'
#: Longest pattern name in bytes: its longest output file, NAME.toolpath.dxf, within a file name's 255 bytes.
MAX_NAME_BYTES = 200
#: Device names Windows reserves, with any extension (NUL.ngc is the null device there).
WINDOWS_DEVICES = frozenset({"CON", "PRN", "AUX", "NUL", *(f"COM{i}" for i in range(1, 10)),
                             *(f"LPT{i}" for i in range(1, 10))})


def check_name(r: _Reader, name) -> None:
    """``name:`` names the output files (NAME.ngc, NAME.job.json, ...): one plain file name, no folders."""
    if name is None:
        return
    if isinstance(name, (dict, list, tuple)):
        r.issue("name", "expected a text", name, "a plain file name (letters, digits, '-', '_', '.')",
                "write e.g. name: tube2")
    elif not isinstance(name, str):   # YAML reads name: 2024-01-01 as a date, name: 123 as a number
        r.issue("name", f"expected a text, got a {type(name).__name__}", name,
                "a plain file name (letters, digits, '-', '_', '.')", f"quote it: name: '{name}'")
    elif one_line(name) != name:
        r.issue("name", "holds a line break or another control character (it is written into the G-code's and the "
                "job file's headers)", name,
                "letters, digits, '-', '_', '.' on one line", "write the name on one line, e.g. name: tube2")
    elif any(c in str(name) for c in "/\\\0") or str(name).strip() in (".", ".."):
        r.issue("name", "names the output files (NAME.ngc, NAME.job.json, ...), so it must be a plain file name",
                name, "letters, digits, '-', '_', '.'; no '/' or '\\'", "drop the folder part, e.g. name: tube2 "
                "(choose the folder with -o)")
    elif not name.strip():
        r.issue("name", "is blank (the output files would be named '.ngc', '.job.json', ...)", name,
                "letters, digits, '-', '_', '.'", "write e.g. name: tube2")
    elif name.split(".")[0].strip().upper() in WINDOWS_DEVICES:
        r.issue("name", f"is {name.split('.')[0]!r}, a device name on Windows (NUL.ngc is the null device there, not "
                "a file)", name, "any name but CON, PRN, AUX, NUL, COM1-9, LPT1-9", f"write e.g. name: {name}-joint")
    elif len(str(name).encode("utf-8")) > MAX_NAME_BYTES:
        # (300 characters: "cannot write: File name too long" named the output folder, not the key)
        r.issue("name", f"is {len(str(name))} characters long: the output files are named after it (NAME.toolpath.dxf, "
                "...), and a file name holds at most 255 bytes", str(name)[:40] + "...",
                f"at most {MAX_NAME_BYTES} bytes", "shorten the name")
    elif any(c in str(name) for c in WINDOWS_RESERVED):
        # (written on Linux, a*b?.ngc cannot be copied to the controller's PC if that runs Windows, nor typed in a
        # shell without quotes)
        bad = "".join(dict.fromkeys(c for c in str(name) if c in WINDOWS_RESERVED))
        r.issue("name", f"holds {' '.join(repr(c) for c in bad)}, which a file name on Windows may not hold (the "
                "output files are named after it)", name,
                "letters, digits, '-', '_', '.', spaces; none of < > : \" | ? * / \\", "write e.g. name: tube2")


def build(raw: dict, file: str | None = None, lines: dict[str, int] | None = None, name: str | None = None) -> Loaded:
    """Validate raw YAML data and build a checked :class:`Pattern`.

    Raises :class:`~camtube.errors.PatternError` listing every problem.
    """
    lines = lines or {}
    r = _Reader(file, lines)
    r.check_keys(raw, SCHEMA, "")
    tube = _section(r, raw, "tube")
    tendon = _section(r, raw, "tendon")
    proc = _section(r, raw, "process")
    rl = _section(r, raw, "rules")
    has_notch = raw.get("notch") is not None
    gen = _section(r, raw, "notch") if has_notch else None
    holes = r.convert(raw.get("holes") or [], SCHEMA["holes"], "holes")
    extra = r.convert(raw.get("cuts") or [], SCHEMA["cuts"], "cuts")
    if gen:
        _check_notch_lists(r, gen, raw.get("notch"))
        _check_unused_notch_keys(r, raw.get("notch"))
    if gen and gen.get("layout") == "directions" and not gen.get("directions_deg") and not gen.get("angles_deg"):
        r.issue("notch.directions_deg", "layout 'directions' needs a list of angles", None,
                "a non-empty list of angles in deg", "add e.g. directions_deg: [0, 90, 180, 270]")
    check_name(r, raw.get("name"))
    if not has_notch and not extra:
        r.issue("notch", "the pattern has no notches", None, "a 'notch:' generator or a 'cuts:' list",
                "add a 'notch:' section")
    if r.issues:
        raise PatternError(r.issues)

    cuts, origins = [], []
    if gen:
        row = notch_row(gen["count"], gen["width"], gen["spacing"], gen["arc"], gen["first_offset"],
                        gen["angle_deg"], gen["layout"], gen["directions_deg"], gen["widths"], gen["arcs"],
                        gen["spacings"], gen["angles_deg"])
        cuts += row
        origins += ["notch"] * len(row)
    for i, c in enumerate(extra):
        cuts.append(notch(c["x"], c["width"], c["arc"], c["angle_deg"]))
        origins.append(f"cuts[{i}]")
    for i, h in enumerate(holes):
        cuts.append(hole(h["x"], h["size"], h["angle_deg"]))
        origins.append(f"holes[{i}]")
    order = sorted(range(len(cuts)), key=lambda k: (cuts[k].x_mm, cuts[k].angle_deg, cuts[k].kind))
    cuts = sort_cuts(cuts)
    origins = [origins[k] for k in order]

    process = _process(proc)
    pattern = Pattern(
        name=raw.get("name") or name or "pattern",
        tube=Tube(tube["outer_radius"], tube["inner_radius"], tube["length"], tube["material"]),
        cuts=cuts,
        process=process,
        tendon=Tendon(tendon["radius"], tendon["length"], tendon["modulus_gpa"], tendon["material"],
                          tendon["friction"]),
        rules=Rules(rl["min_backbone_arc"], rl["min_web"], rl["max_strain"], rl["max_stroke"]),
        source=file,
    )
    errors, warnings = design_rules.check(pattern, origins, file, lines)
    if process.kerf_mm and process.kerf_mm >= min(c.width_mm for c in cuts) / 2:
        errors.append(Issue("process.kerf", "kerf is as wide as half the narrowest cut", process.kerf_mm,
                            f"< {min(c.width_mm for c in cuts) / 2:g} mm", "check the kerf width", file,
                            lines.get("process.kerf")))
    if errors:
        raise PatternError(errors)
    return Loaded(pattern, tuple(warnings), tuple(origins))


def load(path: str | os.PathLike, overrides: Iterable[str] = ()) -> Loaded:
    """Load, override, validate and build a pattern file (or a shipped preset by name, ``tube1``).

    ``process:`` may be a mapping or the name of a process YAML file next to
    the pattern (its keys are the ``process`` keys); the pattern's own
    ``process_overrides``-style changes go through ``--set process.KEY=...``.
    """
    path = resolve_preset(path)
    raw, lines, file = read_yaml(path)
    overrides = list(overrides)
    # --set process=NAME.yaml names a process file as 'process:' may: read in as the file's own would be (it was
    # applied after the file's, and refused as 'expected a mapping')
    whole = [o for o in overrides if parse_override(o)[0] == "process"]
    if whole:
        raw = apply_overrides(raw, whole, file)
        lines = {k: v for k, v in lines.items() if k != "process" and not k.startswith("process.")}
    raw, source = _process_file(raw, Path(path).parent, file, lines)
    raw = apply_overrides(raw, [o for o in overrides if o not in whole], file)
    set_keys = {parse_override(o)[0] for o in overrides}
    lines = {k: v for k, v in lines.items() if k not in set_keys}  # a --set value has no line
    return _build_naming_process_file(raw, file, lines, Path(path).stem, source, set_keys)


def _process_file(raw: dict, folder: Path, file: str, lines: dict) -> tuple[dict, tuple | None]:
    """``raw`` with the process file that ``process: NAME`` names read in, and ``(its path, its lines as
    process.KEY -> line)`` (None when ``process:`` is not a file name). A pattern named there is refused."""
    proc = raw.get("process")
    if not isinstance(proc, str):
        return raw, None
    where = find_process_file(proc, folder, file, lines.get("process"))
    praw, plines, pfile = read_yaml(where, "process")
    if set(praw) & (set(SCHEMA) - {"process", "name", "rules"}):   # tube, notch, tendon, ...: a pattern
        raise PatternError([Issue("process", f"names {pfile}, a pattern file, not a process file", proc,
                                  "a YAML file of process keys (power_w, frequency_khz, ...), with or without a "
                                  "top-level 'process:'", "name the process file the pattern uses, or write the "
                                  "process keys under 'process:'", file, lines.get("process"))])
    _refuse_chained(praw, plines, pfile)
    inner = "process" in praw
    raw = dict(raw)
    raw["process"] = praw.get("process", praw)
    plines = {(k if inner else f"process.{k}"): v for k, v in plines.items()
              if not inner or k == "process" or k.startswith("process.")}
    return raw, (pfile, plines)


def _refuse_chained(praw: dict, plines: dict, pfile: str) -> None:
    """Refuse a process file whose ``process:`` names another process file (it was taken as the pattern's own
    ``process:`` and blamed on the pattern's line)."""
    if isinstance(praw.get("process"), str):
        raise PatternError([Issue("process", f"names another process file ({praw['process']!r}): a process file holds "
                                  "the process keys themselves", praw["process"], "keys " + ", ".join(SCHEMA["process"]),
                                  "name that file from the pattern, or copy its keys here", pfile,
                                  plines.get("process", 1))])


def read_process_file(path: str | os.PathLike) -> dict:
    """The process keys of a process file (with or without a top-level ``process:``), read as a pattern's
    ``process:`` reads them; a :class:`PatternError` naming the file when it is not one."""
    praw, plines, pfile = read_yaml(path, "process")
    _refuse_chained(praw, plines, pfile)
    return praw.get("process", praw)


def _build_naming_process_file(raw: dict, file: str, lines: dict, name: str, source: tuple | None,
                               set_keys: Iterable[str] = ()) -> Loaded:
    """:func:`build`, a problem with a value the process file gave named in that file, at its line (it was named in
    the pattern, without a line)."""
    try:
        return build(raw, file, lines, name=name)
    except PatternError as exc:
        if source is None:
            raise
        pfile, plines = source
        # a --set KEY (process.repeat_rule.0.max_depth) names a value the pattern's command line gave, not the file
        given = [re.sub(r"\.(\d+)(?=\.|$)", r"[\1]", k) for k in set_keys]

        def from_file(key: str) -> bool:
            return key.startswith("process.") and not any(key == g or key.startswith((g + ".", g + "["))
                                                          for g in given)

        issues = [replace(i, file=pfile, line=plines.get(i.key, plines.get(i.key.split("[")[0])))
                  if i.file == file and from_file(i.key) else i for i in exc.issues]
        raise PatternError(issues) from None


def load_text(text: str, path: str | os.PathLike) -> Loaded:
    """Validate and build a pattern from YAML ``text`` as if it were the file ``path`` (which need not exist).

    A ``process:`` file name is looked up beside ``path``, then among the shipped presets. Used to
    check a generated pattern before it is written.
    """
    file = str(path)
    try:
        raw = parse_yaml(text)
    except yaml.YAMLError as exc:
        raise PatternError([Issue("yaml", f"not valid YAML: {exc}", None, "YAML mapping", "", file)]) from None
    if not isinstance(raw, dict):
        raise PatternError([Issue("<top>", "a pattern must be a mapping of sections", None, "", "", file, 1)])
    lines = line_map(text)
    raw, source = _process_file(raw, Path(path).parent, file, lines)
    return _build_naming_process_file(raw, file, lines, Path(path).stem, source)


def find_process_file(name: str, folder: Path, file: str, line: int | None) -> Path:
    """The process YAML that ``process: NAME`` names: in ``folder`` (the pattern's or the drawing's), else a
    shipped preset; a :class:`PatternError` naming ``file`` (and ``line``) and where it looked when neither has it."""
    folders = (folder, PRESETS_DIR)
    for folder in folders:
        for cand in (folder / name, folder / f"{name}.yaml"):
            if cand.is_file():
                return cand
            if cand.exists() and (cand.is_dir() or folder is folders[0]):
                # (a folder or a device was "a process file that is not there")
                what = "a folder" if cand.is_dir() else "not a regular file (a device or a pipe)"
                raise PatternError([Issue("process", f"names {cand}, which is {what}", name,
                                          "a process YAML file", "name the process YAML file", file, line)])
    raise PatternError([Issue("process", "names a process file that is not there", name,
                              f"a process YAML in {folder} or a shipped one: "
                              + ", ".join(_shipped()[1]), "put the file beside the pattern, name a "
                              "shipped process, or write the process keys under 'process:'", file, line)])


def _shipped() -> tuple[tuple[str, ...], tuple[str, ...]]:
    """``(pattern presets, process files)`` shipped in :data:`PRESETS_DIR`, by name."""
    patterns, processes = [], []
    for p in sorted(PRESETS_DIR.glob("*.yaml")):
        (patterns if "\ntube:" in "\n" + p.read_text(encoding="utf-8") else processes).append(p.stem)
    return tuple(patterns), tuple(processes)


def preset_names() -> tuple[str, ...]:
    """Names of the shipped pattern presets (``tube1``, ...), without the process files."""
    return _shipped()[0]


def resolve_preset(path: str | os.PathLike) -> Path:
    """``path`` itself when it is a file, else the shipped preset of that name (``tube1``), else ``path``."""
    p = Path(path)
    if p.exists() or p.suffix.lower() in (".dxf",) or os.sep in str(path):
        return p
    name = p.stem if p.suffix.lower() in (".yaml", ".yml") else p.name
    cand = PRESETS_DIR / f"{name}.yaml"
    return cand if cand.is_file() and name in preset_names() else p


def load_pattern(path: str | os.PathLike, overrides: Iterable[str] = ()) -> Pattern:
    """Shortcut: the validated :class:`Pattern` of a YAML file."""
    return load(path, overrides).pattern
