"""Directional albedo: quadrature, Monte Carlo and tables against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _lambert import LAMBERT, PHONG, LambertParams, PhongParams
from hypothesis import given, settings
from hypothesis import strategies as st

from lookdev.pipeline.analysis import albedo as A

EDGE_ANGLES = np.radians([0.0, 30.0, 60.0, 89.0, 89.99])


def test_lambert_albedo_is_its_base_colour_at_every_angle_quadrature():
    params = LambertParams(base_color=(0.8, 0.5, 0.2))
    curve = A.albedo_quadrature(LAMBERT, params, EDGE_ANGLES, n_mu=8, n_phi=8)
    np.testing.assert_allclose(curve.albedo, np.tile([0.8, 0.5, 0.2], (5, 1)), rtol=1e-12)


def test_lambert_albedo_monte_carlo_is_exact_with_a_cosine_sampler():
    # f·cos/pdf = ρ for every sample: the estimator has zero variance.
    curve = A.albedo_monte_carlo(LAMBERT, LambertParams(), EDGE_ANGLES, n_samples=64)
    np.testing.assert_allclose(curve.albedo, np.tile([0.8, 0.5, 0.2], (5, 1)), rtol=1e-12)
    assert np.all(curve.stderr < 1e-12)


def test_black_lambert_has_zero_albedo():
    curve = A.albedo_quadrature(LAMBERT, LambertParams(base_color=(0, 0, 0)), EDGE_ANGLES)
    assert np.all(curve.albedo == 0)


def test_transmission_hemisphere_adds_nothing_for_a_pure_reflector():
    p = LambertParams()
    both = A.albedo_quadrature(LAMBERT, p, EDGE_ANGLES, hemisphere="both").albedo
    refl = A.albedo_quadrature(LAMBERT, p, EDGE_ANGLES, hemisphere="reflect").albedo
    np.testing.assert_allclose(both, refl, rtol=1e-12)


def test_phong_albedo_at_normal_incidence_is_one():
    # Normalised Phong at θ = 0: ∫ (n+2)/2π cos^n θ cos θ dω = 1 exactly.
    p = PhongParams(exponent=20.0)
    q = A.albedo_quadrature(PHONG, p, [0.0], n_mu=128, n_phi=16).albedo[0]
    np.testing.assert_allclose(q, 1.0, rtol=1e-6)


@pytest.mark.slow
@settings(max_examples=15, deadline=None)
@given(exponent=st.floats(1.0, 200.0), theta=st.floats(0.0, 80.0))
def test_monte_carlo_agrees_with_quadrature_within_its_error(exponent, theta):
    p = PhongParams(exponent=exponent)
    t = math.radians(theta)
    q = A.albedo_quadrature(PHONG, p, [t], n_mu=256, n_phi=256).albedo[0, 0]
    mc = A.albedo_monte_carlo(PHONG, p, [t], n_samples=4096, seed=1)
    assert abs(mc.albedo[0, 0] - q) <= 5 * mc.stderr[0, 0] + 1e-4


def test_float32_quadrature_matches_float64():
    p = PhongParams(exponent=10.0)
    a64 = A.albedo_quadrature(PHONG, p, EDGE_ANGLES).albedo
    a32 = A.albedo_quadrature(PHONG, p, EDGE_ANGLES, dtype=np.float32).albedo
    np.testing.assert_allclose(a32, a64, atol=1e-5)


def test_model_without_a_table_reports_none():
    assert A.albedo_tabulated(LAMBERT, LambertParams(), EDGE_ANGLES) is None


def test_a_registered_table_is_read_and_broadcast_per_channel(monkeypatch):
    monkeypatch.setattr(A, "_TABLES", {})
    A.register_table("lambert", lambda params, cos_theta: cos_theta)  # one grey per angle
    curve = A.albedo_tabulated(LAMBERT, LambertParams(), EDGE_ANGLES)
    assert curve.method == "table"
    np.testing.assert_allclose(curve.albedo, np.tile(np.cos(EDGE_ANGLES)[:, None], (1, 3)))


def test_view_direction_is_unit_and_in_the_xz_plane():
    d = A.view_direction(EDGE_ANGLES)
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1.0)
    assert np.all(d[:, 1] == 0)
