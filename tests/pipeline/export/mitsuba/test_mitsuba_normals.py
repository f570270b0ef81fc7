"""Two shading normals in Mitsuba: diffuse and highlight lobes under their own normal maps."""

from __future__ import annotations

import numpy as np
import pytest

pytestmark = pytest.mark.render

FLAT = np.broadcast_to(np.array([0.0, 0.0, 1.0], np.float32), (4, 4, 3)).copy()
TILTED = np.broadcast_to(np.array([0.5, 0.0, 0.866], np.float32), (4, 4, 3)).copy()


@pytest.fixture(scope="module")
def mi():
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba

    return mitsuba


def _blended(model="disney", normal=FLAT, specular=TILTED, **constants):
    """A uniform BlendedMaterial under two normal maps (4 × 4 texels)."""
    from lookdev.pipeline.blend import BlendedMaterial

    values = {"base_color": (0.6, 0.3, 0.2), "roughness": 0.3} | constants
    return BlendedMaterial(
        "bumpy", model, (4, 4), values, normal_map=normal, specular_normal_map=specular
    )


def _bsdf(blended, **kw):
    from lookdev.pipeline.export.mitsuba import bsdf_dict

    return bsdf_dict(blended, **kw)


def _eval(mi, d, wi, wo):
    """f·cos of the BSDF ``d`` at a hit on a z-up surface (uv in the maps' middle)."""
    import drjit as dr

    bsdf = mi.load_dict(d)
    n = len(wi)
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.n = mi.Normal3f(0.0, 0.0, 1.0)
    si.sh_frame = mi.Frame3f(si.n)
    si.uv = mi.Point2f(0.5, 0.5)
    si.dp_du, si.dp_dv = mi.Vector3f(1.0, 0.0, 0.0), mi.Vector3f(0.0, 1.0, 0.0)
    si.wi = mi.Vector3f(*(np.ascontiguousarray(wi[:, i]) for i in range(3)))
    out = mi.Vector3f(*(np.ascontiguousarray(wo[:, i]) for i in range(3)))
    return np.array(bsdf.eval(mi.BSDFContext(), si, out)).reshape(3, -1).T


def _upper(rng, n):
    d = rng.normal(size=(n, 3))
    d[:, 2] = np.abs(d[:, 2]) + 0.05
    return d / np.linalg.norm(d, axis=1, keepdims=True)


def test_two_normals_make_two_restricted_halves(mi):
    d = _bsdf(_blended(clearcoat=1.0))
    assert d["type"] == "blendbsdf" and d["weight"] == 0.5
    halves = [d["bsdf_0"], d["bsdf_1"]]
    assert all(h["type"] == "normalmap" for h in halves)
    inner = [h["bsdf"] for h in halves]
    assert [h["only_lobes"] for h in inner] == ["diffuse", "specular,clearcoat"]
    assert all(h["weight_scale"] == 2.0 for h in inner)
    tilted = np.array(halves[1]["normalmap"]["data"])
    np.testing.assert_allclose(tilted[0, 0], 0.5 * TILTED[0, 0] + 0.5, atol=1e-6)


def test_split_halves_sum_to_the_whole_material(mi):
    """Both frames flat (the arrays differ below float32 encoding): the split BSDF is the
    unsplit one, lobe for lobe, so doubling each half under a ½ blend is exact."""
    nearly_flat = FLAT.copy()
    nearly_flat[..., 0] = 1e-9
    material = _blended(normal=FLAT, specular=nearly_flat, sheen=0.5, clearcoat=1.0)
    split = _bsdf(material)
    assert split["type"] == "blendbsdf"
    whole = _bsdf(_blended(normal=FLAT, specular=None, sheen=0.5, clearcoat=1.0))
    assert whole["type"] == "normalmap"
    rng = np.random.default_rng(3)
    wi, wo = _upper(rng, 256), _upper(rng, 256)
    np.testing.assert_allclose(_eval(mi, split, wi, wo), _eval(mi, whole, wi, wo), rtol=2e-5)


def test_the_highlight_follows_its_own_normal(mi):
    """A sharp highlight under a normal tilted 30° about y peaks at the mirror direction
    about that normal, not about the geometric one; the diffuse half stays put."""
    d = _bsdf(_blended(roughness=0.15, base_color=(0.5, 0.5, 0.5)))
    view = np.array([[0.0, 0.0, 1.0]])
    n_tilted = TILTED[0, 0] / np.linalg.norm(TILTED[0, 0])
    about_tilted = 2 * n_tilted[2] * n_tilted - view[0]  # reflect the view about it
    about_geometric = np.array([0.0, 0.0, 1.0])
    lights = np.array([about_tilted, about_geometric])
    f = _eval(mi, d, np.repeat(view, 2, axis=0), lights).mean(axis=1)
    assert f[0] > 5 * f[1]


def test_a_metal_has_no_diffuse_half(mi):
    """Only highlight lobes live: one BSDF under the highlight normal, no blend."""
    d = _bsdf(_blended(metallic=1.0, roughness=0.2), allow_principled=False)
    assert d["type"] == "normalmap" and d["bsdf"]["type"] == "lookdev_disney"
    assert "only_lobes" not in d["bsdf"]
    np.testing.assert_allclose(np.array(d["normalmap"]["data"])[0, 0], 0.5 * TILTED[0, 0] + 0.5)


def test_equal_normals_need_no_split(mi):
    d = _bsdf(_blended(normal=TILTED, specular=TILTED.copy()))
    assert d["type"] == "normalmap" and "only_lobes" not in d["bsdf"]


def test_pixar_layered_weights_split_by_lobe_group(mi):
    from lookdev.pipeline.blend import BlendedMaterial

    weights = {"diffN": (0.5, 0.4, 0.3), "diffG": (0.2, 0.2, 0.2), "specN": (0.04,) * 3}
    weights |= {"specG": (0.3,) * 3, "reflN": (0.02,) * 3, "reflG": (0.5,) * 3}
    d = _bsdf(
        BlendedMaterial(
            "layered",
            "pixar",
            (4, 4),
            weights | {"specular_cone": 12.0, "reflection_cone": 1.0},
            representation="lobe_weights",
            normal_map=FLAT,
            specular_normal_map=TILTED,
        )
    )
    inner = [d["bsdf_0"]["bsdf"], d["bsdf_1"]["bsdf"]]
    assert inner[0]["type"] == "lookdev_pixar_layered"
    assert [h["only_lobes"] for h in inner] == ["diffuse", "specular,reflection"]


@pytest.mark.slow
def test_chi2_of_a_restricted_scaled_half(mi):
    """A half samples its own lobes only, with its odds renormalised (Model.restrict)."""
    from _mitsuba_chi2 import chi2

    values = {"clearcoat": 1.0, "clearcoat_gloss": 0.0, "sheen": 1.0, "roughness": 0.5}
    d = _bsdf(_blended(normal=None, specular=None, **values))  # peaks wide enough (α ≥ 0.1)
    d |= {"only_lobes": "specular,clearcoat", "weight_scale": 2.0}
    for wi in ([0.0, 0.0, 1.0], [0.6, 0.0, 0.8]):
        passed, test = chi2(d, wi, test_count=2)
        assert passed, test.messages


def test_weight_scale_scales_f_and_sample_weights_not_pdfs(mi):
    import drjit as dr

    base = _bsdf(_blended(normal=None, specular=None))
    halves = [base | {"only_lobes": "specular", "weight_scale": s} for s in (1.0, 2.0)]
    rng = np.random.default_rng(8)
    wi, wo = _upper(rng, 64), _upper(rng, 64)
    f1, f2 = (_eval(mi, h, wi, wo) for h in halves)
    np.testing.assert_allclose(f2, 2 * f1, rtol=1e-6)
    bsdfs = [mi.load_dict(h) for h in halves]
    si = dr.zeros(mi.SurfaceInteraction3f, 64)
    si.sh_frame = mi.Frame3f(mi.Normal3f(0.0, 0.0, 1.0))
    si.wi = mi.Vector3f(*(np.ascontiguousarray(wi[:, i]) for i in range(3)))
    u1, u2 = mi.Float(rng.random(64)), mi.Point2f(rng.random(64), rng.random(64))
    (s1, w1), (s2, w2) = (b.sample(mi.BSDFContext(), si, u1, u2) for b in bsdfs)
    np.testing.assert_allclose(np.array(s2.pdf), np.array(s1.pdf))
    np.testing.assert_allclose(np.array(w2), 2 * np.array(w1), rtol=1e-6)


def test_a_split_material_exports_to_xml_and_renders(mi, tmp_path):
    from lookdev.pipeline.export.mitsuba import scene_dict, xml

    tree = scene_dict(_blended(clearcoat=1.0), texture_dir=tmp_path, resolution=(8, 8), spp=4)
    text = xml.to_xml(tree, relative_to=tmp_path)
    assert '<bsdf type="blendbsdf"' in text and text.count('<bsdf type="normalmap"') == 2
    assert 'name="only_lobes" value="specular,clearcoat"' in text
    out = tmp_path / "scene.xml"
    out.write_text(text)
    image = np.array(mi.render(mi.load_file(str(out))))
    assert image.shape == (8, 8, 3) and np.all(np.isfinite(image)) and image.mean() > 0


def test_a_metal_on_the_principled_fast_path_keeps_its_normal_map(mi):
    d = _bsdf(_blended(metallic=1.0, roughness=0.2, normal=TILTED, specular=None))
    assert d["type"] == "normalmap" and d["bsdf"]["type"] == "principled"
