"""The plugins' ``eval_diffuse_reflectance``: the albedo guide of Mitsuba's ``aov`` integrator."""

from __future__ import annotations

import math

import numpy as np
import pytest
from _mitsuba_helpers import interaction, mitsuba_module, unit

from lookdev.materials.guides import albedo_guide
from lookdev.materials.params import DisneyParams
from lookdev.materials.registry import MODELS, model_of_params

pytestmark = pytest.mark.render
_mi = pytest.fixture(scope="module", name="mi")(mitsuba_module)

CASES = {
    "diffuse": DisneyParams(base_color=(0.8, 0.4, 0.2), roughness=0.5),
    "plastic": DisneyParams(base_color=(0.1, 0.3, 0.8), roughness=0.05),
    "metal": DisneyParams(base_color=(1.0, 0.78, 0.34), metallic=1.0, roughness=0.2),
    "glass": DisneyParams(base_color=(0.9, 0.7, 0.5), spec_trans=1.0, roughness=0.0, ior=1.5),
    "sheen": MODELS["sheen"].params_type(color=(0.9, 0.5, 0.3), roughness=0.3),
    "pixar": MODELS["pixar"].params_type(surface_color=(0.7, 0.3, 0.2), roughness=0.5),
}


def _plugin(mi, params):
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    return mi.load_dict(bsdf_dict(params, allow_principled=False))


@pytest.mark.parametrize("name", sorted(CASES))
def test_diffuse_reflectance_is_the_models_guide(mi, name):
    params = CASES[name]
    rng = np.random.default_rng(11)
    views = unit(rng.normal(size=(200, 3)))
    got = np.array(_plugin(mi, params).eval_diffuse_reflectance(interaction(mi, views))).T
    want = albedo_guide(model_of_params(params), params, views)
    np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-5)


def _plane_scene(mi, bsdf, tilt_deg):
    """An orthographic camera looking at a large plane at ``tilt_deg`` from its normal:
    every pixel sees the plane at that one angle."""
    t = math.radians(tilt_deg)
    origin = [5 * math.sin(t), 0.0, 5 * math.cos(t)]
    return mi.load_dict(
        {
            "type": "scene",
            "sensor": {
                "type": "orthographic",
                "to_world": mi.ScalarTransform4f().look_at(origin, [0, 0, 0], [0, 1, 0])
                @ mi.ScalarTransform4f().scale([0.5, 0.5, 1]),
                "film": {
                    "type": "hdrfilm",
                    "width": 8,
                    "height": 8,
                    "rfilter": {"type": "box"},
                    "pixel_format": "rgb",
                },
                "sampler": {"type": "independent", "sample_count": 4},
            },
            "plane": {
                "type": "rectangle",
                "to_world": mi.ScalarTransform4f().scale([20, 20, 1]),
                "bsdf": bsdf,
            },
        }
    )


@pytest.mark.parametrize("name", ["diffuse", "plastic", "metal", "glass"])
@pytest.mark.parametrize("tilt", [0.0, 60.0])
def test_aov_albedo_has_no_highlight_and_glass_is_not_black(mi, name, tilt):
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict
    from lookdev.pipeline.proof.denoise import AOVS

    params = CASES[name]
    scene = _plane_scene(mi, bsdf_dict(params, allow_principled=False), tilt)
    aov = mi.load_dict({"type": "aov", "aovs": AOVS})
    out = np.array(mi.render(scene, integrator=aov, seed=1))
    t = math.radians(tilt)
    view = np.array([math.sin(t), 0.0, math.cos(t)])
    want = albedo_guide(MODELS["disney"], params, view)
    albedo, normal = out[..., 0:3], out[..., 3:6]
    np.testing.assert_allclose(albedo, np.broadcast_to(want, albedo.shape), rtol=1e-4, atol=1e-5)
    np.testing.assert_allclose(normal, np.broadcast_to([0, 0, 1], normal.shape), atol=1e-5)
    if name == "diffuse" and tilt == 0.0:
        np.testing.assert_allclose(albedo[0, 0], params.base_color, rtol=1e-5)
    if name == "plastic":  # the highlight is not in it: the same as the diffuse alone
        diffuse_only = params.replace(specular=0.0)
        want_diffuse = albedo_guide(MODELS["disney"], diffuse_only, view)
        np.testing.assert_allclose(albedo[0, 0], want_diffuse, rtol=1e-5)
    if name == "glass":
        assert albedo.min() > 0.4
