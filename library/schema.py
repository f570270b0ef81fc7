"""JSON Schema of preset files, generated from the pydantic models (``lookdev presets schema``).

Editors that read JSON Schema for TOML (Taplo / Even Better TOML, via a
``#:schema ./preset.schema.json`` first line or their settings) then complete field
names, show the descriptions and ranges, and flag mistakes while typing. The schema
is the pydantic one plus what pydantic cannot see: ``[params]`` follows the preset's
``model``, a colour may also be a ``"#rrggbb"`` string or one grey number, any continuous
parameter may be a texture table (:class:`~lookdev.materials.textures.TextureInput`), and
a bare number is a mask.
"""

from __future__ import annotations

from typing import Any

from lookdev.materials.layers import LayerSpec
from lookdev.materials.params import Params, parse_color
from lookdev.materials.textures import TextureInput, texturable

from .preset import MODELS, NAME_RE, PresetFile

__all__ = ["BARE_MASK", "GREY", "HEX_COLOR", "params_schema", "preset_schema"]

HEX_COLOR = {"type": "string", "pattern": "^#?[0-9a-fA-F]{6}$", "description": "sRGB '#rrggbb'"}
GREY = {"type": "number", "minimum": 0, "maximum": 1, "description": "grey: r = g = b"}
BARE_MASK = {"type": "number", "minimum": 0, "maximum": 1, "description": "constant mask"}


def preset_schema() -> dict[str, Any]:
    """The JSON Schema (draft 2020-12) of one preset file."""
    schema = PresetFile.model_json_schema()
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["$id"] = "https://lookdev.invalid/preset.schema.json"
    defs = schema.setdefault("$defs", {})
    for cls in MODELS.values():
        defs[cls.__name__] = params_schema(cls, defs)
    for prop in ("name", "extends"):
        schema["properties"][prop].setdefault("pattern", f"^{NAME_RE.pattern}$")
    schema["allOf"] = _params_follow_model(MODELS)
    defs[LayerSpec.__name__]["allOf"] = _params_follow_model(MODELS)
    return _bare_numbers_are_masks(schema)


def params_schema(cls: type[Params], defs: dict[str, Any]) -> dict[str, Any]:
    """One model's parameter schema; its own ``$defs`` are hoisted into ``defs``."""
    schema = cls.model_json_schema()
    defs.update(schema.pop("$defs", {}))
    texture = TextureInput.model_json_schema()
    defs.update(texture.pop("$defs", {}))
    defs[TextureInput.__name__] = texture
    textured = {"$ref": f"#/$defs/{TextureInput.__name__}"}
    for name, field in cls.model_fields.items():
        prop = schema["properties"][name]
        colour = any(getattr(m, "func", None) is parse_color for m in field.metadata)
        if colour or name in texturable(cls):
            meta = {k: prop.pop(k) for k in ("title", "description", "default") if k in prop}
            choices = [prop, HEX_COLOR, GREY] if colour else [prop]
            schema["properties"][name] = {"anyOf": [*choices, textured], **meta}
    return schema


def _params_follow_model(models: dict[str, type[Params]]) -> list[dict[str, Any]]:
    return [
        {
            "if": {"properties": {"model": {"const": model}}, "required": ["model"]},
            "then": {"properties": {"params": {"$ref": f"#/$defs/{cls.__name__}"}}},
        }
        for model, cls in models.items()
    ]


def _bare_numbers_are_masks(node: Any) -> Any:
    """Wherever a mask union appears (discriminated on ``kind``), also allow a number."""
    if isinstance(node, list):
        return [_bare_numbers_are_masks(n) for n in node]
    if not isinstance(node, dict):
        return node
    out = {k: _bare_numbers_are_masks(v) for k, v in node.items()}
    if (out.get("discriminator") or {}).get("propertyName") == "kind":
        return {"anyOf": [out, BARE_MASK]}
    return out
