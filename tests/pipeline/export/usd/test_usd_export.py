"""USD export: every built-in validates, pruning is visible, libraries and packages work."""

from __future__ import annotations

import zipfile
from pathlib import Path

import pytest

pxr = pytest.importorskip("pxr")
from pxr import Sdf, Usd, UsdShade  # noqa: E402

from lookdev.library import Library, load_material  # noqa: E402
from lookdev.materials.params import DisneyParams  # noqa: E402
from lookdev.pipeline.blend import blend  # noqa: E402
from lookdev.pipeline.export.usd import mtlx  # noqa: E402
from lookdev.pipeline.export.usd.network import CONTEXTS, source_from_params  # noqa: E402
from lookdev.pipeline.export.usd.sources import source_for  # noqa: E402
from lookdev.pipeline.export.usd.validate import validate_usd  # noqa: E402
from lookdev.pipeline.export.usd.writer import export_usd  # noqa: E402

MAP_RES = 16


def _export(tmp: Path, params: dict | None = None, name="m", **kw) -> Usd.Stage:
    source = source_from_params(name, "disney", DisneyParams(**(params or {})))
    out = tmp / f"{name}.usda"
    export_usd([source], out, **kw)
    return Usd.Stage.Open(str(out))


def _authored(stage: Usd.Stage, prefix: str = "/Materials") -> dict[str, list[str]]:
    """prim path → its authored attribute names, for every prim under ``prefix``."""
    out = {}
    for prim in stage.Traverse():
        if str(prim.GetPath()).startswith(prefix):
            out[str(prim.GetPath())] = sorted(a.GetName() for a in prim.GetAuthoredAttributes())
    return out


@pytest.fixture(scope="module")
def library_stage(tmp_path_factory):
    """Every built-in preset in one stage, all contexts, plus the standalone .mtlx."""
    tmp = tmp_path_factory.mktemp("lib")
    lib = Library(use_env=False)
    names = lib.names()
    scratch = tmp / "scratch"
    scratch.mkdir()
    sources = [
        source_for(blend(load_material(n, lib), MAP_RES), tmp / "tex", scratch=scratch, bake=False)
        for n in names
    ]
    out = tmp / "all.usda"
    result = export_usd(sources, out, mtlx_path=tmp / "all.mtlx")
    return out, names, result


def test_every_builtin_preset_exports_and_validates(library_stage):
    out, names, result = library_stage
    report = validate_usd(out)
    assert report.errors == []
    assert report.validators >= 20  # the whole usd-core registry ran
    assert all("MissingShaderIdInRegistry" in a for a in report.allowed)
    assert all(("'ND_" in a) or ("'Pxr" in a) for a in report.allowed)
    assert report.mtlx_networks == len(names)
    assert sorted(result.materials) == sorted(names)


def test_standalone_mtlx_validates_with_materialx(library_stage):
    import MaterialX as mx

    out, names, _ = library_stage
    doc = mx.createDocument()
    mx.readFromXmlFile(doc, str(out.with_suffix(".mtlx")))
    assert mtlx.validate_document(doc) == []
    assert len(doc.getMaterialNodes()) == len(names)


def test_validation_is_not_vacuous(tmp_path):
    """A UsdPreviewSurface input of the wrong type is an error that fails validation."""
    stage = _export(tmp_path, {"roughness": 0.3})
    shader = stage.GetPrimAtPath("/Materials/m/preview_surface")
    attr = shader.CreateAttribute("inputs:metallic", Sdf.ValueTypeNames.Color3f, custom=False)
    attr.Set((0.1, 0.2, 0.3))
    stage.GetRootLayer().Save()
    report = validate_usd(Path(stage.GetRootLayer().realPath))
    assert not report.ok
    assert any("metallic" in e for e in report.errors)


def test_plain_diffuse_has_no_clearcoat_sheen_or_transmission(tmp_path):
    plaster = load_material("plaster", Library(use_env=False))
    source = source_from_params("plaster", "disney", plaster.params)
    export_usd([source], tmp_path / "p.usda")
    attrs = _authored(Usd.Stage.Open(str(tmp_path / "p.usda")))
    names = " ".join(n.lower() for v in attrs.values() for n in v)
    for lobe in ("clearcoat", "sheen", "spectrans", "opacity", "difftrans", "subsurface"):
        assert lobe not in names
    # specular 0.5 is the default IOR 1.5 of UsdPreviewSurface and the default of
    # ND_disney_principled: neither is written; RenderMan's default is not known.
    assert attrs["/Materials/plaster/preview_surface"] == [
        "info:id",
        "inputs:diffuseColor",
        "inputs:roughness",
        "outputs:surface",
    ]
    assert attrs["/Materials/plaster/mtlx_surface"] == [  # OpenPBR Surface
        "info:id",
        "inputs:base_color",
        "inputs:specular_roughness",
        "outputs:out",
    ]
    assert attrs["/Materials/plaster/ri_surface"] == [
        "info:id",
        "inputs:baseColor",
        "inputs:ior",
        "inputs:roughness",
        "outputs:bxdf_out",
    ]
    # the Material: ColorSpaceAPI's colorSpace:name (the working space), its interface
    # (the values every context reads, one override for all), three outputs and
    # MaterialXConfigAPI's config:mtlx:version
    assert attrs["/Materials/plaster"] == [
        "colorSpace:name",
        "config:mtlx:version",
        "inputs:base_color",
        "inputs:ior",
        "inputs:roughness",
        "outputs:mtlx:surface",
        "outputs:ri:surface",
        "outputs:surface",
        "userProperties:lookdev:loss",
    ]
    assert sum(len(v) for v in attrs.values()) == 4 + 4 + 5 + 9


@pytest.mark.parametrize("specular", [0.0, 0.3, 0.5, 2.0])
def test_renderman_disney_takes_f0_as_ior(tmp_path, specular):
    """PxrDisneyBsdf has no ``specular`` (Burley 2015): the same F0 goes in as ``ior``."""
    stage = _export(tmp_path, {"specular": specular})
    surface = stage.GetPrimAtPath("/Materials/m/ri_surface")
    assert not surface.GetAttribute("inputs:specular").IsAuthored()
    ior = surface.GetAttribute("inputs:ior").Get()
    assert ((ior - 1) / (ior + 1)) ** 2 == pytest.approx(0.08 * specular, rel=1e-5, abs=1e-9)


@pytest.mark.parametrize("clearcoat, written", [(0.0, False), (1e-6, True), (4.0, True)])
def test_clearcoat_lobe_at_its_edges(tmp_path, clearcoat, written):
    stage = _export(tmp_path, {"clearcoat": clearcoat, "clearcoat_gloss": 0.5})
    preview = stage.GetPrimAtPath("/Materials/m/preview_surface")
    assert preview.GetAttribute("inputs:clearcoat").IsAuthored() == written
    assert preview.GetAttribute("inputs:clearcoatRoughness").IsAuthored() == written
    if written:  # Burley's weight 0.25·clearcoat (App. B.2): 4 ↦ 1
        value = preview.GetAttribute("inputs:clearcoat").Get()
        assert value == pytest.approx(0.25 * clearcoat, rel=1e-6)


def test_metal_drops_every_dielectric_lobe(tmp_path):
    stage = _export(tmp_path, {"metallic": 1.0, "specular": 0.9, "sheen": 1.0, "spec_trans": 0.5})
    attrs = _authored(stage)
    names = " ".join(n for v in attrs.values() for n in v)
    for gone in ("ior", "specular", "sheen", "specTrans", "opacity"):
        assert f"inputs:{gone} " not in names + " "
    assert "inputs:metallic" in attrs["/Materials/m/preview_surface"]


def test_target_defaults_are_not_written(tmp_path):
    """roughness 0.5 and ior 1.5 are UsdPreviewSurface's own defaults."""
    stage = _export(tmp_path, {"roughness": 0.5, "ior": 1.5, "base_color": (0.18, 0.18, 0.18)})
    preview = _authored(stage)["/Materials/m/preview_surface"]
    assert preview == ["info:id", "outputs:surface"]


def test_loss_is_stated_where_the_surface_cannot_follow(tmp_path):
    velvet = load_material("velvet", Library(use_env=False))
    export_usd([source_from_params("velvet", "disney", velvet.params)], tmp_path / "v.usda")
    stage = Usd.Stage.Open(str(tmp_path / "v.usda"))
    loss = stage.GetPrimAtPath("/Materials/velvet/preview_surface").GetCustomDataByKey(
        "lookdev:loss"
    )
    assert "sheen=" in loss and "UsdPreviewSurface cannot express" in loss


def test_variant_set_switches_presets_on_one_prim(tmp_path):
    sources = [
        source_from_params("red", "disney", DisneyParams(base_color=(1.0, 0.0, 0.0))),
        source_from_params("blue", "disney", DisneyParams(base_color=(0.0, 0.0, 1.0))),
    ]
    out = tmp_path / "lib.usda"
    export_usd(sources, out, contexts=("universal",))
    stage = Usd.Stage.Open(str(out))
    look = stage.GetPrimAtPath("/Materials/Look")
    vset = look.GetVariantSets().GetVariantSet("preset")
    assert sorted(vset.GetVariantNames()) == ["blue", "red"]
    for name, colour in (("red", (1, 0, 0)), ("blue", (0, 0, 1))):
        vset.SetVariantSelection(name)
        surface = UsdShade.Material(look).ComputeSurfaceSource()[0]
        assert tuple(surface.GetInput("diffuseColor").Get()) == colour


def test_split_library_references_one_file_per_material(tmp_path):
    sources = [
        source_from_params(n, "disney", DisneyParams(roughness=r))
        for n, r in (("a", 0.1), ("b-2", 0.9))
    ]
    out = tmp_path / "library.usda"  # the --split folder is created
    result = export_usd(sources, out, split_dir=tmp_path / "parts")
    assert {p.name for p in (tmp_path / "parts").iterdir()} == {"a.usda", "b_2.usda"}
    assert set(result.files) == {out, tmp_path / "parts/a.usda", tmp_path / "parts/b_2.usda"}
    assert validate_usd(out).ok
    stage = Usd.Stage.Open(str(out))
    prim = stage.GetPrimAtPath("/Materials/b_2/preview_surface")
    assert prim.GetAttribute("inputs:roughness").Get() == pytest.approx(0.9)
    refs = stage.GetPrimAtPath("/Materials/a").GetMetadata("references").GetAddedOrExplicitItems()
    assert refs[0].assetPath == "./parts/a.usda"


def test_layered_live_mixes_masks_and_bakes_procedural_ones(tmp_path):
    material = load_material("rusty_iron", Library(use_env=False))
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    source = source_for(blend(material, MAP_RES), tmp_path / "tex", scratch=scratch, bake=False)
    export_usd([source], tmp_path / "r.usda")
    stage = Usd.Stage.Open(str(tmp_path / "r.usda"))
    ids = {
        p.GetName(): UsdShade.Shader(p).GetIdAttr().Get()
        for p in stage.GetPrimAtPath("/Materials/rusty_iron").GetChildren()
    }
    mixes = [n for n, i in ids.items() if i and i.startswith("ND_mix_")]
    assert mixes and ids["mtlx_mask_1"] == "ND_image_float"
    mask = stage.GetPrimAtPath("/Materials/rusty_iron/mtlx_mask_1").GetAttribute("inputs:file")
    assert mask.Get().path == "./tex/rusty_iron_mask1.exr"
    assert (tmp_path / "tex/rusty_iron_mask1.exr").is_file()
    assert ids["preview_base_color"] == "UsdUVTexture"  # no mix node in UsdPreviewSurface
    assert validate_usd(tmp_path / "r.usda").ok


def test_layered_bake_reads_maps_everywhere(tmp_path):
    material = load_material("rusty_iron", Library(use_env=False))
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    source = source_for(blend(material, MAP_RES), tmp_path / "tex", scratch=scratch, bake=True)
    result = export_usd([source], tmp_path / "r.usda")
    stage = Usd.Stage.Open(str(tmp_path / "r.usda"))
    ids = [UsdShade.Shader(p).GetIdAttr().Get() for p in stage.Traverse() if p.IsA(UsdShade.Shader)]
    assert not any(i.startswith("ND_mix_") for i in ids)
    assert ids.count("ND_image_float") + ids.count("ND_image_color3") == len(source.maps) - 1
    assert all(p.is_file() and p.parent == tmp_path / "tex" for p in result.images)
    assert validate_usd(tmp_path / "r.usda").ok


def test_package_holds_stage_and_textures(tmp_path):
    material = load_material("rusty_iron", Library(use_env=False))
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    source = source_for(blend(material, MAP_RES), scratch / "tex", scratch=scratch)
    result = export_usd([source], tmp_path / "r.usdz", contexts=CONTEXTS, workdir=scratch)
    assert result.files == [tmp_path / "r.usdz"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["r.usdz", "scratch"]
    with zipfile.ZipFile(tmp_path / "r.usdz") as z:
        names = z.namelist()
    assert names[0].endswith(".usdc")
    # ARKit reads PNG and JPEG only: maps go in as PNG, none as EXR
    assert sum(n.endswith(".png") for n in names) == len(result.images)
    assert not any(n.endswith(".exr") for n in names)
    assert all(n.startswith("tex/") for n in names[1:])  # packaged by their path from the stage
    assert validate_usd(tmp_path / "r.usdz").ok


def test_layered_pixar_exports_its_lobe_weights(tmp_path):
    """A Pixar stack blends to Smits' weights: PxrSurface takes them, the preview surface
    takes them in its metallic workflow (a mirror metal: metallic 1, its F0 as the colour)."""
    from lookdev.library import Layer, Material
    from lookdev.materials.pixar import PixarParams

    def layer(name, **kw):
        return Layer(material=Material(name=name, model="pixar", params=PixarParams(**kw)))

    metal = layer("metal", surface_color=0.9, metallic=1.0, roughness=0.0)
    material = Material(name="stack", model="layered", layers=[metal])
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    source = source_for(blend(material, MAP_RES), tmp_path / "tex", scratch=scratch)
    assert source.model == "pixar_weights" and not source.maps
    export_usd([source], tmp_path / "s.usda")
    assert validate_usd(tmp_path / "s.usda").ok
    stage = Usd.Stage.Open(str(tmp_path / "s.usda"))
    preview = stage.GetPrimAtPath("/Materials/stack/preview_surface")
    assert not preview.GetAttribute("inputs:useSpecularWorkflow").IsAuthored()
    assert preview.GetAttribute("inputs:metallic").Get() == pytest.approx(1.0)
    assert preview.GetAttribute("inputs:diffuseColor").Get()[0] == pytest.approx(0.9, rel=1e-5)
    ri = stage.GetPrimAtPath("/Materials/stack/ri_surface")
    assert ri.GetAttribute("inputs:diffuseGain").Get() == 0.0


def _write_exr(path: Path, pixels) -> Path:
    from lookdev.pipeline.export.usd.textures import write_image

    write_image(path, pixels, data=True)
    return path


def test_texture_mask_and_normal_map_live(tmp_path):
    """A texture mask is referenced where it is (relative path), not copied; the normal
    map goes through UsdUVTexture's (2, -1) scale/bias, which the validator checks."""
    import numpy as np

    src = tmp_path / "src"
    src.mkdir()
    ramp = np.tile(np.linspace(0.0, 1.0, 8, dtype=np.float32), (8, 1))
    _write_exr(src / "mask.exr", ramp)
    bumps = np.dstack([0.5 + 0.2 * ramp, np.full_like(ramp, 0.5), np.full_like(ramp, 0.9)])
    _write_exr(src / "bumps.exr", bumps)
    (src / "scuffed.toml").write_text(
        'name = "scuffed"\nmodel = "layered"\n'
        '[[layers]]\npreset = "plastic_glossy"\n'
        '[[layers]]\npreset = "rubber"\n'
        'mask = { kind = "texture", path = "mask.exr" }\n'
        'normal_map = { kind = "texture", path = "bumps.exr" }\n'
    )
    lib = Library([src], use_env=False)
    out_dir = tmp_path / "out"
    out_dir.mkdir()
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    source = source_for(
        blend(load_material("scuffed", lib), 8), out_dir / "tex", scratch=scratch, bake=False
    )
    export_usd([source], out_dir / "s.usda")
    report = validate_usd(out_dir / "s.usda")
    assert report.ok, report.errors
    stage = Usd.Stage.Open(str(out_dir / "s.usda"))
    mask = stage.GetPrimAtPath("/Materials/scuffed/mtlx_mask_1").GetAttribute("inputs:file")
    assert mask.Get().path == "../src/mask.exr"
    normal = stage.GetPrimAtPath("/Materials/scuffed/preview_normal_map")
    assert tuple(normal.GetAttribute("inputs:scale").Get()) == (2.0, 2.0, 2.0, 1.0)
    assert tuple(normal.GetAttribute("inputs:bias").Get()) == (-1.0, -1.0, -1.0, 0.0)
    assert normal.GetAttribute("inputs:sourceColorSpace").Get() == "raw"
    loss = stage.GetPrimAtPath("/Materials/scuffed/mtlx_surface").GetCustomDataByKey("lookdev:loss")
    assert "no normal input" not in loss  # OpenPBR takes it (ND_disney_principled has none)
    surface = UsdShade.Shader(stage.GetPrimAtPath("/Materials/scuffed/mtlx_surface"))
    assert surface.GetInput("geometry_normal").HasConnectedSource()
    # --collect: the mask file is copied beside the export, referenced relatively
    export_usd([source], out_dir / "c.usda", collect=True)
    assert (out_dir / "c_textures" / "mask.exr").read_bytes() == (src / "mask.exr").read_bytes()
    stage = Usd.Stage.Open(str(out_dir / "c.usda"))
    mask = stage.GetPrimAtPath("/Materials/scuffed/mtlx_mask_1").GetAttribute("inputs:file")
    assert mask.Get().path == "./c_textures/mask.exr"
    assert validate_usd(out_dir / "c.usda").ok
