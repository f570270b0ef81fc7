"""The Disney specular interface (materials/disney_interface.py): smooth lobes are deltas,
reflection and refraction are chosen by the Fresnel term (issue 16)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from chi2_harness import chi2_details

from lookdev.materials import disney
from lookdev.materials import fresnel as fr
from lookdev.materials import microfacet as mf
from lookdev.materials.arrays import NumpyOps
from lookdev.materials.params import DisneyParams

WHITE = (1.0, 1.0, 1.0)
SIGNIFICANCE = 1e-3
N = 200_000


def _view(theta_deg: float, phi_deg: float = 30.0, side: float = 1.0) -> np.ndarray:
    t, p = math.radians(theta_deg), math.radians(phi_deg)
    return np.array([math.sin(t) * math.cos(p), math.sin(t) * math.sin(p), side * math.cos(t)])


def _draw(params, wo, n=N, seed=3):
    u = np.random.default_rng(seed).random((n, 3))
    return disney.sample(params, wo, u, delta=True)


# -- the threshold rule --------------------------------------------------------------------
def test_delta_below_the_glossy_minimum_alpha_and_only_for_constants():
    edge = math.sqrt(mf.ALPHA_MIN)
    assert mf.is_delta(0.0) and mf.is_delta(0.02) and mf.is_delta(edge * 0.999)
    assert not mf.is_delta(edge * 1.001) and not mf.is_delta(0.3)
    assert mf.is_delta(0.02, 0.5) and not mf.is_delta(0.03, 1.0)  # the larger α decides
    assert not mf.is_delta(np.zeros(4))  # a per-element roughness stays glossy
    xp = NumpyOps()
    assert disney.prepare(xp, DisneyParams(spec_trans=1.0, roughness=0.0)).delta == (
        "specular",
        "spec_trans",
    )
    assert disney.prepare(xp, DisneyParams(spec_trans=1.0, roughness=0.3)).delta == ()
    # A thin sheet's transmission has its own, rougher α (Burley 2015): at η = 3 the
    # reflection of roughness 0.03 is a delta, its transmission (×1.6) is not.
    thin = disney.prepare(xp, DisneyParams(spec_trans=1.0, roughness=0.03, ior=3.0, thin=True))
    assert thin.delta == ("specular",)


def test_smooth_glass_has_no_density_anywhere():
    p = DisneyParams(base_color=WHITE, spec_trans=1.0, roughness=0.0, ior=1.5)
    rng = np.random.default_rng(0)
    wi, wo = rng.normal(size=(2, 4096, 3))
    assert not np.any(disney.eval(p, wi, wo)) and not np.any(disney.pdf(p, wi, wo))


# -- delta weights against the exact Fresnel -----------------------------------------------
@pytest.mark.parametrize("theta", [0.0, 30.0, 60.0, 80.0, 89.0])
@pytest.mark.parametrize("ior", [1.333, 1.5, 2.417])
def test_smooth_solid_glass_splits_by_the_exact_fresnel(theta, ior):
    p = DisneyParams(base_color=WHITE, spec_trans=1.0, roughness=0.0, ior=ior)
    for side, eta in ((1.0, ior), (-1.0, 1.0 / ior)):
        wo = _view(theta, side=side)
        wi, w, pdf, delta = _draw(p, wo)
        assert delta.all() and (pdf > 0).all()
        f = float(fr.dielectric(NumpyOps(), np.float64(math.cos(math.radians(theta))), eta))
        reflected = wi[:, 2] * wo[2] > 0
        # Mirror and Snell directions, exactly.
        mirror = wo * np.array([-1, -1, 1])
        np.testing.assert_allclose(wi[reflected], np.broadcast_to(mirror, wi[reflected].shape))
        sin_o = math.sin(math.radians(theta))
        sin_t = np.hypot(wi[~reflected, 0], wi[~reflected, 1])
        np.testing.assert_allclose(sin_t * eta, sin_o, atol=1e-12)
        # Chosen with probability F, each with weight 1 (reflected) and 1/η² (radiance):
        # R + T = 1 for white glass, with the transport's η² put back.
        share = reflected.mean()
        assert share == pytest.approx(f, abs=4 * math.sqrt(f * (1 - f) / N) + 1e-12)
        np.testing.assert_allclose(w[reflected], 1.0, rtol=1e-12)
        np.testing.assert_allclose(w[~reflected] * eta * eta, 1.0, rtol=1e-12)
        np.testing.assert_allclose(pdf[reflected], f, rtol=1e-12)
        np.testing.assert_allclose(pdf[~reflected], 1.0 - f, rtol=1e-12)


@pytest.mark.parametrize("theta", [0.0, 45.0, 85.0])
def test_smooth_thin_sheet_reflects_f_and_passes_the_rest_straight_through(theta):
    base = (0.25, 0.64, 1.0)
    p = DisneyParams(base_color=base, spec_trans=1.0, roughness=0.0, ior=1.5, thin=True)
    for side in (1.0, -1.0):  # two-sided
        wo = _view(theta, side=side)
        wi, w, _, delta = _draw(p, wo)
        assert delta.all()
        f = float(fr.dielectric(NumpyOps(), np.float64(abs(wo[2])), 1.5))
        reflected = wi[:, 2] * wo[2] > 0
        np.testing.assert_allclose(wi[~reflected], np.broadcast_to(-wo, wi[~reflected].shape))
        energy = w.mean(axis=0)  # E[weight] = R + T·√base, exactly the lobes' values
        stderr = w.std(axis=0) / math.sqrt(N)
        exact = f + (1 - f) * np.sqrt(base)
        np.testing.assert_array_less(np.abs(energy - exact), 4 * stderr + 1e-12)


def test_smooth_glass_inside_reflects_totally_beyond_the_critical_angle():
    p = DisneyParams(base_color=WHITE, spec_trans=1.0, roughness=0.0, ior=1.5)
    wo = _view(60.0, side=-1.0)  # sin 60° · 1.5 > 1
    wi, w, pdf, delta = _draw(p, wo, n=1000)
    assert delta.all() and np.all(wi[:, 2] < 0) and np.all(pdf == 1.0)
    np.testing.assert_allclose(w, 1.0)


def test_smooth_glass_in_a_mixture_keeps_the_other_lobes_density_chi2():
    # Half glass, half plastic at roughness 0: the interface is a delta, the diffuse is
    # not. Delta samples count as the pdf's missing mass (chi2_harness, step 3).
    p = DisneyParams(base_color=(0.8, 0.5, 0.3), spec_trans=0.5, roughness=0.0, ior=1.5)
    for wo in (_view(30.0), _view(75.0)):
        r = chi2_details(disney.MODEL, p, wo, 100_000, 12, alpha=SIGNIFICANCE)
        assert r.passed, (r.p_value, r.statistic, r.dof, r.failures, r.expected_failures)
        assert r.failures > 10_000  # the interface's share was sampled as deltas


def test_smooth_mixture_weights_are_unbiased():
    # E[weight] by sampling = the diffuse's albedo by its own density + the delta weights.
    p = DisneyParams(base_color=(0.8, 0.5, 0.3), spec_trans=0.5, roughness=0.0, ior=1.5)
    glossy = p.replace(roughness=0.02 + 0.0)  # also a delta: same material
    wo = _view(50.0)
    a = _draw(p, wo)[1].mean(axis=0)
    b = _draw(glossy, wo, seed=9)[1].mean(axis=0)
    np.testing.assert_allclose(a, b, rtol=0.02)


# -- rough glass: the per-microfacet Fresnel choice ------------------------------------------
ROUGH = [
    DisneyParams(base_color=WHITE, spec_trans=1.0, roughness=0.3, ior=1.5),
    DisneyParams(base_color=(0.5, 0.9, 0.6), spec_trans=1.0, roughness=0.12, ior=1.31),
    DisneyParams(spec_trans=1.0, roughness=0.4, ior=1.5, thin=True),
    DisneyParams(spec_trans=0.6, roughness=0.35, ior=1.4, diff_trans=0.3, clearcoat=0.5),
    DisneyParams(spec_trans=1.0, roughness=0.03, ior=3.0, thin=True),  # delta R, glossy T
]


@pytest.mark.parametrize("side", [1.0, -1.0], ids=["outside", "inside"])
@pytest.mark.parametrize("params", ROUGH, ids=range(len(ROUGH)))
def test_rough_glass_sampling_matches_its_pdf_chi2(params, side):
    r = chi2_details(disney.MODEL, params, _view(55.0, side=side), 100_000, 12, alpha=SIGNIFICANCE)
    assert r.passed, (r.p_value, r.statistic, r.dof, r.failures, r.expected_failures)


def test_rough_glass_chooses_by_the_fresnel_of_the_sampled_microfacet():
    # White rough glass, one-strategy material: each sample's weight is G1(wi) (over
    # η² when refracted), never the F/P ratio of a fixed choice.
    p = DisneyParams(base_color=WHITE, spec_trans=1.0, roughness=0.3, ior=1.5)
    wo = _view(40.0)
    wi, w, pdf, delta = _draw(p, wo, n=20_000)
    ok = pdf > 0
    assert not delta.any()
    pr = disney.prepare(NumpyOps(), p)
    g1 = mf.smith_g1(NumpyOps(), wi[ok].T, pr.ax, pr.ay)
    refracted = wi[ok, 2] < 0
    expected = np.where(refracted, g1 / 1.5**2, g1)
    np.testing.assert_allclose(w[ok, 0], expected, rtol=1e-6)


def test_rough_glass_albedo_tends_to_the_smooth_one():
    # Energy: the rough lobes' sampled albedo approaches the delta weights as α → 0.
    smooth = DisneyParams(base_color=WHITE, spec_trans=1.0, roughness=0.0, ior=1.5)
    near = smooth.replace(roughness=0.04)
    for theta in (0.0, 60.0):
        wo = _view(theta)
        a = _draw(smooth, wo)[1].mean(axis=0)
        b = _draw(near, wo, seed=5)[1].mean(axis=0)
        np.testing.assert_allclose(a, b, rtol=0.01)
