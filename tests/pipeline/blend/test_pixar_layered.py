"""Layered Pixar materials: Smits' composited lobe weights as the model's inputs.

A layered stack blends to lobe weights at the two ends of the view (lookdev.pipeline.blend
.pixar); :data:`lookdev.materials.pixar.LAYERED_MODEL` renders them with the same lobe
code as the plain model, and a plain material goes through the very same prepared path.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _blend_helpers import layer, layered
from chi2_harness import chi2_test
from hypothesis import given, settings
from hypothesis import strategies as st

from lookdev.library import Library, Material
from lookdev.materials import pixar, pixar_scatter
from lookdev.materials.bsdf import density, draw, evaluate
from lookdev.materials.layers import ConstantMask
from lookdev.materials.pixar import LAYERED_MODEL, PixarLobeWeights, PixarParams
from lookdev.pipeline.blend import blend
from lookdev.pipeline.blend.pixar import VIEWS
from lookdev.pipeline.blend.pixar_composite import composite, layer_lobes

P = PixarParams
EDGES = [
    P(),
    P(roughness=0.0),
    P(roughness=1.0),
    P(surface_color=(0.9, 0.6, 0.2), metallic=1.0, roughness=0.35),
    P(surface_color=1.0, roughness=0.2, clear=0.7, back=0.4, ior=1.45),
    P(roughness=0.004, specular_cone_scale=2.5, reflection_cone_scale=0.0, clear=0.3),
    P(roughness=0.6, normal_fresnel=20.0, grazing_fresnel=0.0, back=1.0, diffuse_scale=2.0),
]
GLAZE = P(surface_color=(0.9, 0.8, 0.7), roughness=0.1, clear=0.6, back=0.3)
CLAY = P(surface_color=(0.6, 0.3, 0.2), roughness=0.7)
LAYERED_PRESETS = ("pixar_painted_metal", "pixar_rusty_metal")


def plain(name: str, params: PixarParams) -> Material:
    return Material(name=name, model="pixar", params=params)


def as_weights(blended, row: int = 0, col: int = 0) -> PixarLobeWeights:
    """The blend's texel as the layered model's parameters (what the exporters hand on)."""
    fields = PixarLobeWeights.model_fields
    values = {k: v for k, v in blended.params_at(row, col).items() if k in fields}
    return PixarLobeWeights.parse(values)


def directions(n: int, seed: int) -> np.ndarray:
    v = np.random.default_rng(seed).normal(size=(n, 3))
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def views() -> np.ndarray:
    """Normal incidence, 60°, grazing (cos 1e-4), exactly tangent, below, and random."""
    fixed = [
        (0, 0, 1),
        (math.sin(1.047), 0, math.cos(1.047)),
        (1, 0, 1e-4),
        (1, 0, 0),
        (0.3, 0.2, -0.9),
    ]
    out = np.concatenate([np.array(fixed, dtype=float), directions(59, 1)])
    return out / np.linalg.norm(out, axis=1, keepdims=True)


def pairs(n: int = 4000):
    """(wi, wo): every view against many lights, mirror directions included."""
    wo = np.repeat(views(), n // 64, axis=0)
    wi = directions(len(wo), 2)
    wi[::7] = wo[::7] * np.array([-1.0, -1.0, 1.0])  # the mirror direction: the peaks
    return wi, wo


# -- one implementation --------------------------------------------------------------------
@pytest.mark.parametrize("params", EDGES, ids=range(len(EDGES)))
def test_plain_weights_drive_the_same_lobes_exactly(params):
    """as_lobe_weights(params) on LAYERED_MODEL is the plain model to float64 rounding."""
    w = pixar.as_lobe_weights(params)
    wi, wo = pairs()
    np.testing.assert_allclose(
        evaluate(LAYERED_MODEL, w, wi, wo), pixar.eval(params, wi, wo), rtol=1e-12, atol=1e-300
    )
    np.testing.assert_allclose(
        density(LAYERED_MODEL, w, wi, wo), pixar.pdf(params, wi, wo), rtol=1e-12, atol=1e-300
    )
    u = np.random.default_rng(3).random((len(wo), 3))
    for got, want in zip(draw(LAYERED_MODEL, w, wo, u), pixar.sample(params, wo, u), strict=True):
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("params", EDGES, ids=range(len(EDGES)))
def test_one_layer_stack_with_presence_1_is_the_preset(params):
    """Blended (full and simple layering), the lone layer evaluates as itself: the weights
    and cones go through float32 maps, so to float32 precision."""
    for mode in ("full", "simple"):
        w = as_weights(blend(layered(layer(plain("only", params))), 2, layering=mode))
        assert w.ior == pytest.approx(params.eta, rel=1e-6)
        wi, wo = pairs()
        f_plain, f_layered = pixar.eval(params, wi, wo), evaluate(LAYERED_MODEL, w, wi, wo)
        np.testing.assert_allclose(f_layered, f_plain, rtol=2e-5, atol=1e-9 * f_plain.max())
        p_plain, p_layered = pixar.pdf(params, wi, wo), density(LAYERED_MODEL, w, wi, wo)
        np.testing.assert_allclose(p_layered, p_plain, rtol=2e-5, atol=1e-9 * p_plain.max())


unit = st.floats(0.0, 1.0)
RANDOM_PARAMS = st.builds(
    P,
    surface_color=st.tuples(unit, unit, unit),
    metallic=unit,
    roughness=unit,
    clear=unit,
    back=unit,
    normal_fresnel=st.floats(0.0, 20.0),
    grazing_fresnel=unit,
    specular_cone_scale=st.floats(0.0, 2.5),
    reflection_cone_scale=st.floats(0.0, 2.5),
    specular_t_scale=unit,
    diffuse_t_scale=unit,
)


@settings(max_examples=30, deadline=None)
@given(params=RANDOM_PARAMS, mode=st.sampled_from(["full", "simple"]))
def test_any_one_layer_stack_is_its_preset(params, mode):
    """Property: over random parameters, the blended lone layer evaluates as the preset."""
    w = as_weights(blend(layered(layer(plain("only", params))), 1, layering=mode))
    wi, wo = pairs(640)
    f_plain, f_layered = pixar.eval(params, wi, wo), evaluate(LAYERED_MODEL, w, wi, wo)
    np.testing.assert_allclose(f_layered, f_plain, rtol=2e-5, atol=1e-9 * max(f_plain.max(), 1.0))


def test_an_unset_grazing_weight_does_not_change_with_the_view():
    """``<weight>_grazing`` left unset is the normal-view weight; set, the weight fades
    to it as s = (1 − V·n)⁵ goes to 1."""
    wo = np.array([[0.0, 0.0, 1.0], [0.8, 0.0, 0.6], [1.0, 0.0, 1e-6]])
    wo /= np.linalg.norm(wo, axis=1, keepdims=True)
    wi = np.broadcast_to(np.array([-0.3, 0.0, 0.95]) / math.hypot(0.3, 0.95), wo.shape)
    steady = evaluate(LAYERED_MODEL, PixarLobeWeights(diffN=0.5), wi, wo)
    cos_i = 0.95 / math.hypot(0.3, 0.95)
    expected = (0.5 + (0.0 - 0.5) * (1 - cos_i) ** 5) / math.pi  # FrnBlend[diffN, diffG, l·n]
    np.testing.assert_allclose(steady, expected, rtol=1e-12)
    fading = evaluate(LAYERED_MODEL, PixarLobeWeights(diffN=0.5, diffN_grazing=0.0), wi, wo)
    s = (1.0 - wo[:, 2]) ** 5
    np.testing.assert_allclose(fading, steady * (1.0 - s)[:, None], rtol=1e-12)
    assert fading[0, 0] == steady[0, 0] and fading[2, 0] < 1e-5 * steady[2, 0]


@pytest.mark.slow
def test_stability_sweep_finds_no_nan_inf_negative_or_crash():
    """``lookdev check``'s sweep (every field at its extremes, stiff directions, float32
    and float64, per-element maps) on the composited-weights model. Energy is not judged
    here: arbitrary weights need not partition energy; composites do (tested below)."""
    from lookdev.pipeline.analysis.stability import check_model

    report = check_model("pixar_layered", LAYERED_MODEL)
    assert report.cases > 10_000
    bad = {k: n for k, n in report.counts.items() if k != "energy_gain" and n}
    assert not bad, {k: report.failures[k].case for k in bad}


# -- view dependence: interpolation in s = (1 − V·n)⁵ ------------------------------------------
def _weights_at(stack_params, alphas, cos_view, mode):
    stack = [(layer_lobes(p, cos_view), a) for p, a in zip(stack_params, alphas, strict=True)]
    return composite(stack, mode)[0]


@pytest.mark.parametrize("mode", ["simple", "full"])
def test_interpolation_in_s_is_exact_where_the_blend_says(mode):
    """Simple layering is affine in s: exact at every view. Full layering multiplies
    view-dependent weights: exact at both ends, an interpolation in between (measured)."""
    top_first, alphas = [GLAZE, CLAY], [0.6, 1.0]
    stack = layered(
        layer(plain("clay", CLAY)), layer(plain("glaze", GLAZE), ConstantMask(value=0.6))
    )
    w = as_weights(blend(stack, 1, layering=mode))
    from lookdev.materials.arrays import NumpyOps

    xp = NumpyOps()
    prep = LAYERED_MODEL.prepare(xp, w)
    worst = 0.0
    for cos_view in (1.0, 0.9, 0.6, 0.3, 0.05, 0.0):
        direct = _weights_at(top_first, alphas, cos_view, mode)
        interp = pixar_scatter.at_view(xp, prep.ends, np.array([cos_view]))
        for lobe, part in direct.items():
            name = pixar_scatter.PREFIX[lobe]
            got = np.stack([np.ravel(interp[name + "N"]), np.ravel(interp[name + "G"])])
            err = np.max(np.abs(got - np.stack([part.n, part.g])))
            if cos_view in VIEWS.values() or mode == "simple":
                assert err < 1e-6, (lobe, cos_view)  # float32 maps
            worst = max(worst, err)
    if mode == "full":
        # Measured 1.5e-3 at V·n = 0.05: between the ends, the glaze's view-dependent
        # transmitted diffuse times the clay's is quadratic in s, not affine.
        assert 1e-5 < worst < 5e-3


# -- energy -------------------------------------------------------------------------------
def _albedo(weights: PixarLobeWeights, cos_view: float, maps: dict, n: int = 4096):
    """Mean sample weight over all directions (reflected + transmitted), per texel."""
    k = len(next(iter(maps.values()))) if maps else 1
    wo = np.broadcast_to([math.sqrt(1 - cos_view**2), 0.0, cos_view], (k, n, 3))
    u = np.random.default_rng(11).random((k, n, 3))
    _, weight, pdf = draw(LAYERED_MODEL, weights, wo, u, **maps)
    weight = np.where((pdf > 0)[..., None], weight, 0.0)
    return weight.mean(axis=1), weight.std(axis=1) / math.sqrt(n)


@pytest.mark.slow
@pytest.mark.parametrize("name", LAYERED_PRESETS)
def test_builtin_layered_pixar_presets_never_reflect_more_than_arrives(name):
    blended = blend(Library(use_env=False).load(name), 64)  # coarser, the noise masks average out
    w = as_weights(blended)
    pick = np.linspace(0, 64 * 64 - 1, 48).astype(int)
    maps = {
        k: (a.reshape(-1, 3) if a.ndim == 3 else a.reshape(-1))[pick][:, None]
        for k, a in blended.maps.items()
        if k in PixarLobeWeights.model_fields
    }
    assert maps, "the preset's masks vary: its weights must be maps"
    for cos_view in (1.0, 0.5, 0.1, 1e-3):
        mean, err = _albedo(w, cos_view, maps)
        assert np.all(mean <= 1.0 + 4 * err + 1e-9), (cos_view, mean.max())
        assert np.all(mean > 0.0)


# -- sampling -----------------------------------------------------------------------------
TWO_LAYERS = [
    pytest.param(GLAZE, CLAY, 0.6, id="glaze-over-clay"),
    pytest.param(
        P(roughness=0.15, clear=1.0), P(roughness=0.3, metallic=1.0), 0.5, id="clear-over-metal"
    ),
]


@pytest.mark.parametrize(("top", "bottom", "alpha"), TWO_LAYERS)
@pytest.mark.parametrize(
    "view", [(0.05, 0.0, 1.0), (0.866, 0.0, 0.5), (0.996, 0.0, 0.087), (0.3, 0.2, -0.93)]
)
def test_chi2_of_a_composited_material(top, bottom, alpha, view):
    """Near normal, 60°, 85° and from below. Not exactly normal: a 1° lobe centred on
    the pole falls between the harness's (cos θ, φ) quadrature nodes there, and the
    plain model fails that view the same way (expected mass short by 30 %)."""
    stack = layered(layer(plain("b", bottom)), layer(plain("t", top), ConstantMask(value=alpha)))
    w = as_weights(blend(stack, 1))
    wo = np.array(view) / np.linalg.norm(view)
    passed, p_value = chi2_test(LAYERED_MODEL, w, wo, n_samples=50_000, res=8)[:2]
    assert passed, p_value


# -- Dr.Jit ------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def mi():
    pytest.importorskip("mitsuba")
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba

    return mitsuba


def test_drjit_backend_agrees_with_numpy_on_composited_weights(mi):
    """Constants and per-element maps (both view ends mapped) through both backends."""
    from lookdev.materials.arrays import DrJitOps

    stack = layered(
        layer(plain("clay", CLAY)), layer(plain("glaze", GLAZE), ConstantMask(value=0.6))
    )
    w = as_weights(blend(stack, 1))
    rng = np.random.default_rng(5)
    n = 256
    wi, wo = directions(n, 6), directions(n, 7)
    u = rng.random((n, 3))
    scale = rng.uniform(0.5, 1.0, n)
    maps = {
        "diffN": np.asarray(w.diffN)[:, None] * scale,
        "diffN_grazing": np.asarray(w.diffN_grazing)[:, None] * scale[::-1],
        "specular_cone": 30.0 * scale,
        "ior": 1.0 + scale,
    }
    xp = DrJitOps.for_mitsuba()
    dmaps = {
        k: (xp.Array3(*map(mi.Float, v)) if v.ndim == 2 else mi.Float(v)) for k, v in maps.items()
    }
    prepared = LAYERED_MODEL.prepare(xp, w, **dmaps)
    vi, vo = mi.Vector3f(wi.T), mi.Vector3f(wo.T)
    nmaps = {k: (v.T if v.ndim == 2 else v) for k, v in maps.items()}
    got = np.array(LAYERED_MODEL.eval(xp, prepared, vi, vo)).T
    np.testing.assert_allclose(
        got, evaluate(LAYERED_MODEL, w, wi, wo, **nmaps), rtol=2e-4, atol=1e-6
    )
    got_pdf = np.array(LAYERED_MODEL.pdf(xp, prepared, vi, vo))
    np.testing.assert_allclose(
        got_pdf, density(LAYERED_MODEL, w, wi, wo, **nmaps), rtol=2e-4, atol=1e-6
    )
    d_wi, _, d_pdf, _ = LAYERED_MODEL.sample(xp, prepared, vo, mi.Vector3f(u.T))
    n_wi, _, n_pdf = draw(LAYERED_MODEL, w, wo, u, **nmaps)
    np.testing.assert_allclose(np.array(d_wi).T, n_wi, atol=1e-4)
    np.testing.assert_allclose(np.array(d_pdf), n_pdf, rtol=1e-3, atol=1e-5)


def test_mitsuba_renders_a_one_layer_stack_as_the_preset(mi):
    """Plugin eval/pdf and a tiny render of the blended one-layer stack equal the preset's."""
    from _mitsuba_helpers import interaction

    from lookdev.pipeline.export.mitsuba import bsdf_dict, scene_dict

    params = P(surface_color=(0.8, 0.5, 0.2), roughness=0.3, clear=0.4, back=0.2, metallic=0.3)
    stacked = layered(layer(plain("only", params)), name="only")
    b_plain = mi.load_dict(bsdf_dict(params))
    stacked = blend(stacked, 2)
    stack_dict = bsdf_dict(stacked)
    assert stack_dict["type"] == "lookdev_pixar_layered"
    b_stack = mi.load_dict(stack_dict)
    ctx = mi.BSDFContext()
    for wi in ((0.0, 0.0, 1.0), (0.7, 0.1, 0.3), (0.99, 0.0, 0.02)):
        si = interaction(mi, wi)
        wo = mi.Vector3f(directions(64, 9).T)
        for fn in ("eval", "pdf"):
            a = np.array(getattr(b_plain, fn)(ctx, si, wo))
            b = np.array(getattr(b_stack, fn)(ctx, si, wo))
            np.testing.assert_allclose(b, a, rtol=2e-5, atol=1e-7)
    images = []
    for material in (params, stacked):
        scene = mi.load_dict(scene_dict(material, resolution=(16, 16), spp=4))
        images.append(np.array(mi.render(scene, seed=3)))
    np.testing.assert_allclose(images[1], images[0], rtol=1e-4, atol=1e-5)


def test_white_furnace_sphere_shows_the_composites_albedo(mi):
    """Glaze over clay (mask 0.6) under a white sky, single scattering: the rendered
    sphere's centre is the numpy model's reflected albedo at the pixels' view angles."""
    from _mitsuba_helpers import pixel_view_angles

    from lookdev.pipeline.analysis.albedo import albedo_monte_carlo
    from lookdev.pipeline.export.mitsuba import scene_dict

    stack = layered(
        layer(plain("clay", CLAY)), layer(plain("glaze", GLAZE), ConstantMask(value=0.6))
    )
    blended = blend(stack, 1)
    scene = scene_dict(blended, resolution=(32, 32), spp=512, max_depth=2)
    assert scene["ball"]["bsdf"]["type"] == "lookdev_pixar_layered"
    image = np.array(mi.render(mi.load_dict(scene), seed=1))
    rows, cols = np.mgrid[14:18, 14:18]
    theta, count = np.unique(np.round(pixel_view_angles(scene, rows, cols), 9), return_counts=True)
    albedo = albedo_monte_carlo(LAYERED_MODEL, as_weights(blended), theta, n_samples=65536).albedo
    expected = (albedo * count[:, None]).sum(axis=0) / count.sum()
    got = image[14:18, 14:18].reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(got, expected, rtol=0.02, atol=2e-3)


@pytest.mark.parametrize("name", LAYERED_PRESETS)
def test_builtin_layered_pixar_presets_become_bsdfs(mi, name):
    from lookdev.pipeline.export.mitsuba.depth import max_depth_for
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict, plugin_inputs

    hub = blend(Library(use_env=False).load(name), 16)
    assert hub.bsdf_model is LAYERED_MODEL
    # Highlight weights do not change with the view: their grazing copies are left out.
    constants, maps = plugin_inputs(hub)
    assert not {"specN_grazing", "reflN_grazing"} & {*maps, *constants}
    bsdf = mi.load_dict(bsdf_dict(hub))
    assert bsdf.flags() & mi.BSDFFlags.GlossyReflection
    assert max_depth_for(hub) in (4, 6)


# -- the commands ---------------------------------------------------------------------------
@pytest.mark.slow
def test_proof_of_a_layered_pixar_preset(cli, tmp_path):
    out = tmp_path / "proof"
    r = cli("proof", "pixar_rusty_metal", "--ibl", "studio", "--frames", "2", "--light-frames",
            "0", "--spp", "4", "--resolution", "32", "32", "-o", str(out), "-j", "1")  # fmt: skip
    assert r.code == 0, r.err
    folder = out / "pixar_rusty_metal" / "studio"
    assert len(list(folder.glob("frame_???.exr"))) == 2  # the raw frames
    assert len(list(folder.glob("frame_???_denoised.exr"))) == 2  # denoised by default


@pytest.mark.slow
def test_plot_of_a_layered_pixar_preset(cli, tmp_path):
    hub = blend(Library(use_env=False).load("pixar_painted_metal"), 64)
    assert hub.bsdf_model is LAYERED_MODEL and hub.maps
    for view in ("albedo", "sphere"):
        r = cli("plot", "pixar_painted_metal", "--view", view, "-o", str(tmp_path / f"{view}.png"))
        assert r.code == 0, r.err
        assert (tmp_path / f"{view}.png").stat().st_size > 0


SATIN = P(surface_color=(0.9, 0.8, 0.7), roughness=0.6, clear=0.6, back=0.3)


@pytest.mark.slow
@pytest.mark.parametrize("view", [(0.866, 0.0, 0.5), (0.3, 0.2, -0.93)], ids=["60deg", "below"])
def test_mitsuba_chi2_of_the_layered_plugin(mi, view):
    """``mitsuba.chi2`` of lookdev_pixar_layered over the whole sphere: a translucent satin
    (no lobe narrower than 23°, which the whole-sphere chart resolves) over clay."""
    from _mitsuba_chi2 import chi2

    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    stack = layered(
        layer(plain("clay", CLAY)), layer(plain("satin", SATIN), ConstantMask(value=0.6))
    )
    bsdf = bsdf_dict(blend(stack, 1))
    assert bsdf["type"] == "lookdev_pixar_layered"
    passed, test = chi2(bsdf, np.array(view) / np.linalg.norm(view), test_count=3)
    assert passed, test.messages


@pytest.mark.slow
def test_mitsuba_chi2_zoomed_on_the_composited_mirror_peak(mi):
    """The glaze's 1° reflection cone, composited over clay, on a chart around its mirror
    direction (as tests/pipeline/export/mitsuba/test_mitsuba_models.py zooms on narrow peaks). 10⁶
    samples: at 2·10⁵ this seed gave p = 0.0015 (the plain glaze 0.058), at 10⁶ p = 0.56; an error
    in the composite's sampler would show more clearly with more samples, not less."""
    from _mitsuba_chi2 import chi2

    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    stack = layered(
        layer(plain("clay", CLAY)), layer(plain("glaze", GLAZE), ConstantMask(value=0.6))
    )
    blended = blend(stack, 1)
    assert blended.constants["reflection_cone"] == pytest.approx(1.0)
    wi = np.array([0.866, 0.0, 0.5])
    mirror = np.array([-wi[0], -wi[1], wi[2]])
    radius = 12.0 * math.radians(1.0)
    bsdf = bsdf_dict(blended)
    passed, test = chi2(bsdf, wi, axis=mirror, radius=radius, test_count=3, sample_count=10**6)
    assert passed, test.messages
