"""The denoiser's albedo guide (materials/guides.py) on the numpy backend, every model."""

from __future__ import annotations

import math

import numpy as np
import pytest

from lookdev.materials import disney
from lookdev.materials.arrays import NumpyOps
from lookdev.materials.bsdf import evaluate
from lookdev.materials.fresnel import dielectric
from lookdev.materials.guides import albedo_guide
from lookdev.materials.params import DisneyParams
from lookdev.materials.registry import MODELS

VIEWS = np.array(
    [[0.0, 0.0, 1.0], [0.6, 0.0, 0.8], [0.0, 0.96, 0.28], [0.995, 0.0, math.sqrt(1 - 0.995**2)]]
)
NORMAL = np.array([0.0, 0.0, 1.0])


def _diffuse_albedo(params, wo):
    """The model's diffuse albedo by Mitsuba's definition, π·f(n, wo), of the diffuse lobe."""
    return math.pi * evaluate(
        disney.lobe_model("diffuse"), params, np.broadcast_to(NORMAL, wo.shape), wo
    )


@pytest.mark.parametrize("roughness", [0.0, 0.5, 1.0])
def test_diffuse_guide_is_base_colour_times_the_diffuse_albedo(roughness):
    base = (0.8, 0.4, 0.2)
    p = DisneyParams(base_color=base, roughness=roughness)
    got = albedo_guide(MODELS["disney"], p, VIEWS)
    np.testing.assert_allclose(got, np.clip(_diffuse_albedo(p, VIEWS), 0, 1), rtol=1e-12)
    # Facing the viewer, Burley's diffuse is exactly Lambert: the guide is the base colour.
    np.testing.assert_allclose(got[0], base, rtol=1e-12)


def test_plastic_guide_has_no_highlight():
    """A glossy plastic's guide is its diffuse alone: the specular (a non-absorbing
    dielectric coat, OIDN) adds nothing, however near the mirror direction the view is."""
    p = DisneyParams(base_color=(0.1, 0.3, 0.8), roughness=0.05, specular=1.0)
    got = albedo_guide(MODELS["disney"], p, VIEWS)
    np.testing.assert_allclose(got, np.clip(_diffuse_albedo(p, VIEWS), 0, 1), rtol=1e-12)
    np.testing.assert_allclose(got[0], (0.1, 0.3, 0.8), rtol=1e-12)


def test_metal_guide_is_its_colour_at_normal_incidence():
    gold = (1.0, 0.78, 0.34)
    got = albedo_guide(MODELS["disney"], DisneyParams(base_color=gold, metallic=1.0), VIEWS)
    np.testing.assert_allclose(got, np.broadcast_to(gold, got.shape), rtol=1e-12)


@pytest.mark.parametrize("thin", [False, True])
def test_glass_guide_is_the_fresnel_blend_of_reflection_and_transmission(thin):
    tint = (0.9, 0.6, 0.3)
    p = DisneyParams(base_color=tint, spec_trans=1.0, roughness=0.0, ior=1.5, thin=thin)
    got = albedo_guide(MODELS["disney"], p, VIEWS)
    f = dielectric(NumpyOps(), VIEWS[:, 2], 1.5)[:, None]
    t = np.sqrt(tint) if thin else np.array(tint)
    np.testing.assert_allclose(got, f + (1 - f) * t, rtol=1e-12)
    assert got.min() > 0.3  # not black (Mitsuba's default π·f(n) is ~0 for glass)


def test_glass_seen_from_inside_uses_the_inverse_ior_and_total_reflection():
    p = DisneyParams(spec_trans=1.0, roughness=0.0, ior=1.5, base_color=(0.5, 0.5, 0.5))
    inside = np.array([[0.0, 0.0, -1.0], [0.9, 0.0, -math.sqrt(1 - 0.81)]])
    got = albedo_guide(MODELS["disney"], p, inside)
    f0 = ((1.5 - 1) / 2.5) ** 2
    np.testing.assert_allclose(got[0], f0 + (1 - f0) * 0.5, rtol=1e-9)
    np.testing.assert_allclose(got[1], 1.0)  # beyond the critical angle: all reflected


def test_opaque_solid_seen_from_below_has_no_albedo():
    p = DisneyParams(base_color=(1.0, 0.5, 0.2), metallic=0.5)
    assert np.all(albedo_guide(MODELS["disney"], p, np.array([0.0, 0.0, -1.0])) == 0)


@pytest.mark.parametrize("name", sorted(MODELS))
@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_every_model_guide_is_finite_and_in_unit_range(name, dtype):
    model = MODELS[name]
    rng = np.random.default_rng(7)
    wo = rng.normal(size=(512, 3))
    wo /= np.linalg.norm(wo, axis=-1, keepdims=True)
    wo = np.concatenate([wo, [[0, 0, 1], [0, 0, -1], [1, 0, 0]]])
    got = albedo_guide(model, model.params_type(), wo, dtype=dtype)
    assert got.shape == wo.shape
    assert np.all(np.isfinite(got)) and got.min() >= 0 and got.max() <= 1


def test_pixar_metal_and_glass_are_not_black_and_pixar_plastic_is_its_colour():
    pixar = MODELS["pixar"]
    up = np.array([0.0, 0.0, 1.0])
    metal = albedo_guide(pixar, pixar.params_type(metallic=1.0, roughness=0.3), up)
    glass = albedo_guide(pixar, pixar.params_type(clear=1.0, roughness=0.0), up)
    assert metal.min() > 0.3 and glass.min() > 0.3
    colour = (0.7, 0.3, 0.2)
    plastic = albedo_guide(pixar, pixar.params_type(surface_color=colour, roughness=1.0), up)
    # Smits: roughness 1 is all diffuse (dN = Mix[…, 1, rough] = 1), no highlight lobe.
    np.testing.assert_allclose(plastic, colour, rtol=1e-6)
