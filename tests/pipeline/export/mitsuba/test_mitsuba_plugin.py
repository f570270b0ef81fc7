"""The generic Mitsuba BSDF plugin (pipeline/export/mitsuba/plugin.py).

Against a tiny two-lobe model (tests/_mitsuba_tiny.py), independent of the shipped
models (those are in test_mitsuba_models.py).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _mitsuba_helpers import interaction as _interaction
from _mitsuba_helpers import mitsuba_module
from _mitsuba_helpers import pixel_view_angles as _pixel_view_angles
from _mitsuba_helpers import unit as _unit
from _mitsuba_tiny import TINY, TinyParams

from lookdev.materials.bsdf import draw, evaluate
from lookdev.materials.errors import LookdevError

pytestmark = pytest.mark.render
_mi = pytest.fixture(scope="module", name="mi")(mitsuba_module)


@pytest.fixture(scope="module")
def tiny(mi):
    from lookdev.pipeline.export.mitsuba.plugin import register_model

    name = register_model(TINY)

    def load(**props):
        return mi.load_dict({"type": name, **props})

    load.name = name
    return load


def _random_directions(n, seed):
    return _unit(np.random.default_rng(seed).normal(size=(n, 3)))


def test_flags_follow_the_lobes_prepare_keeps(mi, tiny):
    opaque, translucent = tiny(translucency=0.0), tiny(translucency=0.3)
    f = mi.BSDFFlags
    assert opaque.component_count() == 1
    assert not opaque.flags() & f.Transmission
    assert opaque.flags() & f.DiffuseReflection
    assert translucent.component_count() == 2
    assert translucent.flags() & f.DiffuseTransmission


def test_eval_is_numpy_eval_times_light_cosine_with_names_swapped(mi, tiny):
    view = _random_directions(256, 1)  # Mitsuba si.wi: the viewer
    light = _random_directions(256, 2)  # Mitsuba wo: the light
    params = TinyParams(base_color=(0.9, 0.4, 0.1), translucency=0.25)
    bsdf = tiny(base_color=[0.9, 0.4, 0.1], translucency=0.25)
    got = np.array(bsdf.eval(mi.BSDFContext(), _interaction(mi, view), mi.Vector3f(light.T))).T
    want = evaluate(TINY, params, light, view) * np.abs(light[:, 2:3])
    np.testing.assert_allclose(got, want, rtol=2e-6, atol=1e-7)
    pdf = np.array(bsdf.pdf(mi.BSDFContext(), _interaction(mi, view), mi.Vector3f(light.T)))
    np.testing.assert_allclose(
        pdf,
        np.abs(light[:, 2]) / math.pi * np.where(view[:, 2] * light[:, 2] > 0, 0.75, 0.25),
        rtol=2e-6,
        atol=1e-7,
    )


def test_sample_matches_numpy_draw_and_eval_over_pdf(mi, tiny):
    rng = np.random.default_rng(3)
    view = _random_directions(128, 4)
    u = rng.random((128, 3))
    params = TinyParams(translucency=0.4)
    bsdf = tiny(translucency=0.4)
    si = _interaction(mi, view)
    bs, value = bsdf.sample(mi.BSDFContext(), si, mi.Float(u[:, 0]), mi.Point2f(u[:, 1], u[:, 2]))
    wi, weight, pdf = draw(TINY, params, view, u)
    np.testing.assert_allclose(np.array(bs.wo).T, wi, atol=1e-6)
    np.testing.assert_allclose(np.array(value).T, weight, rtol=1e-5)
    np.testing.assert_allclose(np.array(bs.pdf), pdf, rtol=1e-5)
    f, p = bsdf.eval_pdf(mi.BSDFContext(), si, bs.wo)
    np.testing.assert_allclose(np.array(f / p).T, np.array(value).T, rtol=1e-4)
    reflected = view[:, 2] * np.array(bs.wo)[2] > 0
    f_ = mi.BSDFFlags
    types = np.array(bs.sampled_type)
    assert np.all(types[reflected] == int(f_.DiffuseReflection))
    assert np.all(types[~reflected] == int(f_.DiffuseTransmission))


@pytest.mark.parametrize("translucency", [0.0, 0.3, 1.0])
@pytest.mark.parametrize("wi", [(0, 0, 1), (0.48, 0, 0.877), (0.999, 0, 0.0447), (0.3, 0.2, -0.93)])
def test_chi2(mi, tiny, translucency, wi):
    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain

    sample, pdf = BSDFAdapter(
        tiny.name, {"type": tiny.name, "translucency": translucency}, wi=_unit(wi).tolist()
    )
    test = ChiSquareTest(domain=SphericalDomain(), sample_func=sample, pdf_func=pdf, sample_dim=3)
    assert test.run(), test.messages


def test_traverse_updates_constants_and_flags(mi, tiny):
    bsdf = tiny(translucency=0.0)
    params = mi.traverse(bsdf)
    assert set(params.keys()) == {"translucency"}
    params["translucency"] = 0.5
    params.update()
    assert bsdf.flags() & mi.BSDFFlags.DiffuseTransmission
    si = _interaction(mi, [(0, 0, 1)])
    below = mi.Vector3f(0, 0, -1)
    assert np.allclose(
        np.array(bsdf.eval(mi.BSDFContext(), si, below)).ravel(),
        np.array(TinyParams().base_color) * 0.5 / math.pi,
        rtol=1e-6,
    )
    params["translucency"] = -1.0
    with pytest.raises(LookdevError, match="translucency"):
        params.update()


def test_texture_parameters_are_evaluated_at_the_hit(mi, tiny):
    # A 2×1 map: translucency 0 on the left half of UV space, 1 on the right.
    data = mi.TensorXf(np.array([[[0.0], [1.0]]], dtype=np.float32))
    bsdf = tiny(
        translucency={"type": "bitmap", "data": data, "raw": True, "filter_type": "nearest"}
    )
    assert bsdf.flags() & mi.BSDFFlags.SpatiallyVarying
    assert bsdf.flags() & mi.BSDFFlags.DiffuseTransmission
    below = mi.Vector3f(0, 0, -1)
    left = bsdf.eval(mi.BSDFContext(), _interaction(mi, [(0, 0, 1)], uv=(0.25, 0.5)), below)
    right = bsdf.eval(mi.BSDFContext(), _interaction(mi, [(0, 0, 1)], uv=(0.75, 0.5)), below)
    assert np.all(np.array(left) == 0)
    np.testing.assert_allclose(
        np.array(right).ravel(), np.array(TinyParams().base_color) / math.pi, rtol=1e-6
    )
    assert "translucency.data" in mi.traverse(bsdf).keys()


def test_force_all_lobes_traces_zero_weight_lobes(mi, tiny):
    forced = tiny(translucency=0.0, force_all_lobes=True)
    assert forced.flags() & mi.BSDFFlags.DiffuseTransmission
    below = mi.Vector3f(0, 0, -1)
    value = forced.eval(mi.BSDFContext(), _interaction(mi, [(0, 0, 1)]), below)
    assert np.all(np.array(value) == 0)


def test_context_type_mask_selects_a_hemisphere(mi, tiny):
    bsdf = tiny(translucency=0.5)
    ctx = mi.BSDFContext()
    ctx.type_mask = int(mi.BSDFFlags.Reflection)
    si = _interaction(mi, [(0, 0, 1), (0, 0, 1)])
    light = mi.Vector3f([0, 0], [0, 0], [1, -1])
    value = np.array(bsdf.eval(ctx, si, light))
    assert np.all(value[:, 0] > 0) and np.all(value[:, 1] == 0)


def test_unknown_parameter_is_one_line_error(mi, tiny):
    with pytest.raises(Exception, match="roughnes.*allowed: base_color, translucency"):
        tiny(roughnes=0.5)


def test_furnace_view_angles_off_centre(mi, monkeypatch):
    """The pixel-angle helper, checked where the tiny model's albedo ρ(1 + cos θ)/2 varies."""
    from lookdev.materials import registry
    from lookdev.pipeline.export.mitsuba.scene import scene_dict

    monkeypatch.setitem(registry.MODELS, "tiny_test", TINY)
    params = TinyParams(base_color=(0.8, 0.5, 0.2))
    scene = scene_dict(params, resolution=(32, 32), spp=512, max_depth=2)
    image = np.array(mi.render(mi.load_dict(scene), seed=2))
    rows, cols = np.mgrid[15:17, 24:26]
    theta = _pixel_view_angles(scene, rows, cols)
    assert 0.6 < theta.mean() < 1.2  # well off the normal
    expected = np.array([0.8, 0.5, 0.2]) * (0.5 + 0.5 * np.cos(theta)).mean()
    got = image[15:17, 24:26].reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(got, expected, rtol=0.02)


def test_chi2_rejects_a_pdf_that_does_not_match_sampling(mi, tmp_path, monkeypatch):
    """Negative control: the same chi2 set-up catches a model whose pdf is wrong."""
    import dataclasses

    monkeypatch.chdir(tmp_path)  # a failed test writes chi2_data.py into the working folder

    from mitsuba.chi2 import BSDFAdapter, ChiSquareTest, SphericalDomain

    from lookdev.pipeline.export.mitsuba.plugin import register_model

    def uniform_pdf(xp, p, wi, wo):  # sampling is cosine-weighted: this pdf is wrong
        return xp.select(wi[2] * wo[2] > 0, 1.0 / (2.0 * math.pi), 0.0)

    name = register_model(dataclasses.replace(TINY, name="tiny_broken", pdf=uniform_pdf))
    sample, pdf = BSDFAdapter(name, {"type": name}, wi=[0.0, 0.0, 1.0])
    test = ChiSquareTest(
        domain=SphericalDomain(),
        sample_func=sample,
        pdf_func=pdf,
        sample_dim=3,
        sample_count=200_000,
        res=61,
    )
    assert not test.run()


def test_traverse_updates_colours(mi, tiny):
    bsdf = tiny(base_color=[0.9, 0.9, 0.9])
    params = mi.traverse(bsdf)
    params["base_color"] = mi.Color3f(0.1, 0.2, 0.3)
    params.update()
    value = bsdf.eval(mi.BSDFContext(), _interaction(mi, [(0, 0, 1)]), mi.Vector3f(0, 0, 1))
    # Normal view and light: f·cos = ρ · (0.5 + 0.5) / π.
    np.testing.assert_allclose(
        np.array(value).ravel(), np.array([0.1, 0.2, 0.3]) / math.pi, rtol=1e-6
    )
