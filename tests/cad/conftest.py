from __future__ import annotations

import math
from functools import lru_cache

import pytest

from camtube.design.loader import load, load_pattern
from tests.conftest import PATTERNS, PRESETS


@lru_cache(maxsize=None)
def preset(name: str, *overrides: str):
    path = PATTERNS / f"{name}.yaml"
    return load(path, list(overrides)).pattern if overrides else load_pattern(path)


@lru_cache(maxsize=None)
def job_of(name: str, *overrides: str):
    from camtube.plan import plan_job

    return plan_job(preset(name, *overrides))


@lru_cache(maxsize=None)
def mesh_of(name: str, *overrides: str):
    from camtube.cad.mesh import design_mesh

    return design_mesh(preset(name, *overrides))


def analytic_volume(pattern) -> float:
    """Independent formula: pi (ro^2 - ri^2) L - sum (s / ro) / 2 (ro^2 - ri^2) h."""
    t = pattern.tube
    ring = t.outer_radius_mm ** 2 - t.inner_radius_mm ** 2
    return math.pi * ring * t.length_mm - sum(c.arc_mm / t.outer_radius_mm / 2 * ring * c.width_mm for c in pattern.cuts)


@pytest.fixture(params=PRESETS)
def preset_name(request):
    return request.param
