"""USD as DCCs and renderers read it (issue 15): input names each renderer defines, glass
that does not vanish, losses a person sees, the MaterialX version declared."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("pxr")

from pxr import Sdf, Usd  # noqa: E402

from lookdev.library import Library, load_material  # noqa: E402
from lookdev.pipeline import api  # noqa: E402
from lookdev.pipeline.export.usd import mtlx, ri  # noqa: E402
from lookdev.pipeline.export.usd.network import ExportError, Network, Node  # noqa: E402
from lookdev.pipeline.export.usd.validate import validate_usd  # noqa: E402

GLASS = [
    n
    for n in Library(use_env=False).names()
    if (p := getattr(load_material(n, Library(use_env=False)), "params", None)) is not None
    and (getattr(p, "spec_trans", 0.0) or getattr(p, "clear", 0.0) or 0.0) > 0.0
]


def _rename_input(path: Path, prim: str, old: str, new: str) -> None:
    """Rename an authored input the way a hand edit or another tool's bug would."""
    layer = Sdf.Layer.FindOrOpen(str(path))
    spec = layer.GetPropertyAtPath(f"{prim}.inputs:{old}")
    assert spec is not None, (prim, old)
    with Sdf.ChangeBlock():
        Sdf.CopySpec(layer, spec.path, layer, Sdf.Path(f"{prim}.inputs:{new}"))
        layer.GetPrimAtPath(prim).RemoveProperty(spec)
    layer.Save()


@pytest.mark.parametrize(
    ("preset", "prim", "old", "new"),
    [
        ("leaf", "/Materials/leaf/ri_surface", "isThin", "thin"),  # PxrDisneyBsdf
        ("gold", "/Materials/gold/preview_surface", "roughness", "roughnes"),
    ],
)
def test_a_misnamed_input_fails_validation_naming_prim_and_input(
    cli, tmp_path, preset, prim, old, new
):
    out = tmp_path / "m.usda"
    assert cli("export", "usd", preset, "-o", str(out), "--json").code == 0
    assert cli("validate", "usd", str(out), "--json").code == 0
    _rename_input(out, prim, old, new)
    result = cli("validate", "usd", str(out), "--json")
    assert result.code == 1
    errors = json.loads(result.out)["errors"]
    assert any(prim in e and f"'{new}'" in e for e in errors), errors


def test_an_unknown_renderman_input_is_a_bug_at_export():
    net = Network("ri", None, [Node("s", "PxrDisneyBsdf", {"thin": ("int", 1)})])
    with pytest.raises(ExportError, match="PxrDisneyBsdf has no input thin"):
        ri.check_network(net, "leaf")
    ri.check_network(Network("ri", None, [Node("s", "PxrDisneyBsdf", {"isThin": ("int", 1)})]), "x")


def test_renderman_input_data_names_its_sources():
    data = json.loads(ri.INPUTS_FILE.read_text(encoding="utf-8"))
    for node in ("PxrDisneyBsdf", "PxrSurface"):
        for source in data["nodes"][node]["sources"]:
            assert source["repository"] and source["path"] and len(source["commit"]) == 40
    disney = ri.renderman_inputs()["PxrDisneyBsdf"]
    assert {"isThin", "scatterDistances", "subsurfaceColor"} <= disney
    assert not {"thin", "scatterDistance", "flatness", "specular"} & disney
    assert {"diffuseDoubleSided", "reflectionGain", "refractionGain"} <= ri.renderman_inputs()[
        "PxrSurface"
    ]


def test_every_builtin_preset_validates_with_no_unknown_input(tmp_path):
    out = tmp_path / "all.usda"
    api.export_usd([], out, all_presets=True, map_resolution=16, library=None)
    report = validate_usd(out)
    assert report.ok, report.errors
    assert not [e for e in report.errors + report.warnings if "UnknownShaderInput" in e]
    assert report.inputs_checked > 66 * 3
    stage = Usd.Stage.Open(str(out))
    version = mtlx.mtlx_version()
    for prim in stage.GetPrimAtPath("/Materials").GetChildren():
        # usd-core's pip build has no UsdMtlx schemas, so GetAppliedSchemas() filters the
        # API out here; a DCC with UsdMtlx reads it from this metadata.
        schemas = prim.GetMetadata("apiSchemas").GetAddedOrExplicitItems()
        assert "MaterialXConfigAPI" in schemas, prim.GetPath()
        assert prim.GetAttribute("config:mtlx:version").Get() == version
        assert prim.GetDocumentation().startswith("lookdev:"), prim.GetPath()


def test_glass_keeps_opacity_1_in_the_preview_surface_and_says_so(tmp_path):
    assert {"glass_clear", "glass_thin", "pixar_clear_glass", "pixar_translucent_plastic"} <= set(
        GLASS
    )
    out = tmp_path / "glass.usda"
    result = api.export_usd(GLASS, out, ("universal",))
    stage = Usd.Stage.Open(str(out))
    for name in GLASS:
        surface = stage.GetPrimAtPath(f"/Materials/{name}/preview_surface")
        opacity = surface.GetAttribute("inputs:opacity")
        assert not opacity or opacity.Get() == 1.0, name
        note = result.losses[name]["universal"]
        assert "transmission is not expressible; opacity kept at 1" in note, name
        assert "spec_trans=" in note or "clear=" in note, name
        doc = stage.GetPrimAtPath(f"/Materials/{name}").GetDocumentation()
        assert note in doc, name


def test_the_spec_s_opacity_reading_is_an_explicit_choice(cli, tmp_path):
    out = tmp_path / "g.usda"
    args = ("export", "usd", "glass_clear", "pixar_translucent_plastic", "-o", str(out))
    assert cli(*args, "-c", "universal", "--preview-opacity", "transmission").code == 0
    stage = Usd.Stage.Open(str(out))
    get = stage.GetAttributeAtPath
    assert get("/Materials/glass_clear/preview_surface.inputs:opacity").Get() == 0.0
    plastic = get("/Materials/pixar_translucent_plastic/preview_surface.inputs:opacity").Get()
    assert plastic == pytest.approx(0.7)


def test_the_printed_table_lists_velvet_s_universal_losses(cli, tmp_path):
    out = tmp_path / "v.usda"
    result = cli("export", "usd", "velvet", "gold", "-o", str(out))
    assert result.code == 0, result.err
    text = " ".join(result.out.replace("│", " ").split())
    assert "What each render context could not express" in text
    assert "velvet universal UsdPreviewSurface cannot express sheen=1," in text
    assert "sheen_model=conty_kulla" in text
    summary = json.loads(cli("export", "usd", "velvet", "gold", "-o", str(out), "--json").out)
    assert "sheen_model=conty_kulla" in summary["losses"]["velvet"]["universal"]
    assert "gold" not in summary["losses"] or "universal" not in summary["losses"]["gold"]


def test_the_mtlx_sheen_note_says_what_materialx_does(tmp_path):
    out = tmp_path / "s.usda"
    result = api.export_usd(["velvet", "satin"], out, ("mtlx",), mtlx_surface="disney")
    # ND_disney_principled's sheen is MaterialX's sheen_bsdf, mode conty_kulla, roughness
    # 0.3: velvet (Conty-Kulla, r = 0.3) is expressed; satin's Burley sheen is not.
    assert "sheen" not in result.losses["velvet"]["mtlx"]
    satin = result.losses["satin"]["mtlx"]
    assert "sheen_bsdf in mode conty_kulla" in satin
    assert "the disney sheen renders as conty_kulla" in satin
