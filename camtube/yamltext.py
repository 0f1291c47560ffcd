"""YAML input helpers shared by every loader (patterns, processes, machine profiles).

Line numbers come from PyYAML's node tree, so an error can name the line of the
key the user wrote; "did you mean" hints come from :mod:`difflib`.
"""
from __future__ import annotations

import difflib
import os
import re
from pathlib import Path
from typing import Callable, Iterable

import yaml

from camtube.errors import Issue, PatternError
from camtube.inputfile import read_input_bytes


class StrictLoader(yaml.SafeLoader):
    """PyYAML's safe loader, stricter where a silent reading would be wrong.

    - A key given twice in one mapping is an error (PyYAML keeps the last one silently).
    - Every number YAML 1.2 accepts is a number: ``5e-1`` and ``1E3`` as well as ``5.0e-1``
      (PyYAML follows YAML 1.1 there and reads ``5e-1`` as a string).
    - Aliases may repeat at most :data:`MAX_ALIAS_VALUES` values in all, and never the value they are inside
      (:class:`AliasError`): a "billion laughs" document of nested anchors, each aliased ten times, is a few
      lines that expand to billions of values, which every later walk over the data would follow.
    """

    def __init__(self, stream):
        super().__init__(stream)
        self._open_anchors: list[str] = []        # anchors of the collections being composed (outermost first)
        self._values: dict[int, int] = {}         # id(node) -> values it holds, aliases expanded
        self._repeated = 0                        # values the aliases read so far repeat

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            node = self.anchors.get(event.anchor)
            if node is not None:
                if event.anchor in self._open_anchors:
                    raise AliasError(f"the alias *{event.anchor} stands inside the value of its own anchor "
                                     f"&{event.anchor} (a value holding itself)", event.start_mark, recursive=True)
                self._repeated += self._count(node)
                if self._repeated > MAX_ALIAS_VALUES:
                    raise AliasError(f"aliases repeat more than {MAX_ALIAS_VALUES} values (*{event.anchor} here "
                                     "brings them over; anchors aliased within anchors multiply)", event.start_mark)
            return super().compose_node(parent, index)
        if getattr(event, "anchor", None) is None or isinstance(event, yaml.ScalarEvent):
            return super().compose_node(parent, index)
        self._open_anchors.append(event.anchor)
        try:
            return super().compose_node(parent, index)
        finally:
            self._open_anchors.pop()

    def _count(self, root) -> int:
        """Values in ``root`` with its aliases expanded (memoised; no recursion, so no depth limit). Capped just
        above :data:`MAX_ALIAS_VALUES`, so a count stays a small number however far the aliases multiply."""
        sizes = self._values
        stack = [(root, False)]
        while stack:
            node, children_done = stack.pop()
            if id(node) in sizes:
                continue
            kids = ([n for kv in node.value for n in kv] if isinstance(node, yaml.MappingNode)
                    else node.value if isinstance(node, yaml.SequenceNode) else [])
            if children_done:
                sizes[id(node)] = min(1 + sum(sizes[id(k)] for k in kids), MAX_ALIAS_VALUES + 1)
            else:
                stack.append((node, True))
                stack.extend((k, False) for k in kids if id(k) not in sizes)
        return sizes[id(root)]

    def construct_mapping(self, node, deep=False):
        if isinstance(node, yaml.MappingNode):
            seen: dict = {}
            for key_node, _ in node.value:
                if not isinstance(key_node, yaml.ScalarNode) or key_node.tag == "tag:yaml.org,2002:merge":
                    continue
                key = key_node.value
                if key in seen:
                    raise yaml.constructor.ConstructorError(
                        None, None, f"key '{key}' is given twice (first at line {seen[key] + 1})",
                        key_node.start_mark)
                seen[key] = key_node.start_mark.line
        return super().construct_mapping(node, deep=deep)

    def construct_yaml_int(self, node):
        try:
            return super().construct_yaml_int(node)
        except ValueError:  # more digits than Python converts (sys.get_int_max_str_digits, 4300)
            digits = sum(c.isdigit() for c in str(node.value))
            raise NumberTooLongError(None, None, f"a whole number of {digits} digits is too long to read",
                                     node.start_mark, digits=digits) from None


class NumberTooLongError(yaml.constructor.ConstructorError):
    """An integer with more digits than Python converts from text (thousands)."""

    def __init__(self, *args, digits: int = 0):
        super().__init__(*args)
        self.digits = digits


StrictLoader.add_constructor("tag:yaml.org,2002:int", StrictLoader.construct_yaml_int)
StrictLoader.yaml_implicit_resolvers = {k: list(v) for k, v in yaml.SafeLoader.yaml_implicit_resolvers.items()}
StrictLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9][0-9_]*)[eE][-+]?[0-9]+$"),
    list("-+.0123456789"))


#: Most values the aliases of one YAML document may repeat in all (a pattern has hundreds of values; a
#: "billion laughs" document repeats billions).
MAX_ALIAS_VALUES = 100_000


class AliasError(yaml.YAMLError):
    """An alias that repeats too much in all (a "billion laughs" document) or stands inside its own anchor."""

    def __init__(self, problem: str, mark, recursive: bool = False):
        super().__init__(problem)
        self.problem = problem
        self.problem_mark = mark
        self.recursive = recursive

    def __str__(self) -> str:
        return self.problem


class TooDeepError(yaml.YAMLError):
    """YAML nested deeper than the parser can follow (PyYAML recurses once per level)."""

    problem = "nested too deeply (thousands of levels of '[', '{' or indentation)"
    problem_mark = None

    def __str__(self) -> str:
        return self.problem


def parse_yaml(text: str):
    """``text`` parsed with :class:`StrictLoader` (raises ``yaml.YAMLError``, also for nesting too deep to parse)."""
    try:
        return yaml.load(text, Loader=StrictLoader)  # noqa: S506 (a SafeLoader subclass)
    except RecursionError:
        raise TooDeepError() from None


def read_yaml_file(path: str | os.PathLike, what: str, fix: str | Callable[[], str]) -> tuple[object, str]:
    """Parse a YAML file; ``(data, text)``. Every failure is a one-line :class:`PatternError`.

    Parameters
    ----------
    path : path
        The file.
    what : str
        What the file should be, in words (``pattern``, ``machine profile``), for the message.
    fix : str or callable returning str
        What to do when the file cannot be read at all (a callable is asked only then).
    """
    file = str(path)
    try:
        data = read_input_bytes(path)
    except OSError as exc:
        raise PatternError([Issue("file", f"cannot read {what}: {exc.strerror}", file, "a readable YAML file",
                                  fix() if callable(fix) else fix)]) from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data[:exc.start].count(b"\n") + 1
        raise PatternError([Issue("file", f"not a text file: byte 0x{data[exc.start]:02x} is not UTF-8",
                                  None, f"a UTF-8 {what} YAML file",
                                  "give the YAML file (save it as UTF-8 text)", file, line)]) from None
    if "\x00" in text:
        raise PatternError([Issue("file", "not a text file: it holds NUL bytes", None, f"a UTF-8 {what} YAML file",
                                  "give the YAML file (save it as UTF-8 text)", file,
                                  text[:text.index("\x00")].count("\n") + 1)])
    try:
        raw = parse_yaml(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        fix_ = ("keep one of the two (a later key would silently replace the earlier one)" if "given twice" in problem
                else "remove the runaway brackets or indentation (the file's keys nest a few levels)"
                if isinstance(exc, TooDeepError) else "write a number in the key's allowed range (camtube schema)"
                if isinstance(exc, NumberTooLongError) else "point the alias at an anchor defined before it, "
                "outside its own value" if isinstance(exc, AliasError) and exc.recursive
                else "write the values out, or alias fewer (an alias of an anchor that holds aliases repeats all of "
                "them)" if isinstance(exc, AliasError) else "fix the syntax at the line shown")
        allowed = (f"at most {MAX_ALIAS_VALUES} values repeated by aliases, none inside its own anchor"
                   if isinstance(exc, AliasError) else "YAML mapping")
        what = "refused YAML" if isinstance(exc, AliasError) else "not valid YAML"
        raise PatternError([Issue("yaml", f"{what}: {problem}", None, allowed, fix_, file,
                                  mark.line + 1 if mark else None)]) from None
    return raw, text


def line_map(text: str) -> dict[str, int]:
    """Dotted key -> 1-based line of its key in ``text`` (list entries as ``key[i]``); {} if unparsable."""
    out: dict[str, int] = {}
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except (yaml.YAMLError, RecursionError):
        return out

    def walk(node, prefix):
        if isinstance(node, yaml.MappingNode):
            for k, v in node.value:
                key = f"{prefix}.{k.value}" if prefix else str(k.value)
                out[key] = k.start_mark.line + 1
                walk(v, key)
        elif isinstance(node, yaml.SequenceNode):
            for i, v in enumerate(node.value):
                key = f"{prefix}[{i}]"
                out[key] = v.start_mark.line + 1
                walk(v, key)

    if root is not None:
        walk(root, "")
    return out


def closest(word: str, options: Iterable[str]) -> str | None:
    """The option closest to ``word`` (difflib ratio >= 0.5), or None."""
    m = difflib.get_close_matches(str(word), list(options), n=1, cutoff=0.5)
    return m[0] if m else None
