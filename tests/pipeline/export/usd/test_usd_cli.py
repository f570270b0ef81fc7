"""``lookdev export usd`` / ``import usd`` / ``validate usd`` as a user runs them."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("pxr")

from pxr import Usd  # noqa: E402

from lookdev.library import parse_preset  # noqa: E402

MAPS = ("--map-resolution", "16")


def _files(folder: Path) -> list[str]:
    return sorted(str(p.relative_to(folder)) for p in folder.rglob("*"))


def test_export_validate_import_round_trip(cli, tmp_path):
    out = tmp_path / "metals.usda"
    result = cli(
        "export",
        "usd",
        "gold",
        "glass_clear",
        "-o",
        str(out),
        "--mtlx",
        str(tmp_path / "metals.mtlx"),
        "--json",
    )
    assert result.code == 0, result.err
    summary = json.loads(result.out)
    assert summary["materials"] == ["gold", "glass_clear"]
    assert summary["contexts"] == ["universal", "mtlx", "ri"]
    assert _files(tmp_path) == ["metals.mtlx", "metals.usda"]

    check = json.loads(cli("validate", "usd", str(out), "--json").out)
    assert check["ok"] and check["errors"] == [] and check["mtlx_networks"] == 2

    result = cli("import", "usd", str(out), "-o", str(tmp_path), "--json")
    assert result.code == 0, result.err
    path = tmp_path / "gold.toml"
    gold = parse_preset(path.read_bytes(), where=str(path), stem="gold")
    assert gold.params == {"base_color": [1.0, 0.782, 0.344], "metallic": 1.0, "roughness": 0.2}


def test_import_prints_a_preset_that_parses(cli, tmp_path):
    out = tmp_path / "v.usda"
    assert cli("export", "usd", "velvet", "-o", str(out), "-c", "universal").code == 0
    result = cli("import", "usd", str(out))
    assert result.code == 0, result.err
    preset = parse_preset(result.out.encode(), where="stdout")
    # lookdev's own export comes back exactly (the record in customData), sheen included,
    # though the surface lost it: the Material's doc says so for a DCC user.
    assert preset.name == "velvet" and preset.params["sheen"] == 1.0
    assert "# loss" not in result.out
    stage = Usd.Stage.Open(str(out))  # held: a prim expires with its stage
    doc = stage.GetPrimAtPath("/Materials/velvet").GetDocumentation()
    assert "UsdPreviewSurface cannot express sheen=" in doc


def test_layered_export_writes_textures_beside_the_file(cli, tmp_path):
    out = tmp_path / "rust.usda"
    result = cli("export", "usd", "rusty_iron", "-o", str(out), *MAPS, "--json")
    assert result.code == 0, result.err
    files = _files(tmp_path)
    assert "rust_textures/rusty_iron_mask1.exr" in files  # the procedural mask, baked
    assert not any(f.startswith(".") for f in files)  # no scratch left behind
    assert cli("validate", "usd", str(out)).code == 0


def test_package_and_split(cli, tmp_path):
    assert cli("export", "usd", "rusty_iron", "-o", str(tmp_path / "r.usdz"), *MAPS).code == 0
    assert _files(tmp_path) == ["r.usdz"]
    result = cli(
        "export",
        "usd",
        "gold",
        "iron",
        "-o",
        str(tmp_path / "lib.usda"),
        "--split",
        str(tmp_path / "parts"),
    )
    assert result.code == 0, result.err
    assert _files(tmp_path / "parts") == ["gold.usda", "iron.usda"]
    again = cli(
        "export",
        "usd",
        "gold",
        "-o",
        str(tmp_path / "lib.usda"),
        "--split",
        str(tmp_path / "parts"),
    )  # an existing folder is fine; files are replaced
    assert again.code == 0, again.err
    line = _one_line_error(
        cli(
            "export",
            "usd",
            "gold",
            "-o",
            str(tmp_path / "x.usda"),
            "--split",
            str(tmp_path / "r.usdz"),
        )
    )
    assert "--split takes a folder" in line
    assert cli("validate", "usd", str(tmp_path / "lib.usda")).code == 0


def _one_line_error(result) -> str:
    assert result.code == 2, (result.out, result.err)
    lines = [line for line in result.err.splitlines() if line.strip()]
    assert len(lines) == 1 and lines[0].startswith("lookdev: error: "), result.err
    assert "Traceback" not in result.err
    return lines[0]


@pytest.mark.parametrize(
    "target, words",
    [
        ("afile.txt/out.usda", "afile.txt is a file"),  # issue 13: it exists
        ("out.txt", "not a USD file name"),
    ],
)
def test_unwritable_output_exits_2_with_one_line(cli, tmp_path, target, words):
    (tmp_path / "afile.txt").write_text("x")
    line = _one_line_error(cli("export", "usd", "gold", "-o", str(tmp_path / target)))
    assert words in line
    assert _files(tmp_path) == ["afile.txt"]


def test_invalid_material_exits_2_and_writes_nothing(cli, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "bad"\nmodel = "disney"\n[params]\nroughness = -1\n')
    line = _one_line_error(cli("export", "usd", str(bad), "-o", str(tmp_path / "bad.usda")))
    assert "roughness" in line
    assert _files(tmp_path) == ["bad.toml"]


def test_missing_texture_exits_2_and_writes_nothing(cli, tmp_path):
    layered = tmp_path / "stained.toml"
    layered.write_text(
        'name = "stained"\nmodel = "layered"\n'
        '[[layers]]\npreset = "plaster"\n'
        '[[layers]]\npreset = "rust"\nmask = { kind = "texture", path = "nowhere.exr" }\n'
    )
    line = _one_line_error(cli("export", "usd", str(layered), "-o", str(tmp_path / "s.usda")))
    assert "nowhere.exr" in line
    assert _files(tmp_path) == ["stained.toml"]


def test_failure_after_textures_leaves_no_partial_file(cli, tmp_path, monkeypatch):
    from lookdev.pipeline.export.usd import mtlx
    from lookdev.pipeline.export.usd.network import ExportError

    def fail(*args, **kwargs):
        raise ExportError("simulated failure while writing the .mtlx")

    monkeypatch.setattr(mtlx, "write_document", fail)
    result = cli(
        "export",
        "usd",
        "rusty_iron",
        "-o",
        str(tmp_path / "r.usda"),
        *MAPS,
        "--mtlx",
        str(tmp_path / "r.mtlx"),
    )
    assert "simulated failure" in _one_line_error(result)
    assert _files(tmp_path) == []


def test_conflicting_options_and_missing_presets(cli, tmp_path):
    line = _one_line_error(
        cli("export", "usd", "gold", "-o", str(tmp_path / "a.usdz"), "--split", str(tmp_path))
    )
    assert "--package and --split" in line
    assert "--all" in _one_line_error(cli("export", "usd", "-o", str(tmp_path / "a.usda")))
    line = _one_line_error(
        cli(
            "export",
            "usd",
            "gold",
            "-o",
            str(tmp_path / "a.usda"),
            "-c",
            "universal",
            "--mtlx",
            str(tmp_path / "a.mtlx"),
        )
    )
    assert "--context mtlx" in line
    assert "did you mean" in _one_line_error(
        cli("export", "usd", "gld", "-o", str(tmp_path / "a.usda"))
    )
    assert _files(tmp_path) == []


def test_validate_fails_with_exit_1_on_an_invalid_stage(cli, tmp_path):
    bad = tmp_path / "bad.usda"
    bad.write_text(
        '#usda 1.0\ndef Material "M" {\n token outputs:surface.connect = </M/S.outputs:surface>\n'
        ' def Shader "S" {\n  uniform token info:id = "UsdPreviewSurface"\n'
        "  color3f inputs:metallic = (1, 0, 0)\n  token outputs:surface\n }\n}\n"
    )
    result = cli("validate", "usd", str(bad))
    assert result.code == 1
    assert "not valid" in result.out
    assert "does not exist" in _one_line_error(cli("validate", "usd", str(tmp_path / "no.usda")))
    assert "does not exist" in _one_line_error(cli("import", "usd", str(tmp_path / "no.usda")))
