"""``lookdev import usd --openpbr itself``: the specification's 83 example materials,
written as OpenPBR Surface shaders in a USD stage the way other tools write them, come
back as ``openpbr`` presets holding their inputs, which load and evaluate as themselves."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pxr")
from pxr import Sdf, Usd, UsdShade  # noqa: E402

from lookdev.pipeline.analysis.openpbr_reference import examples  # noqa: E402

EXAMPLES = Path(__file__).parents[3] / "data" / "openpbr_examples"


def _stage(path: Path, materials: dict) -> None:
    stage = Usd.Stage.CreateNew(str(path))
    for name, params in materials.items():
        mat = UsdShade.Material.Define(stage, f"/Materials/{name}")
        shader = UsdShade.Shader.Define(stage, f"/Materials/{name}/surface")
        shader.CreateIdAttr("ND_open_pbr_surface_surfaceshader")
        for key, value in params.model_dump(exclude_defaults=True).items():
            if isinstance(value, bool):
                shader.CreateInput(key, Sdf.ValueTypeNames.Bool).Set(value)
            elif isinstance(value, tuple):
                shader.CreateInput(key, Sdf.ValueTypeNames.Color3f).Set(value)
            else:
                shader.CreateInput(key, Sdf.ValueTypeNames.Float).Set(value)
        out = shader.CreateOutput("out", Sdf.ValueTypeNames.Token)
        mat.CreateSurfaceOutput("mtlx").ConnectToSource(out)
    stage.Save()


@pytest.fixture(scope="module")
def imported(tmp_path_factory):
    from typer.testing import CliRunner

    from lookdev.pipeline.cli import app

    folder = tmp_path_factory.mktemp("openpbr_import")
    materials = examples(EXAMPLES)
    _stage(folder / "examples.usda", materials)
    (folder / "presets").mkdir()
    result = CliRunner().invoke(
        app,
        ["import", "usd", str(folder / "examples.usda"), "-o", str(folder / "presets"),
         "--openpbr", "itself"],
    )  # fmt: skip
    assert result.exit_code == 0, result.output
    return folder / "presets", materials


def test_every_example_imports_as_itself(imported):
    from lookdev.library import Library, load_material

    folder, materials = imported
    lib = Library([folder], use_env=False)
    assert len(list(folder.glob("*.toml"))) == 83
    for name, want in materials.items():
        material = load_material(name, lib)
        assert material.model == "openpbr"
        got = material.params.model_dump()
        for key, value in want.model_dump().items():
            np.testing.assert_allclose(got[key], value, rtol=1e-6, err_msg=f"{name}.{key}")


def test_an_imported_openpbr_preset_is_proofed_by_the_openpbr_model(imported):
    from lookdev.library import Library, load_material
    from lookdev.pipeline import api

    folder, _ = imported
    hub = api.hub(load_material("carpaint", Library([folder], use_env=False)), 4)
    assert hub.bsdf_model.name == "openpbr" and hub.params.coat_weight == 1.0


def test_without_the_flag_openpbr_is_translated_to_disney(tmp_path):
    from lookdev.pipeline.export.usd.reader import import_usd

    _stage(tmp_path / "g.usda", {"gold": examples(EXAMPLES)["gold"]})
    (found,) = import_usd(tmp_path / "g.usda")
    assert found.model == "disney"
