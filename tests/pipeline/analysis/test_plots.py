"""BRDF-explorer views: each view's numbers against an independent computation."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from _lambert import LAMBERT, PHONG, LambertParams, PhongParams

from lookdev.library import load_material
from lookdev.materials import registry
from lookdev.materials.colour import luminance
from lookdev.pipeline.analysis import plots as P
from lookdev.pipeline.analysis import sphere as S
from lookdev.pipeline.blend import BlendedMaterial, blend

RHO = np.array([0.8, 0.5, 0.2])


# -- slice ---------------------------------------------------------------------------
def test_slice_directions_have_the_asked_half_and_difference_angles():
    th = np.radians([0.0, 10.0, 45.0, 89.0])
    td = np.radians([0.0, 30.0, 89.0])
    wi, wo = P.slice_directions(th, td)
    h = wi + wo
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    np.testing.assert_allclose(np.arccos(np.clip(h[..., 2], -1, 1)), np.tile(th, (3, 1)), atol=1e-7)
    cos_d = np.clip((wi * h).sum(-1), -1, 1)
    np.testing.assert_allclose(np.arccos(cos_d), np.tile(td[:, None], (1, 4)), atol=1e-7)
    # φd = 90°: the difference vector is perpendicular to the plane of n and h.
    np.testing.assert_allclose(wi[..., 0] * h[..., 2] - wi[..., 2] * h[..., 0], 0, atol=1e-12)


@pytest.mark.parametrize("phi_d", [math.pi / 2, 0.0])
def test_lambert_slice_is_flat_where_both_directions_are_above_the_horizon(phi_d):
    th, td, f = P.brdf_slice(LAMBERT, LambertParams(base_color=tuple(RHO)), n=32, phi_d=phi_d)
    wi, wo = P.slice_directions(th, td, phi_d)
    above = (wi[..., 2] > 0) & (wo[..., 2] > 0)
    np.testing.assert_allclose(f[above], np.tile(RHO / math.pi, (above.sum(), 1)), rtol=1e-12)
    assert np.all(f[~above] == 0)
    # Burley Fig. 4: the φd = 90° slice lies wholly above the horizon, others lose a corner.
    assert above.all() == (phi_d == math.pi / 2)


def test_glossy_slice_peaks_at_theta_h_zero():
    _, _, f = P.brdf_slice(PHONG, PhongParams(exponent=200.0), n=64)
    assert np.all(np.argmax(f[:48, :, 0], axis=1) == 0)  # rows up to θd ≈ 67°


def test_slice_isolines_are_the_incidence_angle_of_both_directions():
    th = np.radians(np.linspace(0.5, 89.5, 7))
    wi, wo = P.slice_directions(th, th)
    expected = np.degrees(np.arccos(wi[..., 2]))
    np.testing.assert_allclose(P.incidence_on_slice(*np.meshgrid(th, th)), expected, atol=1e-9)
    np.testing.assert_allclose(wo[..., 2], wi[..., 2], atol=1e-12)  # φd = 90°: θl = θv


def test_slices_and_spheres_are_shown_through_the_proofs_view_transform(monkeypatch):
    import matplotlib.pyplot as plt

    from lookdev.pipeline.proof import tonemap

    seen, original = [], tonemap.view

    def view(rgb, exposure=0.0):
        seen.append((np.shape(rgb), exposure))
        return original(rgb, exposure)

    monkeypatch.setattr(P.tonemap, "view", view)
    fig, (a, b) = plt.subplots(1, 2)
    monkeypatch.setitem(registry.MODELS, "lambert", LAMBERT)
    P.draw_slice(a, BlendedMaterial.of_params(LambertParams(), "lambert"), exposure=1.5, n=8)
    P.draw_sphere(b, np.full((4, 4, 3), 0.5), -1.0, "sphere")
    plt.close(fig)
    assert seen == [((8, 8, 3), 1.5), ((4, 4, 3), -1.0)]


# -- polar ---------------------------------------------------------------------------
@pytest.mark.parametrize("incidence", [0.0, 30.0, 60.0, 80.0])
def test_polar_peak_is_at_the_mirror_direction(incidence):
    theta_o, lum = P.polar_curves(PHONG, PhongParams(exponent=300.0), [incidence], n=721)
    assert math.degrees(theta_o[np.argmax(lum[0])]) == pytest.approx(incidence, abs=0.25)


def test_lambert_polar_is_rho_over_pi_luminance_everywhere():
    _, lum = P.polar_curves(LAMBERT, LambertParams(base_color=tuple(RHO)), [0, 45, 89.9])
    np.testing.assert_allclose(lum, luminance(RHO) / math.pi, rtol=1e-12)


# -- sphere --------------------------------------------------------------------------
def test_point_lit_lambert_sphere_is_n_dot_l_albedo_over_pi():
    light = np.array([-1.0, 1.0, 1.0]) / math.sqrt(3.0)
    img = S.point_light_sphere(
        LAMBERT,
        LambertParams(base_color=tuple(RHO)),
        resolution=48,
        light=tuple(light),
        irradiance=1.0,
    )
    n, inside = S.sphere_normals(48)
    expected = np.clip(n @ light, 0, None)[..., None] * RHO / math.pi * inside[..., None]
    np.testing.assert_allclose(img, expected, atol=1e-15)
    assert img[~inside].max() == 0


def test_sphere_wraps_parameter_maps_left_to_right_and_bottom_to_top():
    # A 2×2 colour map: left/right halves in u, bottom/top halves in v.
    colours = np.array([[[1, 0, 0], [0, 1, 0]], [[0, 0, 1], [1, 1, 1]]], dtype=np.float32)
    img = S.point_light_sphere(
        LAMBERT,
        LambertParams(),
        resolution=32,
        light=(0, 0, 1),
        irradiance=math.pi,
        maps={"base_color": colours},
    )
    n, _ = S.sphere_normals(32)
    np.testing.assert_allclose(img[24, 12], colours[0, 0] * n[24, 12, 2])  # bottom left
    np.testing.assert_allclose(img[24, 20], colours[0, 1] * n[24, 20, 2])  # bottom right
    np.testing.assert_allclose(img[7, 12], colours[1, 0] * n[7, 12, 2])  # top left
    ibl = S.ibl_sphere(
        LAMBERT,
        LambertParams(),
        np.ones((8, 16, 3)),
        resolution=16,
        spp=64,
        maps={"base_color": colours},
    )
    assert ibl[4, 6].argmax() == 2 and ibl[12, 9].argmax() == 1  # blue top left, green bottom right


def test_shading_frames_are_orthonormal_including_the_poles():
    n = np.array([[0, 0, 1.0], [0, 0, -1.0], [1.0, 0, 0], [0, 1.0, 0], [0.6, 0, 0.8]])
    t, s = S.shading_frames(n)
    for a, b in ((t, s), (t, n), (s, n)):
        np.testing.assert_allclose((a * b).sum(-1), 0, atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(t, axis=-1), 1)
    np.testing.assert_allclose(np.cross(t, s), n, atol=1e-12)


def test_white_furnace_lambert_sphere_shows_its_albedo():
    img = S.ibl_sphere(
        LAMBERT, LambertParams(base_color=tuple(RHO)), np.ones((16, 32, 3)), resolution=24, spp=64
    )
    _, inside = S.sphere_normals(24)
    np.testing.assert_allclose(img[inside].mean(axis=0), RHO, rtol=0.01)


def test_ibl_lights_the_sphere_from_the_side_the_environment_is_bright():
    env = np.zeros((16, 32, 3))
    env[:3] = 10.0  # a bright zenith (row 0 is +y)
    img = S.ibl_sphere(LAMBERT, LambertParams(), env, resolution=24, spp=32)
    assert img[:6].mean() > 20 * img[-6:].mean()


def test_lat_long_sampling_density_integrates_to_one():
    rng = np.random.default_rng(3)
    env = S.LatLong(rng.random((8, 16, 3)) * 5)
    d = env.sample(rng.random((20000, 3)))
    np.testing.assert_allclose(np.linalg.norm(d, axis=-1), 1)
    # E[1/pdf] over the sampler's own directions is the sphere's area.
    assert np.mean(1.0 / env.pdf(d)) == pytest.approx(4 * math.pi, rel=0.02)


def test_lat_long_lookup_finds_each_texel_where_mitsuba_shows_it():
    from lookdev.pipeline.proof import ibl

    d, _ = ibl.directions(32)  # Mitsuba's envmap convention, measured by the proof module
    pixels = np.arange(16 * 32 * 3, dtype=np.float64).reshape(16, 32, 3)
    looked_up = S.LatLong(pixels).lookup(d)
    np.testing.assert_array_equal(looked_up[1:-1], pixels[1:-1])  # poles: any column


def test_mirror_like_sphere_reflects_the_environment_without_bias():
    # Phong with a high exponent in a constant sky: radiance = albedo(θ) ≈ cos-weighted.
    p = PhongParams(exponent=50.0)
    img = S.ibl_sphere(PHONG, p, np.ones((8, 16, 3)), resolution=9, spp=256, seed=2)
    from lookdev.pipeline.analysis.albedo import albedo_quadrature

    centre = albedo_quadrature(PHONG, p, [0.0], n_mu=128, n_phi=32).albedo[0, 0]
    assert img[4, 4, 0] == pytest.approx(centre, rel=0.03)


# -- figures -------------------------------------------------------------------------
@pytest.mark.slow
@pytest.mark.parametrize("view", P.VIEWS)
def test_every_view_draws_several_materials_labelled(tmp_path, view, monkeypatch):
    monkeypatch.setitem(registry.MODELS, "lambert", LAMBERT)
    monkeypatch.setitem(registry.MODELS, "phong", PHONG)
    hubs = [
        BlendedMaterial.of_params(LambertParams(), name="lambert"),
        BlendedMaterial.of_params(PhongParams(), name="phong"),
    ]
    env = np.ones((8, 16, 3)) if view == "sphere" else None
    fig = P.figure(hubs, view, environment=env, resolution=24)
    titles = [ax.get_title() for ax in fig.axes]
    assert any("lambert" in t for t in titles) and any("phong" in t for t in titles)
    out = P.save_figure(fig, tmp_path / f"{view}.png")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert not list(tmp_path.glob(".*tmp*"))


# -- lookdev plot ----------------------------------------------------------------------
def test_cli_rejects_an_unknown_output_format_in_one_line(cli, tmp_path):
    res = cli("plot", "gold", "-o", str(tmp_path / "a.jpg"))
    assert res.code == 2
    assert "allowed .png, .pdf, .svg" in res.err and "Traceback" not in res.err
    assert not list(tmp_path.iterdir())


def test_cli_names_a_missing_preset(cli, tmp_path):
    res = cli("plot", "no_such_preset", "-o", str(tmp_path / "a.png"))
    assert res.code == 2 and "no_such_preset" in res.err
    assert not list(tmp_path.iterdir())


def test_cli_ibl_only_with_sphere(cli, tmp_path):
    res = cli("plot", "gold", "--view", "slice", "--ibl", "studio", "-o", str(tmp_path / "a.png"))
    assert res.code == 2 and "--ibl" in res.err


@pytest.mark.slow
@pytest.mark.parametrize("view", P.VIEWS)
def test_cli_plots_presets_side_by_side(cli, tmp_path, view):
    out = tmp_path / f"{view}.png"
    ibl = ["--ibl", "studio"] if view == "sphere" else []
    res = cli(
        "plot",
        "gold",
        "plaster",
        "--view",
        view,
        "-o",
        str(out),
        "--resolution",
        "24",
        "--json",
        *ibl,
    )
    assert res.code == 0, res.err
    assert json.loads(res.out) == {
        "output": str(out),
        "view": view,
        "materials": ["gold", "plaster"],
    }
    assert out.read_bytes()[:4] == b"\x89PNG"


# -- the shipped models, checked the same way -----------------------------------------
def _preset(name: str) -> BlendedMaterial:
    return blend(load_material(name), 16)


def test_metal_with_roughness_0_2_slice_peaks_at_theta_h_zero():
    gold = _preset("gold")
    assert gold.params.metallic == 1.0 and gold.params.roughness == 0.2
    _, td, f = P.brdf_slice(gold.bsdf_model, gold.params, n=90)
    for c in range(3):
        assert np.all(np.argmax(f[:, :, c], axis=1) == 0)  # every θd row, every channel


@pytest.mark.parametrize("incidence", [0.0, 30.0, 60.0])
def test_metal_polar_peak_is_at_the_mirror_direction(incidence):
    gold = _preset("gold")
    theta_o, lum = P.polar_curves(gold.bsdf_model, gold.params, [incidence], n=1441)
    # G and 1/cos θo lean the peak of f a little past the mirror direction, growing to
    # grazing (0.2° at 60°); the mirror direction itself is the D peak.
    assert math.degrees(theta_o[np.argmax(lum[0])]) == pytest.approx(incidence, abs=0.3)


def test_disney_albedo_sampler_and_quadrature_agree_on_a_rough_material():
    from lookdev.pipeline.analysis.albedo import albedo_monte_carlo, albedo_quadrature

    plaster = _preset("plaster")
    theta = np.radians([0.0, 30.0, 60.0, 80.0])
    q = albedo_quadrature(plaster.bsdf_model, plaster.params, theta, n_mu=128, n_phi=128)
    mc = albedo_monte_carlo(plaster.bsdf_model, plaster.params, theta, n_samples=8192)
    assert np.all(np.abs(mc.albedo - q.albedo) <= 5 * mc.stderr + 1e-3)


@pytest.mark.parametrize("r", [0.05, 0.3, 1.0])
def test_sheen_albedo_table_agrees_with_quadrature(r):
    from lookdev.materials import sheen
    from lookdev.pipeline.analysis.albedo import albedo_quadrature, albedo_tabulated

    p = sheen.SheenParams(roughness=r, color=(1.0, 0.5, 0.25))
    theta = np.radians([0.0, 30.0, 60.0, 80.0])
    q = albedo_quadrature(sheen.MODEL, p, theta, n_mu=256, n_phi=128).albedo
    t = albedo_tabulated(sheen.MODEL, p, theta).albedo
    np.testing.assert_allclose(t, q, atol=5e-4)
    np.testing.assert_allclose(t[:, 1] / t[:, 0], 0.5)  # F scales the table per channel


def test_layered_preset_is_plotted_at_its_centre_texel(tmp_path):
    hub = blend(load_material("rusty_iron"), 32)
    assert hub.maps, "rusty_iron should vary across the surface"
    assert hub.name == "rusty_iron"
    assert hub.bsdf_model is registry.model_named("disney")
    assert hub.centre_params.model_dump() == hub.params_at(16, 16).model_dump()
    fig = P.figure([hub], "albedo", resolution=16)
    assert [ax.get_title() for ax in fig.axes] == ["rusty_iron\n(centre texel)"]


LAMBERTIAN_PRESET = """\
name = "matte"
model = "pixar"
description = "Pixar's all-diffuse end: roughness 1 is a Lambertian surface."
[params]
surface_color = [0.8, 0.5, 0.2]
roughness = 1.0
"""


@pytest.fixture
def lambertian_preset(tmp_path):
    path = tmp_path / "matte.toml"
    path.write_text(LAMBERTIAN_PRESET)
    return blend(load_material(str(path)), 16)


def test_lambertian_preset_views_match_closed_forms(lambertian_preset):
    s = lambertian_preset
    (curve,) = P.albedo_curves(s)  # what the albedo view draws
    np.testing.assert_allclose(curve.albedo, np.tile(RHO, (len(curve.theta), 1)), rtol=1e-12)
    _, lum = P.polar_curves(s.bsdf_model, s.params, [0, 60, 89])
    np.testing.assert_allclose(lum, luminance(RHO) / math.pi, rtol=1e-12)
    light = np.array([-1.0, 1.0, 1.0]) / math.sqrt(3.0)
    img = S.point_light_sphere(
        s.bsdf_model, s.params, resolution=32, light=tuple(light), irradiance=1.0
    )
    n, inside = S.sphere_normals(32)
    expected = np.clip(n @ light, 0, None)[..., None] * RHO / math.pi * inside[..., None]
    np.testing.assert_allclose(img, expected, atol=1e-15)


@pytest.mark.parametrize("model_name", ["disney", "pixar", "sheen"])
@pytest.mark.parametrize("roughness", [0.0, 1.0])
def test_views_of_every_model_are_finite_at_the_roughness_edges(model_name, roughness):
    model = registry.model_named(model_name)
    params = model.params_type().replace(roughness=roughness)
    with np.errstate(all="raise"):  # the views themselves must not over/underflow
        _, _, f = P.brdf_slice(model, params, n=24)
        _, lum = P.polar_curves(model, params, [0, 89.5], n=91)
        (curve, *_) = P.albedo_curves(BlendedMaterial.of_params(params), n_theta=10)
        img = S.point_light_sphere(model, params, resolution=16)
    for a in (f, lum, curve.albedo, curve.stderr, img):
        assert np.all(np.isfinite(a)) and np.all(a >= 0)


def test_clear_glass_albedo_adds_the_transmitted_share_compressed_by_eta_squared():
    glass = _preset("glass_clear")
    total = P.total_curve(glass, n_theta=3)
    eta = glass.params.ior
    f0 = ((eta - 1) / (eta + 1)) ** 2  # Fresnel at normal incidence, an independent number
    assert total.albedo[0] == pytest.approx(np.full(3, f0 + (1 - f0) / eta**2), rel=0.02)
    assert P.total_curve(_preset("gold")) is None  # an opaque metal transmits nothing


# -- one parameter varied (--vary) -------------------------------------------------------
def test_varied_draws_one_column_per_gamma_and_lower_gamma_has_the_longer_tail():
    from lookdev.materials.params import DisneyParams

    gold = BlendedMaterial.of_params(DisneyParams(metallic=1.0, roughness=0.3), name="gold")
    hubs = P.varied([gold], "specular_gamma", [1.0, 1.5, 2.0, 3.0])
    assert [h.params.specular_gamma for h in hubs] == [1.0, 1.5, 2.0, 3.0]
    assert [h.name for h in hubs][0] == "gold specular_gamma=1"
    # the slice's tail (θh = 45°, θd = 0) falls as γ grows: GTR's shape knob (App. B)
    tails = [P.brdf_slice(h.bsdf_model, h.params, 16)[2][0, 8, 1] for h in hubs]
    assert tails == sorted(tails, reverse=True) and tails[0] > 3 * tails[-1]


def test_varied_rejects_what_the_schema_rejects_in_one_line(cli, tmp_path):
    res = cli("plot", "gold", "--vary", "specular_gamma=0", "-o", str(tmp_path / "a.png"))
    assert res.code == 2 and "specular_gamma" in res.err and "Traceback" not in res.err
    res = cli("plot", "gold", "--vary", "nonsense", "-o", str(tmp_path / "a.png"))
    assert res.code == 2 and "--vary" in res.err
    assert not list(tmp_path.iterdir())


def test_varied_switch_shows_energy_compensation_off_and_on(cli, tmp_path):
    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.analysis.albedo import albedo_monte_carlo

    metal = DisneyParams(metallic=1.0, base_color=(1.0, 1.0, 1.0), roughness=0.9)
    hubs = P.varied([BlendedMaterial.of_params(metal, name="m")], "energy_compensation", [0, 1])
    assert [h.name for h in hubs] == ["m energy_compensation=off", "m energy_compensation=on"]
    assert [h.params.energy_compensation for h in hubs] == [False, True]
    off, on = (albedo_monte_carlo(h.bsdf_model, h.params, [0.0]).albedo[0, 0] for h in hubs)
    assert off < 0.5 and on == pytest.approx(1.0, abs=0.01)
    out = tmp_path / "ms.png"
    res = cli(
        "plot", "gold", "--view", "albedo", "--vary", "energy_compensation=off,on", "-o", str(out)
    )
    assert res.code == 0 and out.stat().st_size > 0
