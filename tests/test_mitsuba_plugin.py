"""The generic Mitsuba BSDF plugin (pipeline/export/mitsuba/plugin.py).

First against a tiny two-lobe model (tests/_mitsuba_tiny.py), then against the shipped
models.
"""

from __future__ import annotations

import gc
import math

import numpy as np
import pytest
from _mitsuba_tiny import TINY, TinyParams

from lookdev.materials.bsdf import draw, evaluate
from lookdev.materials.errors import LookdevError

pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def mi():
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba

    return mitsuba


@pytest.fixture(scope="module")
def tiny(mi):
    from lookdev.pipeline.export.mitsuba.plugin import register_model

    name = register_model(TINY)

    def load(**props):
        return mi.load_dict({"type": name, **props})

    load.name = name
    return load


def _interaction(mi, wi, uv=(0.5, 0.5)):
    import drjit as dr

    wi = np.atleast_2d(np.asarray(wi, dtype=np.float32))
    si = dr.zeros(mi.SurfaceInteraction3f, len(wi))
    si.wi = mi.Vector3f(wi.T)
    si.uv = mi.Point2f(*uv)
    return si


def _unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


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


# -- the shipped models ------------------------------------------------------------------
# (model, parameters, id, sharpest α or None): the grid of the issue, extremes included.
CASES = [
    ("sheen", {"roughness": 0.0}, "sheen-r0", None),
    ("sheen", {"roughness": 0.3, "color": [0.9, 0.5, 0.3]}, "sheen-r0.3", None),
    ("sheen", {"roughness": 1.0, "terminator_softening": False}, "sheen-r1-reciprocal", None),
    ("disney", {"roughness": 0.0}, "disney-r0", 1e-3),
    ("disney", {"roughness": 1.0}, "disney-r1", 1.0),
    ("disney", {"roughness": 0.3, "anisotropic": 1.0}, "disney-aniso1", 0.028),
    ("disney", {"metallic": 1.0, "roughness": 0.2}, "disney-metal", 0.04),
    ("disney", {"metallic": 0.0, "roughness": 0.5, "specular_tint": 1.0}, "disney-tinted", 0.25),
    ("disney", {"clearcoat": 1.0, "clearcoat_gloss": 1.0, "roughness": 0.6}, "disney-coat1", 1e-3),
    ("disney", {"clearcoat": 1.0, "clearcoat_gloss": 0.5, "roughness": 0.6}, "disney-coat.5", 0.05),
    ("disney", {"spec_trans": 1.0, "roughness": 0.1, "ior": 1.5}, "disney-glass", 0.01),
    ("disney", {"spec_trans": 1.0, "roughness": 0.3, "thin": True}, "disney-thin-glass", 0.035),
    ("disney", {"diff_trans": 0.7, "thin": True, "flatness": 0.5}, "disney-leaf", 0.25),
    ("disney", {"sheen": 1.0, "sheen_tint": 0.5, "subsurface": 1.0}, "disney-sheen", 0.25),
    (
        "disney",
        {"sheen": 1.0, "sheen_model": "conty_kulla", "sheen_roughness": 0.5},
        "disney-ck-sheen",
        0.25,
    ),
    # Pixar: "α" here is the reflection cone's half-angle in radians (10·r degrees).
    ("pixar", {"roughness": 0.0}, "pixar-r0", math.radians(0.5)),
    ("pixar", {"roughness": 0.3}, "pixar-r0.3", math.radians(3.0)),
    ("pixar", {"roughness": 1.0}, "pixar-r1", None),
    ("pixar", {"metallic": 1.0, "roughness": 0.4}, "pixar-metal", math.radians(4.0)),
    ("pixar", {"clear": 1.0, "roughness": 0.6, "ior": 1.5}, "pixar-clear", math.radians(6.0)),
    ("pixar", {"back": 1.0, "roughness": 0.8}, "pixar-back", None),
]
# Views: normal incidence, 60°, nearly grazing (85°), and from below for transmitters.
VIEWS = {
    "normal": (0.0, 0.0, 1.0),
    "60deg": (math.sin(math.radians(60)), 0.0, math.cos(math.radians(60))),
    "85deg": (math.sin(math.radians(85)), 0.0, math.cos(math.radians(85))),
    "below": (0.3, 0.2, -0.93),
}
GLOBAL_MIN_ALPHA = 0.1  # narrower peaks need the zoomed chart (tests/_mitsuba_chi2.py)
# Dr.Jit's backend evaluates both branches of a select on Python floats, and its expm1
# then divides by log(1) = 0: Pixar's weightS at roughness 0 (a constant) raises.
EXPM1_OF_FLOATS = "arrays.DrJitOps.expm1 divides by zero on Python floats near 0"


def _known_failure(name, check):
    """Run ``check``; a known model-side failure ends as xfail with its BSDFs released.

    Mitsuba traces every live BSDF instance in a render's virtual calls, so one that
    raises while traced must not outlive its test (a failing test's traceback would keep
    it alive and break every later render).
    """
    if name != "pixar-r0":
        return check()
    try:
        check()
    except ZeroDivisionError:
        raised = True
    else:
        raised = False
    gc.collect()
    if raised:
        pytest.xfail(EXPM1_OF_FLOATS)
    pytest.fail(f"{name} passes now: remove it from the known failures")


def _case_params(model_name, values):
    from lookdev.pipeline.export.mitsuba.plugin import MitsubaExportError
    from lookdev.pipeline.export.mitsuba.scene import model_for

    try:
        model = model_for(model_name)
    except MitsubaExportError as exc:
        pytest.skip(str(exc))
    return model, model.params_type.parse(values)


def _plugin(mi, params):
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    d = bsdf_dict(params, allow_principled=False)
    assert d["type"].startswith("lookdev_")
    return d


def _views(values):
    transmits = any(values.get(k) for k in ("spec_trans", "diff_trans", "clear", "back"))
    return [v for v in VIEWS if v != "below" or transmits]


def _peaks(values, wi):
    """(name, axis) of each narrow peak seen from ``wi``: mirror, refraction, or through."""
    wi = _unit(wi)
    peaks = [("mirror", np.array([-wi[0], -wi[1], wi[2]]))]
    if values.get("spec_trans") and values.get("thin"):
        peaks.append(("through", -wi))
    elif values.get("spec_trans"):
        eta = values.get("ior", 1.5) if wi[2] > 0 else 1.0 / values.get("ior", 1.5)
        cos_t = -np.sign(wi[2]) * math.sqrt(1.0 - (1.0 - wi[2] ** 2) / eta**2)
        peaks.append(("refract", -wi / eta + np.array([0.0, 0.0, wi[2] / eta + cos_t])))
    return peaks


GLOBAL_CASES = [
    pytest.param(model, values, view, id=f"{name}-{view}")
    for model, values, name, alpha in CASES
    for view in _views(values)
    if alpha is None or alpha >= GLOBAL_MIN_ALPHA
]
PEAK_CASES = [
    pytest.param(model, values, view, peak, alpha, name, id=f"{name}-{view}-{peak}")
    for model, values, name, alpha in CASES
    if alpha is not None
    for view in _views(values)
    for peak, _ in _peaks(values, VIEWS[view])
]

CHI2_TESTS = len(GLOBAL_CASES) + len(PEAK_CASES)


@pytest.mark.slow
@pytest.mark.parametrize(("model_name", "values", "view"), GLOBAL_CASES)
def test_chi2_whole_sphere(mi, model_name, values, view):
    from _mitsuba_chi2 import chi2

    _, params = _case_params(model_name, values)
    passed, test = chi2(_plugin(mi, params), _unit(VIEWS[view]), test_count=CHI2_TESTS)
    assert passed, test.messages


@pytest.mark.slow
@pytest.mark.parametrize(("model_name", "values", "view", "peak", "alpha", "name"), PEAK_CASES)
def test_chi2_zoomed_on_peak(mi, model_name, values, view, peak, alpha, name):
    _known_failure(name, lambda: _chi2_zoomed(mi, model_name, values, view, peak, alpha))


def _chi2_zoomed(mi, model_name, values, view, peak, alpha):
    from _mitsuba_chi2 import chi2

    _, params = _case_params(model_name, values)
    axis = dict(_peaks(values, VIEWS[view]))[peak]
    # A dozen lobe widths, but the chart (corners at 1.41 radii) stays off the horizon,
    # where the density jumps to zero and no per-cell quadrature is accurate.
    elevation = math.asin(min(abs(axis[2]) / np.linalg.norm(axis), 1.0))
    radius = min(max(12.0 * alpha, 0.01), 0.6, elevation / 1.5)
    passed, test = chi2(
        _plugin(mi, params), _unit(VIEWS[view]), axis=axis, radius=radius, test_count=CHI2_TESTS
    )
    assert passed, test.messages


@pytest.mark.parametrize(
    ("model_name", "values", "name", "alpha"),
    [pytest.param(*c, id=c[2]) for c in CASES],
)
def test_drjit_eval_equals_numpy_eval(mi, model_name, values, name, alpha):
    _known_failure(name, lambda: _drjit_vs_numpy(mi, model_name, values))


def _drjit_vs_numpy(mi, model_name, values):
    model, params = _case_params(model_name, values)
    rng = np.random.default_rng(7)
    view = _unit(rng.normal(size=(2048, 3)))
    light = _unit(rng.normal(size=(2048, 3)))
    view[:64, 2] = np.abs(view[:64, 2]) * 1e-3  # grazing
    view = _unit(view)
    bsdf = mi.load_dict(_plugin(mi, params))
    si = _interaction(mi, view)
    got = np.array(bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(light.astype(np.float32).T))).T
    view32, light32 = np.array(si.wi).T.astype(np.float64), light.astype(np.float32)
    want = evaluate(model, params, light32.astype(np.float64), view32) * np.abs(light32[:, 2:3])
    assert np.all(np.isfinite(got))
    scale = max(float(np.max(np.abs(want))), 1e-6)
    np.testing.assert_allclose(got, want, rtol=2e-4, atol=2e-5 * scale)


FURNACE_CASES = [
    ("disney", {"roughness": 0.5, "base_color": [0.8, 0.4, 0.2]}, "disney-plastic"),
    ("disney", {"metallic": 1.0, "roughness": 0.2}, "disney-metal"),
    ("disney", {"clearcoat": 1.0, "roughness": 0.7, "base_color": [0.2, 0.3, 0.8]}, "disney-coat"),
    ("disney", {"spec_trans": 1.0, "roughness": 0.0, "ior": 1.5}, "disney-glass"),
    ("sheen", {"roughness": 0.3, "color": [0.9, 0.5, 0.3]}, "sheen"),
    ("pixar", {"roughness": 0.5, "surface_color": [0.7, 0.3, 0.2]}, "pixar-plastic"),
    ("pixar", {"metallic": 1.0, "roughness": 0.3}, "pixar-metal"),
]


def _pixel_view_angles(scene, rows, cols):
    """View angle θ of the sphere's surface seen through each pixel centre (pinhole)."""
    film = scene["sensor"]["film"]
    width, height = film["width"], film["height"]
    matrix = np.array(scene["sensor"]["to_world"].matrix, dtype=np.float64)
    origin = matrix[:3, 3]
    half = math.tan(math.radians(scene["sensor"]["fov"]) / 2)  # fov along x
    x = (1 - 2 * (cols + 0.5) / width) * half  # Mitsuba's image x runs opposite world x
    y = (1 - 2 * (rows + 0.5) / height) * half * height / width
    d = _unit(np.stack([x, y, -np.ones_like(x)], axis=-1))
    b = (d * origin).sum(-1)
    t = -b - np.sqrt(b * b - (origin @ origin - 1.0))
    normal = origin + t[..., None] * d
    return np.arccos(np.clip(-(d * normal).sum(-1), -1, 1))


@pytest.mark.parametrize(
    ("model_name", "values"), [c[:2] for c in FURNACE_CASES], ids=[c[2] for c in FURNACE_CASES]
)
def test_white_furnace_sphere_matches_numpy_albedo(mi, model_name, values):
    """Single scattering on a convex sphere under a white sky: radiance = albedo(θ)."""
    from lookdev.pipeline.analysis.albedo import albedo_monte_carlo
    from lookdev.pipeline.export.mitsuba.scene import scene_dict

    model, params = _case_params(model_name, values)
    scene = scene_dict(params, resolution=(32, 32), spp=512, max_depth=2)
    scene["ball"]["bsdf"] = _plugin(mi, params)
    image = np.array(mi.render(mi.load_dict(scene), seed=1))
    rows, cols = np.mgrid[14:18, 14:18]
    # The window's pixels see the sphere at three distinct angles (by symmetry).
    theta, count = np.unique(np.round(_pixel_view_angles(scene, rows, cols), 9), return_counts=True)
    albedo = albedo_monte_carlo(model, params, theta, n_samples=65536).albedo
    expected = (albedo * count[:, None]).sum(axis=0) / count.sum()
    got = image[14:18, 14:18].reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(got, expected, rtol=0.02, atol=2e-3)


def test_furnace_view_angles_off_centre(mi, monkeypatch):
    """The pixel-angle helper, checked where the tiny model's albedo ρ(1 + cos θ)/2 varies."""
    from lookdev.pipeline.export.mitsuba import scene as export

    monkeypatch.setitem(export.MODEL_MODULES, "tiny_test", "_mitsuba_tiny")
    params = TinyParams(base_color=(0.8, 0.5, 0.2))
    scene = export.scene_dict(params, resolution=(32, 32), spp=512, max_depth=2)
    image = np.array(mi.render(mi.load_dict(scene), seed=2))
    rows, cols = np.mgrid[15:17, 24:26]
    theta = _pixel_view_angles(scene, rows, cols)
    assert 0.6 < theta.mean() < 1.2  # well off the normal
    expected = np.array([0.8, 0.5, 0.2]) * (0.5 + 0.5 * np.cos(theta)).mean()
    got = image[15:17, 24:26].reshape(-1, 3).mean(axis=0)
    np.testing.assert_allclose(got, expected, rtol=0.02)


def test_chi2_rejects_a_pdf_that_does_not_match_sampling(mi):
    """Negative control: the same chi2 set-up catches a model whose pdf is wrong."""
    import dataclasses

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


def test_sampled_eta_follows_refraction(mi):
    import drjit as dr

    _, params = _case_params("disney", {"spec_trans": 1.0, "roughness": 0.2, "ior": 1.5})
    bsdf = mi.load_dict(_plugin(mi, params))
    n = 4096
    for side, want in ((1.0, 1.5), (-1.0, 1.0 / 1.5)):
        si = dr.zeros(mi.SurfaceInteraction3f, n)
        si.wi = mi.Vector3f(0.0, 0.0, side)
        rng = np.random.default_rng(5)
        u = rng.random((3, n))
        bs, value = bsdf.sample(mi.BSDFContext(), si, mi.Float(u[0]), mi.Point2f(u[1], u[2]))
        eta, z = np.array(bs.eta), np.array(bs.wo)[2]
        ok = np.array(bs.pdf) > 0
        assert np.any(ok & (z * side < 0)) and np.any(ok & (z * side > 0))
        np.testing.assert_allclose(eta[ok & (z * side < 0)], want, rtol=1e-6)
        np.testing.assert_allclose(eta[ok & (z * side > 0)], 1.0)
