"""Multiple-scattering energy compensation of the Disney specular lobe (``energy_compensation``).

Turquin 2019's factor 1 + F0 (1 − E)/E from the shipped E(μ, r) table
(:mod:`lookdev.materials.energy`): off is Burley's lobe bit for bit; on, a white metal
passes the white furnace at 1 within 1 % for every roughness and view, float32 and float64;
a white dielectric stays within the Disney model's documented allowance; sampling still
agrees with the pdf (χ²); the table is as accurate as its data module says.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from chi2_harness import chi2_details

from lookdev.materials import disney, energy
from lookdev.materials.params import DisneyParams
from lookdev.pipeline.analysis import energy_fit
from lookdev.pipeline.analysis.albedo import albedo_monte_carlo
from lookdev.pipeline.analysis.stability_cases import allowance

WHITE = (1.0, 1.0, 1.0)
ROUGHNESS = [0.0, 0.02, 0.1, 0.3, 0.5, 0.7, 0.9, 1.0]
THETA_DEG = [0.0, 30.0, 60.0, 80.0, 88.0, 89.9]
SIGNIFICANCE = 1e-3


def _metal(roughness: float, **kw) -> DisneyParams:
    return DisneyParams(metallic=1.0, base_color=WHITE, roughness=roughness, **kw)


def _grid(n: int = 64) -> np.ndarray:
    rng = np.random.default_rng(3)
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def test_off_is_the_single_scattering_lobe_bit_for_bit():
    wi, wo = _grid(), _grid()[::-1]
    for kw in ({}, {"metallic": 1.0, "roughness": 0.2}, {"spec_trans": 1.0, "roughness": 0.4}):
        base, off = DisneyParams(**kw), DisneyParams(energy_compensation=False, **kw)
        np.testing.assert_array_equal(disney.eval(base, wi, wo), disney.eval(off, wi, wo))


@pytest.mark.parametrize("dtype", [np.float64, np.float32], ids=["f64", "f32"])
@pytest.mark.parametrize("roughness", ROUGHNESS)
def test_white_metal_passes_the_furnace_within_one_percent(roughness, dtype):
    theta = np.radians(THETA_DEG)
    p = _metal(roughness, energy_compensation=True)
    curve = albedo_monte_carlo(disney.MODEL, p, theta, n_samples=16384, dtype=dtype)
    e = curve.albedo[:, 0]
    assert np.all(np.abs(e - 1.0) < 0.01 + 3.0 * curve.stderr[:, 0]), (e, curve.stderr[:, 0])


def test_without_it_a_rough_white_metal_keeps_under_a_third_of_the_light():
    off = albedo_monte_carlo(disney.MODEL, _metal(1.0), [0.0], n_samples=16384).albedo[0, 0]
    assert abs(off - 0.307) < 0.005  # the loss the switch undoes (energy_albedo: E(1, 1))
    assert abs(energy.albedo(1.0, 1.0) - off) < 0.005


@pytest.mark.parametrize(("anisotropic", "roughness"), [(0.5, 0.7), (0.5, 1.0), (1.0, 0.7)])
def test_anisotropic_metal_reads_the_geometric_mean_alpha(anisotropic, roughness):
    """α = √(αx αy) is an approximation (MaterialX's ``mx_average_alpha`` too): an
    anisotropic white metal is compensated only in part, and never gains more than 3 %
    (measured: anisotropic 0.5 → 0.84 … 1.023 over roughness 0.3 … 1; anisotropic 1 at
    roughness 1, where αx = 3.2 lies far beyond the table, 0.29 … 0.47 against 0.11 off)."""
    theta = np.radians([0.0, 60.0, 85.0, 89.9])
    p = _metal(roughness, anisotropic=anisotropic)
    for phi in (0.0, math.pi / 2):
        off = albedo_monte_carlo(disney.MODEL, p, theta, n_samples=8192, phi=phi).albedo
        on_p = p.replace(energy_compensation=True)
        on = albedo_monte_carlo(disney.MODEL, on_p, theta, n_samples=8192, phi=phi).albedo
        assert np.all(on >= off) and np.all(on <= 1.03), (phi, off[:, 0], on[:, 0])


@pytest.mark.parametrize("roughness", [0.3, 0.7, 1.0])
def test_tinted_metal_gains_light_but_never_more_than_white(roughness):
    gold = (1.0, 0.71, 0.29)
    theta = np.radians([0.0, 45.0, 80.0])
    p = DisneyParams(metallic=1.0, base_color=gold, roughness=roughness)
    off = albedo_monte_carlo(disney.MODEL, p, theta, n_samples=8192).albedo
    on = albedo_monte_carlo(
        disney.MODEL, p.replace(energy_compensation=True), theta, n_samples=8192
    ).albedo
    assert np.all(on >= off - 1e-9) and np.all(on <= 1.01)


@pytest.mark.parametrize(("specular", "most"), [(0.5, 0.0015), (1.0, 0.005)])
def test_white_dielectric_gains_only_its_specular_share(specular, most):
    """The Disney diffuse is not reduced by the specular (Burley), so a white plastic
    reflects more than the light by design (rough white plastic 1.567 at 89°,
    stability_cases); compensation adds F0 (1/E − 1) of the specular lobe only: measured
    ≤ 0.0011 at specular 0.5 (F0 0.04), ≤ 0.0044 at specular 1 (F0 0.08)."""
    theta = np.radians([0.0, 60.0, 80.0, 89.0])
    plastic = DisneyParams(base_color=WHITE, roughness=1.0, specular=specular)
    off = albedo_monte_carlo(disney.MODEL, plastic, theta, n_samples=16384).albedo[:, 0]
    on_p = plastic.replace(energy_compensation=True)
    on = albedo_monte_carlo(disney.MODEL, on_p, theta, n_samples=16384).albedo[:, 0]
    assert np.all(on >= off) and np.all(on - off < most), on - off
    if specular == 0.5:
        assert on[-1] < 1.567 + 0.003  # the documented rough white plastic, within noise


def test_most_energetic_disney_case_stays_within_the_allowance():
    """Every lobe on, anisotropic 1, along the bitangent at θo = 89.9999° (the documented
    maximum, stability_cases): 1.782 off, 1.787 ± 0.0014 on (2.6·10⁵ samples), passing
    ``lookdev check``'s test mean − 4σ ≤ 1 + allowance."""
    every = dict(sheen=1.0, clearcoat=1.0, clearcoat_gloss=0.0, anisotropic=1.0)
    worst = DisneyParams(
        base_color=WHITE, roughness=1.0, specular=1.0, energy_compensation=True, **every
    )
    top = albedo_monte_carlo(
        disney.MODEL, worst, [math.radians(89.9999)], n_samples=65536, phi=math.pi / 2
    )
    assert top.albedo[0, 0] - 4 * top.stderr[0, 0] < 1.0 + allowance("disney")


def test_gamma_other_than_two_is_left_uncompensated():
    wi, wo = _grid(), _grid()[::-1]
    p = _metal(0.5, specular_gamma=1.5)
    on = p.replace(energy_compensation=True)
    np.testing.assert_array_equal(disney.eval(p, wi, wo), disney.eval(on, wi, wo))


@pytest.mark.parametrize(
    "kw",
    [
        {"metallic": 1.0, "roughness": 0.6},
        {"roughness": 0.5, "specular_tint": 1.0},
        {"spec_trans": 1.0, "roughness": 0.5, "ior": 1.5},
    ],
    ids=["metal", "plastic", "glass"],
)
@pytest.mark.parametrize("theta", [30.0, 75.0])
def test_sampling_matches_pdf_chi2(kw, theta):
    p = DisneyParams(energy_compensation=True, **kw)
    view = (math.sin(math.radians(theta)), 0.0, math.cos(math.radians(theta)))
    r = chi2_details(disney.MODEL, p, view, 100_000, 12, alpha=SIGNIFICANCE)
    assert r.passed, (r.p_value, r.statistic, r.dof)


def test_sample_weight_is_eval_over_pdf_with_the_factor():
    p = _metal(0.8, energy_compensation=True)
    wo = np.array([0.6, 0.0, 0.8])
    u = np.random.default_rng(1).random((512, 3))
    wi, w, pdf = disney.sample(p, np.broadcast_to(wo, (512, 3)), u)
    ok = pdf > 0
    f = disney.eval(p, wi[ok], np.broadcast_to(wo, (int(ok.sum()), 3)))
    np.testing.assert_allclose(w[ok], f * wi[ok, 2:3] / pdf[ok, None], rtol=1e-9)


def test_table_matches_direct_integration_at_off_node_points():
    """The data module states the worst interpolation error; spot-check it off the nodes."""
    mu = np.array([0.0, 3e-4, 0.013, 0.21, 0.77])
    for r in (energy.R_MIN, 0.137, 0.55, 0.93):
        ref = energy_fit.albedo_integrated(mu, r, n=128)
        np.testing.assert_allclose(energy.albedo(mu, r), ref, atol=6e-3)


def test_table_nodes_span_the_glossy_range():
    mu, r = energy.table_nodes(energy.N_MU, energy.N_R)
    assert mu[0] == 0.0 and mu[-1] == 1.0 and r[0] == energy.R_MIN and r[-1] == 1.0
    assert energy.N_MU * energy.N_R == len(energy.VALUES)
    assert min(energy.VALUES) > 0.05  # 1/E stays finite and modest everywhere


def test_per_element_maps_give_the_constants_values():
    """A textured roughness and colour (the array path the plugin's textures take)."""
    wi, wo = _grid(8), _grid(8)[::-1]
    rough = np.linspace(0.0, 1.0, 8)
    base = np.random.default_rng(4).random((8, 3))
    p = DisneyParams(metallic=1.0, energy_compensation=True)
    mapped = disney.eval(p, wi, wo, roughness=rough, base_color=base)
    for k in range(1, 8):  # roughness 0: a delta as a constant, the clamped lobe as a map
        q = p.replace(roughness=float(rough[k]), base_color=tuple(base[k]))
        np.testing.assert_allclose(mapped[k], disney.eval(q, wi[k], wo[k]), rtol=1e-9)
