"""The model's kept stage signals (camtube.model.core.model._Checkpoints) give the numbers a fresh evaluation
gives, to the bit: for a step in any parameter, back and forth, for equal models built anew, and never hand out
an array they keep."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from camtube.model.core.predict import model_for_pattern, pattern_values
from camtube.model.core.registry import builtin_registry
from tests.model.toe_bench import fresh, toe_bench

CHAIN = ["force_zero", "creep_load", "viscoelastic", "toe_shape", "rest_angle", "relaxation", "hardstop",
         "angle_bias"]


@pytest.fixture(scope="module")
def bench():
    return toe_bench(seed=3)


def _models(p, names=CHAIN):
    reg = builtin_registry()
    kept = model_for_pattern(p).with_effects(names, reg)
    # the same effects, not pure: evaluated afresh every time
    plain = replace(kept, effects=tuple(replace(e, pure=False) for e in kept.effects))
    return kept, plain


def _start(p, model, data):
    v = model.initial_values(data, base=pattern_values(p))
    v.update({"force_zero.zero_N": 0.01, "creep_load.creep_mm": 0.05, "creep_load.exponent": 0.5,
              "viscoelastic.ratio": 0.05, "viscoelastic.tau_s": 3.0, "toe_shape.offset_mm": 0.1,
              "toe_shape.shape": 2.0, "rest_angle.rest_deg": 0.3, "relaxation.fraction": 0.1,
              "relaxation.tau_s": 1.5, "hardstop.stop_deg": 200.0, "angle_bias.bias_deg": 0.2})
    return v


def test_every_step_gives_the_fresh_numbers(bench):
    p, data = bench
    kept, plain = _models(p)
    assert kept._chain[1] and not plain._chain[1]
    data = fresh(data)
    base = _start(p, kept, data)
    evals = [base]
    for nm in list(base):          # a finite-difference Jacobian: each parameter stepped alone from one point
        evals.append(dict(base, **{nm: base[nm] * (1 + 1e-7) + 1e-9}))
    evals.append(base)                                    # back to the point itself
    evals.append(dict(base, arm_scale=1.01))              # the arm only (no effect parameter moves)
    evals.append(dict(base, **{"relaxation.fraction": 0.2, "angle_bias.bias_deg": -0.1}))
    evals.append(dict(base, **{"rest_angle.rest_deg": -0.0}))
    evals.append(dict(base, **{"rest_angle.rest_deg": 0.0}))
    for v in evals:
        got = kept.predict(data, v)
        want = plain.predict(fresh(data), v)
        assert np.array_equal(got, want), v
    assert data.cache.get("model.checkpoints")


def test_per_sample_values_and_models_built_anew(bench):
    p, data = bench
    kept, plain = _models(p)
    data = fresh(data)
    base = _start(p, kept, data)
    base.update({f"relaxation.fraction@{s}": 0.1 + 0.05 * i for i, s in enumerate(data.samples)})
    for v in (base, dict(base, **{f"relaxation.fraction@{data.samples[0]}": 0.3}), base):
        again = model_for_pattern(p).with_effects(CHAIN, builtin_registry())   # an equal model, a new object
        assert np.array_equal(again.predict(data, v), plain.predict(fresh(data), v))
        assert np.array_equal(kept.predict(data, v), plain.predict(fresh(data), v))


def test_the_output_is_never_a_kept_array(bench):
    p, data = bench
    for names in (CHAIN, ["creep_load"], ["angle_bias"]):
        kept, plain = _models(p, names)
        data = fresh(data)
        v = _start(p, kept, data)
        first = kept.predict(data, v)
        first[:] = np.nan                                 # a caller may write into what it got
        assert np.array_equal(kept.predict(data, v), plain.predict(fresh(data), v))


def test_the_builtins_are_pure():
    from camtube.model.effects.builtin import BUILTIN_EFFECTS

    assert all(e.pure for e in BUILTIN_EFFECTS)


def test_the_kept_force_lag_gives_the_fresh_numbers(bench):
    """viscoelastic's lag of the force, kept per Dataset and force: the same numbers as a fresh evaluation for
    every step, a new force (force_zero) or time constant computed anew."""
    from camtube.model.effects import builtin

    p, data = bench
    kept, plain = _models(p, ["force_zero", "viscoelastic", "angle_bias"])
    # ``plain`` keeps no checkpoints: its viscoelastic stage runs every time, on the kept lag of one Dataset
    data = fresh(data)
    base = _start(p, kept, data)
    steps = [base] + [dict(base, **{nm: base[nm] * (1 + 1e-7) + 1e-9}) for nm in base] + [base]
    for v in steps:
        want = builtin.first_order_lag(data, np.asarray(data.force_N, float) - v["force_zero.zero_N"],
                                       v["viscoelastic.tau_s"])
        assert np.array_equal(plain.predict(data, v), plain.predict(fresh(data), v))
        assert np.array_equal(kept.predict(data, v), plain.predict(fresh(data), v))
        ctx = kept.context(data, v)
        ctx.force_N = np.asarray(data.force_N, float) - v["force_zero.zero_N"]
        got = builtin.force_lag(ctx, v["viscoelastic.tau_s"])
        assert np.array_equal(got, want) and not got.flags.writeable
    assert 1 <= len(data.cache.get("builtin.force_lags")[1]) <= builtin.FORCE_LAGS_KEPT
