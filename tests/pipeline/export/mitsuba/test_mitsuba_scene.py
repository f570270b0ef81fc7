"""Mitsuba BSDF dicts, scenes and XML (pipeline/export/mitsuba/scene.py, xml.py)."""

from __future__ import annotations

import numpy as np
import pytest
from _mitsuba_tiny import TinyParams

from lookdev.materials.errors import LookdevError
from lookdev.pipeline.export.mitsuba.scene import scene_dict

pytestmark = pytest.mark.render


@pytest.fixture(scope="module")
def mi():
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba

    return mitsuba


@pytest.fixture
def m(mi, monkeypatch):
    """The export module with the tiny test model known as model 'tiny_test'."""
    from _mitsuba_tiny import TINY

    from lookdev.materials import registry
    from lookdev.pipeline.export.mitsuba import scene

    monkeypatch.setitem(registry.MODELS, "tiny_test", TINY)
    return scene


def _blended(name="tiled", constants=None, **maps):
    """A BlendedMaterial of the tiny model: ``constants`` (default a grey base colour)
    and ``maps``, as the blending engine returns them."""
    from lookdev.pipeline.blend import BlendedMaterial

    h, w = next(iter(maps.values())).shape[:2] if maps else (1, 1)
    if constants is None:
        constants = {"base_color": (0.5, 0.5, 0.5)}
    return BlendedMaterial(name, "tiny_test", (w, h), dict(constants), maps=dict(maps))


def _render(mi, scene, seed=0):
    return np.array(mi.render(mi.load_dict(scene) if isinstance(scene, dict) else scene, seed=seed))


def test_bsdf_dict_of_params_uses_our_plugin(mi, m):
    d = m.bsdf_dict(TinyParams(translucency=0.25, base_color=(0.1, 0.2, 0.3)))
    assert d["type"] == "lookdev_tiny_test"
    assert d["translucency"] == 0.25
    assert d["base_color"] == {"type": "rgb", "value": [0.1, 0.2, 0.3]}
    assert mi.load_dict(d).flags() & mi.BSDFFlags.DiffuseTransmission


def test_given_parameters_only(mi, m):
    assert m.bsdf_dict(TinyParams()) == {"type": "lookdev_tiny_test"}


def test_bad_parameters_are_one_line_errors(mi, m):
    """A hub's constants are not validated again on export; the plugin validates them when
    Mitsuba loads it; a constant or map the model does not take is refused on export."""
    with pytest.raises(LookdevError, match="roughnes") as info:
        m.bsdf_dict(_blended("bad", {"roughnes": 0.5}))
    assert "\n" not in str(info.value)
    foreign_map = _blended(roughnes=np.zeros((2, 2), np.float32))
    with pytest.raises(LookdevError, match="roughnes") as info:
        m.scene_dict(foreign_map)  # before the depth rule runs the model on it
    assert "\n" not in str(info.value)
    d = m.bsdf_dict(_blended("bad", {"translucency": 2.0}))
    with pytest.raises(Exception, match="translucency"):
        mi.load_dict(d)


def test_a_library_material_must_be_blended_first(m):
    from lookdev.library import load_material

    with pytest.raises(LookdevError, match="blended material"):
        m.bsdf_dict(load_material("gold"))


def test_maps_become_bitmaps_in_memory_and_in_files(mi, m, tmp_path):
    h, w = 4, 8
    trans = np.zeros((h, w), np.float32)
    trans[:, w // 2 :] = 1.0  # right half of UV space transmits everything
    color = np.broadcast_to(np.array([0.9, 0.3, 0.1], np.float32), (h, w, 3)).copy()
    blended = _blended(translucency=trans, base_color=color)
    in_memory = mi.load_dict(m.bsdf_dict(blended))
    on_disk_dict = m.bsdf_dict(blended, tmp_path / "tex")
    files = sorted(p.name for p in (tmp_path / "tex").iterdir())
    assert files == ["tiled_base_color.exr", "tiled_translucency.exr"]
    on_disk = mi.load_dict(on_disk_dict)
    import drjit as dr

    si = dr.zeros(mi.SurfaceInteraction3f, 2)
    si.wi = mi.Vector3f(0, 0, 1)
    si.uv = mi.Point2f([0.25, 0.75], [0.5, 0.5])
    below = mi.Vector3f(0, 0, -1)
    for bsdf in (in_memory, on_disk):
        value = np.array(bsdf.eval(mi.BSDFContext(), si, below))
        np.testing.assert_allclose(value[:, 0], 0.0)
        np.testing.assert_allclose(value[:, 1], np.array([0.9, 0.3, 0.1]) / np.pi, rtol=1e-5)


def test_map_rows_follow_v(mi, m):
    """Row 0 of a map is v = 0 (BlendedMaterial's texel (0, 0) = UV (0, 0))."""
    import drjit as dr

    trans = np.zeros((2, 1), np.float32)
    trans[0] = 1.0
    bsdf = mi.load_dict(m.bsdf_dict(_blended(translucency=trans)))
    si = dr.zeros(mi.SurfaceInteraction3f, 2)
    si.wi = mi.Vector3f(0, 0, 1)
    si.uv = mi.Point2f([0.5, 0.5], [0.25, 0.75])  # the two texel centres
    value = np.array(bsdf.eval(mi.BSDFContext(), si, mi.Vector3f(0, 0, -1)))
    np.testing.assert_allclose(value[:, 0], 0.5 / np.pi, rtol=1e-5)
    assert np.all(value[:, 1] == 0)


def test_max_depth_follows_the_material(m):
    from lookdev.pipeline.export.mitsuba import depth

    dark = TinyParams(base_color=(0.1, 0.1, 0.1))
    assert depth.max_depth_for(dark) == depth.DEPTH_DARK
    assert depth.max_depth_for(TinyParams()) == depth.DEPTH_BRIGHT  # ρ = 0.8
    assert depth.max_depth_for(TinyParams(translucency=0.5)) == depth.DEPTH_THIN_DIFFUSE
    zero = _blended(constants={"base_color": (0.1, 0.1, 0.1)}, translucency=np.zeros((4, 4)))
    assert depth.max_depth_for(zero) == depth.DEPTH_DARK
    some = np.zeros((4, 4), np.float32)
    some[3, 3] = 0.01  # one texel transmits: the whole material needs the longer paths
    assert depth.max_depth_for(_blended(translucency=some)) == depth.DEPTH_THIN_DIFFUSE


def test_albedo_for_is_the_normal_incidence_albedo_anywhere(m):
    """Tiny model at normal view: albedo ρ(1 + cos 0)/2 = ρ, the largest channel and texel."""
    from lookdev.pipeline.export.mitsuba import depth

    assert depth.albedo_for(TinyParams(base_color=(0.3, 0.7, 0.2))) == pytest.approx(0.7, rel=1e-6)
    color = np.full((8, 8, 3), 0.2, np.float32)
    color[5, 6] = (0.1, 0.9, 0.3)  # one bright texel among 64: sampled, so it counts
    assert depth.albedo_for(_blended(base_color=color)) == pytest.approx(0.9, rel=1e-6)


def test_force_all_lobes_is_passed_to_the_plugin(mi, m):
    d = m.bsdf_dict(TinyParams(), force_all_lobes=True)
    assert d["force_all_lobes"] is True
    assert mi.load_dict(d).flags() & mi.BSDFFlags.DiffuseTransmission


def test_white_furnace_sphere_shows_the_model(mi, m):
    """Centre of a sphere under a constant white sky, single scattering: its albedo."""
    params = TinyParams(base_color=(0.8, 0.5, 0.2))
    scene = scene_dict(params, resolution=(32, 32), spp=256, max_depth=2)
    image = _render(mi, scene)
    centre = image[14:18, 14:18].reshape(-1, 3)
    # Tiny model at normal view: albedo = ρ · (0.5 + 0.5·1) = ρ.
    np.testing.assert_allclose(centre.mean(axis=0), [0.8, 0.5, 0.2], rtol=0.02)


def test_xml_loads_and_renders_like_the_dict(mi, m, tmp_path):
    from lookdev.pipeline.export.mitsuba import xml

    trans = np.zeros((4, 4), np.float32)
    trans[:2] = 0.5
    blended = _blended(translucency=trans)
    path = tmp_path / "out" / "scene.xml"
    written = xml.export_scene(blended, path, resolution=(16, 16), spp=8)
    assert written["ball"]["bsdf"]["translucency"]["filename"].endswith("tiled_translucency.exr")
    text = path.read_text()
    first = text.splitlines()[0]
    assert first.startswith("<!--") and "register_plugins()" in first and first.endswith("-->")
    assert 'value="scene_textures/tiled_translucency.exr"' in text
    assert sorted(p.name for p in path.parent.iterdir()) == ["scene.xml", "scene_textures"]
    loaded = mi.load_file(str(path))
    same = scene_dict(blended, resolution=(16, 16), spp=8)
    np.testing.assert_allclose(_render(mi, loaded), _render(mi, same), rtol=1e-5, atol=1e-6)


def test_xml_without_our_plugins_has_no_hint(mi):
    from lookdev.pipeline.export.mitsuba import xml

    text = xml.to_xml({"type": "scene", "s": {"type": "sphere", "bsdf": {"type": "diffuse"}}})
    assert xml.LOAD_HINT not in text
    comment, scene = text.split("\n", 1)  # only the colour note: the space its RGB is in
    assert comment == f"<!--{xml.colour_note()}-->" and scene.startswith("<scene")
    assert '<bsdf type="diffuse" name="bsdf"' in text


def test_unwritable_folder_is_one_line_and_leaves_nothing(mi, m, tmp_path):
    from lookdev.pipeline.export.mitsuba import xml

    blocker = tmp_path / "a-file"
    blocker.write_text("not a folder")
    with pytest.raises(LookdevError, match="cannot create folder .*a-file is a file") as info:
        xml.export_scene(TinyParams(), blocker / "scene.xml")
    assert "\n" not in str(info.value)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a-file"]


def test_in_memory_textures_cannot_go_to_xml(mi, m):
    from lookdev.pipeline.export.mitsuba import xml

    scene = scene_dict(_blended(translucency=np.ones((2, 2), np.float32)))
    with pytest.raises(LookdevError, match="texture folder"):
        xml.to_xml(scene)


# -- with the Disney model and the library ------------------------------------------------
@pytest.fixture
def disney():
    return pytest.importorskip("lookdev.materials.disney")


def _principled_vs_plugin(mi, m, params, n=4096, seed=0):
    """Max relative difference of principled and our plugin on random direction pairs."""
    import drjit as dr

    from lookdev.pipeline.blend import BlendedMaterial

    fast = m.principled_equivalent(BlendedMaterial.of_params(params))
    assert fast is not None
    ours = mi.load_dict(m.bsdf_dict(params, allow_principled=False))
    theirs = mi.load_dict(fast)
    rng = np.random.default_rng(seed)
    view = rng.normal(size=(n, 3))
    view[:, 2] = np.abs(view[:, 2])
    light = rng.normal(size=(n, 3))
    light[:, 2] = np.abs(light[:, 2])
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f((view / np.linalg.norm(view, axis=1, keepdims=True)).T)
    si.sh_frame = mi.Frame3f(mi.Vector3f(0, 0, 1))
    wo = mi.Vector3f((light / np.linalg.norm(light, axis=1, keepdims=True)).T)
    a = np.array(ours.eval(mi.BSDFContext(), si, wo))
    b = np.array(theirs.eval(mi.BSDFContext(), si, wo))
    return float(np.max(np.abs(a - b) / np.maximum(np.abs(b), 1e-3)))


@pytest.mark.parametrize("roughness", [0.04, 0.05, 0.5, 1.0])
@pytest.mark.parametrize("anisotropic", [0.0, 1.0])
def test_principled_fast_path_equals_our_metal(mi, m, disney, roughness, anisotropic):
    from lookdev.materials.params import DisneyParams

    params = DisneyParams(
        metallic=1.0, base_color=(0.95, 0.64, 0.54), roughness=roughness, anisotropic=anisotropic
    )
    assert _principled_vs_plugin(mi, m, params) < 1e-4


def test_a_smooth_metal_is_our_delta_mirror_not_principled(m):
    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.blend import BlendedMaterial

    for anisotropic in (0.0, 0.5):
        smooth = DisneyParams(metallic=1.0, roughness=0.0, anisotropic=anisotropic)
        assert m.principled_equivalent(BlendedMaterial.of_params(smooth)) is None


def test_fast_path_only_where_measured(m, disney):
    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.blend import BlendedMaterial

    def fast(**kw):
        return m.principled_equivalent(BlendedMaterial.of_params(DisneyParams(**kw)))

    assert fast(metallic=1.0, roughness=0.3) == {
        "type": "principled",
        "metallic": 1.0,
        "roughness": 0.3,
        "base_color": {"type": "rgb", "value": list(DisneyParams().base_color)},
    }
    assert fast(metallic=0.99) is None  # dielectric Fresnel part differs
    assert fast(metallic=1.0, clearcoat=0.5) is None  # clearcoat normalisation differs
    assert fast(metallic=1.0, specular_gamma=3.0) is None  # principled is GGX (γ = 2) only
    assert fast(metallic=1.0, specular_gamma=2.0) is not None
    assert fast(metallic=1.0, energy_compensation=True) is None  # principled: single scattering
    assert m.bsdf_dict(DisneyParams(metallic=1.0), force_all_lobes=True)["type"] == "lookdev_disney"


def test_depth_for_disney(m, disney):
    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.export.mitsuba import depth

    assert depth.max_depth_for(DisneyParams(base_color=(0.05, 0.05, 0.05))) == depth.DEPTH_DARK
    assert depth.max_depth_for(DisneyParams(metallic=1.0)) == depth.DEPTH_BRIGHT
    thin_glass = DisneyParams(spec_trans=1.0, thin=True)
    assert depth.max_depth_for(thin_glass) == depth.DEPTH_THIN_GLOSSY
    solid_glass = DisneyParams(spec_trans=1.0, ior=1.5)
    assert depth.max_depth_for(solid_glass) == depth.DEPTH_SOLID_GLOSSY


def test_cli_export_mitsuba(mi, cli, disney, tmp_path):
    import json

    out = tmp_path / "gold" / "gold.xml"
    result = cli(
        "export",
        "mitsuba",
        "gold",
        "-o",
        str(out),
        "--resolution",
        "16",
        "16",
        "--spp",
        "4",
        "--json",
    )
    assert result.code == 0, result.err
    summary = json.loads(result.out)
    assert summary["scene"] == str(out) and summary["max_depth"] == 6  # a bright metal
    assert summary["bsdf"] == "principled" and not summary["plugins"]  # untextured metal
    assert np.all(np.isfinite(np.array(mi.render(mi.load_file(str(out))))))


def test_cli_bad_input_exits_2_with_one_line(cli, tmp_path):
    out = tmp_path / "x.xml"
    for args in (["no_such_preset"], ["gold", "--ibl", str(tmp_path / "missing.exr")]):
        result = cli("export", "mitsuba", *args, "-o", str(out))
        assert result.code == 2
        assert result.err.startswith("lookdev: error:") and result.err.count("\n") == 1
        assert not out.exists()


def test_forcing_all_lobes_traces_more_and_renders_the_same(mi, m, disney):
    """The pruning baseline: a metal's diffuse lobe (weight 1 − metallic = 0) is traced."""
    from lookdev.materials.params import DisneyParams

    metal = DisneyParams(metallic=1.0, roughness=0.3, base_color=(0.9, 0.6, 0.3))
    pruned = mi.load_dict(m.bsdf_dict(metal, allow_principled=False))
    forced = mi.load_dict(m.bsdf_dict(metal, force_all_lobes=True))
    assert not pruned.flags() & mi.BSDFFlags.Diffuse
    assert forced.flags() & mi.BSDFFlags.DiffuseReflection
    assert forced.flags() & mi.BSDFFlags.Transmission
    images = []
    for force in (False, True):
        scene = scene_dict(metal, resolution=(16, 16), spp=16, force_all_lobes=force)
        scene["ball"]["bsdf"] = m.bsdf_dict(metal, allow_principled=False, force_all_lobes=force)
        images.append(_render(mi, scene, seed=3))
    np.testing.assert_allclose(images[0], images[1], rtol=1e-4, atol=1e-5)


def test_every_builtin_preset_becomes_a_bsdf(mi, m, disney):
    """Each built-in preset exports (blended at 32²) and Mitsuba loads it."""
    from lookdev.library import Library
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.export.mitsuba import depth

    library = Library(use_env=False)
    for name in library.names():
        hub = blend(library.load(name), 32)
        bsdf = mi.load_dict(m.bsdf_dict(hub))
        assert bsdf.flags() != 0, name
        assert depth.max_depth_for(hub) in (4, 6, 10, 16, 64, 128), name


def test_cli_exports_a_layered_preset_with_its_maps(mi, cli, disney, tmp_path):
    import json

    out = tmp_path / "rust.xml"
    result = cli(
        "export",
        "mitsuba",
        "rusty_iron",
        "-o",
        str(out),
        "--map-resolution",
        "16",
        "--resolution",
        "8",
        "8",
        "--spp",
        "2",
        "--json",
    )
    assert result.code == 0, result.err
    summary = json.loads(result.out)
    assert summary["plugins"] and summary["bsdf"] == "lookdev_disney"
    assert len(summary["textures"]) >= 2
    assert all(p.startswith(str(tmp_path / "rust_textures")) for p in summary["textures"])
    assert out.read_text().startswith("<!-- lookdev BSDF plugins")
    image = np.array(mi.render(mi.load_file(str(out))))
    assert image.shape == (8, 8, 3) and np.all(np.isfinite(image))


def test_normal_maps_wrap_our_bsdf(mi, m, tmp_path):
    """A flat normal map (all +z) changes nothing; a tilted one changes the shading."""
    from lookdev.pipeline.export.mitsuba import xml

    flat_normals = np.zeros((4, 4, 3), np.float32)
    flat_normals[..., 2] = 1.0
    plain = _blended()
    bumped = _blended()
    bumped.normal_map = flat_normals
    d = m.bsdf_dict(bumped)
    assert d["type"] == "normalmap" and d["bsdf"]["type"] == "lookdev_tiny_test"
    np.testing.assert_allclose(
        np.array(d["normalmap"]["data"]), [0.5, 0.5, 1.0] * np.ones((4, 4, 1))
    )
    scenes = [scene_dict(b, resolution=(16, 16), spp=64) for b in (plain, bumped)]
    a, b = (_render(mi, s, seed=4) for s in scenes)
    np.testing.assert_allclose(a.mean(), b.mean(), rtol=0.01)
    tilted = _blended()
    tilted.normal_map = np.broadcast_to(np.array([0.6, 0.0, 0.8], np.float32), (4, 4, 3)).copy()
    assert (
        abs(_render(mi, scene_dict(tilted, resolution=(16, 16), spp=64)).mean() - a.mean()) > 0.01
    )
    text = xml.to_xml(scene_dict(bumped, texture_dir=tmp_path), relative_to=tmp_path)
    assert '<bsdf type="normalmap"' in text and "tiled_normal.exr" in text


SCALAR_SCRIPT = """
import sys, numpy as np, mitsuba as mi
mi.set_variant("scalar_rgb")
import lookdev.pipeline.export.mitsuba as m
from lookdev.library import load_material
from lookdev.pipeline.blend import blend
m.register_plugins()
for name in sys.argv[1:]:
    scene = m.scene_dict(blend(load_material(name), 16), resolution=(4, 4), spp=2)
    print(name, float(np.mean(np.array(mi.render(mi.load_dict(scene))))))
"""


@pytest.mark.slow
def test_plugins_render_on_the_scalar_fallback_variant(disney):
    """Without a usable libLLVM lookdev falls back to scalar_rgb: the plugins work there."""
    import subprocess
    import sys

    presets = ["plastic_glossy", "glass_clear", "rusty_iron", "pixar_translucent_plastic"]
    run = subprocess.run(
        [sys.executable, "-c", SCALAR_SCRIPT, *presets],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    means = dict(line.split() for line in run.stdout.splitlines())
    assert sorted(means) == sorted(presets)
    assert all(0.0 < float(v) < 10.0 for v in means.values())
