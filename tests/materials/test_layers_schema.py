"""lookdev.materials.layers: mask and layer-entry schemas."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from lookdev.materials.errors import ParameterError
from lookdev.materials.layers import (
    CombineMask,
    ConstantMask,
    InvertMask,
    LayerSpec,
    LevelsMask,
    NoiseMask,
    RampMask,
    TextureMask,
    children,
    map_textures,
    mask_adapter,
    textures,
)

RUST_IN_CAVITIES = """
[[layers]]
name = "rust"
preset = "rust"
presence = 0.8
[layers.mask]
kind = "multiply"
inputs = [
  { kind = "texture", path = "cavity.exr", channel = "R", uv_scale = [4, 4], wrap = "mirror" },
  { kind = "levels", input = { kind = "noise", scale = 8, seed = 3 }, low = 0.4, gamma = 2 },
  { kind = "invert", input = { kind = "ramp", axis = "radial", end = 0.5 } },
  { kind = "screen", inputs = [0.25, { kind = "max", inputs = [0.1, 0.2] }] },
]
"""


def test_a_toml_layer_parses_into_the_mask_tree():
    spec = LayerSpec.parse(tomllib.loads(RUST_IN_CAVITIES)["layers"][0])
    assert spec.presence == 0.8 and spec.preset == "rust" and spec.model is None
    tex, lev, inv, scr = spec.mask.inputs
    assert isinstance(spec.mask, CombineMask) and spec.mask.kind == "multiply"
    assert tex == TextureMask(
        path=Path("cavity.exr"), channel="R", uv_scale=(4.0, 4.0), wrap="mirror"
    )
    assert isinstance(lev, LevelsMask) and lev.input == NoiseMask(scale=8, seed=3)
    assert isinstance(inv.input, RampMask) and inv.input.axis == "radial"
    assert scr.inputs[0] == ConstantMask(value=0.25)  # a bare number is a constant mask
    assert [type(c).__name__ for c in children(spec.mask)] == [
        "TextureMask",
        "LevelsMask",
        "InvertMask",
        "CombineMask",
    ]


def test_defaults_inline_model_and_full_constant_mask():
    spec = LayerSpec.parse({"model": "disney", "params": {"roughness": 0.2}})
    assert spec.mask == ConstantMask(value=1.0) and spec.presence == 1.0
    assert spec.normal_map is None and spec.specular_normal_map is None
    assert spec.params == {"roughness": 0.2}


def test_schema_round_trips_through_json():
    spec = LayerSpec.parse(tomllib.loads(RUST_IN_CAVITIES)["layers"][0])
    again = LayerSpec.model_validate_json(spec.model_dump_json())
    assert again == spec


def test_json_schema_has_a_discriminated_union_and_descriptions():
    schema = mask_adapter().json_schema()
    assert set(schema["discriminator"]["mapping"]) == {
        "constant",
        "texture",
        "noise",
        "ramp",
        "multiply",
        "screen",
        "max",
        "min",
        "invert",
        "levels",
    }
    tex = schema["$defs"]["TextureMask"]["properties"]
    assert tex["wrap"]["enum"] == ["periodic", "clamp", "black", "mirror"]
    assert all("description" in tex[k] for k in ("path", "channel", "uv_scale", "wrap"))
    assert LayerSpec.model_json_schema()["additionalProperties"] is False


@pytest.mark.parametrize(
    ("data", "field", "words"),
    [
        ({"preset": "a", "model": "disney"}, None, "exactly one of 'preset'"),
        ({"params": {"roughness": 1}}, None, "exactly one of 'preset'"),
        ({"preset": "a", "presence": 1.5}, "presence", "out of range"),
        ({"preset": "a", "mask": 2.0}, "mask.constant.value", "out of range"),
        ({"preset": "a", "mask": {"kind": "blob"}}, "mask", "'blob'"),
        ({"preset": "a", "mask": {"kind": "texture"}}, "mask.texture.path", "required"),
        (
            {"preset": "a", "mask": {"kind": "texture", "path": "x", "channel": -1}},
            "mask.texture",
            "negative",
        ),
        (
            {"preset": "a", "mask": {"kind": "levels", "input": 1, "low": 0.6, "high": 0.5}},
            "mask.levels",
            "below high",
        ),
        ({"preset": "a", "mask": {"kind": "ramp", "start": 0.3, "end": 0.3}}, "mask.ramp", "step"),
        ({"preset": "a", "mask": {"kind": "noise", "octaves": 0}}, "mask.noise.octaves", "range"),
        ({"preset": "a", "mask": {"kind": "noise", "scale": 0}}, "mask.noise.scale", "range"),
        ({"preset": "a", "mask": {"kind": "max", "inputs": []}}, "mask.max.inputs", "at least"),
        ({"preset": "a", "mask": {"kind": "constant", "value": float("nan")}}, None, "finite"),
        ({"preset": "a", "opacity": 1}, "opacity", "unknown field; allowed: name, preset"),
    ],
)
def test_bad_layers_are_one_line_errors_naming_the_field(data, field, words):
    with pytest.raises(ParameterError) as info:
        LayerSpec.parse(data, where="stack.toml")
    message = str(info.value)
    assert "\n" not in message and message.startswith("stack.toml: ")
    assert words in message
    if field is not None:
        assert info.value.field == field


def test_texture_leaves_can_be_listed_and_rebased():
    spec = LayerSpec.parse(tomllib.loads(RUST_IN_CAVITIES)["layers"][0])
    inner = {"kind": "texture", "path": "deep.png"}
    mask = InvertMask(input=CombineMask(kind="min", inputs=[spec.mask, inner]))
    assert [t.path.name for t in textures(mask)] == ["cavity.exr", "deep.png"]
    rebased = map_textures(mask, lambda t: t.model_copy(update={"path": Path("/p") / t.path}))
    assert [str(t.path) for t in textures(rebased)] == ["/p/cavity.exr", "/p/deep.png"]
    assert [t.path.name for t in textures(mask)] == ["cavity.exr", "deep.png"]  # not mutated


def test_every_builtin_layered_preset_validates():
    folder = Path(__file__).resolve().parents[2] / "presets" / "layered"
    files = sorted(folder.glob("*.toml"))
    assert files
    for path in files:
        for entry in tomllib.loads(path.read_text())["layers"]:
            LayerSpec.parse(entry, where=str(path))


@pytest.mark.parametrize(
    "entry, field",
    [
        ({"preset": "gold", "presence": "0.5"}, "presence"),
        ({"preset": "gold", "mask": {"kind": "constant", "value": True}}, "value"),
        ({"preset": "gold", "mask": {"kind": "noise", "octaves": 4.5}}, "octaves"),
        ({"preset": "gold", "mask": {"kind": "texture", "path": "m.png", "invert": 1}}, "invert"),
    ],
)
def test_scalar_fields_take_their_toml_type_only(entry, field):
    # TOML is typed: a quoted number or a 1 for true is a typo, not a value to coerce.
    with pytest.raises(ParameterError) as info:
        LayerSpec.parse(entry)
    assert field in str(info.value) and "\n" not in str(info.value)
