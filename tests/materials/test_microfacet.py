"""Microfacet building blocks against Burley App. B, Heitz 2014/2018 and quadrature."""

from __future__ import annotations

import math

import numpy as np
import pytest
from chi2_harness import chi2_details
from hypothesis import given, settings
from hypothesis import strategies as st

from lookdev.materials import fresnel as fr
from lookdev.materials import microfacet as mf
from lookdev.materials.arrays import NumpyOps
from lookdev.materials.bsdf import Model
from lookdev.materials.params import Params

XP = NumpyOps()
GAMMAS = [0.5, 1.0, 1.0 - 1e-6, 1.0 + 1e-6, 1.5, 2.0, 3.0, 10.0]
ALPHAS = [1e-3, 0.1, 0.5, 1.0 - 1e-6, 1.0]
# ~40 χ² tests here: significance 10⁻³ each keeps the family-wise false alarm rate near 4 %
# (Šidák), as Mitsuba's own χ² suite corrects for the number of tests.
SIGNIFICANCE = 1e-3


def _graded_nodes(n: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre on [0, 1] over sub-intervals graded geometrically towards 0.

    The GTR peak sits at sin²θh ≲ α² (10⁻⁶ for α = 10⁻³): intervals 10⁻¹⁶…10⁻¹…1
    resolve it without knowing where it is.
    """
    edges = np.concatenate([[0.0], 10.0 ** np.arange(-16, 0), [1.0]])
    x, w = np.polynomial.legendre.leggauss(n)
    lo, hi = edges[:-1, None], edges[1:, None]
    return (0.5 * (hi - lo) * (x + 1) + lo).ravel(), (0.5 * (hi - lo) * w).ravel()


@pytest.mark.parametrize("alpha", ALPHAS)
@pytest.mark.parametrize("gamma", GAMMAS)
def test_gtr_is_normalised_by_quadrature(gamma, alpha):
    # ∫ D cos θh dω = 2π ∫ D μ dμ = π ∫ D d(sin²θh): integrate in s = sin²θh.
    s, w = _graded_nodes()
    d = mf.gtr_d(XP, gamma, alpha * alpha, 1.0 - s, s)
    assert abs(math.pi * np.sum(w * d) - 1.0) < 1e-4


def test_gtr_normalisation_matches_the_closed_forms_of_eqs_4_6_8():
    for a in (1e-3, 0.1, 0.5, 0.9):
        a2 = a * a
        assert mf.gtr_norm(XP, 1.0, a2) == pytest.approx((a2 - 1) / (math.pi * math.log(a2)))
        assert mf.gtr_norm(XP, 1.5, a2) == pytest.approx((a2 + a) / (2 * math.pi))
        assert mf.gtr_norm(XP, 2.0, a2) == pytest.approx(a2 / math.pi)


def test_gtr_normalisation_is_continuous_through_gamma_one_and_alpha_one():
    a2 = np.array([1e-6, 0.25, 1.0 - 2e-6, 1.0 - 1e-12, 1.0])
    for g in (1.0, 2.0):
        at = mf.gtr_norm(XP, g, a2)
        near = mf.gtr_norm(XP, g + 1e-9, a2)
        np.testing.assert_allclose(near, at, rtol=1e-7)
    np.testing.assert_allclose(mf.gtr_norm(XP, 3.0, 1.0) * math.pi, 1.0, rtol=1e-15)
    assert np.all(np.isfinite(mf.gtr_norm(NumpyOps(np.float32), 1.0, np.float32(a2))))


def test_gtr_sampling_matches_eqs_5_7_9():
    xi = np.linspace(0.0, 1.0, 11)
    for a in (1e-3, 0.3, 0.8):
        a2 = a * a
        eq5 = (1 - a2 ** (1 - xi)) / (1 - a2)
        eq7 = (1 - a2 / (1 + (a - 1) * xi) ** 2) / (1 - a2)
        eq9 = (1 - xi) / (1 + (a2 - 1) * xi)
        np.testing.assert_allclose(mf.gtr_sample_cos2(XP, 1.0, a2, xi), eq5, atol=1e-12)
        np.testing.assert_allclose(mf.gtr_sample_cos2(XP, 1.5, a2, xi), eq7, atol=1e-12)
        np.testing.assert_allclose(mf.gtr_sample_cos2(XP, 2.0, a2, xi), eq9, atol=1e-12)


@given(st.floats(0.3, 10.0), st.floats(1e-3, 1.0), st.floats(0.0, 1.0))
@settings(max_examples=200, deadline=None)
def test_gtr_sampling_inverts_the_cdf(gamma, alpha, xi):
    # The cdf of cos²θh under D cos θh dω is F(v) = π ∫_v^1 D dv'; sampling must invert it.
    a2 = alpha * alpha
    v = float(mf.gtr_sample_cos2(XP, gamma, a2, np.float64(xi)))
    s, w = _graded_nodes(12)
    tail = (1.0 - v) * s  # sin² from 0 to 1 − v, i.e. cos² from v to 1
    cdf = math.pi * (1.0 - v) * np.sum(w * mf.gtr_d(XP, gamma, a2, 1.0 - tail, tail))
    assert cdf == pytest.approx(xi, abs=2e-6)


# -- distributions as tiny models, for the χ² harness --------------------------------------
class _DistParams(Params):
    gamma: float = 2.0
    ax: float = 0.5
    ay: float = 0.5
    wo: tuple[float, float, float] = (0.0, 0.0, 1.0)
    kind: str = "gtr"


def _prep(xp, p, **maps):
    return p


def _dist_pdf(xp, p, h, _wo):
    up = h[2] > 0
    if p.kind == "gtr":
        d = mf.gtr_d(xp, p.gamma, p.ax * p.ax, h[2] * h[2], h[0] * h[0] + h[1] * h[1])
        return xp.select(up, d * h[2], 0.0)
    if p.kind == "ggx":
        return xp.select(up, mf.ggx_d(xp, h, p.ax, p.ay) * h[2], 0.0)
    wo = xp.color(p.wo)
    return xp.select(up, mf.visible_ggx_pdf(xp, wo, h, p.ax, p.ay), 0.0)


def _dist_sample(xp, p, wo, u):
    if p.kind == "gtr":
        h = mf.sample_gtr(xp, p.gamma, p.ax * p.ax, u[1], u[2])
    elif p.kind == "ggx":
        h = mf.sample_ggx(xp, p.ax, p.ay, u[1], u[2])
    else:
        h = mf.sample_visible_ggx(xp, xp.color(p.wo), p.ax, p.ay, u[1], u[2])
    pdf = _dist_pdf(xp, p, h, wo)
    return h, xp.vec3(pdf, pdf, pdf), pdf, False


def _dist_eval(xp, p, wi, wo):
    d = _dist_pdf(xp, p, wi, wo)
    return xp.vec3(d, d, d)


DIST = Model("dist", _DistParams, _prep, _dist_eval, _dist_pdf, _dist_sample)


@pytest.mark.parametrize("gamma", [0.5, 1.0, 1.5, 2.0, 3.0, 10.0])
@pytest.mark.parametrize("alpha", [1e-3, 0.2, 1.0])
def test_gtr_sampling_chi2(gamma, alpha):
    r = chi2_details(
        DIST, _DistParams(gamma=gamma, ax=alpha), (0, 0, 1), 50_000, 12, alpha=SIGNIFICANCE
    )
    assert r.passed, (r.p_value, r.statistic, r.dof)


@pytest.mark.parametrize("ax,ay", [(0.5, 0.05), (1e-3, 0.3), (1.0, 1.0)])
def test_anisotropic_projected_half_vector_sampling_chi2(ax, ay):
    # Eqs. 14-15 sample D(h) cos θh for the anisotropic GGX of eq. 13.
    r = chi2_details(
        DIST, _DistParams(kind="ggx", ax=ax, ay=ay), (0, 0, 1), 50_000, 12, alpha=SIGNIFICANCE
    )
    assert r.passed, (r.p_value, r.statistic, r.dof)


@pytest.mark.parametrize("theta", [0.0, 1.0, 1.55])
@pytest.mark.parametrize("ax,ay", [(0.3, 0.3), (0.6, 0.06), (1e-3, 1e-3)])
def test_visible_normal_sampling_chi2(theta, ax, ay):
    wo = (math.sin(theta) * 0.6, math.sin(theta) * 0.8, math.cos(theta))
    p = _DistParams(kind="vndf", ax=ax, ay=ay, wo=wo)
    r = chi2_details(DIST, p, (0, 0, 1), 50_000, 12, alpha=SIGNIFICANCE)
    assert r.passed, (r.p_value, r.statistic, r.dof)


def _hemisphere(n_s=16, n_phi=256):
    s, ws = _graded_nodes(n_s)
    phi = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    ss, pp = np.meshgrid(s, phi, indexing="ij")
    sin_t = np.sqrt(ss)
    cos_t = np.sqrt(1 - ss)
    h = np.stack([sin_t * np.cos(pp), sin_t * np.sin(pp), cos_t])
    # dω = dμ dφ and dμ = ds / (2μ) with s = sin²θ = 1 − μ².
    w = (ws[:, None] / (2 * cos_t)) * (2 * math.pi / n_phi)
    return h.reshape(3, -1), w.ravel()


def _hemisphere_mu(n_mu=400, n_phi=1024):
    """Gauss-Legendre in μ = cos θ × trapezoid in φ: for integrands smooth in μ."""
    x, wx = np.polynomial.legendre.leggauss(n_mu)
    mu, wmu = 0.5 * (x + 1), 0.5 * wx
    phi = (np.arange(n_phi) + 0.5) * 2 * math.pi / n_phi
    mm, pp = np.meshgrid(mu, phi, indexing="ij")
    s = np.sqrt(1 - mm * mm)
    h = np.stack([s * np.cos(pp), s * np.sin(pp), mm])
    return h.reshape(3, -1), (wmu[:, None] * (2 * math.pi / n_phi) + 0 * pp).ravel()


@pytest.mark.parametrize("ax,ay", [(0.3, 0.3), (0.8, 0.2), (0.1, 0.5)])
@pytest.mark.parametrize("theta", [0.3, 1.0, 1.5])
def test_smith_g1_equals_the_projected_area_ratio(ax, ay, theta):
    # Heitz 2014 eq. 2: G1(ωo) ∫ max(0, ωo·m) D(m) dm = cos θo, by quadrature (the kink of
    # max(0, ·) limits it to ~10⁻⁴).
    h, w = _hemisphere_mu()
    wo = np.array([math.sin(theta) * 0.8, math.sin(theta) * 0.6, math.cos(theta)])[:, None]
    projected = np.sum(w * np.maximum(0.0, XP.dot(wo, h)) * mf.ggx_d(XP, h, ax, ay))
    g1 = float(mf.smith_g1(XP, wo, ax, ay)[0])
    assert g1 * projected == pytest.approx(math.cos(theta), rel=5e-4)


def test_ggx_is_normalised_anisotropic_by_quadrature():
    h, w = _hemisphere()
    for ax, ay in [(0.3, 0.3), (0.8, 0.2), (1.0, 1.0)]:
        assert np.sum(w * mf.ggx_d(XP, h, ax, ay) * h[2]) == pytest.approx(1.0, rel=2e-4)


def test_g1_edges_normal_grazing_float32():
    xp32 = NumpyOps(np.float32)
    w = xp32.asarray([[0.0, 1.0, 1.0], [0.0, 0.0, 0.0], [1.0, 0.0, 1e-30]])
    g = mf.smith_g1(xp32, w, 0.5, 0.5)
    assert g[0] == 1.0 and g[1] == 0.0 and 0.0 <= g[2] < 1e-29


def test_anisotropic_alphas_follow_the_2014_addendum():
    ax, ay = mf.anisotropic_alphas(XP, 0.5, 1.0)
    aspect = math.sqrt(1 - 0.9)
    assert (ax, ay) == pytest.approx((0.25 / aspect, 0.25 * aspect))
    assert mf.anisotropic_alphas(XP, 0.0, 0.0) == (mf.ALPHA_MIN, mf.ALPHA_MIN)


def test_ggx_peak_is_finite_in_float32_at_minimum_alpha():
    xp32 = NumpyOps(np.float32)
    h = xp32.asarray([[0.0], [0.0], [1.0]])
    d = mf.ggx_d(xp32, h, np.float32(mf.ALPHA_MIN), np.float32(mf.ALPHA_MIN))
    assert d.dtype == np.float32
    assert d[0] == pytest.approx(1 / (math.pi * mf.ALPHA_MIN**2), rel=1e-5)


# -- Fresnel --------------------------------------------------------------------------------
def test_dielectric_fresnel_known_values():
    assert fr.dielectric(XP, np.float64(1.0), 1.5) == pytest.approx(0.04)
    assert fr.dielectric(XP, np.float64(0.0), 1.5) == pytest.approx(1.0)
    assert fr.dielectric(XP, np.float64(0.0), 1.0) == 1.0  # grazing: TIR branch, no NaN
    # Brewster's angle: tan θB = η, r_parallel = 0, so F = r_perp² / 2.
    tb = math.atan(1.5)
    rs = (
        (math.cos(tb) - 1.5 * math.cos(math.pi / 2 - tb))
        / (math.cos(tb) + 1.5 * math.cos(math.pi / 2 - tb))
    ) ** 2
    assert fr.dielectric(XP, np.float64(math.cos(tb)), 1.5) == pytest.approx(rs / 2)


@given(st.floats(0.0, 1.0), st.floats(1.0, 3.0))
def test_dielectric_fresnel_is_the_same_from_both_sides(cos_i, eta):
    # Stokes relations: F(θi, η) = F(θt, 1/η) for the refracted θt.
    sin_t2 = (1 - cos_i * cos_i) / (eta * eta)
    cos_t = math.sqrt(1 - sin_t2)
    a = float(fr.dielectric(XP, np.float64(cos_i), eta))
    b = float(fr.dielectric(XP, np.float64(cos_t), 1 / eta))
    assert 0.0 <= a <= 1.0 and 0.0 <= b <= 1.0
    # F's slope is infinite at grazing and at the critical angle: a rounding of cos t there
    # moves F by ~cos-rounding / cos. Both ends have their own exact edge tests.
    if min(cos_i, cos_t) > 1e-2:
        assert a == pytest.approx(b, abs=1e-9)


def test_schlick_edges():
    assert fr.schlick(XP, 0.04, np.float64(0.0)) == 1.0
    assert fr.schlick(XP, 0.04, np.float64(1.0)) == 0.04
    assert fr.schlick_weight(XP, np.float64(1.0 + 1e-9)) == 0.0


@pytest.mark.parametrize("name", ["microfacet", "fresnel", "disney"])
def test_doctests(name):
    import doctest
    import importlib

    module = importlib.import_module(f"lookdev.materials.{name}")
    result = doctest.testmod(module)
    assert result.failed == 0 and result.attempted > 0


@pytest.mark.parametrize("gamma", [0.5, 1.0, 1.5, 3.0])
@pytest.mark.parametrize("a2", [1e-6, 0.01, 0.25, 1.0])
def test_sampled_sin2_keeps_float32_digits_at_the_peak(gamma, a2):
    # 1 − cos²θh would lose all of them near ξ = 0 for a sharp lobe (clearcoat at α = 1e-3).
    xi = np.array([0.0, 1e-7, 1e-4, 1e-3, 0.3, 0.9, 1.0])
    s64 = mf.gtr_sample_sin2(XP, gamma, a2, xi)
    np.testing.assert_allclose(s64 + mf.gtr_sample_cos2(XP, gamma, a2, xi), 1.0, atol=1e-12)
    with np.errstate(all="ignore"):
        s32 = mf.gtr_sample_sin2(NumpyOps(np.float32), gamma, np.float32(a2), xi.astype(np.float32))
    assert s32.dtype == np.float32
    np.testing.assert_allclose(s32, s64, rtol=2e-6, atol=1e-30)
