"""``export usd --report``: every context measured against the material (fidelity.py,
context_views.py): a row per material × context, both mtlx surfaces of a Disney preset,
a reason instead of figures where a context's model is not known, renderer notes."""

from __future__ import annotations

import json

import pytest

pytest.importorskip("pxr")


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    from typer.testing import CliRunner

    from lookdev.pipeline.cli import app

    out = tmp_path_factory.mktemp("ctx") / "r.usda"
    names = ["gold", "velvet", "pixar_gold", "rusty_iron"]
    result = CliRunner().invoke(
        app,
        ["export", "usd", *names, "-o", str(out), "--report", "--json", "--map-resolution", "16"],
    )
    assert result.exit_code == 0, result.output
    return json.loads(result.stdout)


def _rows(report, material):
    return {
        (r["context"], r["surface"]): r
        for r in report["context_fidelity"]
        if r["material"] == material
    }


def test_a_disney_preset_has_every_context(report):
    rows = _rows(report, "gold")
    assert set(rows) == {
        ("universal", "UsdPreviewSurface"),
        ("mtlx", "ND_open_pbr_surface_surfaceshader"),
        ("mtlx", "ND_disney_principled"),
        ("ri", "PxrDisneyBsdf"),
    }
    # Burley's own parameters by name: nothing lost; OpenPBR's F82 metal is close
    assert rows[("mtlx", "ND_disney_principled")]["rms"] < 1e-3
    assert rows[("mtlx", "ND_open_pbr_surface_surfaceshader")]["rms"] < 0.05
    for r in rows.values():
        assert len(r["albedo_source"]) == len(r["angles_deg"]) == 6
        assert r["highlight_width_deg"] > 0.0


def test_an_unknown_model_says_so_instead_of_a_number(report):
    ri = _rows(report, "pixar_gold")[("ri", "PxrSurface")]
    assert ri["rms"] is None and "not available" in ri["unavailable"]


def test_live_layering_names_renderman(report):
    rows = _rows(report, "rusty_iron")
    notes = rows[("mtlx", "ND_open_pbr_surface_surfaceshader")]["notes"]
    assert any("RenderMan" in n and "layer" in n for n in notes)
    assert any("Storm" in n for n in rows[("universal", "UsdPreviewSurface")]["notes"])


def test_named_losses_ride_with_the_row(report):
    row = _rows(report, "velvet")[("mtlx", "ND_open_pbr_surface_surfaceshader")]
    assert "sheen → fuzz" in row["loss"]


def test_mtlx_proof_hub_is_the_openpbr_model_of_the_mtlx_context():
    from lookdev.library import Library, load_material
    from lookdev.pipeline import api
    from lookdev.pipeline.export.usd.context_views import mtlx_hub

    lib = Library(use_env=False)
    gold = mtlx_hub(api.hub(load_material("gold", lib), 8))
    assert gold.name == "gold-mtlx" and gold.bsdf_model.name == "openpbr"
    assert gold.params.base_metalness == 1.0
    rusty = mtlx_hub(api.hub(load_material("rusty_iron", lib), 8))
    assert "base_color" in rusty.maps  # the texture is kept per texel
    pixar = mtlx_hub(api.hub(load_material("pixar_gold", lib), 8))
    assert pixar.bsdf_model.name == "openpbr"


def test_proof_context_rejects_unknown_in_one_line(tmp_path):
    from typer.testing import CliRunner

    from lookdev.pipeline.cli import app

    result = CliRunner().invoke(app, ["proof", "gold", "-o", str(tmp_path), "--context", "ri"])
    assert result.exit_code == 2 and "Traceback" not in result.output
