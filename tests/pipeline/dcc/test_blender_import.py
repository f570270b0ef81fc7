"""Blender (the ``bpy`` wheel, in its own interpreter) imports lookdev's USD with its
default options and gets every value, texture and binding the file holds.

Marked ``dcc``: ``-m "not dcc"`` skips them locally; ``scripts/test.sh`` installs Blender
(``.venv-blender``) and runs them.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("pxr")

from lookdev.library import Library, load_material  # noqa: E402
from lookdev.pipeline import api  # noqa: E402
from lookdev.pipeline.bench import blender, dcc_import  # noqa: E402

pytestmark = [
    pytest.mark.dcc,
    pytest.mark.slow,
    pytest.mark.skipif(blender.interpreter() is None, reason="no Blender (bpy) installed"),
]

REPO = Path(__file__).resolve().parents[3]


BLENDERS = [pytest.param(p, id=p.parent.parent.name) for p in blender.interpreters()]
"""Every installed Blender (bpy 4.5, and the newest bpy where it installed)."""


@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    """``export usd --all --preview-geometry``."""
    out = tmp_path_factory.mktemp("all") / "all.usda"
    api.export_usd([], out, all_presets=True, preview_geometry=True)
    return out


@pytest.fixture(scope="module", params=BLENDERS)
def python(request):
    return request.param


@pytest.fixture(scope="module")
def library_file(exported, python):
    """The export and what a Blender's default import made of it."""
    return exported, blender.run({"op": "read", "usd": str(exported)}, python=python)


def test_every_preset_is_bound_to_its_sphere_under_default_options(library_file):
    out, answer = library_file
    names = Library(use_env=False).names()
    assert answer["meshes"] == {f"{n}_sphere": [n] for n in names}


def test_every_principled_input_holds_what_the_file_resolves_to(library_file):
    """usd-core's resolution of each UsdPreviewSurface input and Blender's Principled BSDF
    agree for every material (constants bit-exact in float32, maps by file and space)."""
    out, answer = library_file
    view = dcc_import.file_view(out)
    names = Library(use_env=False).names()
    counts = dcc_import.faithful_counts(view, answer, names)
    wrong = {socket: c["wrong"] for socket, c in counts.items() if c["wrong"]}
    assert not wrong, wrong
    assert all(c["faithful"] == len(names) for c in counts.values())


def test_constant_disney_presets_arrive_with_their_own_values(library_file):
    """Base colour, metallic and roughness map one to one: Blender shows the preset's."""
    _, answer = library_file
    lib = Library(use_env=False)
    checked = 0
    for name in lib.names():
        preset = load_material(name, lib)
        if preset.model != "disney" or getattr(preset, "textures", None):
            continue
        p = preset.params
        if 0.0 < p.metallic < 1.0:
            continue  # refitted for UsdPreviewSurface (a named loss), not one to one
        inputs = answer["materials"][name]["inputs"]
        assert inputs["Base Color"]["value"][:3] == pytest.approx(p.base_color, abs=1e-6), name
        assert inputs["Metallic"]["value"] == pytest.approx(p.metallic, abs=1e-6), name
        assert inputs["Roughness"]["value"] == pytest.approx(p.roughness, abs=1e-6), name
        checked += 1
    assert checked >= 50


def test_a_textured_asset_arrives_with_its_maps_and_colour_spaces(tmp_path, python):
    asset = tmp_path / "asset"
    subprocess.run(
        [sys.executable, str(REPO / "scripts" / "make_example_asset.py"), str(asset)],
        check=True,
        capture_output=True,
    )
    out = tmp_path / "pub" / "pebble.usda"
    out.parent.mkdir()
    api.export_usd([asset / "pebble.toml"], out, collect=True, preview_geometry=True)
    answer = blender.run({"op": "read", "usd": str(out)}, python=python)
    assert answer["meshes"] == {"pebble_sphere": ["pebble"]}
    inputs = answer["materials"]["pebble"]["inputs"]
    assert dcc_import.compare(dcc_import.file_view(out)["pebble"], inputs) == dict.fromkeys(
        dcc_import.SOCKETS.values(), ""
    )
    base, rough = inputs["Base Color"]["image"], inputs["Roughness"]["image"]
    assert base["colorspace"] == "sRGB" and base["tiled"]  # 8-bit sRGB UDIM tiles
    assert rough["colorspace"] == "Non-Color" and rough["tiled"]
    assert Path(base["file"]).name == "pebble_BaseColor.<UDIM>.png"
    assert [n["node"] for n in inputs["Normal"]["chain"]] == [
        "ShaderNodeNormalMap",
        "ShaderNodeTexImage",
    ]


def test_blender_shows_each_materials_universal_loss_as_a_custom_property(library_file):
    _, answer = library_file
    notes = {n: m["custom"].get("lookdev:loss", "") for n, m in answer["materials"].items()}
    assert notes["gold"].startswith("UsdPreviewSurface's BRDF is not the material's; measured")
    assert "sheen" in notes["velvet"] and "anisotropic" in notes["brushed_steel"]
    assert "measured against the material: albedo −" in notes["velvet"]
    assert all(notes[n] for n in Library(use_env=False).names())
