"""YAML input helpers shared by every loader (patterns, processes, machine profiles).

Line numbers come from PyYAML's node tree, so an error can name the line of the
key the user wrote; "did you mean" hints come from :mod:`difflib`.
"""
from __future__ import annotations

import difflib
from typing import Iterable

import yaml


def line_map(text: str) -> dict[str, int]:
    """Dotted key -> 1-based line of its key in ``text`` (list entries as ``key[i]``); {} if unparsable."""
    out: dict[str, int] = {}
    try:
        root = yaml.compose(text, Loader=yaml.SafeLoader)
    except yaml.YAMLError:
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
