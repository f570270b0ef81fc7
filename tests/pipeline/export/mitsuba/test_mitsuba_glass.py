"""Smooth glass through the plugin is Mitsuba's ``dielectric``; rough glass is near
``roughdielectric`` (issue 16)."""

from __future__ import annotations

import numpy as np
import pytest
from _mitsuba_helpers import interaction as _interaction
from _mitsuba_helpers import mitsuba_module

from lookdev.materials.params import DisneyParams

pytestmark = pytest.mark.render
_mi = pytest.fixture(scope="module", name="mi")(mitsuba_module)

SMOOTH = DisneyParams(base_color=(1.0, 1.0, 1.0), spec_trans=1.0, roughness=0.0, ior=1.52)


def _bsdf(mi, params):
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    return mi.load_dict(bsdf_dict(params, allow_principled=False))


def test_smooth_glass_is_flagged_delta_so_lights_are_not_sampled(mi):
    f = mi.BSDFFlags
    smooth = _bsdf(mi, SMOOTH)
    assert smooth.flags() & f.DeltaReflection and smooth.flags() & f.DeltaTransmission
    assert not smooth.flags() & f.Smooth  # the path tracer skips emitter sampling
    assert smooth.flags() & f.NonSymmetric
    rough = _bsdf(mi, SMOOTH.replace(roughness=0.3))
    assert rough.flags() & f.GlossyTransmission and not rough.flags() & f.Delta
    mixed = _bsdf(mi, SMOOTH.replace(spec_trans=0.5))
    assert mixed.flags() & f.DiffuseReflection and mixed.flags() & f.DeltaTransmission


def test_sampled_type_and_component_say_which_delta_was_taken(mi):
    bsdf = _bsdf(mi, SMOOTH.replace(spec_trans=0.5, base_color=(0.8, 0.5, 0.3)))
    n = 8192
    rng = np.random.default_rng(2)
    view = np.tile([0.3, 0.1, 0.9487], (n, 1))
    si = _interaction(mi, view)
    u = rng.random((3, n))
    bs, value = bsdf.sample(mi.BSDFContext(), si, mi.Float(u[0]), mi.Point2f(u[1], u[2]))
    kind = np.array(bs.sampled_type)
    z = np.array(bs.wo)[2]
    ok = np.array(bs.pdf) > 0
    f = mi.BSDFFlags
    delta = (kind & int(f.Delta)) != 0
    assert delta.any() and (~delta & ok).any()
    assert np.all(kind[ok & delta & (z < 0)] == int(f.DeltaTransmission))
    assert np.all(kind[ok & delta & (z > 0)] == int(f.DeltaReflection))
    assert np.all(kind[ok & ~delta] == int(f.DiffuseReflection))
    # Each sample names the component it came from, and that component has its type.
    comp = np.array(bs.sampled_component)
    for c in set(comp[ok].tolist()):
        assert np.all(bsdf.flags(c) & kind[ok & (comp == c)])
    # Asked for its smooth components only, the BSDF gives the delta samples no weight.
    smooth_only = mi.BSDFContext(mi.TransportMode.Radiance, mi.BSDFFlags.Smooth)
    _, v2 = bsdf.sample(smooth_only, si, mi.Float(u[0]), mi.Point2f(u[1], u[2]))
    assert not np.any(np.array(v2).T[delta])


def _render(mi, bsdf, spp, seed):
    from lookdev.pipeline.export.mitsuba import scene_dict

    scene = scene_dict(SMOOTH, resolution=(24, 24), spp=spp, max_depth=12)
    scene["ball"]["bsdf"] = bsdf
    scene["environment"] = {
        "type": "envmap",
        "bitmap": mi.Bitmap(_sky()),
    }
    return np.array(mi.render(mi.load_dict(scene), seed=seed), dtype=np.float64)


def _sky():
    """A small lat-long with a bright patch, so refraction and reflection show."""
    h, w = 16, 32
    img = np.full((h, w, 3), 0.2, dtype=np.float32)
    img[3:6, 5:10] = (8.0, 6.0, 4.0)
    img[10:13, 20:26] = (0.5, 1.5, 3.0)
    return img


@pytest.mark.parametrize("tint", [(1.0, 1.0, 1.0), (0.55, 0.85, 0.55)], ids=["clear", "green"])
def test_smooth_glass_sphere_renders_as_mitsubas_dielectric(mi, tint):
    from lookdev.pipeline.bench.glass import builtin_dict
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    glass = SMOOTH.replace(base_color=tint)
    ours = _render(mi, bsdf_dict(glass, allow_principled=False), 64, 3)
    theirs = _render(mi, builtin_dict(glass), 64, 4)  # other seed: agree within noise
    again = _render(mi, builtin_dict(glass), 64, 5)
    noise = np.abs(theirs - again).mean()
    assert np.abs(ours - theirs).mean() < 1.5 * noise
    assert ours.mean() == pytest.approx(theirs.mean(), rel=0.02)
    # Same seed: the same choices (reflect with probability F) and weights, the same image;
    # tinted glass too: the tint is applied at every crossing, as dielectric's
    # specular_transmittance is (glass_green costs what dielectric costs, issue 16).
    same = _render(mi, builtin_dict(glass), 64, 3)
    np.testing.assert_allclose(ours, same, rtol=1e-3, atol=1e-4)


@pytest.mark.parametrize("roughness", [0.12, 0.35], ids=["ice", "frosted"])
def test_rough_glass_samples_as_roughdielectric_does(mi, roughness):
    """Per incidence (outside and inside), the plugin's sample weights have the mean (the
    albedo) and the mean square (the variance of one bounce) of Mitsuba's
    ``roughdielectric`` at the same GGX α and η: the two differ only in how (u1, u2) map
    to a visible normal, not in the noise they give (ice, issue 16)."""
    from lookdev.pipeline.bench.glass import builtin_dict

    glass = SMOOTH.replace(roughness=roughness, ior=1.31, base_color=(0.95, 0.98, 1.0))
    ours, theirs = _bsdf(mi, glass), mi.load_dict(builtin_dict(glass))
    n = 1 << 16
    rng = np.random.default_rng(5)
    for cos in (0.95, 0.5, 0.1, -0.1, -0.5, -0.95):
        view = np.tile([np.sqrt(1 - cos * cos), 0.0, cos], (n, 1))
        si = _interaction(mi, view)
        moments = []
        for bsdf in (ours, theirs):
            u = rng.random((3, n))
            _, value = bsdf.sample(mi.BSDFContext(), si, mi.Float(u[0]), mi.Point2f(u[1], u[2]))
            w = np.array(value, dtype=np.float64)[2]
            moments.append(
                (w.mean(), (w * w).mean(), w.std() / np.sqrt(n), (w * w).std() / np.sqrt(n))
            )
        (m1, m2, s1, s2), (t1, t2, e1, e2) = moments
        assert abs(m1 - t1) < 4 * np.hypot(s1, e1) + 1e-4, cos
        assert abs(m2 - t2) < 4 * np.hypot(s2, e2) + 1e-4, cos


def test_rough_glass_sphere_is_near_mitsubas_roughdielectric(mi):
    from lookdev.pipeline.bench.glass import builtin_dict
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    rough = SMOOTH.replace(roughness=0.35)
    ours = _render(mi, bsdf_dict(rough, allow_principled=False), 128, 3)
    theirs = _render(mi, builtin_dict(rough), 128, 4)
    assert ours.mean() == pytest.approx(theirs.mean(), rel=0.03)
