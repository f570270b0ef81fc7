"""Textured materials in USD: the original files referenced with their colour spaces in
every context, displacement from height, --collect, publishable assets (issues 14, 15)."""

from __future__ import annotations

import hashlib
import zipfile
from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest
from _blend_helpers import write_image
from pxr import Usd, UsdShade

from lookdev.materials.textures import TextureInput
from lookdev.pipeline.blend.result import BlendedMaterial
from lookdev.pipeline.export.usd import export_materials
from lookdev.pipeline.export.usd.network import ExportError
from lookdev.pipeline.export.usd.validate import validate_usd

RES = 8


@pytest.fixture
def maps(tmp_path):
    """A texture set: a UDIM base colour (2 tiles, sRGB 8-bit), a roughness and a height."""
    src = tmp_path / "src"
    src.mkdir()
    rng = np.random.default_rng(0)
    for tile in (1001, 1002):
        write_image(src / f"hero_BaseColor.{tile}.png", rng.random((RES, RES, 3)), oiio.UINT8)
    write_image(src / "hero_Roughness.png", rng.random((RES, RES)), oiio.UINT8)
    write_image(src / "hero_Height.png", rng.random((RES, RES)), oiio.UINT16)
    return src


def _hub(src: Path) -> BlendedMaterial:
    """A hub as blending leaves it: decoded maps, and the files they were read from."""
    base = np.full((RES, RES, 3), (0.2, 0.3, 0.4), np.float32)
    rough = np.linspace(0.1, 0.7, RES * RES, dtype=np.float32).reshape(RES, RES)
    hub = BlendedMaterial(
        "hero",
        "disney",
        (RES, RES),
        {"metallic": 0.0},
        maps={"base_color": base, "roughness": rough},
        textures={
            "base_color": TextureInput(
                texture=str(src / "hero_BaseColor.<UDIM>.png"), colorspace="sRGB - Texture"
            ),
            "roughness": TextureInput(
                texture=str(src / "hero_Roughness.png"), channel="r", scale=0.5, offset=0.1
            ),
            "height": TextureInput(texture=str(src / "hero_Height.png"), scale=0.01),
        },
    )
    hub.height_map = np.full((RES, RES), 0.004, np.float32)
    return hub


def _shader(stage, name: str):
    return UsdShade.Shader(stage.GetPrimAtPath(f"/Materials/hero/{name}"))


def test_textured_export_references_the_original_files(tmp_path, maps):
    out = tmp_path / "out" / "hero.usda"
    out.parent.mkdir()
    result = export_materials([_hub(maps)], out, mtlx=out.with_suffix(".mtlx"))
    # Nothing baked: the three files are referenced where they are, relative to the stage.
    assert result.files == [out, out.with_suffix(".mtlx")]
    assert not (out.parent / "hero_textures").exists()
    stage = Usd.Stage.Open(str(out))
    base = _shader(stage, "preview_base_color")
    file_attr = base.GetInput("file").GetAttr()
    assert file_attr.Get().path == "../src/hero_BaseColor.<UDIM>.png"
    assert base.GetInput("sourceColorSpace").Get() == "sRGB"
    assert file_attr.GetColorSpace() == "sRGB Encoded Rec.709 (sRGB)"  # the OCIO name
    assert tuple(base.GetInput("fallback").Get())[:3] == pytest.approx((0.2, 0.3, 0.4))
    rough = _shader(stage, "preview_roughness")
    assert rough.GetInput("sourceColorSpace").Get() == "raw"
    assert not rough.GetInput("file").GetAttr().HasColorSpace()
    assert tuple(rough.GetInput("scale").Get())[:3] == (0.5, 0.5, 0.5)
    assert tuple(rough.GetInput("bias").Get())[:3] == pytest.approx((0.1, 0.1, 0.1))
    # the fallback is the map's mean before scale and bias: a missing file reads as it
    assert rough.GetInput("fallback").Get()[0] == pytest.approx((0.4 - 0.1) / 0.5)
    surface = _shader(stage, "preview_surface")
    assert surface.GetInput("roughness").GetConnectedSources()[0][0].sourceName == "r"
    # st comes from the Material's interface, one override for every texture
    reader = _shader(stage, "preview_st")
    assert reader.GetInput("varname").GetConnectedSources()[0][0].sourceName == (
        "frame:stPrimvarName"
    )
    material = UsdShade.Material(stage.GetPrimAtPath("/Materials/hero"))
    assert material.GetInput("frame:stPrimvarName").Get() == "st"
    # MaterialX: colorspace by MaterialX's name, UDIM file name kept
    mx_base = _shader(stage, "mtlx_base_color")
    assert mx_base.GetInput("file").GetAttr().GetColorSpace() == "srgb_texture"
    import MaterialX as mx

    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(out.with_suffix(".mtlx")))
    file_input = doc.getNode("hero_mtlx_base_color").getInput("file")
    assert file_input.getValueString() == "../src/hero_BaseColor.<UDIM>.png"
    assert file_input.getColorSpace() == "srgb_texture"
    # RenderMan: linearize the sRGB file, the value rule on colorScale/colorOffset
    ri_base, ri_rough = _shader(stage, "ri_base_color"), _shader(stage, "ri_roughness")
    assert ri_base.GetInput("linearize").Get() == 1
    assert ri_base.GetInput("filename").Get().path == "../src/hero_BaseColor.<UDIM>.png"
    assert tuple(ri_rough.GetInput("colorScale").Get()) == (0.5, 0.5, 0.5)
    assert validate_usd(out).ok


def test_height_becomes_displacement_in_every_context(tmp_path, maps):
    out = tmp_path / "hero.usda"
    export_materials([_hub(maps)], out)
    stage = Usd.Stage.Open(str(out))
    material = stage.GetPrimAtPath("/Materials/hero")
    targets = {
        name: material.GetAttribute(f"outputs:{name}").GetConnections()[0].GetPrimPath().name
        for name in ("displacement", "mtlx:displacement", "ri:displacement")
    }
    assert targets == {
        "displacement": "preview_surface",
        "mtlx:displacement": "mtlx_displacement",
        "ri:displacement": "ri_displacement",
    }
    height = _shader(stage, "preview_height")
    assert tuple(height.GetInput("scale").Get())[:3] == pytest.approx((0.01,) * 3)  # scene units
    assert height.GetInput("fallback").Get()[0] == 0.0  # a missing map: no displacement
    assert _shader(stage, "mtlx_displacement").GetIdAttr().Get() == "ND_displacement_float"
    disp = _shader(stage, "ri_displacement")
    assert disp.GetIdAttr().Get() == "PxrDisplace"
    assert disp.GetInput("dispAmount").Get() == 1.0
    assert validate_usd(out).ok


def test_materialx_code_generation_succeeds_for_a_textured_material(tmp_path, maps):
    import MaterialX as mx
    from MaterialX import PyMaterialXGenGlsl as glsl
    from MaterialX import PyMaterialXGenShader as gen

    out = tmp_path / "hero.usda"
    export_materials([_hub(maps)], out, mtlx=tmp_path / "hero.mtlx")
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(tmp_path / "hero.mtlx"))
    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    doc.importLibrary(lib)
    assert doc.validate()[0]
    generator = glsl.GlslShaderGenerator.create()
    context = gen.GenContext(generator)
    context.registerSourceCodeSearchPath(mx.getDefaultDataSearchPath())
    (material,) = doc.getMaterialNodes()
    for shader in mx.getShaderNodes(material):
        code = generator.generate(shader.getName(), shader, context)
        assert "hero_BaseColor" not in code.getSourceCode(gen.PIXEL_STAGE)  # a uniform, not code
        assert len(code.getSourceCode(gen.PIXEL_STAGE)) > 1000


def test_collect_copies_every_tile_and_points_at_the_copies(tmp_path, maps):
    out = tmp_path / "pub" / "hero.usda"
    out.parent.mkdir()
    result = export_materials([_hub(maps)], out, collect=True)
    folder = out.parent / "hero_textures"
    assert sorted(p.name for p in folder.iterdir()) == [
        "hero_BaseColor.1001.png",
        "hero_BaseColor.1002.png",
        "hero_Height.png",
        "hero_Roughness.png",
    ]
    assert (folder / "hero_BaseColor.1002.png").read_bytes() == (
        maps / "hero_BaseColor.1002.png"
    ).read_bytes()
    assert set(result.files) == {out, *folder.iterdir()}
    stage = Usd.Stage.Open(str(out))
    paths = {
        _shader(stage, n).GetInput(f).Get().path
        for n, f in (("preview_base_color", "file"), ("ri_base_color", "filename"))
    }
    assert paths == {"./hero_textures/hero_BaseColor.<UDIM>.png"}
    assert validate_usd(out).ok


def test_missing_texture_with_collect_is_one_error_and_nothing_written(tmp_path, maps):
    hub = _hub(maps)
    (maps / "hero_Roughness.png").unlink()
    out = tmp_path / "pub" / "hero.usda"
    out.parent.mkdir()
    with pytest.raises(ExportError) as err:
        export_materials([hub], out, collect=True)
    assert "hero_Roughness.png: texture does not exist" in str(err.value)
    assert "\n" not in str(err.value)
    assert list(out.parent.iterdir()) == []


def test_missing_texture_at_the_cli_is_one_line_exit_2(cli, tmp_path):
    write_image(tmp_path / "h.png", np.full((4, 4), 0.5), oiio.UINT8)
    (tmp_path / "bumpy.toml").write_text(
        'name = "bumpy"\nmodel = "disney"\nheight = { texture = "h.png", scale = 0.01 }\n'
    )
    (tmp_path / "h.png").unlink()
    out = tmp_path / "out"
    out.mkdir()
    r = cli("export", "usd", str(tmp_path / "bumpy.toml"), "-o", str(out / "b.usda"), "--collect")
    assert r.code == 2
    assert len(r.err.strip().splitlines()) == 1 and "h.png" in r.err
    assert list(out.iterdir()) == []


def _digest(paths) -> dict[str, str]:
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest() for p in paths}


def test_baked_maps_are_half_tiled_mipmapped_and_reexports_are_identical(tmp_path, maps):
    hub = _hub(maps)
    hub.textures.pop("roughness")  # changed by a blend: baked, not referenced
    first = export_materials([hub], tmp_path / "a.usda", preview_geometry=True).files
    before = _digest(first)
    again = export_materials([hub], tmp_path / "a.usda", preview_geometry=True).files
    assert _digest(again) == before
    (exr,) = [p for p in first if p.suffix == ".exr"]
    image = oiio.ImageInput.open(str(exr))
    spec = image.spec()
    assert str(spec.format) == "half" and spec.tile_width > 0
    assert spec.getattribute("oiio:miplevels") == 4  # 8, 4, 2, 1
    image.close()


def test_published_layer_metadata_and_preview_geometry(tmp_path, maps):
    plain = BlendedMaterial("plain", "disney", (1, 1), {"roughness": 0.3})
    out = tmp_path / "lib.usda"
    export_materials([_hub(maps), plain], out, preview_geometry=True)
    stage = Usd.Stage.Open(str(out))
    root = stage.GetDefaultPrim()
    assert root.GetPath() == "/Materials"
    assert Usd.ModelAPI(root).GetKind() == "component"
    info = Usd.ModelAPI(root).GetAssetInfo()
    assert info["name"] == "lib.usda" and info["version"]
    assert "lookdev" in stage.GetRootLayer().documentation
    assert stage.GetPrimAtPath("/Materials/Look").GetVariantSets().GetNames() == ["preset"]
    for name in ("hero", "plain"):
        sphere = stage.GetPrimAtPath(f"/Materials/Geometry/{name}_sphere")
        assert sphere.HasAPI(UsdShade.MaterialBindingAPI)
        bound = UsdShade.MaterialBindingAPI(sphere).ComputeBoundMaterial()[0]
        assert bound.GetPath() == f"/Materials/{name}"
    assert validate_usd(out).ok


def test_usdz_holds_png_only_and_validates(tmp_path, maps):
    hub = _hub(maps)
    hub.textures.pop("roughness")  # baked: written as PNG inside the package
    out = tmp_path / "hero.usdz"
    export_materials([hub], out)
    with zipfile.ZipFile(out) as z:
        names = z.namelist()
    textures = [n for n in names if not n.endswith(".usdc")]
    assert textures and all(n.endswith(".png") for n in textures)
    assert sum("hero_BaseColor." in n for n in names) == 2  # both UDIM tiles
    assert validate_usd(out).ok
