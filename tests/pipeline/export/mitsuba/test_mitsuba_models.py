"""The shipped models (Disney, Conty-Kulla sheen, Pixar) through the Mitsuba plugin.

Each passes ``mitsuba.chi2`` over a grid with the extremes, its Dr.Jit evaluation equals
the numpy one to float32 precision, and a rendered sphere under a white sky shows the
directional albedo the numpy backend computes.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from _mitsuba_helpers import interaction as _interaction
from _mitsuba_helpers import mitsuba_module
from _mitsuba_helpers import pixel_view_angles as _pixel_view_angles
from _mitsuba_helpers import unit as _unit

from lookdev.materials.bsdf import evaluate

pytestmark = pytest.mark.render
_mi = pytest.fixture(scope="module", name="mi")(mitsuba_module)


# -- the shipped models ------------------------------------------------------------------
# (model, parameters, id, sharpest α or None): the grid of the issue, extremes included.
CASES = [
    ("sheen", {"roughness": 0.0}, "sheen-r0", None),
    ("sheen", {"roughness": 0.3, "color": [0.9, 0.5, 0.3]}, "sheen-r0.3", None),
    ("sheen", {"roughness": 1.0, "terminator_softening": False}, "sheen-r1-reciprocal", None),
    # the exact Λ (sheen_lambda), at its floor r = 0.01 and at 0.3
    ("sheen", {"roughness": 0.01, "sheen_lambda": "exact"}, "sheen-exact-r0.01", None),
    ("sheen", {"roughness": 0.3, "sheen_lambda": "exact"}, "sheen-exact-r0.3", None),
    ("disney", {"roughness": 0.0}, "disney-r0", None),  # delta specular over the diffuse
    ("disney", {"roughness": 0.04, "anisotropic": 1.0}, "disney-alpha-min", 1e-3),
    ("disney", {"roughness": 1.0}, "disney-r1", 1.0),
    ("disney", {"roughness": 0.3, "anisotropic": 1.0}, "disney-aniso1", 0.028),
    ("disney", {"metallic": 1.0, "roughness": 0.2}, "disney-metal", 0.04),
    ("disney", {"metallic": 0.0, "roughness": 0.5, "specular_tint": 1.0}, "disney-tinted", 0.25),
    ("disney", {"clearcoat": 1.0, "clearcoat_gloss": 1.0, "roughness": 0.6}, "disney-coat1", 1e-3),
    ("disney", {"clearcoat": 1.0, "clearcoat_gloss": 0.5, "roughness": 0.6}, "disney-coat.5", 0.05),
    ("disney", {"spec_trans": 1.0, "roughness": 0.1, "ior": 1.5}, "disney-glass", 0.01),
    ("disney", {"spec_trans": 1.0, "roughness": 0.3, "thin": True}, "disney-thin-glass", 0.035),
    # Refraction into glass narrows the lobe by about (η − 1)/η: α 0.12 → 0.04.
    ("disney", {"spec_trans": 1.0, "roughness": 0.35, "ior": 1.52}, "disney-frosted", 0.04),
    ("disney", {"spec_trans": 0.5, "roughness": 0.0, "ior": 1.5}, "disney-smooth-mix", None),
    ("disney", {"diff_trans": 0.7, "thin": True, "flatness": 0.5}, "disney-leaf", 0.25),
    ("disney", {"sheen": 1.0, "sheen_tint": 0.5, "subsurface": 1.0}, "disney-sheen", 0.25),
    # a solid with a scatter distance: the diffuse's Lambertian part enters the interior
    ("disney", {"scatter_distance": 0.01, "roughness": 0.5}, "disney-subsurface", 0.25),
    (
        "disney",
        {"sheen": 1.0, "sheen_model": "conty_kulla", "sheen_roughness": 0.5},
        "disney-ck-sheen",
        0.25,
    ),
    (
        "disney",
        {
            "sheen": 1.0,
            "sheen_model": "conty_kulla",
            "sheen_roughness": 0.01,
            "sheen_lambda": "exact",
        },
        "disney-ck-sheen-exact",
        0.25,
    ),
    # the GTR γ of the specular lobe (sampled by App. B eqs. 2–3 where γ ≠ 2)
    ("disney", {"specular_gamma": 1.0, "roughness": 0.5}, "disney-gamma1", 0.25),
    ("disney", {"specular_gamma": 1.5, "metallic": 1.0, "roughness": 0.5}, "disney-gamma1.5", 0.25),
    ("disney", {"specular_gamma": 3.0, "metallic": 1.0, "roughness": 0.3}, "disney-gamma3", 0.09),
    # Turquin's multiple-scattering factor on the specular lobe (sampling unchanged)
    (
        "disney",
        {"metallic": 1.0, "roughness": 0.7, "energy_compensation": True},
        "disney-ms-metal",
        0.49,
    ),
    ("disney", {"roughness": 0.6, "energy_compensation": True}, "disney-ms-plastic", 0.36),
    (
        "disney",
        {"spec_trans": 1.0, "roughness": 0.5, "ior": 1.5, "energy_compensation": True},
        "disney-ms-glass",
        0.08,  # refracted: α 0.25 narrows by (η − 1)/η, as the frosted glass's
    ),
    # Pixar: "α" here is the reflection cone's half-angle in radians (10·r degrees).
    ("pixar", {"roughness": 0.0}, "pixar-r0", None),  # a delta reflection over the diffuse
    ("pixar", {"clear": 1.0, "roughness": 0.0, "ior": 1.52}, "pixar-clear-glass", None),
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


def _case_params(model_name, values):
    from lookdev.materials.registry import model_named

    model = model_named(model_name)
    return model, model.params_type.parse(values)


def _plugin(mi, params):
    from lookdev.pipeline.export.mitsuba.scene import bsdf_dict

    d = bsdf_dict(params, allow_principled=False)
    assert d["type"].startswith("lookdev_")
    return d


def _views(values):
    keys = ("spec_trans", "diff_trans", "clear", "back", "scatter_distance")
    transmits = any(values.get(k) for k in keys)
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
    pytest.param(model, values, view, peak, alpha, id=f"{name}-{view}-{peak}")
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
    # A uniform sampler of a lobe that is 0 in float32 over most of the sphere (sheen at
    # r = 0.01) draws zero-valued directions, part of its distribution all the same.
    uniform = model_name == "sheen"
    passed, test = chi2(
        _plugin(mi, params), _unit(VIEWS[view]), test_count=CHI2_TESTS, count_zero_values=uniform
    )
    assert passed, test.messages


@pytest.mark.slow
@pytest.mark.parametrize(("model_name", "values", "view", "peak", "alpha"), PEAK_CASES)
def test_chi2_zoomed_on_peak(mi, model_name, values, view, peak, alpha):
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
    ("model_name", "values"), [c[:2] for c in CASES], ids=[c[2] for c in CASES]
)
def test_drjit_eval_equals_numpy_eval(mi, model_name, values):
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
    ("disney", {"metallic": 1.0, "roughness": 0.4, "specular_gamma": 1.5}, "disney-gamma1.5"),
    ("disney", {"metallic": 1.0, "roughness": 0.8, "energy_compensation": True}, "disney-ms-metal"),
    ("disney", {"clearcoat": 1.0, "roughness": 0.7, "base_color": [0.2, 0.3, 0.8]}, "disney-coat"),
    ("disney", {"spec_trans": 1.0, "roughness": 0.0, "ior": 1.5}, "disney-glass"),
    ("sheen", {"roughness": 0.3, "color": [0.9, 0.5, 0.3]}, "sheen"),
    ("pixar", {"roughness": 0.5, "surface_color": [0.7, 0.3, 0.2]}, "pixar-plastic"),
    ("pixar", {"metallic": 1.0, "roughness": 0.3}, "pixar-metal"),
]


@pytest.mark.parametrize(
    ("model_name", "values"), [c[:2] for c in FURNACE_CASES], ids=[c[2] for c in FURNACE_CASES]
)
def test_white_furnace_sphere_matches_numpy_albedo(mi, model_name, values):
    """Single scattering on a convex sphere under a white sky: radiance = albedo(θ)."""
    from lookdev.pipeline.analysis.albedo import albedo_monte_carlo
    from lookdev.pipeline.export.mitsuba import scene_dict

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


def test_traverse_exposes_numbers_and_colours_not_switches(mi):
    _, params = _case_params(
        "disney", {"spec_trans": 1.0, "thin": True, "ior": 1.4, "sheen_model": "conty_kulla"}
    )
    bsdf = mi.load_dict(_plugin(mi, params))
    assert set(mi.traverse(bsdf).keys()) == {"spec_trans", "ior"}


def test_a_black_colour_prunes_its_lobe_on_both_backends(mi):
    from lookdev.pipeline.blend import BlendedMaterial

    _, params = _case_params("sheen", {"color": [0.0, 0.0, 0.0]})
    assert BlendedMaterial.of_params(params).live_lobes == ()
    assert mi.load_dict(_plugin(mi, params)).flags() == 0


# -- transport mode (issue 17, §5): the models describe radiance ------------------------------
NON_SYMMETRIC = [
    ("disney", {"spec_trans": 1.0, "roughness": 0.3, "ior": 1.5}, 1.5),
    ("disney", {"spec_trans": 0.6, "diff_trans": 0.3, "roughness": 0.3, "ior": 1.5}, 1.5),
    ("pixar", {"clear": 1.0, "back": 1.0, "roughness": 0.6, "ior": 1.5}, None),
    ("pixar", {"clear": 1.0, "back": 1.0, "roughness": 0.6, "ior": 1.0}, None),
]
"""(model, values, η of a radiance-form refraction or None where f is not of that form:
Smits' transmitted highlights are centred on the refracted view, at any IOR)."""
SYMMETRIC = [
    ("disney", {"spec_trans": 1.0, "roughness": 0.3, "thin": True}),
    ("disney", {"roughness": 0.5}),
    ("pixar", {"roughness": 0.5}),
    ("pixar", {"back": 1.0, "roughness": 0.5}),  # Lambertian transmission is reciprocal
]  # (Disney clamps η = 1 to 1.001: that still bends the path, a little)


def _both_sides(n, seed):
    rng = np.random.default_rng(seed)
    view, light = _unit(rng.normal(size=(n, 3))), _unit(rng.normal(size=(n, 3)))
    return view, light, rng.random((3, n))


@pytest.mark.parametrize(
    ("model_name", "values", "ior"),
    NON_SYMMETRIC,
    ids=["disney-glass", "disney-glass-diff-trans", "pixar", "pixar-ior-1"],
)
def test_importance_transport_evaluates_the_adjoint(mi, model_name, values, ior):
    """Importance: eval(si.wi, wo) = f(light = si.wi, viewer = wo) and the sampled value
    is that f·|cos|/pdf; for a radiance-form refraction that is f_radiance·η²."""
    model, params = _case_params(model_name, values)
    bsdf = mi.load_dict(_plugin(mi, params))
    t = mi.BSDFFlags.GlossyTransmission
    assert bsdf.flags() & mi.BSDFFlags.NonSymmetric
    assert bsdf.flags(1) & mi.BSDFFlags.NonSymmetric and bsdf.flags(1) & t
    assert not bsdf.flags(0) & mi.BSDFFlags.NonSymmetric  # reflection stays symmetric
    view, light, u = _both_sides(4096, 11)
    si = _interaction(mi, view)
    wo = mi.Vector3f(light.astype(np.float32).T)
    radiance, importance = mi.BSDFContext(), mi.BSDFContext(mi.TransportMode.Importance)
    view32 = np.array(si.wi).T
    light32 = np.array(wo).T
    crossing = view32[:, 2] * light[:, 2] < 0
    cos = np.abs(light32[:, 2:3])
    want_r = evaluate(model, params, light32, view32) * cos
    want_i = evaluate(model, params, view32, light32) * cos  # the roles as they physically are
    f_r = np.array(bsdf.eval(radiance, si, wo)).T
    f_i = np.array(bsdf.eval(importance, si, wo)).T
    scale = float(np.max(np.abs(want_r)))
    np.testing.assert_allclose(f_r, want_r, rtol=2e-4, atol=2e-5 * scale)  # as today
    np.testing.assert_allclose(f_i, want_i, rtol=2e-4, atol=2e-5 * scale)
    assert np.any(crossing & (np.abs(f_i - f_r).max(axis=1) > 1e-2 * scale))
    if ior is not None:
        # η = η(wo side)/η(si.wi side): Mitsuba's roughdielectric drops its sqr(inv_eta)
        eta = np.where(crossing, np.where(view32[:, 2] > 0, ior, 1.0 / ior), 1.0)
        if "diff_trans" not in values:  # a Lambertian transmission has no η²
            np.testing.assert_allclose(f_i, f_r * eta[:, None] ** 2, rtol=2e-4, atol=1e-6 * scale)
    fp_i, p_i = bsdf.eval_pdf(importance, si, wo)
    np.testing.assert_allclose(np.array(fp_i).T, f_i, rtol=1e-6, atol=1e-7 * scale)
    np.testing.assert_allclose(np.array(p_i), np.array(bsdf.pdf(radiance, si, wo)), rtol=1e-6)
    # sampling: same directions and pdfs; the value is the adjoint f·|cos|/pdf
    s1, s2 = mi.Float(u[0]), mi.Point2f(u[1], u[2])
    bs_r, w_r = bsdf.sample(radiance, si, s1, s2)
    bs_i, w_i = bsdf.sample(importance, si, s1, s2)
    np.testing.assert_array_equal(np.array(bs_i.wo), np.array(bs_r.wo))
    np.testing.assert_array_equal(np.array(bs_i.pdf), np.array(bs_r.pdf))
    ok = np.array(bs_i.pdf) > 0
    f_at = np.array(bsdf.eval(importance, si, bs_i.wo)).T
    w_i = np.array(w_i).T
    pdf = np.array(bs_i.pdf)[ok, None]
    np.testing.assert_allclose(w_i[ok], f_at[ok] / pdf, rtol=1e-5)
    refracted = ok & (view32[:, 2] * np.array(bs_r.wo)[2] < 0)
    assert np.any(refracted) and np.any(np.abs(w_i - np.array(w_r).T)[refracted] > 1e-3)
    from lookdev.materials.bsdf import draw

    wi_np, weight_np, _ = draw(model, params, view32, u.T)
    np.testing.assert_allclose(np.array(w_r).T[ok], weight_np[ok], rtol=2e-3, atol=2e-5)


@pytest.mark.parametrize(
    ("model_name", "values"),
    [
        ("sheen", {"color": (1.0, 1.0, 1.0), "roughness": 0.3}),
        ("disney", {"sheen": 1.0, "sheen_model": "conty_kulla", "roughness": 0.5}),
    ],
    ids=["sheen", "disney-conty-kulla"],
)
def test_importance_transport_softens_the_sheen_terminator_on_the_light_side(
    mi, model_name, values
):
    """Conty–Kulla eq. 4 softens Λ of the light direction only: not reciprocal."""
    model, params = _case_params(model_name, values)
    bsdf = mi.load_dict(_plugin(mi, params))
    assert bsdf.flags(0) & mi.BSDFFlags.NonSymmetric
    view, light, u = _both_sides(4096, 14)
    view[:, 2], light[:, 2] = np.abs(view[:, 2]), np.abs(light[:, 2])  # reflection pairs
    si = _interaction(mi, view)
    wo = mi.Vector3f(light.astype(np.float32).T)
    view32, light32 = np.array(si.wi).T, np.array(wo).T
    cos = np.abs(light32[:, 2:3])
    want_i = evaluate(model, params, view32, light32) * cos
    f_i = np.array(bsdf.eval(mi.BSDFContext(mi.TransportMode.Importance), si, wo)).T
    f_r = np.array(bsdf.eval(mi.BSDFContext(), si, wo)).T
    scale = float(np.max(np.abs(want_i)))
    np.testing.assert_allclose(f_i, want_i, rtol=2e-4, atol=2e-5 * scale)
    assert np.abs(f_i - f_r).max() > 1e-2 * scale  # the softening shows at grazing light


def test_importance_transport_weights_a_smooth_refraction_by_eta_squared(mi):
    """A delta has no f to evaluate: Mitsuba's dielectric weight, T(1 − F), in both."""
    from lookdev.pipeline.bench.glass import builtin_dict

    _, params = _case_params("disney", {"spec_trans": 1.0, "roughness": 0.0, "ior": 1.5})
    ours, theirs = mi.load_dict(_plugin(mi, params)), mi.load_dict(builtin_dict(params))
    view, _, u = _both_sides(2048, 13)
    si = _interaction(mi, view)
    s1, s2 = mi.Float(u[0]), mi.Point2f(u[1], u[2])
    for mode in (mi.TransportMode.Radiance, mi.TransportMode.Importance):
        ctx = mi.BSDFContext(mode)
        (bs_a, w_a), (bs_b, w_b) = ours.sample(ctx, si, s1, s2), theirs.sample(ctx, si, s1, s2)
        ok = (np.array(bs_a.pdf) > 0) & (np.array(bs_b.pdf) > 0)
        same = ok & (np.abs(np.array(bs_a.wo) - np.array(bs_b.wo)).max(axis=0) < 1e-4)
        assert same.mean() > 0.95
        np.testing.assert_allclose(np.array(w_a).T[same], np.array(w_b).T[same], rtol=1e-4)
        np.testing.assert_allclose(np.array(bs_a.eta)[same], np.array(bs_b.eta)[same], rtol=1e-6)


@pytest.mark.parametrize(
    ("model_name", "values"),
    SYMMETRIC,
    ids=["disney-thin", "disney-opaque", "pixar-opaque", "pixar-diffuse-t"],
)
def test_transport_mode_leaves_non_refracting_lobes_alone(mi, model_name, values):
    _, params = _case_params(model_name, values)
    bsdf = mi.load_dict(_plugin(mi, params))
    assert not bsdf.flags() & mi.BSDFFlags.NonSymmetric
    view, light, u = _both_sides(1024, 12)
    si = _interaction(mi, view)
    wo = mi.Vector3f(light.astype(np.float32).T)
    importance = mi.BSDFContext(mi.TransportMode.Importance)
    np.testing.assert_array_equal(
        np.array(bsdf.eval(importance, si, wo)), np.array(bsdf.eval(mi.BSDFContext(), si, wo))
    )
    s1, s2 = mi.Float(u[0]), mi.Point2f(u[1], u[2])
    np.testing.assert_array_equal(
        np.array(bsdf.sample(importance, si, s1, s2)[1]),
        np.array(bsdf.sample(mi.BSDFContext(), si, s1, s2)[1]),
    )


def test_energy_compensation_reads_a_roughness_texture_at_the_hit(mi):
    """The table look-up on Dr.Jit arrays from a texture (the array path), against numpy."""
    from lookdev.materials.params import DisneyParams
    from lookdev.materials.registry import model_named
    from lookdev.pipeline.export.mitsuba import register_plugins

    register_plugins()
    data = mi.TensorXf(np.array([[[0.3], [0.9]]], dtype=np.float32))
    bsdf = mi.load_dict(
        {
            "type": "lookdev_disney",
            "metallic": 1.0,
            "energy_compensation": True,
            "roughness": {"type": "bitmap", "data": data, "raw": True, "filter_type": "nearest"},
        }
    )
    view = _unit(np.array([[0.3, 0.1, 0.9]]))
    light = _unit(np.array([0.2, -0.4, 0.7]))
    for u, r in ((0.25, 0.3), (0.75, 0.9)):
        si = _interaction(mi, view, uv=(u, 0.5))
        wl = mi.Vector3f(light[None, :].astype(np.float32).T)
        got = np.array(bsdf.eval(mi.BSDFContext(), si, wl)).ravel()
        params = DisneyParams(metallic=1.0, roughness=r, energy_compensation=True)
        want = evaluate(model_named("disney"), params, light, view[0]) * light[2]
        off = evaluate(
            model_named("disney"), params.replace(energy_compensation=False), light, view[0]
        )
        assert np.all(want > off * light[2])  # the factor is there to see
        np.testing.assert_allclose(got, want.ravel(), rtol=2e-4)


def test_energy_compensation_is_non_symmetric_and_a_light_tracer_sees_the_adjoint(mi):
    """Turquin's factor is read at the viewer: f(l, v) ≠ f(v, l). With the switch on the
    reflection is flagged NonSymmetric and Importance mode evaluates the model with the
    roles as they physically are; off, the plain metal stays symmetric."""
    model, params = _case_params(
        "disney", {"metallic": 1.0, "roughness": 0.8, "energy_compensation": True}
    )
    plain = mi.load_dict(_plugin(mi, params.replace(energy_compensation=False)))
    assert not plain.flags() & mi.BSDFFlags.NonSymmetric
    bsdf = mi.load_dict(_plugin(mi, params))
    assert bsdf.flags() & mi.BSDFFlags.NonSymmetric
    rng = np.random.default_rng(8)
    view = _unit(np.abs(rng.normal(size=(256, 3))))
    light = _unit(np.abs(rng.normal(size=(256, 3))))
    si = _interaction(mi, view)
    wo = mi.Vector3f(light.astype(np.float32).T)
    importance = mi.BSDFContext(mi.TransportMode.Importance)
    got = np.array(bsdf.eval(importance, si, wo)).T
    view32, light32 = np.array(si.wi).T.astype(np.float64), light.astype(np.float32)
    # adjoint: light arrives along si.wi, leaves towards wo (the sensor side)
    want = evaluate(model, params, view32, light32.astype(np.float64)) * light32[:, 2:3]
    np.testing.assert_allclose(got, want, rtol=2e-4, atol=1e-6)
    radiance = np.array(bsdf.eval(mi.BSDFContext(), si, wo)).T
    assert np.max(np.abs(radiance - got)) > 1e-3  # the two modes differ
