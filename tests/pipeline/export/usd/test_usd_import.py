"""lookdev import usd (issue 15 §5): own exports come back exactly; other tools' patterns
(interface inputs, cut-outs, the specular workflow, OpenPBR, Standard Surface) give a
valid preset and name what a preset cannot hold."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

pytest.importorskip("pxr")
from pxr import Sdf, Usd, UsdShade  # noqa: E402

from lookdev.library import Library, load_material  # noqa: E402
from lookdev.library.preset import parse_preset  # noqa: E402
from lookdev.materials.params import DisneyParams  # noqa: E402
from lookdev.pipeline import api  # noqa: E402
from lookdev.pipeline.blend import BlendedMaterial  # noqa: E402
from lookdev.pipeline.export.usd import export_materials  # noqa: E402
from lookdev.pipeline.export.usd.network import ExportError  # noqa: E402
from lookdev.pipeline.export.usd.presets import import_names, preset_toml  # noqa: E402
from lookdev.pipeline.export.usd.reader import import_usd  # noqa: E402

LIB = Library(use_env=False)
T = Sdf.ValueTypeNames


def _preset(m, name=None):
    return parse_preset(preset_toml(m, name).encode(), where="test")


def test_every_builtin_preset_round_trips_exactly(tmp_path):
    out = tmp_path / "all.usda"
    api.export_usd([], out, ("universal",), all_presets=True, map_resolution=8, library=None)
    found = {m.name: m for m in import_usd(out)}
    assert set(found) == set(LIB.names())
    for name in LIB.names():
        got = _preset(found[name])
        material = load_material(name, LIB)
        if material.model == "layered":
            want = parse_preset(material.source.read_bytes(), where=name)
            assert got.layers == want.layers, name  # as parsed: defaults spelled or not
        else:
            given_ = material.params.model_dump(mode="json", exclude_unset=True, exclude_none=True)
            assert got.params == given_, name
            assert got.model == material.model
        assert found[name].loss == [], name


disney = st.fixed_dictionaries(
    {},
    optional={
        "base_color": st.tuples(*[st.floats(0, 1)] * 3),
        "metallic": st.floats(0, 1),
        "roughness": st.floats(0, 1),
        "clearcoat": st.floats(0, 4),
        "spec_trans": st.floats(0, 1),
        "ior": st.floats(1.0, 3.0),
        "thin": st.booleans(),
    },
)


@settings(
    max_examples=20, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(data=disney)
def test_random_presets_come_back_with_the_same_values(tmp_path, data):
    params = DisneyParams(**data)
    out = tmp_path / "r.usda"
    export_materials([BlendedMaterial.of_params(params, "rnd")], out, contexts=("universal",))
    (found,) = import_usd(out)
    assert DisneyParams.parse(found.params) == params  # exact: the record, not the network


def _stage(path: Path):
    stage = Usd.Stage.CreateNew(str(path))
    return stage


def _surface(stage, material_path: str, shader_id: str, output: str = "surface"):
    material = UsdShade.Material.Define(stage, material_path)
    shader = UsdShade.Shader.Define(stage, f"{material_path}/Surface")
    shader.CreateIdAttr(shader_id)
    port = material.CreateOutput(output, T.Token)
    port.ConnectToSource(shader.ConnectableAPI(), "surface" if output == "surface" else "out")
    return material, shader


def test_values_on_the_material_interface_are_followed(tmp_path):
    """usdex/Houdini/Omniverse: shader inputs connect to the Material's own inputs."""
    path = tmp_path / "iface.usda"
    stage = _stage(path)
    material, shader = _surface(stage, "/Looks/Tile", "UsdPreviewSurface")
    for name, kind, value in (
        ("diffuseColor", T.Color3f, (0.7, 0.2, 0.1)),
        ("roughness", T.Float, 0.35),
        ("metallic", T.Float, 0.0),
    ):
        iface = material.CreateInput(name, kind)
        iface.Set(value)
        shader.CreateInput(name, kind).ConnectToSource(iface)
    stage.Save()
    (found,) = import_usd(path)
    assert found.params["base_color"] == pytest.approx((0.7, 0.2, 0.1))
    assert found.params["roughness"] == pytest.approx(0.35)


def test_cut_out_alpha_stays_opaque_and_is_named(tmp_path):
    path = tmp_path / "leaf.usda"
    stage = _stage(path)
    _, shader = _surface(stage, "/Looks/Leaf", "UsdPreviewSurface")
    shader.CreateInput("diffuseColor", T.Color3f).Set((0.1, 0.5, 0.1))
    shader.CreateInput("opacity", T.Float).Set(0.2)
    shader.CreateInput("opacityThreshold", T.Float).Set(0.5)
    shader.CreateInput("emissiveColor", T.Color3f).Set((1.0, 0.5, 0.0))
    shader.CreateInput("occlusion", T.Float).Set(0.5)
    normal = UsdShade.Shader.Define(stage, "/Looks/Leaf/Normal")
    normal.CreateIdAttr("UsdUVTexture")
    normal.CreateInput("file", T.Asset).Set("./leaf_n.png")
    shader.CreateInput("normal", T.Normal3f).ConnectToSource(normal.CreateOutput("rgb", T.Float3))
    stage.Save()
    (found,) = import_usd(path)
    assert "spec_trans" not in found.params  # not turned into glass
    text = " ".join(found.loss)
    assert "cut-out (opacityThreshold 0.5)" in text and "imported opaque" in text
    assert "emissiveColor" in text and "occlusion = 0.5" in text and "leaf_n.png" in text
    assert "# loss: universal: opacity = 0.2" in preset_toml(found)


def test_specular_workflow_copper_becomes_a_valid_metal(tmp_path):
    path = tmp_path / "copper.usda"
    stage = _stage(path)
    _, shader = _surface(stage, "/Looks/Copper", "UsdPreviewSurface")
    shader.CreateInput("useSpecularWorkflow", T.Int).Set(1)
    shader.CreateInput("diffuseColor", T.Color3f).Set((0.0, 0.0, 0.0))
    shader.CreateInput("specularColor", T.Color3f).Set((0.955, 0.638, 0.538))
    stage.Save()
    (found,) = import_usd(path)
    preset = _preset(found)  # valid: no ior beyond the preset's range (was 11.19)
    assert preset.params["metallic"] == pytest.approx(1.0)
    assert preset.params["base_color"] == pytest.approx((0.955, 0.638, 0.538), abs=1e-3)
    assert "ior" not in preset.params
    assert any("converted to metallic" in line for line in found.loss)


@pytest.mark.parametrize(
    ("shader_id", "inputs", "want"),
    [
        (
            "ND_open_pbr_surface_surfaceshader",
            {
                "base_color": (T.Color3f, (0.8, 0.4, 0.2)),
                "base_metalness": (T.Float, 1.0),
                "specular_roughness": (T.Float, 0.25),
                "coat_weight": (T.Float, 0.5),
                "emission_luminance": (T.Float, 10.0),
            },
            {"metallic": 1.0, "roughness": 0.25, "clearcoat": 2.0},
        ),
        (
            "ND_standard_surface_surfaceshader",
            {
                "base_color": (T.Color3f, (0.8, 0.4, 0.2)),
                "base": (T.Float, 0.5),
                "specular_roughness": (T.Float, 0.4),
                "transmission": (T.Float, 1.0),
                "specular_IOR": (T.Float, 1.33),
                "thin_walled": (T.Bool, True),
            },
            {"roughness": 0.4, "spec_trans": 1.0, "thin": True, "ior": 1.33},
        ),
    ],
)
def test_openpbr_and_standard_surface_are_read(tmp_path, shader_id, inputs, want):
    path = tmp_path / "mx.usda"
    stage = _stage(path)
    _, shader = _surface(stage, "/Looks/M", shader_id, output="mtlx:surface")
    for name, (kind, value) in inputs.items():
        shader.CreateInput(name, kind).Set(value)
    stage.Save()
    (found,) = import_usd(path)
    preset = _preset(found)
    for key, value in want.items():
        assert preset.params[key] == pytest.approx(value), key
    base = preset.params.get("base_color", (1.0, 1.0, 1.0))
    if preset.params.get("spec_trans") == 1.0:  # glass: tinted by transmission_color (white)
        assert base == pytest.approx((1.0, 1.0, 1.0))
    else:
        assert base == pytest.approx((0.8, 0.4, 0.2), rel=1e-6)  # base_weight default 1
    if "emission_luminance" in inputs:
        assert any("emission_luminance" in line for line in found.loss)


@pytest.mark.parametrize(
    ("shader_id", "radius", "scale"),
    [
        ("ND_open_pbr_surface_surfaceshader", (T.Float, 0.2), (T.Color3f, (1.0, 0.5, 0.25))),
        ("ND_standard_surface_surfaceshader", (T.Color3f, (1.0, 0.5, 0.25)), (T.Float, 0.2)),
    ],
)
def test_a_foreign_radius_is_read_per_channel_only_where_it_scatters(
    tmp_path, shader_id, radius, scale
):
    weight = "subsurface_weight" if "open_pbr" in shader_id else "subsurface"
    scale_name = "subsurface_radius_scale" if "open_pbr" in shader_id else "subsurface_scale"
    found = {}
    for w in (0.0, 0.5):
        path = tmp_path / f"sss{w}.usda"
        stage = _stage(path)
        _, shader = _surface(stage, "/Looks/M", shader_id, output="mtlx:surface")
        shader.CreateInput(weight, T.Float).Set(w)
        shader.CreateInput("subsurface_radius", radius[0]).Set(radius[1])
        shader.CreateInput(scale_name, scale[0]).Set(scale[1])
        stage.Save()
        (found[w],) = import_usd(path)
    # weight 0 (the DCCs' default): the radius shows nothing, so no interior
    assert "scatter_distance" not in found[0.0].params
    params = found[0.5].params
    # 0.2 units at USD's fallback metersPerUnit 0.01 (the stage authors none)
    assert params["scatter_distance"] == pytest.approx(0.002, rel=1e-6)
    assert params["scatter_distance_scale"] == pytest.approx((1.0, 0.5, 0.25), rel=1e-6)
    assert any("subsurface weight 0.5" in line for line in found[0.5].loss)


def _png(path: Path, channels: int) -> None:
    import OpenImageIO as oiio

    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(2, 2, channels, oiio.UINT8))
    out.write_image(np.full((2, 2, channels), 128, np.uint8))
    out.close()


def test_a_texture_feeding_an_input_is_kept_as_a_texture_input(tmp_path):
    path = tmp_path / "tex.usda"
    stage = _stage(path)
    _, shader = _surface(stage, "/Looks/T", "UsdPreviewSurface")
    tex = UsdShade.Shader.Define(stage, "/Looks/T/Rough")
    tex.CreateIdAttr("UsdUVTexture")
    _png(tmp_path / "rough.png", 3)
    tex.CreateInput("file", T.Asset).Set("./rough.png")
    tex.CreateInput("sourceColorSpace", T.Token).Set("raw")
    tex.CreateInput("scale", T.Float4).Set((0.5, 0.5, 0.5, 1.0))
    tex.CreateInput("wrapS", T.Token).Set("clamp")
    shader.CreateInput("roughness", T.Float).ConnectToSource(tex.CreateOutput("g", T.Float))
    stage.Save()
    (found,) = import_usd(path)
    rough = found.maps["roughness"]
    assert Path(rough.texture).name == "rough.png"
    assert (rough.channel, rough.colorspace, rough.scale, rough.wrap) == ("g", "Raw", 0.5, "clamp")
    preset = _preset(found)  # a texture-driven parameter of the preset
    assert preset.params["roughness"]["channel"] == "g"
    assert preset.params["roughness"]["scale"] == 0.5


def test_name_clashes_are_refused_unless_renamed(cli, tmp_path, monkeypatch):
    out = tmp_path / "g.usda"
    assert cli("export", "usd", "gold", "-o", str(out), "-c", "universal").code == 0
    library = tmp_path / "lib"
    library.mkdir()
    monkeypatch.setenv("LOOKDEV_LIBRARY_PATH", str(library))
    # Into a library folder: the built-in gold would be shadowed.
    result = cli("import", "usd", str(out), "-o", str(library))
    assert result.code == 2 and "--rename" in result.err and len(result.err.splitlines()) == 1
    result = cli("import", "usd", str(out), "-o", str(library), "--rename", "--json")
    assert result.code == 0, result.err
    assert json.loads(result.out)["materials"][0]["preset"] == "gold_imported"
    assert (library / "gold_imported.toml").is_file()
    # A plain folder: no clash; a second import there is renamed, not replaced.
    plain = tmp_path / "plain"
    plain.mkdir()
    assert cli("import", "usd", str(out), "-o", str(plain)).code == 0
    assert cli("import", "usd", str(out), "-o", str(plain), "--rename").code == 0
    assert sorted(p.name for p in plain.iterdir()) == ["gold.toml", "gold_imported.toml"]
    (found,) = import_usd(out)
    with pytest.raises(ExportError, match="another material in the file"):
        import_names([found, found])
    assert import_names([found, found], rename=True) == ["gold", "gold_imported"]


@pytest.mark.parametrize(
    ("contexts", "edited"),
    [
        # Only a UsdPreviewSurface: the user edits the surface's own input (it holds
        # its constants, so that Blender reads them; there is no interface to edit).
        (("universal",), "/Materials/gold/preview_surface.inputs:roughness"),
        # All contexts: the Material's interface input, which MaterialX and RenderMan
        # read (the override a Houdini or Katana user makes).
        (("universal", "mtlx", "ri"), "/Materials/gold.inputs:roughness"),
    ],
)
def test_a_file_edited_after_export_is_read_from_its_networks(tmp_path, contexts, edited):
    out = tmp_path / "g.usda"
    api.export_usd(["gold"], out, contexts)
    (found,) = import_usd(out)
    assert found.contexts == ["record"] and found.params["roughness"] == 0.2
    layer = Sdf.Layer.FindOrOpen(str(out))
    layer.GetAttributeAtPath(edited).default = 0.35
    layer.Save()
    (found,) = import_usd(out)
    assert "record" not in found.contexts and "universal" in found.contexts
    assert found.params["roughness"] == pytest.approx(0.35)  # the edit, not the stale record
    assert any("edited after lookdev exported" in line for line in found.loss)
