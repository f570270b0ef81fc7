"""Foreign files import as far as they can: MaterialX's, OpenPBR's and the USD working
group's own example materials (tests/data/foreign, wrapped in one USD stage as usdMtlx
encodes them), one refusal line per bad material, exit 3 when partly imported."""

from __future__ import annotations

import json
import re
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pxr")
pytest.importorskip("MaterialX")
oiio = pytest.importorskip("OpenImageIO")

from pxr import Sdf, Usd, UsdShade  # noqa: E402

import lookdev  # noqa: E402
from lookdev.library.preset import parse_preset  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
from _mtlx_usd import wrap  # noqa: E402

DATA = Path(__file__).resolve().parents[3] / "data" / "foreign"
EXAMPLES = DATA / "materialx" / "resources" / "Materials" / "Examples"
MATERIALX_FILES = [
    EXAMPLES / path
    for path in (
        "DisneyPrincipled/disney_principled_gold.mtlx",
        "GltfPbr/gltf_pbr_glass.mtlx",
        "OpenPbr/open_pbr_glass.mtlx",
        "SimpleHair/simple_hair_default.mtlx",
        "StandardSurface/standard_surface_glass.mtlx",
        "StandardSurface/standard_surface_glass_tinted.mtlx",
        "StandardSurface/standard_surface_gold.mtlx",
        "StandardSurface/standard_surface_velvet.mtlx",
        "UsdPreviewSurface/usd_preview_surface_gold.mtlx",
    )
]
"""One example of each MaterialX surface and the Standard Surface cases these tests name
(the whole shipped set goes through ``test_import_corpus``)."""


def _import(cli, stage: Path, out: Path, *extra: str):
    result = cli("import", "usd", str(stage), "-o", str(out), "--rename", "--json", *extra)
    doc = json.loads(result.out) if result.out.strip() else {}
    return result, doc


def _loads_and_blends(paths: list[str]) -> None:
    """Every written preset validates and loads its textures, as the library does."""
    for path in paths:
        lookdev.blend(lookdev.load(path), 8)


@pytest.fixture(scope="module")
def examples(tmp_path_factory):
    """The shipped MaterialX and OpenPBR examples, in one USD file each."""
    folder = tmp_path_factory.mktemp("foreign")
    mx = folder / "materialx.usda"
    wrap(MATERIALX_FILES, mx)
    opbr = folder / "openpbr.usda"
    wrap(sorted((DATA / "openpbr").glob("*.mtlx")), opbr)
    return mx, opbr


def test_materialx_examples_import_as_far_as_they_can(cli, tmp_path, examples):
    result, doc = _import(cli, examples[0], tmp_path / "out")
    assert result.code == 3, result.err  # partly imported: the hair has no preset
    lines = result.err.strip().splitlines()
    assert lines[-1] == "lookdev: partly imported: 8 of 9 materials"
    assert [line for line in lines if "skipped" in line] == [
        lines[0]
    ] and "simple_hair_default" in lines[0]
    assert len(doc["written"]) == 8 and doc["refused"] == []
    _loads_and_blends(doc["written"])


def test_a_dead_lobe_does_not_refuse_the_velvet(cli, tmp_path, examples):
    _, doc = _import(cli, examples[0], tmp_path / "out")
    velvet = next(
        m for m in doc["materials"] if m["prim"].endswith("standard_surface_velvet/Velvet")
    )
    # specular_IOR = 0 sits on a specular of weight 0: not read; F0 0 is Burley's specular 0
    assert velvet["params"]["specular"] == 0.0 and "ior" not in velvet["params"]
    assert velvet["params"]["sheen"] == 1.0 and velvet["params"]["sheen_model"] == "conty_kulla"
    assert not any("specular_IOR" in line for line in velvet["loss"])


@pytest.mark.parametrize(
    "prim, colour",
    [
        ("standard_surface_glass/Glass", (1.0, 1.0, 1.0)),  # base = 0: clear, not black
        ("standard_surface_glass_tinted/GlassTinted", (0.2, 0.1, 1.0)),  # transmission_color
        ("open_pbr_glass/Glass", (1.0, 1.0, 1.0)),
    ],
)
def test_transmission_arrives_as_glass_of_its_transmission_colour(
    cli, tmp_path, examples, prim, colour
):
    _, doc = _import(cli, examples[0], tmp_path / "out")
    glass = next(m for m in doc["materials"] if m["prim"].endswith(prim))
    assert glass["params"]["spec_trans"] == 1.0
    assert glass["params"].get("base_color", (1.0, 1.0, 1.0)) == pytest.approx(colour, abs=1e-6)


def test_openpbr_examples_import_and_load(cli, tmp_path, examples):
    result, doc = _import(cli, examples[1], tmp_path / "out")
    assert result.code == 0, result.err
    assert len(doc["written"]) == len(list((DATA / "openpbr").glob("*.mtlx")))
    _loads_and_blends(doc["written"])
    by = {m["prim"].rsplit("/", 2)[1]: m for m in doc["materials"]}
    assert by["open_pbr_glass"]["params"]["spec_trans"] == 1.0
    skin = by["open_pbr_skin_iii"]["params"]  # subsurface_color is Burley's base colour
    assert skin["scatter_distance"] > 0 and max(skin["scatter_distance_scale"]) == 1.0
    # ACEScg documents: colours converted; out-of-range results clipped and named
    gold = by["open_pbr_gold"]
    assert max(gold["params"]["base_color"]) <= 1.0
    assert any("clipped" in line for line in gold["loss"])


def _stage_with(path: Path, materials: dict[str, dict[str, float]]) -> Path:
    stage = Usd.Stage.CreateNew(str(path))
    for name, inputs in materials.items():
        material = UsdShade.Material.Define(stage, f"/Looks/{name}")
        shader = UsdShade.Shader.Define(stage, f"/Looks/{name}/Surface")
        shader.CreateIdAttr("ND_standard_surface_surfaceshader")
        for key, value in inputs.items():
            shader.CreateInput(key, Sdf.ValueTypeNames.Float).Set(value)
        material.CreateSurfaceOutput("mtlx").ConnectToSource(
            shader.CreateOutput("out", Sdf.ValueTypeNames.Token)
        )
    stage.Save()
    return path


def test_a_bad_value_refuses_its_material_in_one_line_and_exits_3(cli, tmp_path):
    path = _stage_with(
        tmp_path / "two.usda",
        {"Good": {"specular_roughness": 0.3}, "Bad": {"specular_roughness": 7.0}},
    )
    result = cli("import", "usd", str(path), "-o", str(tmp_path / "out"))
    assert result.code == 3
    refused = [line for line in result.err.splitlines() if "refused" in line]
    assert refused == [
        "lookdev: refused /Looks/Bad: roughness: 7.0 is out of range; allowed [0, 1]"
    ]
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["Good.toml"]
    assert "partly imported" in result.err and "exit" not in result.out


def test_nothing_importable_is_bad_input_exit_2(cli, tmp_path):
    path = _stage_with(tmp_path / "bad.usda", {"Bad": {"specular_roughness": float("nan")}})
    result = cli("import", "usd", str(path), "-o", str(tmp_path / "out"))
    assert result.code == 2
    (line,) = result.err.strip().splitlines()
    assert line.startswith("lookdev: error: ") and "/Looks/Bad" in line
    assert not (tmp_path / "out").exists()


def test_help_names_the_exit_codes(cli):
    text = " ".join(cli("import", "usd", "--help").out.split())
    assert "3 partly imported" in text and "2 bad input" in text


def test_usdmtlx_flattening_of_a_preview_surface_is_read(tmp_path):
    from lookdev.pipeline.export.usd.reader import import_usd

    (found,) = import_usd(DATA / "usd-wg" / "basic_flatten.usda")
    assert found.prim == "/MaterialX/Materials/USD_Plastic"
    assert found.params["base_color"] == pytest.approx((0.10470402, 0.24188282, 0.818))
    assert found.params["roughness"] == pytest.approx(0.32467532)


def _jpeg(path: Path, channels: int) -> None:
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(4, 4, channels, oiio.UINT8))
    out.write_image(np.full((4, 4, channels), 128, np.uint8))
    out.close()


def test_materialx_image_nodes_become_textures_that_load(cli, tmp_path):
    shutil.copy(DATA / "usd-wg" / "standard_surface_brass_tiled.mtlx", tmp_path)
    wrap([tmp_path / "standard_surface_brass_tiled.mtlx"], tmp_path / "brass.usda")
    files = {a.path for a in _assets(tmp_path / "brass.usda")}
    for name in files:  # stand-ins for the JPEGs the repository keeps elsewhere
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        _jpeg(tmp_path / name, 3 if "color" in name else 1)
    result, doc = _import(cli, tmp_path / "brass.usda", tmp_path / "out")
    assert result.code == 0, result.err
    (brass,) = doc["materials"]
    assert Path(brass["maps"]["roughness"]["texture"]).name == "brass_roughness.jpg"
    assert brass["maps"]["roughness"]["colorspace"] == "Raw"  # a float image: data
    assert any("coat_color" in line for line in brass["loss"])
    _loads_and_blends(doc["written"])


def _assets(path: Path):
    stage = Usd.Stage.Open(str(path))
    for prim in stage.Traverse():
        for attr in prim.GetAttributes():
            value = attr.Get()
            if isinstance(value, Sdf.AssetPath):
                yield value


def test_a_missing_map_is_named_and_the_preset_still_loads(cli, tmp_path):
    shutil.copy(DATA / "usd-wg" / "standard_surface_brass_tiled.mtlx", tmp_path)
    wrap([tmp_path / "standard_surface_brass_tiled.mtlx"], tmp_path / "brass.usda")
    result, doc = _import(cli, tmp_path / "brass.usda", tmp_path / "out")
    assert result.code == 0, result.err
    (brass,) = doc["materials"]
    assert "roughness" not in brass["maps"]
    assert any("brass_roughness.jpg of roughness does not exist" in line for line in brass["loss"])
    _loads_and_blends(doc["written"])


@pytest.mark.parametrize(
    "output, channels, want",
    [("g", 1, 0), ("a", 1, None), ("a", 2, 1), ("b", 3, "b"), ("a", 4, "a")],
)
def test_usd_uv_texture_channels_follow_usds_rule(tmp_path, output, channels, want):
    """One channel: r, g, b repeat it and a is 1; two: a is the second; else as named."""
    from lookdev.pipeline.export.usd.reader import import_usd

    _jpeg_png = tmp_path / "t.png"
    out = oiio.ImageOutput.create(str(_jpeg_png))
    out.open(str(_jpeg_png), oiio.ImageSpec(2, 2, channels, oiio.UINT8))
    out.write_image(np.full((2, 2, channels), 64, np.uint8))
    out.close()
    stage = Usd.Stage.CreateNew(str(tmp_path / "t.usda"))
    material = UsdShade.Material.Define(stage, "/Looks/T")
    surface = UsdShade.Shader.Define(stage, "/Looks/T/Surface")
    surface.CreateIdAttr("UsdPreviewSurface")
    tex = UsdShade.Shader.Define(stage, "/Looks/T/Tex")
    tex.CreateIdAttr("UsdUVTexture")
    tex.CreateInput("file", Sdf.ValueTypeNames.Asset).Set("./t.png")
    tex.CreateInput("scale", Sdf.ValueTypeNames.Float4).Set((0.5, 0.5, 0.5, 0.5))
    port = tex.CreateOutput(output, Sdf.ValueTypeNames.Float)
    surface.CreateInput("roughness", Sdf.ValueTypeNames.Float).ConnectToSource(port)
    material.CreateSurfaceOutput().ConnectToSource(surface.ConnectableAPI(), "surface")
    stage.Save()
    (found,) = import_usd(tmp_path / "t.usda")
    if want is None:  # alpha of a file without alpha: the constant 1 × scale
        assert "roughness" not in found.maps and found.params["roughness"] == 0.5
        assert any("1 by USD's rule" in line for line in found.loss)
    else:
        assert found.maps["roughness"].channel == want
        text = lookdev.pipeline.export.usd.presets.preset_toml(found)
        preset = parse_preset(text.encode(), where="t.toml", stem=found.name)
        assert preset.params["roughness"]["texture"].endswith("t.png")


def _render_mean(preset: str, tmp_path: Path) -> float:
    """Mean luminance of lookdev's own render of ``preset`` (a sphere under the studio
    IBL, 24x24, 64 spp, one seed)."""
    sys.path.insert(0, str(Path(__file__).resolve().parents[3]))
    from _mitsuba_helpers import mitsuba_module

    mi = mitsuba_module()
    import lookdev.pipeline.export.mitsuba as export

    export.register_plugins()
    scene = tmp_path / f"{Path(preset).stem}.xml"
    lookdev.export_mitsuba(preset, scene, ibl="studio", resolution=(24, 24), spp=64)
    image = np.asarray(mi.render(mi.load_file(str(scene)), seed=1))[..., :3]
    return float((image @ np.array([0.2126, 0.7152, 0.0722])).mean())


def test_imported_standard_surface_glass_renders_as_clear_glass(cli, tmp_path, examples):
    _, doc = _import(cli, examples[0], tmp_path / "out")
    (path,) = [
        p
        for p, m in zip(doc["written"], doc["materials"], strict=True)
        if m["prim"].endswith("standard_surface_glass/Glass")
    ]
    clear = _render_mean("glass_clear", tmp_path)
    black = tmp_path / "black" / Path(path).name  # its base colour (base = 0) as the glass's
    black.parent.mkdir()
    text = re.sub(r"(?m)^base_color = .*$", "base_color = [0.0, 0.0, 0.0]", Path(path).read_text())
    black.write_text(text)
    assert _render_mean(path, tmp_path) == pytest.approx(clear, rel=0.02)
    assert _render_mean(str(black), tmp_path) < 0.7 * clear


def test_standard_surface_imports_as_openpbr_with_the_flag(cli, tmp_path):
    files = sorted((EXAMPLES / "StandardSurface").glob("*.mtlx"))
    wrap(files, tmp_path / "standard.usda")
    result, doc = _import(cli, tmp_path / "standard.usda", tmp_path / "out", "--openpbr", "itself")
    assert result.code == 0, result.err
    assert len(doc["written"]) == len(files) == 15
    assert {m["model"] for m in doc["materials"]} == {"openpbr"}
    by = {m["name"]: m for m in doc["materials"]}
    # MaterialX's translation folds a metal's coat colour into its base colour
    assert by["Copper"]["params"]["base_color"] == pytest.approx((0.96468, 0.376263, 0.258183))
    assert by["Copper"]["params"].get("coat_weight", 0.0) == 0.0
    assert any("MaterialX's translation" in line for line in by["Copper"]["loss"])
    _loads_and_blends(doc["written"])
