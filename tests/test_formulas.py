"""Formulas with one home each (issue 12), tested at their edges: specular ↔ IOR."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lookdev.materials.arrays import NumpyOps
from lookdev.materials.fresnel import (
    ETA_MAX,
    F0_MAX,
    SPECULAR_F0_SCALE,
    f0_to_ior,
    ior_to_f0,
    ior_to_specular,
    specular_to_ior,
)
from lookdev.materials.params import DisneyParams
from lookdev.materials.pixar import PixarParams

SPECULAR_CEILING = DisneyParams.model_fields["specular"].metadata[-1].le


# -- specular ↔ IOR ------------------------------------------------------------------------
def test_specular_zero_is_ior_one_and_back():
    assert specular_to_ior(0.0) == 1.0 and ior_to_specular(1.0) == 0.0
    assert f0_to_ior(0.0) == 1.0 and ior_to_f0(1.0) == 0.0


def test_burleys_default_and_range():
    """§5.4: specular 0..1 ↦ F0 0..0.08 ↦ IOR 1.0..1.8, the middle 0.5 ↦ 1.5."""
    assert specular_to_ior(0.5) == pytest.approx(1.5, abs=1e-12)
    assert specular_to_ior(1.0) == pytest.approx(1.7888, abs=1e-4)
    assert ior_to_specular(1.5) == pytest.approx(0.5, abs=1e-12)
    assert SPECULAR_F0_SCALE == 0.08


@pytest.mark.parametrize("s", [0.0, 1e-9, 0.01, 0.5, 1.0, 4.0, 12.0, 12.49])
def test_round_trip_below_the_clamp(s):
    assert ior_to_specular(specular_to_ior(s)) == pytest.approx(s, rel=1e-9, abs=1e-15)


def test_the_clamp_is_at_f0_max_and_keeps_eta_finite_in_float32():
    at_clamp = F0_MAX / SPECULAR_F0_SCALE
    assert specular_to_ior(at_clamp) == pytest.approx(ETA_MAX, rel=1e-12)
    assert specular_to_ior(SPECULAR_CEILING) == ETA_MAX == f0_to_ior(1.0)
    assert specular_to_ior(1e30) == ETA_MAX
    assert 3.9e6 < ETA_MAX < 4.1e6
    xp = NumpyOps(np.float32)
    eta = specular_to_ior(xp.asarray([0.0, 0.5, SPECULAR_CEILING]), xp)
    assert eta.dtype == np.float32 and np.isfinite(eta).all() and np.isfinite(eta * eta).all()
    assert eta[1] == pytest.approx(1.5, rel=1e-6) and eta[0] == 1.0


def test_floats_give_floats_and_arrays_keep_their_shape():
    assert type(specular_to_ior(0.5)) is float and type(f0_to_ior(0.04)) is float
    a = specular_to_ior(np.full((2, 3), 0.5, np.float32))
    assert a.shape == (2, 3) and a.dtype == np.float32


def test_every_spelling_uses_the_one_conversion():
    assert DisneyParams(specular=0.3).effective_ior == specular_to_ior(0.3)
    assert DisneyParams(ior=1.7).effective_specular == ior_to_specular(1.7)
    assert DisneyParams(specular=SPECULAR_CEILING).effective_ior == ETA_MAX
    assert PixarParams(normal_fresnel=0.8).eta == f0_to_ior(0.04)
    assert PixarParams(normal_fresnel=20.0).eta == ETA_MAX
    assert math.isfinite(PixarParams(normal_fresnel=20.0).eta)
