"""The last hostile inputs: each one line and exit 2 (or a documented policy), from the
CLI, with the Python API's error naming its argument where the input was one."""

from __future__ import annotations

import json
import math
import subprocess
import sys

import numpy as np
import OpenImageIO as oiio
import pytest

import lookdev


def one_line_error(r, *needles: str) -> str:
    """Exit 2, exactly one ``lookdev: error:`` line on stderr holding ``needles``."""
    lines = r.err.strip().splitlines()
    assert r.code == 2 and len(lines) == 1 and lines[0].startswith("lookdev: error: "), r.err
    assert all(n in lines[0] for n in needles), lines[0]
    return lines[0]


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("LOOKDEV_CACHE", str(tmp_path_factory.getbasetemp() / "cache"))
    monkeypatch.delenv("LOOKDEV_LIBRARY_PATH", raising=False)


def _image(path, channels):
    buf = oiio.ImageBuf(oiio.ImageSpec(4, 4, channels, oiio.UINT8))
    buf.set_pixels(oiio.ROI(), np.full((4, 4, channels), 128, np.uint8))
    assert buf.write(str(path))
    return path


def _preset(lib, name, body):
    lib.mkdir(exist_ok=True)
    (lib / f"{name}.toml").write_text(f'name = "{name}"\nmodel = "disney"\n{body}')


# -- texture references ---------------------------------------------------------------------
@pytest.mark.parametrize(
    ("body", "words"),
    [
        ('[params]\nbase_color = { texture = "a\\u0000b.png" }\n', "holds a NUL byte"),
        ('[params]\nroughness = { texture = "r.png", uv_scale = [0, 0] }\n', "zero along u"),
        ('[params]\nroughness = { texture = "r.png", uv_scale = [1, 0] }\n', "zero along v"),
    ],
)
def test_a_texture_no_file_can_have_or_no_surface_can_show_is_one_line(cli, tmp_path, body, words):
    _preset(tmp_path / "lib", "bad", body)
    one_line_error(cli("presets", "show", "bad", "-L", str(tmp_path / "lib"), "-r"), words)


def test_a_nul_byte_in_a_mask_path_is_one_line(cli, tmp_path):
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "stack.toml").write_text(
        'name = "stack"\nmodel = "layered"\n[[layers]]\npreset = "gold"\n'
        '[[layers]]\npreset = "copper"\nmask = { kind = "texture", path = "m\\u0000.png" }\n'
    )
    line = one_line_error(cli("presets", "show", "stack", "-L", str(lib)), "NUL byte")
    assert "layers[1].mask" in line


def test_a_two_channel_image_is_no_colour_until_a_channel_is_named(cli, tmp_path):
    _image(tmp_path / "ya.png", 2)
    lib = tmp_path / "lib"
    _preset(lib, "two", '[params]\nbase_color = { texture = "ya.png" }\n')
    (lib / "ya.png").write_bytes((tmp_path / "ya.png").read_bytes())
    one_line_error(cli("presets", "show", "two", "-L", str(lib), "-r"), "has 2 channels")
    _preset(lib, "two", '[params]\nbase_color = { texture = "ya.png", channel = "Y" }\n')
    assert cli("presets", "show", "two", "-L", str(lib), "-r").code == 0
    # a scalar still takes the first channel of a two-channel file
    _preset(lib, "two", '[params]\nroughness = { texture = "ya.png" }\n')
    assert cli("presets", "show", "two", "-L", str(lib), "-r").code == 0


# -- the texture-path policy of shared libraries ----------------------------------------------
def test_a_relative_texture_path_out_of_the_library_is_refused(cli, tmp_path):
    _image(tmp_path / "outside.png", 3)
    lib = tmp_path / "lib"
    _preset(lib, "leaks", '[params]\nbase_color = { texture = "../outside.png" }\n')
    line = one_line_error(cli("presets", "show", "leaks", "-L", str(lib), "-r"), "leads out of")
    assert "params.base_color" in line and str(tmp_path / "outside.png") in line
    with pytest.raises(lookdev.LookdevError, match="absolute path"):
        lookdev.load("leaks", library=lib)


def test_inside_the_library_and_absolute_paths_are_accepted(cli, tmp_path):
    lib = tmp_path / "lib"
    (lib / "maps").mkdir(parents=True)
    _image(lib / "maps" / "in.png", 3)
    outside = _image(tmp_path / "server.png", 3)
    _preset(lib, "inside", '[params]\nbase_color = { texture = "maps/../maps/in.png" }\n')
    _preset(lib, "server", f'[params]\nbase_color = {{ texture = "{outside}" }}\n')
    for name in ("inside", "server"):
        assert cli("presets", "show", name, "-L", str(lib), "-r").code == 0


def test_the_policy_covers_layer_masks_and_parents(cli, tmp_path):
    _image(tmp_path / "mask.png", 1)
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "stack.toml").write_text(
        'name = "stack"\nmodel = "layered"\n[[layers]]\npreset = "gold"\n[[layers]]\n'
        'preset = "copper"\nmask = { kind = "texture", path = "../mask.png" }\n'
    )
    one_line_error(cli("presets", "show", "stack", "-L", str(lib), "-r"), "layers[1].mask")
    _preset(lib, "child", 'extends = "stack_parent"\n')
    (lib / "stack_parent.toml").write_text(
        'name = "stack_parent"\nmodel = "disney"\n[params]\n'
        'roughness = { texture = "../mask.png" }\n'
    )
    one_line_error(cli("presets", "show", "child", "-L", str(lib), "-r"), "stack_parent.toml")


# -- colour settings ------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("space", "kind"),
    [("sRGB - Display", "display-referred"), ("acescct", "log-encoded"), ("Raw", "data")],
)
def test_a_space_that_is_not_scene_linear_is_no_working_space(cli, space, kind):
    line = one_line_error(cli("--working-space", space, "presets", "show", "gold", "-r"), kind)
    assert line.startswith("lookdev: error: --working-space: ")
    with pytest.raises(lookdev.LookdevError, match=rf"^working_space: .*{kind}"):
        with lookdev.colour_settings(working_space=space):
            pass


@pytest.mark.parametrize("look", [",", "a,,b", " , "])
def test_a_look_list_with_an_empty_name_is_one_line(cli, look):
    one_line_error(cli("--look", look, "presets", "show", "gold", "-r"), "empty name")


def test_scene_linear_spaces_are_still_working_spaces(cli):
    for space in ("acescg", "lin_rec709", "Linear Rec.2020"):
        assert cli("--working-space", space, "presets", "show", "gold", "-r").code == 0


# -- validate usd: values ---------------------------------------------------------------------
@pytest.fixture(scope="module")
def exported(tmp_path_factory):
    out = tmp_path_factory.mktemp("usd") / "gold.usda"
    lookdev.export_usd(["gold", "diamond"], out)
    return out


def _with(text: str, old: str, new: str) -> str:
    assert old in text, old
    return text.replace(old, new, 1)


@pytest.mark.parametrize(
    ("old", "new", "kind", "where"),
    [
        (
            "float inputs:roughness = 0.2\n",
            "float inputs:roughness = nan\n",
            "NonFiniteShaderInput",
            "input 'roughness'",
        ),
        (
            "color3f inputs:base_color = (1, 0.782, 0.344)",
            "color3f inputs:base_color = (1, inf, 0.344)",
            "NonFiniteShaderInput",
            "input 'baseColor'",  # the interface drives RenderMan's (and MaterialX's) surface
        ),
        (
            "float inputs:metallic = 1\n",
            "float inputs:metallic = -0.5\n",
            "ShaderInputOutOfRange",
            "input 'base_metalness'",  # OpenPBR's, which the interface's metallic drives
        ),
    ],
)
def test_validate_usd_names_prim_and_input_of_a_bad_value(
    cli, exported, tmp_path, old, new, kind, where
):
    bad = tmp_path / "bad.usda"
    bad.write_text(_with(exported.read_text(), old, new))
    r = cli("validate", "usd", str(bad), "--json")
    assert r.code == 1, r.err
    errors = json.loads(r.out)["errors"]
    hits = [e for e in errors if e.startswith(kind) and where in e]
    assert hits and all(e.split(": ")[1].startswith("/Materials/") for e in hits), errors


def test_validate_usd_passes_our_own_exports_and_only_warns_above_a_ui_maximum(
    cli, exported, tmp_path
):
    r = cli("validate", "usd", str(exported), "--json")
    assert r.code == 0, r.out
    assert json.loads(r.out)["errors"] == []
    # the diamond's specular > 1 (Burley allows it) is beyond ND_disney_principled's
    # slider: a warning (OpenPBR, the default mtlx surface, takes it as an IOR in range)
    disney = tmp_path / "diamond.usda"
    lookdev.export_usd(["diamond"], disney, mtlx_surface="disney")
    r = cli("validate", "usd", str(disney), "--json")
    doc = json.loads(r.out)
    assert r.code == 0 and doc["errors"] == [], r.out
    assert any(w.startswith("ShaderInputAboveUiMax") and "diamond" in w for w in doc["warnings"])


def test_value_checks_read_every_component():
    from lookdev.pipeline.export.usd.validate import _value_problem

    assert _value_problem("UsdPreviewSurface", "diffuseColor", (0.1, -0.2, 0.3))[2]
    assert _value_problem("UsdPreviewSurface", "roughness", math.nan)[0] == "NonFiniteShaderInput"
    assert _value_problem("UsdPreviewSurface", "roughness", 0.5) is None
    assert _value_problem("UsdPreviewSurface", "file", "wood.png") is None
    assert _value_problem("PxrDisneyBsdf", "roughness", -1.0) is None  # no range known


def test_a_truncated_png_texture_prints_one_line_and_no_libpng_line(tmp_path):
    lib = tmp_path / "lib"
    good = _image(tmp_path / "good.png", 3)
    _preset(lib, "cut", '[params]\nbase_color = { texture = "cut.png" }\n')
    (lib / "cut.png").write_bytes(good.read_bytes()[:100])
    code = "import sys; from lookdev.pipeline.cli import main; main(sys.argv[1:])"
    r = subprocess.run(
        [sys.executable, "-c", code, "presets", "show", "cut", "-L", str(lib), "-r"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    lines = r.stderr.strip().splitlines()
    assert r.returncode == 2 and len(lines) == 1, r.stderr
    assert lines[0].startswith("lookdev: error: ") and "cannot decode" in lines[0]


def test_a_maps_warning_is_not_printed_before_the_error_of_the_same_material(cli, tmp_path):
    lib = tmp_path / "lib"
    lib.mkdir()
    _image(lib / "c.png", 3)  # 8-bit colour without a colour space: a warning when it loads
    _preset(lib, "warned", '[params]\nbase_color = { texture = "c.png" }\n')
    _preset(
        lib,
        "bad",
        '[params]\nbase_color = { texture = "c.png" }\nroughness = 0.5\n'
        'metallic = { texture = "missing.png" }\n',
    )
    one_line_error(cli("presets", "show", "bad", "-L", str(lib), "-r"), "does not exist")
    r = cli("presets", "show", "warned", "-L", str(lib), "-r")
    assert r.code == 0 and r.err.count("lookdev: warning:") == 1 and "no colorspace" in r.err


def test_a_batch_prints_the_error_of_its_bad_preset_alone(cli, tmp_path):
    lib = tmp_path / "lib"
    lib.mkdir()
    _image(lib / "c.png", 3)
    _preset(lib, "warned", '[params]\nbase_color = { texture = "c.png" }\n')
    _preset(lib, "bad", '[params]\nmetallic = { texture = "missing.png" }\n')
    out = str(tmp_path / "x.usda")
    one_line_error(cli("export", "usd", "warned", "bad", "-L", str(lib), "-o", out), "missing.png")
