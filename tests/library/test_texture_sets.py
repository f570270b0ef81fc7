"""Texture sets (library/texture_sets.py), the preset keys ``textures =`` and ``height =``,
and ``lookdev presets new --textures``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest

from lookdev.library import Library, PresetError
from lookdev.library.preset import check_params
from lookdev.library.texture_sets import CHANNELS, channel_of, expand, from_files, lookup
from lookdev.materials.colour import RAW, SRGB_TEXTURE
from lookdev.materials.errors import LookdevError


def _png(path: Path, value: float = 0.5, channels: int = 1) -> Path:
    px = np.full((4, 4, channels), value, dtype=np.float32)
    out = oiio.ImageOutput.create(str(path))
    out.open(str(path), oiio.ImageSpec(4, 4, channels, oiio.UINT8))
    out.write_image(px)
    out.close()
    return path


def _set(folder: Path, channels: list[str], tiles=(1001, 1002)) -> None:
    for ch in channels:
        for t in tiles:
            _png(
                folder / f"hero_{ch}.{t}.png", channels=3 if "Color" in ch or "Normal" in ch else 1
            )


def test_the_table_knows_painters_spellings():
    for name in ("BaseColor", "Base_Color", "basecolor", "Albedo", "Diffuse", "Base Color"):
        assert lookup(name).param == "base_color"
        assert lookup(name).colorspace == SRGB_TEXTURE
    assert lookup("Metalness").param == lookup("Metallic").param == "metallic"
    assert lookup("Roughness").colorspace == RAW
    assert lookup("Normal_DirectX").flip_y and not lookup("Normal_OpenGL").flip_y
    assert lookup("Displacement").param == lookup("Height").param == "height"
    assert lookup("Emissive").param is None and "emission" in lookup("Emissive").why_unused
    assert all(c.param is None or c.why_unused == "" for c in CHANNELS.values())


def test_expand_groups_udim_tiles_and_names_what_it_leaves_out(tmp_path):
    _set(tmp_path, ["BaseColor", "Roughness", "Metalness", "Normal_OpenGL", "Height", "Emissive"])
    found = expand("hero_<channel>.<UDIM>.png", tmp_path)
    assert sorted(found.inputs) == ["base_color", "metallic", "roughness"]
    assert found.inputs["base_color"] == {
        "texture": str(tmp_path / "hero_BaseColor.<UDIM>.png"),
        "colorspace": SRGB_TEXTURE,
    }
    assert found.inputs["roughness"]["colorspace"] == RAW
    assert found.height["texture"].endswith("hero_Height.<UDIM>.png")
    assert found.normal_map == {
        "path": str(tmp_path / "hero_Normal_OpenGL.<UDIM>.png"),
        "flip_y": False,
    }
    assert list(found.unused) == ["Emissive"]
    assert "emission" in found.notes[0]


def test_expand_refuses_two_files_for_one_parameter_and_empty_sets(tmp_path):
    _set(tmp_path, ["Normal", "Normal_OpenGL"], tiles=(1001,))
    with pytest.raises(PresetError, match="both drive normal_map"):
        expand("hero_<channel>.<UDIM>.png", tmp_path)
    with pytest.raises(PresetError, match="names no channel"):
        expand("hero.png", tmp_path)
    with pytest.raises(PresetError, match="matches no texture-set channel"):
        expand("other_<channel>.png", tmp_path)


def test_from_files_finds_the_shared_pattern(tmp_path):
    _set(tmp_path, ["Base_Color", "Roughness", "Normal_DirectX"])
    files = sorted(tmp_path.glob("hero_*.png"))
    pattern, folder = from_files(files)
    assert (pattern, folder) == ("hero_<channel>.<UDIM>.png", tmp_path)
    assert channel_of("hero_Base_Color.1001.png", pattern) == "Base_Color"
    with pytest.raises(PresetError, match="several patterns"):
        from_files([*files, _png(tmp_path / "other_Roughness.png")])


def _write(folder: Path, name: str, text: str) -> Path:
    path = folder / f"{name}.toml"
    path.write_text(text, encoding="utf-8")
    return path


def test_height_key_resolves_relative_to_the_preset(tmp_path):
    _png(tmp_path / "h.png", 0.5)
    _write(
        tmp_path,
        "bumpy",
        'name = "bumpy"\nmodel = "disney"\n'
        'height = { texture = "h.png", scale = 0.01 }\n[params]\nroughness = 0.4\n',
    )
    material = Library([tmp_path], use_env=False).load("bumpy")
    assert material.height.texture == str(tmp_path / "h.png")
    assert material.height.scale == 0.01


def test_height_from_a_texture_set_and_the_preset_s_own_wins(tmp_path):
    _set(tmp_path, ["Height", "Normal_DirectX", "AO"], tiles=(1001,))
    _write(tmp_path, "a", 'name = "a"\nmodel = "disney"\ntextures = "hero_<channel>.<UDIM>.png"\n')
    _write(
        tmp_path,
        "b",
        'name = "b"\nextends = "a"\n'
        'height = { texture = "hero_Height.<UDIM>.png", scale = 0.02 }\n',
    )
    lib = Library([tmp_path], use_env=False)
    a, b = lib.load("a"), lib.load("b")
    assert a.height.scale == 1.0 and b.height.scale == 0.02
    assert a.normal_map.path == tmp_path / "hero_Normal_DirectX.<UDIM>.png"
    assert any("DirectX" in n for n in a.notes) and any("'AO'" in n for n in a.notes)


def _core_accepts_textures() -> bool:
    """The texture core (issue 14, the `tex` branch) validates texture inputs in params."""
    try:
        check_params("disney", {"roughness": {"texture": "x.png"}}, where=None)
    except LookdevError:
        return False
    except Exception:  # noqa: BLE001 - a missing file is the core's own error
        return True
    return True


needs_core = pytest.mark.skipif(
    not _core_accepts_textures(), reason="texture inputs in [params] come with the texture core"
)


@needs_core
def test_textures_key_fills_parameters_and_params_win(tmp_path):
    _set(tmp_path, ["BaseColor", "Roughness"])
    _write(
        tmp_path,
        "hero",
        'name = "hero"\nmodel = "disney"\n'
        'textures = "hero_<channel>.<UDIM>.png"\n[params]\nroughness = 0.3\n',
    )
    material = Library([tmp_path], use_env=False).load("hero")
    assert material.params.roughness == 0.3
    assert "hero_BaseColor" in material.textures["base_color"].texture  # Material.textures


@needs_core
def test_presets_new_builds_a_preset_from_a_folder_of_maps(cli, tmp_path):
    maps, lib = tmp_path / "maps", tmp_path / "lib"
    maps.mkdir(), lib.mkdir()
    _set(maps, ["BaseColor", "Roughness", "Emissive"])
    r = cli("presets", "new", "hero", "--textures", str(maps / "hero_*.png"), "-L", str(lib))
    assert r.code == 0, r.err
    text = (lib / "hero.toml").read_text()
    # the maps sit outside the library: named absolutely, as relative paths stay inside
    assert f'textures = "{maps.resolve().as_posix()}/hero_<channel>.<UDIM>.png"' in text
    assert "Emissive" in r.err
    assert cli("presets", "show", "hero", "-L", str(lib), "--resolved").code == 0


def test_presets_new_textures_bad_input_is_one_line(cli, tmp_path):
    r = cli(
        "presets", "new", "hero", "--textures", str(tmp_path / "none_*.png"), "-L", str(tmp_path)
    )
    assert r.code == 2 and len(r.err.strip().splitlines()) == 1
    assert "matches no files" in r.err
    assert not (tmp_path / "hero.toml").exists()
