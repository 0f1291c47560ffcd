"""toe_shape's kept row elongations (camtube.model.effects.builtin._kept_toe_rows) give the numbers a fresh
evaluation gives, for the same law and force only."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from camtube.model.core.predict import model_for_pattern, pattern_values
from camtube.model.core.registry import builtin_registry
from camtube.model.effects import builtin
from tests.model.toe_bench import fresh, toe_bench


@pytest.fixture(scope="module")
def bench():
    return toe_bench(seed=2)


def _values(p, model, data, **kw):
    v = model.initial_values(data, base=pattern_values(p))
    v.update(kw)
    return v


def test_a_law_evaluated_again_gives_the_fresh_numbers(bench):
    p, data = bench
    model = model_for_pattern(p).with_effects(["toe_shape", "rest_angle"], builtin_registry())
    data = fresh(data)
    a = _values(p, model, data, **{"toe_shape.offset_mm": 0.15, "toe_shape.shape": 2.0})
    b = dict(a, **{"toe_shape.shape": 2.0 + 1e-8})
    c = dict(a, **{"rest_angle.rest_deg": 0.3})            # another effect's step: the law is reused
    d = dict(a, **{"E_t": a["E_t"] * (1 + 1e-8)})           # the compliance changes: not reused
    first = {k: model.predict(data, v) for k, v in (("a", a), ("b", b), ("c", c), ("d", d))}
    kept = data.cache.get("builtin.toe_rows")[1]
    assert len(kept) == 3
    for k, v in (("a", a), ("b", b), ("c", c), ("d", d)):
        assert np.array_equal(model.predict(data, v), first[k])
        assert np.array_equal(model.predict(fresh(data), v), first[k])
    assert not np.array_equal(first["a"], first["b"]) and not np.array_equal(first["a"], first["d"])


def test_a_new_force_starts_afresh(bench):
    """With a force-stage effect the law's input changes between evaluations: nothing is reused across it."""
    p, data = bench
    model = model_for_pattern(p).with_effects(["force_zero", "toe_shape"], builtin_registry())
    data = fresh(data)
    for zero in (0.0, 0.02, 0.0):
        v = _values(p, model, data, **{"force_zero.zero_N": zero, "toe_shape.offset_mm": 0.15})
        assert np.array_equal(model.predict(data, v), model.predict(fresh(data), v))


def test_the_least_recently_used_law_is_dropped(bench, monkeypatch):
    p, data = bench
    monkeypatch.setattr(builtin, "TOE_ROWS_KEPT", 3)
    model = model_for_pattern(p).with_effects(["toe_shape"], builtin_registry())
    # not pure: the model's own kept signals (test_checkpoints.py) would answer the repeated law before it
    model = replace(model, effects=tuple(replace(e, pure=False) for e in model.effects))
    data = fresh(data)
    shapes = [1.5, 2.0, 2.5, 1.5, 3.0]      # 1.5 used again before 3.0 comes: 2.0 is dropped
    for k in shapes:
        model.predict(data, _values(p, model, data, **{"toe_shape.shape": k}))
    kept = data.cache.get("builtin.toe_rows")[1]
    assert [key[3] for key in kept] == [2.5, 1.5, 3.0]
    assert all(not toe.flags.writeable for toe in kept.values())


def test_the_toe_table_kept_longest_is_the_least_recently_used(monkeypatch):
    monkeypatch.setattr(builtin, "_TOE_TABLES", {})
    monkeypatch.setattr(builtin, "TOE_TABLES_KEPT", 2)
    first = builtin._toe_table(1.5, 3.0)
    builtin._toe_table(2.0, 3.0)
    assert builtin._toe_table(1.5, 3.0) is first          # kept, and now the most recent
    builtin._toe_table(2.5, 3.0)                            # drops 2.0, not 1.5
    assert [k[0] for k in builtin._TOE_TABLES] == [1.5, 2.5]
    assert np.array_equal(first[1], builtin.weibull_toe_force(first[0], 1.5))
