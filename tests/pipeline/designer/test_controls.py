"""Every parameter of every model gets a control from its schema, with its range,
default and documentation; the slider never leaves what the schema accepts."""

from __future__ import annotations

import math

import pytest

from lookdev.library.preset import MODELS
from lookdev.materials.textures import field_range, texturable
from lookdev.pipeline.designer.controls import controls_for, mask_kinds, texture_fields


@pytest.mark.parametrize("model", sorted(MODELS))
def test_every_field_has_a_control(model):
    cls = MODELS[model]
    controls = controls_for(model)
    assert [c["name"] for c in controls] == list(cls.model_fields)
    for c in controls:
        assert c["kind"] in ("number", "colour", "switch", "choice"), c
        assert c["doc"], f"{model}.{c['name']} has no documentation"
        assert c["texturable"] == (c["name"] in texturable(cls))


@pytest.mark.parametrize("model", sorted(MODELS))
def test_ranges_are_the_schemas(model):
    cls = MODELS[model]
    for c in controls_for(model):
        if c["kind"] != "number":
            continue
        if c["name"] in texturable(cls):
            low, high = field_range(cls, c["name"])
            assert (c["min"], c["max"]) == (low, high)
        assert c["min"] <= c["slider_min"] < c["slider_max"] <= c["max"]
        assert math.isfinite(c["slider_max"])
        if c["default"] is not None:
            assert c["min"] <= c["default"] <= c["max"]
            cls(**{c["name"]: c["slider_max"]})  # the slider's end is accepted
    if model == "disney":
        sheen = {c["name"]: c for c in controls_for(model)}
        assert sheen["sheen_model"]["choices"] == ["disney", "conty_kulla"]
        assert sheen["sheen_lambda"]["choices"] == ["fit", "exact"]
        assert sheen["ior"]["optional"] and sheen["ior"]["slider_max"] == 3.0


def test_masks_and_textures_are_described():
    kinds = mask_kinds()
    assert {"constant", "texture", "noise", "ramp", "levels", "invert", "multiply"} <= set(kinds)
    fields = {k: {f["name"]: f for f in v["fields"]} for k, v in kinds.items()}
    assert fields["noise"]["scale"]["kind"] == "number" and fields["noise"]["scale"]["max"] == 4096
    assert fields["noise"]["octaves"]["integer"] and fields["noise"]["octaves"]["min"] == 1
    tex = fields["texture"]
    assert (tex["path"]["kind"], tex["path"]["required"]) == ("file", True)
    assert tex["channel"]["kind"] == "channel" and tex["invert"]["kind"] == "switch"
    assert tex["wrap"]["choices"] == ["periodic", "clamp", "black", "mirror"]
    assert tex["uv_scale"]["kind"] == "pair" and tex["uv_scale"]["default"] == [1.0, 1.0]
    assert fields["invert"]["input"]["kind"] == "mask"
    assert fields["multiply"]["inputs"]["kind"] == "masks"
    assert fields["multiply"] == fields["screen"]  # one schema, four kinds
    for kind, spec in kinds.items():
        assert spec["doc"], kind
        assert all(f["doc"] or f["kind"] == "mask" for f in spec["fields"]), kind


def test_a_texture_input_is_described():
    from lookdev.materials import colour

    fields = {f["name"]: f for f in texture_fields()}
    assert fields["texture"]["kind"] == "file" and fields["texture"]["required"]
    assert fields["colorspace"]["kind"] == "space" and fields["colorspace"]["optional"]
    assert fields["colorspace"]["choices"] == colour.spaces()
    assert fields["range"]["kind"] == "pair" and fields["range"]["optional"]
    assert fields["scale"]["default"] == 1.0
