"""Smits' Wall-E/Up model: weights, lobes, energy, sampling."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from chi2_harness import chi2_test
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy import integrate

from lookdev.materials import pixar
from lookdev.materials import pixar_lobes as lobes
from lookdev.materials.arrays import NumpyOps
from lookdev.materials.params import ParameterError
from lookdev.materials.pixar_scatter import LOBES

P = pixar.PixarParams
XP = NumpyOps()
UP = np.array([0.0, 0.0, 1.0])


def _dir(cos_theta: float, phi: float = 0.0) -> np.ndarray:
    s = math.sqrt(max(0.0, 1.0 - cos_theta * cos_theta))
    return np.array([s * math.cos(phi), s * math.sin(phi), cos_theta])


# -- Smits' printed checks -----------------------------------------------------------------
@pytest.mark.parametrize(("rough", "expected"), [(0.0, 0.9025), (1.0, 1.0)])
def test_smits_diffuse_check_values(rough, expected):
    # metallic = 0, surfColor = 1, Vdir = Ldir = n: FrnlBlend[diffN, diffG, Ldir.n].
    p = P(surface_color=1.0, metallic=0.0, roughness=rough)
    w = pixar.lobe_weights(p, cos_view=1.0)
    np.testing.assert_allclose(w["diffN"], expected, rtol=1e-12)
    # The same number from the diffuse lobe itself (Smits' lobe is π × our BRDF).
    only_diffuse = p.replace(specular_scale=0.0, reflection_scale=0.0)
    f = pixar.eval(only_diffuse, UP, UP)
    np.testing.assert_allclose(f * math.pi, expected, rtol=1e-12)


def test_smits_transmission_example_by_hand():
    # The seed's example: clear = .25, back = .5 (metallic 0, rough 0, surfColor 1).
    w = pixar.lobe_weights(P(surface_color=1.0, roughness=0.0, clear=0.25, back=0.5))
    d_n = 0.75 * 0.95 * 0.95  # (1 − clear)(1 − nRefl) FrnlBlend[.95, 0, 1]
    expected = {
        "diffN": d_n * 0.5,
        "diffTN": d_n * 0.5,
        "diffG": 0.0,
        "reflN": 0.05,  # reflRatio = 1 at rough 0
        "reflG": 1.0,
        "specN": 0.0,
        "reflTN": 0.95 * 0.25,
        "reflTG": 0.0,
    }
    for name, value in expected.items():
        np.testing.assert_allclose(w[name], value, atol=1e-12, err_msg=name)


def test_weight_names_are_smits():
    assert sorted(pixar.lobe_weights(P())) == sorted(pixar.WEIGHT_NAMES)
    assert len(pixar.WEIGHT_NAMES) == 12


def test_refl_ratio_and_rough_fade():
    # reflRatio = Max[(1 − 2 rough)³, 0]; (1 − rough) fades every highlight.
    for rough in (0.0, 0.1, 0.25, 0.5, 0.7, 1.0):
        w = pixar.lobe_weights(P(surface_color=1.0, metallic=1.0, roughness=rough))
        ratio = max(1.0 - 2.0 * rough, 0.0) ** 3
        np.testing.assert_allclose(w["reflG"], ratio * (1 - rough), atol=1e-15)
        np.testing.assert_allclose(w["specG"], (1 - ratio) * (1 - rough), atol=1e-15)


# -- the highlight distribution ------------------------------------------------------------
@pytest.mark.parametrize("rough", [0.0, 1e-6, 0.05, 0.3, 0.7, 1.0])
@pytest.mark.parametrize("which", ["specular", "reflection"])
def test_distribution_integrates_to_one(rough, which):
    power = lobes.power_specular if which == "specular" else lobes.power_reflection
    p = float(power(XP, rough))
    assert math.isfinite(p)
    width = 1.0 / math.sqrt(max(p, 1.0))
    value, _ = integrate.quad(
        lambda t: float(lobes.distribution(XP, math.sin(t) ** 2, p)) * math.cos(t) * math.sin(t),
        0.0,
        math.pi / 2,
        points=[k * width for k in (0.5, 1, 2, 4, 8) if k * width < math.pi / 2],
        epsabs=1e-13,
        limit=400,
    )
    assert 2 * math.pi * value == pytest.approx(1.0, abs=1e-9)


def test_roughness_zero_limits():
    # powerS(0) = 0 so weightS is 0/0 → 1; powerR(0) = ∞ → the 0.5° cone.
    assert float(lobes.power_specular(XP, 0.0)) == 0.0
    assert float(lobes.weight(XP, 0.0)) == 1.0
    assert float(lobes.weight(XP, 1e-300)) == 1.0
    cone = math.radians(lobes.CONE_MIN_DEG)
    expected = math.log(10) / math.sin(cone) ** 2
    assert float(lobes.power_reflection(XP, 0.0)) == pytest.approx(expected)
    assert float(lobes.weight(XP, 1e-3)) == pytest.approx(1e-3 / -math.expm1(-1e-3))


def _head_on_albedo(rough: float) -> float:
    """White PSpecular's albedo seen along n, as a 1D integral over θh (φ-independent).

    wi = reflect(n, h): cos θi = cos 2θh, dωi = 4 cos θh dωh, only θh < 45° is above.
    """
    p = float(lobes.power_specular(XP, rough))

    def integrand(t):
        c2 = math.cos(2 * t)
        d = float(lobes.distribution(XP, math.sin(t) ** 2, p))
        return 2 * math.pi * d * c2 * math.cos(t) / (c2 * c2 + 1 - c2) * math.sin(t)

    return integrate.quad(integrand, 0.0, math.pi / 4, epsabs=1e-12)[0]


@pytest.mark.parametrize("rough", [0.1, 0.3, 0.8])
def test_specular_lobe_albedo_head_on(rough):
    # Smits wants each highlight lobe to integrate to about 1 "or less": measured 0.83
    # (r = 1) to 0.94 (r = 0.2); the sampler agrees with the independent 1D integral.
    expected = _head_on_albedo(rough)
    assert 0.8 < expected <= 1.0
    p = P(surface_color=1.0, metallic=1.0, roughness=rough, diffuse_scale=0.0)
    p = p.replace(reflection_scale=0.0)
    u = np.random.default_rng(0).random((100_000, 3))
    _, weight, _ = pixar.sample(p, UP, u)
    spec_n = pixar.lobe_weights(p)["specN"][0]
    mean, err = weight[:, 0].mean() / spec_n, weight[:, 0].std() / spec_n / math.sqrt(len(u))
    assert abs(mean - expected) < 4 * err


# -- energy partition ----------------------------------------------------------------------
def _sums(params: pixar.PixarParams, cos_view) -> tuple[np.ndarray, np.ndarray]:
    w = pixar.lobe_weights(params, cos_view)
    normal = sum(w[n] for n in pixar.WEIGHT_NAMES if n.endswith("N"))
    grazing = sum(w[n] for n in pixar.WEIGHT_NAMES if n.endswith("G"))
    return normal, grazing


@pytest.mark.slow
def test_weights_partition_energy_on_a_dense_grid():
    grid = np.linspace(0.0, 1.0, 5)
    cos_view = np.linspace(0.0, 1.0, 9)
    worst = 0.0
    for surf, metal, rough, clear, back, nf, gf in itertools.product(
        grid, grid, grid, grid, (0.0, 1.0), (0.0, 1.0, 20.0), (0.0, 0.5, 1.0)
    ):
        p = P(
            surface_color=(surf, 1.0, 0.2),
            metallic=metal,
            roughness=rough,
            clear=clear,
            back=back,
            normal_fresnel=nf,
            grazing_fresnel=gf,
        )
        n, g = _sums(p, cos_view)
        worst = max(worst, float(n.max()), float(g.max()))
        assert np.all(n >= 0) and np.all(g >= 0)
    print(f"\nlargest per-channel weight sum on the grid: {worst:.12f}")
    assert worst <= 1.0 + 1e-12


unit = st.floats(0.0, 1.0)


@pytest.mark.slow
@settings(max_examples=300, deadline=None)
@given(
    surf=st.tuples(unit, unit, unit),
    tint=st.tuples(unit, unit, unit),
    ttint=st.tuples(unit, unit, unit),
    metal=unit,
    rough=unit,
    clear=unit,
    back=unit,
    nf=st.floats(0.0, 20.0),
    gf=unit,
    scales=st.tuples(unit, unit, unit, unit, unit, unit),
    cos_view=unit,
)
def test_weights_partition_energy_property(
    surf, tint, ttint, metal, rough, clear, back, nf, gf, scales, cos_view
):
    p = P(
        surface_color=surf,
        specular_tint=tint,
        transmission_tint=ttint,
        metallic=metal,
        roughness=rough,
        clear=clear,
        back=back,
        normal_fresnel=nf,
        grazing_fresnel=gf,
        **dict(
            zip(
                [f"{lobe}_scale" for lobe in LOBES],
                scales,
                strict=True,
            )
        ),
    )
    n, g = _sums(p, cos_view)
    assert np.all(n <= 1.0 + 1e-12) and np.all(g <= 1.0 + 1e-12)
    assert np.all(n >= 0.0) and np.all(g >= 0.0)


# -- the diffuse lobe's energy: Smits' Plot3D ----------------------------------------------
def _plot3d_energy(incidence_deg: np.ndarray, rough: np.ndarray, n: int = 64) -> np.ndarray:
    """∫ PDiffuse[in, ω, .05(1 − rough), 1 − rough] cos θ dω / π (Smits' Plot3D), on the
    grid incidence × rough; Gauss-Legendre in cos θ, the integrand has no φ dependence."""
    x, w = np.polynomial.legendre.leggauss(n)
    mu, wmu = 0.5 * (x + 1), 0.5 * w
    cos_in = np.cos(np.radians(incidence_deg))[:, None, None]
    r = rough[None, :, None]
    f = lobes.p_diffuse(XP, cos_in, mu[None, None, :], 0.05 * (1 - r), 1 - r)
    return 2 * math.pi * np.sum(f * mu * wmu, axis=-1)


def test_diffuse_energy_reproduces_smits_plot3d():
    incidence = np.linspace(0.0, 90.0, 19)
    rough = np.linspace(0.0, 1.0, 11)
    energy = _plot3d_energy(incidence, rough)
    # Closed form: FrnBlend[a, b, cos in] · (a + (b − a)/21), a = 1 − nRefl, b = 1 − gRefl.
    a, b = 1 - 0.05 * (1 - rough), rough
    t = (1 - np.cos(np.radians(incidence)))[:, None] ** 5
    np.testing.assert_allclose(energy, (a + (b - a) * t) * (a + (b - a) / 21), rtol=1e-10)
    assert energy[0, 0] == pytest.approx(0.95 * (0.95 - 0.95 / 21))  # smooth, head-on: 0.86
    np.testing.assert_allclose(energy[:, -1], 1.0)  # rough: traditional diffuse
    assert energy[-1, 0] == pytest.approx(0.0, abs=1e-12)  # smooth at grazing: nothing
    assert np.all(np.diff(energy, axis=0) <= 1e-12)  # falls towards grazing
    assert np.all(np.diff(energy, axis=1) >= -1e-12)  # rises with roughness
    # "Most of the plot above .9": all but the smooth or near-grazing corner.
    assert np.all(energy[incidence <= 60][:, rough >= 0.5] > 0.9)
    assert np.mean(energy > 0.9) > 0.5
    assert np.all(energy <= 1.0 + 1e-12)


# -- the lobes -----------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("params", "wo"),
    [
        (P(roughness=0.3), _dir(0.9, 0.3)),
        (P(roughness=0.02, metallic=1.0), _dir(0.7, 1.0)),
        (P(roughness=0.2, clear=0.6, back=0.5, surface_color=0.9), _dir(0.6, 0.2)),
        (P(roughness=0.7, clear=0.3, back=1.0), _dir(0.25, 2.0)),
        (P(roughness=0.45, clear=1.0, ior=1.33), -_dir(0.8, 0.5)),  # seen from below
    ],
)
def test_sampling_passes_chi_square(params, wo):
    passed, p_value = chi2_test(pixar.MODEL, params, wo, n_samples=50_000, res=8)
    assert passed, p_value


def test_sample_weight_is_f_cos_over_pdf():
    p = P(roughness=0.35, clear=0.4, back=0.3, metallic=0.2)
    wo = _dir(0.5, 0.7)
    wi, weight, pdf = pixar.sample(p, wo, np.random.default_rng(4).random((512, 3)))
    ok = pdf > 0
    f = pixar.eval(p, wi[ok], wo)
    np.testing.assert_allclose(weight[ok], f * np.abs(wi[ok, 2:3]) / pdf[ok, None], rtol=1e-10)
    np.testing.assert_allclose(pdf[ok], pixar.pdf(p, wi[ok], wo), rtol=1e-10)


def test_refraction_lobe_peaks_in_the_refracted_direction():
    eta = 1.5
    p = P(roughness=0.1, clear=1.0, ior=eta, diffuse_scale=0, reflection_scale=0)
    wo = _dir(math.cos(math.radians(45.0)))  # in the x-z plane, x > 0
    # Far-side directions continuing away from the viewer: β from −z towards −x.
    beta = np.radians(np.linspace(0.0, 89.5, 1791))
    wi = np.stack([-np.sin(beta), np.zeros_like(beta), -np.cos(beta)], axis=-1)
    peak = beta[np.argmax(pixar.eval(p, wi, wo)[:, 0])]
    snell = math.asin(math.sin(math.radians(45.0)) / eta)  # sin θt = sin θo / η
    assert abs(peak - snell) < math.radians(0.1)


def test_a_closed_reflection_cone_is_a_delta_along_the_mirror_and_the_refraction():
    # roughness 0.05: cone 0.5°, the old floor: now the delta limit of the lobe (issue 16).
    eta = 1.5
    p = P(surface_color=1.0, roughness=0.05, clear=1.0, ior=eta)
    assert pixar.MODEL.prepare(XP, p).delta == ("reflection", "reflection_t")
    wo = _dir(math.cos(math.radians(45.0)))
    u = np.random.default_rng(2).random((4096, 3))
    wi, weight, pdf, delta = pixar.sample(p, wo, u, delta=True)
    ok = pdf > 0
    refl = ok & delta & (wi[:, 2] > 0)
    trans = ok & delta & (wi[:, 2] < 0)
    assert refl.any() and trans.any()
    np.testing.assert_allclose(wi[refl], np.broadcast_to(wo * [-1, -1, 1], wi[refl].shape))
    snell = math.sin(math.radians(45.0)) / eta
    np.testing.assert_allclose(np.hypot(wi[trans, 0], wi[trans, 1]), snell, rtol=1e-12)
    # The delta is the lobe's limit: the albedo does not jump at the cone's floor.
    u = np.random.default_rng(3).random((400_000, 3))
    closed = pixar.sample(p, wo, u)[1].mean(axis=0)
    open_ = pixar.sample(p.replace(roughness=0.06), wo, u)[1].mean(axis=0)  # 0.6°, glossy
    np.testing.assert_allclose(closed, open_, rtol=0.01)


def test_the_adjoint_of_the_refraction_delta_sees_the_light_from_its_one_viewer():
    """A light tracer (prepared.adjoint) gets, for light from l, the viewer v* whose
    refracted view is l, weighted η² W(v*): projected solid angle goes as sin²θ."""
    import dataclasses

    eta = 1.52
    p = P(surface_color=(0.9, 0.8, 0.7), roughness=0.0, clear=1.0, ior=eta)
    pr = pixar.MODEL.prepare(XP, p)
    rng = np.random.default_rng(4)
    n = 512
    z = rng.uniform(0.05, 1.0, n)
    phi = rng.uniform(0.0, 2.0 * math.pi, n)
    r = np.sqrt(1.0 - z * z)
    light = XP.vec3(r * np.cos(phi), r * np.sin(phi), z)
    u = XP.vec3(np.full(n, 0.99999), np.full(n, 0.5), np.full(n, 0.5))  # the last lobe
    v, w_adj, p_adj, d_adj = pixar.MODEL.sample(XP, dataclasses.replace(pr, adjoint=True), light, u)
    ok = p_adj > 0
    assert np.all(d_adj[ok]) and np.all(v[2][ok] < 0)
    # Light beyond sin θ = 1/η reaches no viewer through this lobe.
    np.testing.assert_array_equal(ok, eta * r < 1.0)
    assert ok.any() and (~ok).any()
    back = XP.vec3(*(np.where(ok, v[k], -light[k]) for k in range(3)))
    lw, w_rad, p_rad, _ = pixar.MODEL.sample(XP, pr, back, u)
    for k in range(3):  # the viewer's refracted view is the light
        np.testing.assert_allclose(lw[k][ok], light[k][ok], atol=1e-12)
    weight_adj = np.asarray(w_adj)[:, ok] * p_adj[ok]  # the lobe's W, not over its odds
    weight_rad = np.asarray(w_rad)[:, ok] * p_rad[ok]
    np.testing.assert_allclose(weight_adj, eta * eta * weight_rad, rtol=1e-12)


def test_two_sided():
    p = P(roughness=0.3, clear=0.5, back=0.5)
    wi, wo = _dir(0.4, 2.0), _dir(0.8, 0.1)
    flip = np.array([1.0, 1.0, -1.0])
    np.testing.assert_allclose(pixar.eval(p, wi, wo), pixar.eval(p, wi * flip, wo * flip))
    np.testing.assert_allclose(pixar.pdf(p, wi, wo), pixar.pdf(p, wi * flip, wo * flip))


def test_lobes_known_zero_are_dropped():
    def kept(**kw):
        return pixar.MODEL.prepare(XP, P(**kw)).lobes

    assert kept(roughness=0.5) == ("diffuse", "specular")  # reflRatio = 0 from 0.5 up
    assert kept(roughness=1.0) == ("diffuse",)  # the (1 − rough) fade
    assert kept(roughness=0.2) == ("diffuse", "specular", "reflection")
    assert kept(roughness=0.0) == ("diffuse", "reflection")
    assert kept(roughness=0.2, clear=0.5, back=0.5) == LOBES
    # A black metal still has Fresnel's grazing highlight; without it, nothing is left.
    assert kept(roughness=0.2, surface_color=0.0, metallic=1.0) == ("specular", "reflection")
    assert kept(roughness=0.2, surface_color=0.0, metallic=1.0, grazing_fresnel=0.0) == ()


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_no_nan_at_the_edges(dtype):
    cosines = [-1.0, -0.5, -1e-9, 0.0, 1e-9, 0.5, 1.0]
    dirs = np.array([_dir(c, phi) for c in cosines for phi in (0.0, 1.5, math.pi)])
    u = np.random.default_rng(0).random((32, 3)).astype(dtype)
    for rough, cone, clear in itertools.product((0.0, 1e-7, 0.5, 1.0), (0.0, 1.0, 2.5), (0, 1)):
        p = P(
            roughness=rough,
            clear=clear,
            back=0.5,
            specular_cone_scale=cone,
            reflection_cone_scale=cone,
        )
        f = pixar.eval(p, dirs[:, None], dirs[None, :], dtype=dtype)
        pdf = pixar.pdf(p, dirs[:, None], dirs[None, :], dtype=dtype)
        assert np.all(np.isfinite(f)) and np.all(f >= 0), (rough, cone)
        assert np.all(np.isfinite(pdf)) and np.all(pdf >= 0)
        wi, weight, spdf = pixar.sample(p, dirs[:, None], u[None], dtype=dtype)
        assert np.all(np.isfinite(wi)) and np.all(np.isfinite(weight)) and np.all(weight >= 0)
        assert np.all(np.isfinite(spdf))


def test_bad_parameters_are_one_line_errors():
    with pytest.raises(ParameterError, match="roughness"):
        P.parse({"roughness": -0.1}, where="x.toml")
    with pytest.raises(ParameterError, match="unknown"):
        P.parse({"rougness": 0.1})


def test_ior_defaults_to_the_dielectric_reflectance():
    f0 = ((P().eta - 1) / (P().eta + 1)) ** 2
    assert f0 == pytest.approx(0.05)
    assert P(ior=1.33).eta == 1.33


def test_drjit_backend_agrees_with_numpy():
    pytest.importorskip("mitsuba")
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba as mi

    from lookdev.materials.arrays import DrJitOps

    xp = DrJitOps.for_mitsuba()
    rng = np.random.default_rng(5)
    wi = rng.normal(size=(128, 3))
    wi /= np.linalg.norm(wi, axis=1, keepdims=True)
    wo = _dir(0.6, 0.4)
    u = rng.random((128, 3))
    p = P(roughness=0.25, clear=0.5, back=0.4, metallic=0.3, surface_color=(0.8, 0.5, 0.2))
    prepared = pixar.MODEL.prepare(xp, p)
    vi, vo = mi.Vector3f(wi.T), mi.Vector3f(*map(float, wo))
    got = np.array(pixar.MODEL.eval(xp, prepared, vi, vo))
    np.testing.assert_allclose(got, pixar.eval(p, wi, wo).T, rtol=2e-4, atol=1e-6)
    got_pdf = np.array(pixar.MODEL.pdf(xp, prepared, vi, vo))
    np.testing.assert_allclose(got_pdf, pixar.pdf(p, wi, wo), rtol=2e-4, atol=1e-6)
    d_wi, _, d_pdf, _ = pixar.MODEL.sample(xp, prepared, vo, mi.Vector3f(u.T))
    n_wi, _, n_pdf = pixar.sample(p, wo, u)
    np.testing.assert_allclose(np.array(d_wi).T, n_wi, atol=1e-4)
    np.testing.assert_allclose(np.array(d_pdf), n_pdf, rtol=1e-3, atol=1e-5)


@pytest.mark.parametrize(
    "params",
    [
        P(surface_color=1.0, roughness=0.1, clear=1.0),
        P(surface_color=1.0, roughness=0.5, clear=0.5, back=0.5),
        P(surface_color=1.0, roughness=0.0, clear=0.3, back=1.0, metallic=0.5),
        P(surface_color=1.0, roughness=0.3, grazing_fresnel=0.4, clear=0.7),
    ],
    ids=range(4),
)
def test_white_furnace_never_gains_energy(params):
    # The weights partition energy only if the lobes blend them at the same incidence:
    # the transmitted highlights take the front view's, like the reflected ones.
    u = np.random.default_rng(6).random((10_000, 3))
    for cos_o in (1.0, 0.5, 0.02, 1e-4):
        _, weight, _ = pixar.sample(params, _dir(cos_o, 0.3), u)
        mean, err = weight.mean(axis=0), weight.std(axis=0) / math.sqrt(len(u))
        assert np.all(mean <= 1.0 + 4 * err + 1e-12), (cos_o, mean)


@pytest.mark.parametrize("rough", [0.0, 0.5, 1.0])
def test_tangent_back_view_stays_finite_in_float32(rough):
    # Found by lookdev check: with η = 1 and a grazing view, float32 rounds the back view
    # into the tangent plane, and a light just below the horizon opposite makes wi = −wo
    # for the transmitted highlight (Jacobian 1/4|wo·h| singular). Per-element maps keep
    # every lobe, so a zero odds met that ∞ as NaN.
    wi, wo = np.array([-1.0, 0.0, -1e-7]), np.array([1.0, 0.0, 1e-4])
    p = P(roughness=0.5, clear=1.0, ior=1.0)
    maps = {"roughness": np.array(rough), "clear": np.array(1.0)}
    for dtype in (np.float32, np.float64):
        assert np.isfinite(pixar.pdf(p, wi, wo, dtype=dtype, **maps))
        assert np.all(np.isfinite(pixar.eval(p, wi, wo, dtype=dtype, **maps)))


def test_drjit_constant_roughness_zero():
    # Constants reach the Dr.Jit backend as Python floats; weightS's expm1 of a float near
    # 0 must fold in Python (Dr.Jit's select would evaluate log(1) = 0 as a divisor).
    pytest.importorskip("mitsuba")
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba as mi

    from lookdev.materials.arrays import DrJitOps

    xp = DrJitOps.for_mitsuba()
    p = P(roughness=0.0, clear=0.5)
    prepared = pixar.MODEL.prepare(xp, p)
    wo = _dir(0.8, 0.2)
    wi = np.array([_dir(0.8, 0.2 + math.pi), _dir(0.3, 1.0), -_dir(0.5, 2.0)])
    got = np.array(pixar.MODEL.eval(xp, prepared, mi.Vector3f(wi.T), mi.Vector3f(*map(float, wo))))
    np.testing.assert_allclose(got, pixar.eval(p, wi, wo).T, rtol=1e-3, atol=1e-6)
    u = mi.Vector3f(np.random.default_rng(8).random((3, 64)))
    _, weight, pdf, _ = pixar.MODEL.sample(xp, prepared, mi.Vector3f(*map(float, wo)), u)
    assert np.all(np.isfinite(np.array(weight))) and np.all(np.isfinite(np.array(pdf)))
