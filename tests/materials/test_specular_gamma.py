"""The GTR γ of the Disney primary specular lobe (``specular_gamma``, Burley 2012 App. B).

γ = 2 is Burley's lobe bit for bit; any other γ is the isotropic GTR of eq. 1, sampled by
eqs. 2–3, with the V-cavity shadowing (see ``disney._v_cavity_over_cos``): sampling agrees
with the pdf (χ²), a white metal never reflects more than the light, float32 stays finite
at γ = 1 ± 10⁻⁶ and γ = 10, and the exported GGX roughness matches the highlight's width.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from chi2_harness import chi2_details

from lookdev.materials import disney, highlight
from lookdev.materials import microfacet as mf
from lookdev.materials.bsdf import draw
from lookdev.materials.params import DisneyParams, ParameterError

WHITE = (1.0, 1.0, 1.0)
SIGNIFICANCE = 1e-3  # ~20 χ² tests: family-wise false alarms near 2 % (Šidák)
SWEPT = [1.0 - 1e-6, 1.0 + 1e-6, 1.5, 3.0, 10.0]


def _view(theta_deg: float, phi_deg: float = 0.0) -> tuple[float, float, float]:
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return (math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), math.cos(t))


def _grid(n: int = 64) -> np.ndarray:
    rng = np.random.default_rng(3)
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def test_gamma_two_is_burleys_lobe_exactly():
    wi, wo = _grid(), _grid()[::-1]
    for kw in ({}, {"metallic": 1.0, "roughness": 0.2}, {"anisotropic": 0.7}):
        base, explicit = DisneyParams(**kw), DisneyParams(specular_gamma=2.0, **kw)
        np.testing.assert_array_equal(disney.eval(base, wi, wo), disney.eval(explicit, wi, wo))
        np.testing.assert_array_equal(disney.pdf(base, wi, wo), disney.pdf(explicit, wi, wo))


@pytest.mark.parametrize("gamma", [1.0, *SWEPT])
@pytest.mark.parametrize(
    ("kw", "theta"),
    [({"metallic": 1.0, "roughness": 0.5}, 40.0), ({"roughness": 0.3}, 70.0)],
    ids=["metal", "plastic"],
)
def test_sampling_matches_pdf_chi2(gamma, kw, theta):
    p = DisneyParams(specular_gamma=gamma, **kw)
    r = chi2_details(disney.MODEL, p, _view(theta), 100_000, 12, alpha=SIGNIFICANCE)
    assert r.passed, (r.p_value, r.statistic, r.dof)


@pytest.mark.parametrize("gamma", [1.0 - 1e-6, 1.5, 3.0, 10.0])
@pytest.mark.parametrize("roughness", [0.0, 0.5, 1.0])
def test_white_metal_never_gains_energy(gamma, roughness):
    # GGX's Smith G under GTR1's tail reflected 1.92 (roughness 0.5) and 131 (roughness 0)
    # at cos θo = 10⁻⁴; the V-cavity G is normalised for any D.
    p = DisneyParams(base_color=WHITE, metallic=1.0, roughness=roughness, specular_gamma=gamma)
    u = np.random.default_rng(7).random((50_000, 3))
    for theta in (0.0, 60.0, 89.0, math.degrees(math.acos(1e-4))):
        _, w, _ = draw(disney.MODEL, p, np.array(_view(theta)), u)
        mean, se = w[:, 0].mean(), w[:, 0].std() / math.sqrt(len(u))
        assert mean <= 1.0 + 4 * se, (theta, mean)


@pytest.mark.parametrize("gamma", SWEPT)
@pytest.mark.parametrize("roughness", [0.0, 0.5, 1.0])
def test_float32_is_finite_and_agrees_with_float64(gamma, roughness):
    p = DisneyParams(metallic=1.0, roughness=roughness, specular_gamma=gamma)
    wi, wo = _grid(256), _grid(256)[::-1]
    wo[0] = (0.0, 0.0, 1.0)
    wi[0] = wo[0]  # the peak of the sharpest lobe: D = 2.9·10⁶ at γ = 10, roughness 0
    f64 = disney.eval(p, wi, wo)
    f32 = disney.eval(p, wi, wo, dtype=np.float32)
    assert f32.dtype == np.float32 and np.all(np.isfinite(f32)) and np.all(f32 >= 0)
    np.testing.assert_allclose(f32, f64, rtol=2e-3, atol=1e-6)
    u = np.random.default_rng(5).random((256, 3))
    u[:8] = [[0, 0, 0], [0.5, 0.5, 0.5], [1 - 2**-24] * 3, [0, 1 - 2**-24, 0]] * 2
    got = disney.sample(p, wo, u, dtype=np.float32)
    assert all(a.dtype == np.float32 and np.all(np.isfinite(a)) for a in got)


def test_gamma_one_is_continuous_through_the_normalisations_zero_over_zero():
    wi, wo = _grid(), _grid()[::-1]
    at = disney.eval(DisneyParams(metallic=1.0, roughness=0.4, specular_gamma=1.0), wi, wo)
    for g in (1.0 - 1e-6, 1.0 + 1e-6):
        near = disney.eval(DisneyParams(metallic=1.0, roughness=0.4, specular_gamma=g), wi, wo)
        np.testing.assert_allclose(near, at, rtol=1e-4, atol=1e-12)


@pytest.mark.parametrize("gamma", [1.0, 1.5, 3.0, 10.0])
@pytest.mark.parametrize("roughness", [0.05, 0.2, 0.5])
def test_exported_ggx_roughness_has_the_same_measured_highlight_width(gamma, roughness):
    gtr = DisneyParams(metallic=1.0, roughness=roughness, specular_gamma=gamma)
    matched = highlight.ggx_roughness_like(gtr)
    ggx = DisneyParams(metallic=1.0, roughness=matched)
    assert highlight.half_width(ggx) == pytest.approx(highlight.half_width(gtr), rel=1e-3)
    # D's closed-form half width is the same to within the shadowing's share (≤ 2.1 %)
    assert matched == pytest.approx(mf.ggx_roughness_like_gtr(gamma, roughness), rel=0.021)


def test_gamma_other_than_two_is_isotropic_and_bounded():
    with pytest.raises(ParameterError, match="isotropic"):
        DisneyParams.parse({"specular_gamma": 3.0, "anisotropic": 0.5})
    for bad in (0.0, -1.0, 10.5):
        with pytest.raises(ParameterError):
            DisneyParams.parse({"specular_gamma": bad})
