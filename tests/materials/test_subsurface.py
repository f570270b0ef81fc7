"""The (colour, scatter distance) ↔ medium mapping and the solid's boundary lobes."""

import numpy as np
import pytest

from lookdev.materials import disney
from lookdev.materials.params import DisneyParams, ParameterError
from lookdev.materials.subsurface import (
    JENSEN_2001,
    REFLECTANCE_MAX,
    SLAB_TABLE,
    albedo_of,
    colour_for_albedo,
    from_measured,
    has_interior,
    interior,
    scatter_distances,
)


def test_inversion_round_trips_up_to_the_boundary_s_cap():
    a = np.linspace(0.0, REFLECTANCE_MAX, 101)
    assert np.allclose(colour_for_albedo(albedo_of(a)), a, atol=1e-9)
    # brighter colours than a slab of albedo 1 reflects take albedo 1 (the cap)
    assert np.all(albedo_of([REFLECTANCE_MAX, 0.9, 1.0]) == 1.0)
    assert albedo_of(0.0) == 0.0 and colour_for_albedo(1.0) == REFLECTANCE_MAX


def test_the_slab_table_is_increasing_and_tighter_than_the_fit_it_replaces():
    a, alpha = np.array(SLAB_TABLE).T
    assert np.all(np.diff(a) > 0) and np.all(np.diff(alpha) > 0)
    assert SLAB_TABLE[0] == (0.0, 0.0) and SLAB_TABLE[-1][1] == 1.0
    # Chiang-Kutz-Burley's α(A) = 1 − exp(−5.09406 A + 2.61188 A² − 4.31805 A³) gives
    # less albedo than our slab needs (its slab reflected 4-14 % too little).
    ckb = 1.0 - np.exp(a * (-5.09406 + a * (2.61188 - 4.31805 * a)))
    assert np.all(ckb[1:-1] < alpha[1:-1])


def test_interior_follows_the_seed_and_scales_with_the_scene_unit():
    p = DisneyParams(base_color=(0.8, 0.8, 0.8), scatter_distance=0.5)
    sigma_t, albedo = interior(p)
    assert np.allclose(sigma_t, 1.0 / (1.1 * 0.5))  # s(0.8) = 1.1: CalculateExtinction
    assert np.allclose(interior(p, 0.05)[0], sigma_t * 0.05)
    assert np.all(albedo < 1.0)


def test_measured_media_convert_back_to_their_coefficients():
    for ss, sa in JENSEN_2001.values():
        colour, d, scale = from_measured(ss, sa)
        p = DisneyParams(base_color=colour, scatter_distance=d, scatter_distance_scale=scale)
        sigma_t, albedo = interior(p, 1e-3)  # per millimetre
        ss, sa = np.asarray(ss), np.asarray(sa)
        assert np.allclose(sigma_t, ss + sa, rtol=1e-6)
        keep = np.asarray(colour) < REFLECTANCE_MAX  # the cap: albedo 1 and beyond
        assert np.allclose(albedo[keep], (ss / (ss + sa))[keep], atol=1e-6)


def test_per_channel_distance_and_its_float32_floor():
    p = DisneyParams(scatter_distance=0.01, scatter_distance_scale=(1.0, 0.5, 0.25))
    assert np.allclose(scatter_distances(p), (0.01, 0.005, 0.0025))
    with pytest.raises(ParameterError, match="scatter_distance"):
        DisneyParams.parse({"scatter_distance": 1e-6, "scatter_distance_scale": [1, 0.5, 0.5]})


def test_only_solid_materials_with_a_distance_have_an_interior():
    assert has_interior(DisneyParams(scatter_distance=0.1))
    assert not has_interior(DisneyParams(scatter_distance=0.1, thin=True))
    assert not has_interior(DisneyParams(subsurface=0.5))


def _albedo(p, cos_o, inside=False, n=200_000):
    u = np.random.default_rng(1).random((n, 3))
    wo = np.broadcast_to([np.sqrt(1 - cos_o**2), 0.0, -cos_o if inside else cos_o], (n, 3))
    wi, w, pdf = disney.sample(p, wo, u)
    return np.where((pdf > 0)[:, None], w, 0.0).mean(axis=0)


def test_the_boundary_keeps_the_light_below_one_from_inside():
    p = DisneyParams(base_color=(1, 1, 1), scatter_distance=0.1, roughness=0.5)
    assert set(disney.MODEL.prepare(disney.NumpyOps(), p).lobes) >= {"diff_trans"}
    for c in (1.0, 0.5, 0.1):
        assert np.all(_albedo(p, c, inside=True) <= 1.0)


def test_thin_and_distance_free_presets_keep_the_2012_blend():
    wi = np.array([0.3, 0.0, 0.954])
    wo = np.array([0.0, 0.0, 1.0])
    hk = DisneyParams(subsurface=0.6)
    thin = DisneyParams(subsurface=0.6, thin=True, scatter_distance=0.1)
    assert np.allclose(disney.eval(hk, wi, wo), disney.eval(hk.replace(thin=True), wi, wo))
    assert np.allclose(disney.eval(thin, wi, wo), disney.eval(hk.replace(thin=True), wi, wo))
