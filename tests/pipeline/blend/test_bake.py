"""Baking blended materials to EXR + JSON, and ``lookdev blend``."""

from __future__ import annotations

import importlib
import json

import numpy as np
import OpenImageIO as oiio
import pytest
from _blend_helpers import disney, layer, layered, write_image

from lookdev.materials.layers import NoiseMask, TextureMask
from lookdev.pipeline.blend import BlendError, bake, blend
from lookdev.pipeline.blend.resample import read_channels

bake_module = importlib.import_module("lookdev.pipeline.blend.bake")  # the package exports bake()
GOLD = disney("gold", base_color=(1.0, 0.78, 0.34), metallic=1.0, roughness=0.2)
RUBBER = disney("rubber", base_color=(0.05, 0.1, 0.6), roughness=0.9)


def _read(path):
    buf = oiio.ImageBuf(str(path))
    return buf.spec(), buf.get_pixels(oiio.FLOAT)


def test_only_varying_maps_are_written_top_row_v_1(tmp_path):
    stack = layered(layer(GOLD), layer(RUBBER, NoiseMask(seed=2)), name="worn")
    blended = blend(stack, (16, 8))
    files = bake(blended, tmp_path / "out")
    assert set(files) == {"roughness", "metallic", "base_color", "sidecar"}  # specular: 0.5 both
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == sorted(
        p.name for p in files.values()
    )
    spec, pixels = _read(files["base_color"])
    assert (spec.width, spec.height, spec.nchannels) == (16, 8, 3)
    assert spec.channelnames == ("R", "G", "B") and spec.format == oiio.FLOAT
    assert np.array_equal(pixels[::-1], blended.maps["base_color"])  # file top row = v = 1
    back = read_channels(TextureMask(path=files["roughness"]))[..., 0]
    assert np.array_equal(back, blended.maps["roughness"])  # round trip in UV order


def test_sidecar_holds_constants_and_map_files(tmp_path):
    blended = blend(layered(layer(GOLD), layer(RUBBER, NoiseMask()), name="worn"), 8)
    files = bake(blended, tmp_path)
    doc = json.loads(files["sidecar"].read_text())
    assert doc["name"] == "worn" and doc["model"] == "disney" and doc["resolution"] == [8, 8]
    assert doc["constants"]["clearcoat"] == 0.0 and doc["constants"]["thin"] is False
    assert doc["maps"]["roughness"] == {
        "file": "worn_roughness.exr",
        "colour_space": "Raw",
        "channels": ["Y"],
        "encoding": "linear",
    }
    assert doc["colour_space"] == "Linear Rec.709 (sRGB)"  # of the constants and colour maps
    assert doc["maps"]["base_color"]["colour_space"] == "Linear Rec.709 (sRGB)"
    assert set(doc["constants"]).isdisjoint(doc["maps"])
    assert [entry["kept"] for entry in doc["layers"]] == [True, True]


def test_a_uniform_material_bakes_to_a_sidecar_alone(tmp_path):
    files = bake(blend(GOLD, 64), tmp_path)
    assert list(files) == ["sidecar"] and [p.name for p in tmp_path.iterdir()] == ["gold.json"]
    assert json.loads(files["sidecar"].read_text())["constants"]["base_color"] == [1.0, 0.78, 0.34]


def test_normal_maps_are_written_encoded(tmp_path):
    n = np.array([0.6, 0.0, 0.8], dtype=np.float32)
    tex = TextureMask(path=write_image(tmp_path / "n.exr", np.ones((4, 4, 3)) * (0.5 * n + 0.5)))
    blended = blend(layered(layer(GOLD, normal_map=tex)), 4)
    files = bake(blended, tmp_path / "out")
    _, pixels = _read(files["normal_map"])
    assert np.allclose(pixels, 0.5 * n + 0.5, atol=1e-6)
    doc = json.loads(files["sidecar"].read_text())
    assert doc["maps"]["normal_map"]["encoding"] == "(n + 1) / 2"


def test_stale_maps_of_an_earlier_bake_are_removed(tmp_path):
    bake(blend(layered(layer(GOLD), layer(RUBBER, NoiseMask()), name="m"), 4), tmp_path)
    assert (tmp_path / "m_roughness.exr").exists()
    rougher = disney("r", base_color=(1.0, 0.78, 0.34), metallic=1.0, roughness=0.3)
    bake(blend(layered(layer(GOLD), layer(rougher, 0.5), name="m"), 4), tmp_path)
    assert [p.name for p in tmp_path.iterdir()] == ["m.json"]


def test_a_failing_write_leaves_nothing_half_written(tmp_path, monkeypatch):
    out = tmp_path / "out"
    blended = blend(layered(layer(GOLD), layer(RUBBER, NoiseMask()), name="m"), 4)
    real = bake_module._write_exr
    calls = []

    def flaky(path, pixels, where, final, space):
        calls.append(path)
        if len(calls) == 3:
            raise BlendError("disk full", where=where)
        real(path, pixels, where, final, space)

    monkeypatch.setattr(bake_module, "_write_exr", flaky)
    with pytest.raises(BlendError, match="disk full"):
        bake(blended, out)
    assert not out.exists()  # no maps, no sidecar, no temporary, not even the new folder
    out.mkdir()
    with pytest.raises(BlendError, match="disk full"):
        calls.clear()
        bake(blended, out)
    assert list(out.iterdir()) == []  # an existing folder stays, empty


# -- the CLI -------------------------------------------------------------------------------
def test_cli_blend_writes_maps_and_prints_json(cli, tmp_path):
    r = cli("blend", "rusty_iron", "-o", str(tmp_path), "--resolution", "16", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    assert doc["name"] == "rusty_iron" and doc["resolution"] == [16, 16]
    assert set(doc["maps"]) >= {"roughness", "base_color"}
    for entry in doc["maps"].values():
        assert (tmp_path / entry["file"].rsplit("/", 1)[-1]).exists()
        assert 0.0 <= entry["min"] <= entry["max"]
    assert (tmp_path / "rusty_iron.json").exists()


def test_cli_blend_table_for_people(cli, tmp_path):
    r = cli("blend", "dust_over_plastic", "-o", str(tmp_path), "-r", "8")
    assert r.code == 0, r.err
    assert "dust_over_plastic" in r.out and "maps (8×8)" in r.out and "sidecar" in r.out


def test_cli_bad_texture_is_one_line_and_writes_nothing(cli, tmp_path):
    preset = tmp_path / "broken.toml"
    preset.write_text(
        'name = "broken"\nmodel = "layered"\n'
        '[[layers]]\npreset = "gold"\n'
        '[[layers]]\nname = "grime"\npreset = "rust"\n'
        'mask = { kind = "texture", path = "missing_grime.png" }\n'
    )
    out = tmp_path / "out"
    r = cli("blend", str(preset), "-o", str(out))
    assert r.code == 2 and r.out == ""
    line = r.err.strip()
    assert "\n" not in line and "layer 'grime'" in line and "missing_grime.png" in line
    assert not out.exists() or list(out.iterdir()) == []


def test_cli_unknown_preset(cli, tmp_path):
    r = cli("blend", "no_such_preset", "-o", str(tmp_path))
    assert r.code == 2 and "no_such_preset" in r.err and "Traceback" not in r.err


def test_cli_pixar_layering_option(cli, tmp_path):
    base = 'model = "pixar"\n[params]\nroughness = 0.6\n'
    (tmp_path / "clay.toml").write_text('name = "clay"\n' + base)
    (tmp_path / "glaze.toml").write_text(
        'name = "glaze"\nmodel = "pixar"\n[params]\nroughness = 0.1\nclear = 0.6\n'
    )
    (tmp_path / "glazed.toml").write_text(
        'name = "glazed"\nmodel = "layered"\n[[layers]]\npreset = "clay"\n'
        '[[layers]]\npreset = "glaze"\nmask = { kind = "noise", seed = 2 }\n'
    )
    out = {}
    for mode in ("full", "simple"):
        args = ["-L", str(tmp_path), "-o", str(tmp_path / mode), "-r", "8", "--layering", mode]
        r = cli("blend", "glazed", *args, "--json")
        assert r.code == 0, r.err
        out[mode] = json.loads(r.out)
        assert out[mode]["representation"] == "lobe_weights"
    assert out["full"]["maps"]["diffN"] != out["simple"]["maps"]["diffN"]
    r = cli("blend", "glazed", "-L", str(tmp_path), "-o", str(tmp_path), "--layering", "x")
    assert r.code == 2 and "unknown Pixar layering 'x'" in r.err


@pytest.mark.slow
def test_bench_blend_smoke(cli):
    r = cli("bench", "blend", "--resolution", "16", "--repeat", "1", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    assert doc["maps"] == 16 and doc["layers"] == 4
    assert doc["ratio_blend_to_copy"] > 0 and doc["peak_to_output"] > 0
    saving = doc["pruning"]["hidden+zero layers"]
    assert saving["layers_kept"] == saving["layers_total"] - 2
    assert (
        doc["pruning"]["rusty_car_paint"]["maps"]
        < doc["pruning"]["rusty_car_paint"]["maps_without"]
    )


def test_cli_texture_paths_are_relative_to_the_preset(cli, tmp_path, monkeypatch):
    looks = tmp_path / "looks"
    looks.mkdir()
    write_image(looks / "grime.png", np.tile([[0.0, 1.0]], (4, 2)), fmt=oiio.UINT8)
    (looks / "grimy_gold.toml").write_text(
        'name = "grimy_gold"\nmodel = "layered"\n'
        '[[layers]]\npreset = "gold"\n'
        '[[layers]]\nname = "grime"\npreset = "rust"\n'
        'mask = { kind = "texture", path = "grime.png", wrap = "clamp" }\n'
    )
    monkeypatch.chdir(tmp_path)  # not the preset's folder
    r = cli("blend", "grimy_gold", "-L", "looks", "-o", "out", "-r", "4", "--json")
    assert r.code == 0, r.err
    doc = json.loads(r.out)
    assert doc["maps"]["roughness"]["min"] < doc["maps"]["roughness"]["max"]
