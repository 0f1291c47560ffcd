"""Explicit effect registries: built from lists, passed to the calls that need them.

A :class:`Registry` is an immutable name -> :class:`~camtube.model.core.model.Effect`
table. :func:`builtin_registry` is the table of the built-in effects
(:mod:`camtube.model.effects`); a command that loads a user's file builds its
own table with :meth:`Registry.with_effects` and passes it on. Loading a file
(:func:`load_effect_file`) returns its effects and changes nothing else, so a
later diagnosis in the same process sees only the effects it is given.

A user's effect file keeps working as documented: its module-level
:class:`Effect` objects are found, and a call of :func:`register` inside the
file adds that effect too (it is collected for the file being loaded).
"""
from __future__ import annotations

import contextvars
import difflib
import functools
import importlib.util
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Iterable, Iterator, Mapping

from camtube.errors import CamtubeError
from camtube.model.core.model import Effect, user_raised


class EffectError(CamtubeError, ValueError):
    """An effect name is unknown, or an effect file cannot be loaded."""


@dataclass(frozen=True)
class Registry(Mapping):
    """An immutable table of effects by name, in registration order."""

    effects: tuple = ()

    def __post_init__(self):
        seen: dict[str, Effect] = {}
        for e in self.effects:
            if e.name in seen and seen[e.name] is not e:
                raise EffectError(f"two different effects are named {e.name!r}"
                                  + (f" ({seen[e.name].source or 'built-in'} and {e.source or 'built-in'})")
                                  + "; fix: rename the effect of your file (Effect(name=...))")
            seen[e.name] = e
        object.__setattr__(self, "effects", tuple(seen.values()))

    def __getitem__(self, name: str) -> Effect:
        for e in self.effects:
            if e.name == name:
                return e
        raise KeyError(name)

    def __iter__(self) -> Iterator[str]:
        return (e.name for e in self.effects)

    def __len__(self) -> int:
        return len(self.effects)

    def __hash__(self) -> int:
        return hash(tuple(id(e) for e in self.effects))

    def with_effects(self, effects: Iterable[Effect]) -> "Registry":
        """A new registry with ``effects`` added (same name and object: kept once; another object: an error)."""
        return Registry(self.effects + tuple(effects))

    def get_effect(self, name: str) -> Effect:
        """The effect called ``name``; an unknown name raises :class:`EffectError` with a hint."""
        if name in self:
            return self[name]
        hint = difflib.get_close_matches(name, list(self), n=1)
        raise EffectError(f"unknown effect {name!r}" + (f"; did you mean {hint[0]!r}?" if hint else "")
                          + f" (known: {', '.join(sorted(self))}); fix: use a known name, or load the file that "
                          "defines it with --effect-file")


@functools.lru_cache(maxsize=1)
def builtin_registry() -> Registry:
    """The built-in effects (see :mod:`camtube.model.effects`), in their documented order."""
    from camtube.model.effects import BUILTIN_EFFECTS

    return Registry(tuple(BUILTIN_EFFECTS))


_COLLECTING: contextvars.ContextVar = contextvars.ContextVar("camtube_effect_file", default=None)


def register(effect: Effect, replace_existing: bool = False) -> Effect:
    """Mark ``effect`` as one of the effects of the file being loaded; returns it unchanged.

    Kept for effect files written against the earlier API. Outside
    :func:`load_effect_file` it only returns the effect: pass effects to
    :meth:`JointModel.with_effects` or :meth:`Registry.with_effects` instead.
    """
    if not isinstance(effect, Effect):
        raise EffectError(f"register() takes an Effect, not {type(effect).__name__}")
    bucket = _COLLECTING.get()
    if bucket is not None:
        bucket.append(effect)
    return effect


def load_effect_file(path: str | Path) -> tuple[Effect, ...]:
    """Import a user's ``.py`` file and return its effects (module-level :class:`Effect` objects and
    those passed to :func:`register`), each with ``source`` set to the file.

    Nothing global changes: add the effects to a registry to use them by name.

    Raises
    ------
    EffectError
        When the file cannot be read or raises while it is imported (the message names the file and line).
    """
    path = Path(path)
    if not path.is_file():
        raise EffectError(f"{path}: no such effect file; fix: check the path of the .py file" if not path.exists()
                          else f"{path}: not a file; fix: give the path of the effect's .py file")
    spec = importlib.util.spec_from_file_location(f"camtube_user_effect_{path.stem}", path)
    if spec is None or spec.loader is None:
        raise EffectError(f"{path}: cannot import the effect file (is it a .py file?); fix: give a Python "
                          "file named NAME.py (see docs/diagnose.md)")
    mod = importlib.util.module_from_spec(spec)
    bucket: list[Effect] = []
    token = _COLLECTING.set(bucket)
    try:
        spec.loader.exec_module(mod)
    except SyntaxError as exc:
        if exc.lineno is None:  # not Python source at all (binary, null bytes)
            raise EffectError(f"{path}: cannot load the effect file: {exc.msg}; fix: give a Python source file "
                              "(UTF-8 text; see docs/diagnose.md)") from None
        raise EffectError(f"{path}:{exc.lineno}: cannot load the effect file: {exc.msg}; fix: correct the Python "
                          "at that line") from None
    except KeyboardInterrupt:  # Ctrl-C (or SIGTERM) while importing: an interrupt, not a broken file
        raise
    except BaseException as exc:  # noqa: BLE001 - a user's file may raise anything; report it with its line
        import traceback

        here = path.resolve()
        tb = [f for f in traceback.extract_tb(exc.__traceback__) if Path(f.filename).resolve() == here]
        if isinstance(exc, ValueError) and not tb:  # the source is not text (null bytes): no line of it ran
            raise EffectError(f"{path}: cannot load the effect file: {exc}; fix: give a Python source file "
                              "(UTF-8 text; see docs/diagnose.md)") from None
        line = f":{tb[-1].lineno}" if tb else ""
        what = "it called sys.exit()" if isinstance(exc, SystemExit) else user_raised(exc)
        fix = "" if "; fix:" in str(exc) else "; fix: correct the file at that line (importing it must only define effects)"
        raise EffectError(f"{path}{line}: cannot load the effect file: {what}{fix}") from None
    finally:
        _COLLECTING.reset(token)
    found = list(bucket) + [v for v in vars(mod).values() if isinstance(v, Effect)]
    out: dict[str, Effect] = {}
    for e in found:
        if e.name in out and out[e.name] is not e and out[e.name] != e:
            raise EffectError(f"{path}: defines two different effects named {e.name!r}; fix: give each Effect "
                              "a name of its own (or delete the older one)")
        if e.name not in out:
            out[e.name] = e if e.source else replace(e, source=str(path), pure=False)  # a file's copy: not vouched for
    return tuple(out.values())


def registry_with_files(paths: Iterable[str | Path], base: Registry | None = None) -> tuple[Registry, tuple]:
    """``base`` (default the built-ins) plus the effects of each file; also returns the files' effects."""
    reg = base if base is not None else builtin_registry()
    added: list[Effect] = []
    for p in paths:
        effs = load_effect_file(p)
        if not effs:
            raise EffectError(f"{p}: defines no Effect (a module-level Effect(...) object is needed); fix: add one, "
                              "e.g. start from `camtube model effect new NAME`")
        added += list(effs)
    return reg.with_effects(added), tuple(added)


def registry() -> Registry:
    """The built-in effects (compatibility name of :func:`builtin_registry`)."""
    return builtin_registry()


def get_effect(name: str, registry: Registry | None = None) -> Effect:
    """The effect ``name`` of ``registry`` (default: the built-ins)."""
    return (registry if registry is not None else builtin_registry()).get_effect(name)
