"""Parameters driven by textures in preset files: load-time checks and the bad-input lines.

Every image is generated with OpenImageIO in a temporary folder.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import OpenImageIO as oiio
import pytest
from _blend_helpers import write_image

from lookdev.library import Library
from lookdev.library.errors import TextureError
from lookdev.materials import colour
from lookdev.materials.errors import ParameterError
from lookdev.pipeline.cli import main

TILES = {1001: (0.8, 0.1, 0.1), 1002: (0.1, 0.8, 0.1), 1011: (0.1, 0.1, 0.8), 1012: (0.8, 0.8, 0.1)}


def preset(folder: Path, params: str, name: str = "t") -> Path:
    path = folder / f"{name}.toml"
    path.write_text(f'name = "{name}"\nmodel = "disney"\n[params]\n{params}\n')
    return path


def udim_set(folder: Path, tiles=TILES, fmt=oiio.UINT8, stem: str = "col") -> str:
    suffix = "png" if fmt == oiio.UINT8 else "exr"
    for tile, rgb in tiles.items():
        pixels = np.broadcast_to(np.float32(rgb), (4, 4, 3))
        write_image(folder / f"{stem}.{tile}.{suffix}", pixels, fmt=fmt)
    return f"{stem}.<UDIM>.{suffix}"


def test_texture_paths_are_relative_to_the_preset_and_carried_on_the_material(tmp_path):
    write_image(tmp_path / "r.exr", np.linspace(0.1, 0.9, 16, dtype=np.float32).reshape(4, 4))
    path = preset(tmp_path, 'roughness = { texture = "r.exr", channel = "r" }\nmetallic = 1.0')
    m = Library([tmp_path], use_env=False).load_file(path)
    assert m.textures["roughness"].texture == str(tmp_path / "r.exr")
    assert m.params.metallic == 1.0 and "roughness" not in m.params.model_fields_set


def test_a_child_inherits_a_texture_relative_to_the_parent_file(tmp_path):
    sub = tmp_path / "maps"
    sub.mkdir()
    write_image(sub / "r.exr", np.full((2, 2), 0.4, dtype=np.float32))
    preset(sub, 'roughness = { texture = "r.exr" }', name="parent")
    (tmp_path / "child.toml").write_text(
        'name = "child"\nextends = "parent"\n[params]\nmetallic = 1.0\n'
    )
    m = Library([tmp_path], use_env=False).load("child")
    assert m.textures["roughness"].texture == str(sub / "r.exr")


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ('roughness = { texture = "gone.png" }', "gone.png does not exist"),
        ('roughness = { texture = "r.exr", channel = "g" }', "has no channel 'g'"),
        ('base_color = { texture = "c.exr", colorspace = "Nope" }', "unknown colour space 'Nope'"),
        ('roughness = { texture = "big.exr" }', r"values 0 \.\. 1\.5, outside the allowed range"),
        ('thin = { texture = "r.exr" }', "'thin' cannot be a texture"),
        ('roughness = { texture = "r.exr", chanel = "r" }', "chanel: unknown field"),
        ('base_color = { texture = "c.exr", channel = "rg" }', "names 2 channels"),
    ],
)
def test_bad_textures_are_one_line(tmp_path, params, message):
    write_image(tmp_path / "r.exr", np.full((2, 2), 0.5, dtype=np.float32))
    write_image(tmp_path / "c.exr", np.full((2, 2, 3), 0.5, dtype=np.float32))
    write_image(tmp_path / "big.exr", np.array([[0.0, 1.5]], dtype=np.float32))
    path = preset(tmp_path, params)
    with pytest.raises((TextureError, ParameterError), match=message) as info:
        Library([tmp_path], use_env=False).load_file(path)
    assert "\n" not in str(info.value) and str(path) in str(info.value)


def test_a_slight_overshoot_is_clamped_with_one_warning(tmp_path, capsys):
    write_image(tmp_path / "r.exr", np.array([[-0.004, 0.5, 1.003]], dtype=np.float32))
    Library([tmp_path], use_env=False).load_file(
        preset(tmp_path, 'roughness = { texture = "r.exr" }')
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "clamped" in err[0] and "roughness" in err[0]


def test_an_8bit_colour_map_without_colour_space_warns_and_reads_srgb(tmp_path, capsys):
    write_image(tmp_path / "c.png", np.full((2, 2, 3), 0.5, dtype=np.float32), fmt=oiio.UINT8)
    Library([tmp_path], use_env=False).load_file(
        preset(tmp_path, 'base_color = { texture = "c.png" }')
    )
    err = capsys.readouterr().err
    assert "no colorspace" in err and "sRGB" in err


def test_udim_tile_missing_in_one_map_of_the_material(tmp_path):
    udim_set(tmp_path)
    rough = {t: (0.5, 0.5, 0.5) for t in (1001, 1002, 1011)}
    udim_set(tmp_path, rough, fmt=oiio.FLOAT, stem="rough")
    path = preset(
        tmp_path,
        'base_color = { texture = "col.<UDIM>.png", colorspace = "sRGB - Texture" }\n'
        'roughness = { texture = "rough.<UDIM>.exr", channel = "r" }',
    )
    with pytest.raises(TextureError, match=r"missing UDIM tile 1012 \(.*rough\.1012\.exr"):
        Library([tmp_path], use_env=False).load_file(path)


def test_udim_tiles_stored_differently_are_refused(tmp_path):
    write_image(
        tmp_path / "mix.1001.tif", np.full((2, 2, 3), 0.5, dtype=np.float32), fmt=oiio.UINT16
    )
    write_image(
        tmp_path / "mix.1002.tif", np.full((2, 2, 3), 0.5, dtype=np.float32), fmt=oiio.FLOAT
    )
    path = preset(tmp_path, 'base_color = { texture = "mix.<UDIM>.tif" }')
    with pytest.raises(TextureError, match="uint16.*float|float.*uint16"):
        Library([tmp_path], use_env=False).load_file(path)


@pytest.mark.parametrize("command", [["presets", "show"], ["export", "usd"]])
def test_cli_bad_texture_is_one_line_exit_2(tmp_path, capsys, command):
    path = preset(tmp_path, 'roughness = { texture = "gone.<UDIM>.png" }')
    out = ["-o", str(tmp_path / "out.usda")] if "export" in command else []
    with pytest.raises(SystemExit) as exit_:
        main([*command, str(path), *out])
    assert exit_.value.code == 2
    lines = [line for line in capsys.readouterr().err.splitlines() if line.strip()]
    assert len(lines) == 1 and "no tile of the UDIM set" in lines[0]
    assert not list(tmp_path.glob("out*"))  # nothing half-written


def test_texture_space_rule():
    assert colour.texture_space(True, True, None) == colour.canonical("sRGB - Texture")
    assert colour.texture_space(False, True, None) == colour.working_space()
    assert colour.texture_space(True, False, None) == colour.canonical("Raw")
    assert colour.texture_space(False, True, "ACEScg") == "ACEScg"
    with colour.use(working_space="acescg"):
        assert colour.texture_space(False, True, None) == "ACEScg"


def test_presets_set_takes_a_texture_and_writes_it_inline(tmp_path, capsys):
    write_image(tmp_path / "rough.png", np.full((2, 2), 0.5, dtype=np.float32), fmt=oiio.UINT8)
    preset(tmp_path, "roughness = 0.3", name="teal")
    main(
        [
            "presets",
            "set",
            "teal",
            'roughness={texture="rough.png", channel="r"}',
            "-L",
            str(tmp_path),
        ]
    )
    text = (tmp_path / "teal.toml").read_text()
    assert 'roughness = { texture = "rough.png", channel = "r" }' in text
    before = text
    with pytest.raises(SystemExit) as exit_:
        main(["presets", "set", "teal", 'roughness={texture="nope.png"}', "-L", str(tmp_path)])
    assert exit_.value.code == 2 and "nope.png does not exist" in capsys.readouterr().err
    assert (tmp_path / "teal.toml").read_text() == before  # nothing half-written


def test_texture_statistics_are_remembered_on_disk_per_file_state(tmp_path, monkeypatch):
    from lookdev.library import textures

    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path / "cache"))
    write_image(tmp_path / "r.exr", np.array([[0.2, 0.6]], dtype=np.float32))
    path = preset(tmp_path, 'roughness = { texture = "r.exr" }')
    Library([tmp_path], use_env=False).load_file(path)
    stored = list((tmp_path / "cache" / "textures").glob("*.json"))
    assert len(stored) == 1
    textures._STATS.clear()  # a new process: the numbers come from the file, not the texels
    monkeypatch.setattr(textures.ParamTexture, "_read_stats", lambda self, key: 1 / 0)
    Library([tmp_path], use_env=False).load_file(path)
    write_image(tmp_path / "r.exr", np.array([[0.2, 0.7, 0.1]], dtype=np.float32))
    with pytest.raises(ZeroDivisionError):  # the file changed: read again
        Library([tmp_path], use_env=False).load_file(path)
