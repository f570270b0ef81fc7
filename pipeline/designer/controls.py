"""The designer's controls, generated from each model's Pydantic JSON Schema.

The page holds no knowledge of any model: for every parameter it gets a descriptor made
here from the schema (kind, allowed range, default, documentation, whether a texture may
drive it) and draws a slider, a colour, a switch or a choice. Values are checked on the
server by the same model (:mod:`.session`); the range here only shapes the slider.

Sliders span the plausible range (:cite:`Burley2012` §5.1: 0..1 for most parameters); the
number box beside accepts the schema's whole range, so ``specular`` may be pushed to its
ceiling and ``roughness`` 1.5 is refused with the schema's message.

>>> spec = {c["name"]: c for c in controls_for("disney")}
>>> spec["roughness"]["kind"], spec["roughness"]["min"], spec["roughness"]["max"]
('number', 0.0, 1.0)
>>> spec["specular"]["slider_max"], spec["specular"]["max"]
(1.0, 12.5)
>>> spec["sheen_model"]["kind"], spec["sheen_model"]["choices"]
('choice', ['disney', 'conty_kulla'])
>>> spec["base_color"]["kind"], spec["base_color"]["texturable"], spec["thin"]["kind"]
('colour', True, 'switch')
"""

from __future__ import annotations

import math
from functools import cache
from typing import Any

from lookdev.library.preset import MODELS
from lookdev.materials.params import Params, parse_color
from lookdev.materials.textures import TextureInput, texturable

__all__ = ["FILE_FIELDS", "controls_for", "form_field", "mask_kinds", "texture_fields"]

PLAUSIBLE_MAX = 1.0
"""Slider end of a parameter whose schema allows more (Burley's "may be pushed beyond")."""


@cache
def controls_for(model: str) -> list[dict[str, Any]]:
    """The control descriptors of ``model``'s parameters, in the schema's order."""
    cls = MODELS[model]
    schema = cls.model_json_schema()
    textured = texturable(cls)
    return [
        _descriptor(cls, name, schema["properties"][name], name in textured)
        for name in cls.model_fields
    ]


def _descriptor(cls: type[Params], name: str, prop: dict[str, Any], textured: bool) -> dict:
    field = cls.model_fields[name]
    out: dict[str, Any] = {
        "name": name,
        "title": name.replace("_", " "),
        "doc": field.description or "",
        "default": _default(field),
        "texturable": textured,
    }
    choices = [p for p in prop.get("anyOf", [prop]) if p.get("type") != "null"]
    core = choices[0] if choices else prop
    if any(getattr(m, "func", None) is parse_color for m in field.metadata):
        item = core.get("prefixItems", [{}])[0]
        return out | {"kind": "colour", "min": item.get("minimum", 0.0), "max": item.get("maximum")}
    if core.get("type") == "boolean":
        return out | {"kind": "switch"}
    if "enum" in core or "const" in core:
        return out | {"kind": "choice", "choices": list(core.get("enum", [core.get("const")]))}
    if core.get("type") == "number":
        low = core.get("minimum", core.get("exclusiveMinimum", -math.inf))
        high = core.get("maximum", math.inf)
        return out | {
            "kind": "number",
            "optional": len(choices) < len(prop.get("anyOf", [prop])),
            "min": low,
            "max": high,
            "exclusive_min": "exclusiveMinimum" in core,
            "slider_min": low,
            "slider_max": _slider_max(low, high, field.default),
        }
    return out | {"kind": "text"}


def _default(field: Any) -> Any:
    """A field's default as JSON (None for a required field)."""
    return None if field.is_required() else field.get_default(call_default_factory=True)


def _slider_max(low: float, high: float, default: Any) -> float:
    if low >= PLAUSIBLE_MAX:  # an IOR: 1 .. a few
        return min(high, low + 2.0)
    top = max(PLAUSIBLE_MAX, float(default) if isinstance(default, int | float) else 0.0)
    return min(high, top) if math.isfinite(high) else top


FILE_FIELDS = ("texture", "path")
"""Fields naming an image: drawn as the server's file picker (library folders only)."""


@cache
def texture_fields() -> list[dict[str, Any]]:
    """Form descriptors of a texture input's own fields (file, channel, colour space, …)."""
    schema = TextureInput.model_json_schema()
    required = set(schema.get("required", ()))
    return [
        form_field(n, schema["properties"][n], n in required)
        for n in TextureInput.model_fields
        if n in schema["properties"]
    ]


@cache
def mask_kinds() -> dict[str, dict[str, Any]]:
    """Every mask kind with form descriptors of its fields (the masks' existing options)."""
    from lookdev.materials.layers import mask_adapter

    out = {}
    for cls_schema in mask_adapter().json_schema().get("$defs", {}).values():
        props = cls_schema.get("properties", {})
        kind = props.get("kind", {})
        names = kind.get("enum") or [kind.get("const") or kind.get("default")]
        required = set(cls_schema.get("required", ())) - {"kind"}
        fields = [form_field(k, v, k in required) for k, v in props.items() if k != "kind"]
        for name in filter(None, names):
            out[name] = {"doc": cls_schema.get("description", ""), "fields": fields}
    return out


def form_field(name: str, prop: dict[str, Any], required: bool) -> dict[str, Any]:
    """A control descriptor of one JSON-schema property: ``kind`` is one of ``number``,
    ``switch``, ``choice``, ``text``, ``channel`` (an index or a name), ``pair`` (two
    numbers), ``file``, ``space`` (an OCIO colour space), ``mask`` or ``masks`` (nested).

    >>> form_field("wrap", {"enum": ["periodic", "clamp"], "default": "periodic"}, False)["kind"]
    'choice'
    >>> form_field("low", {"type": "number", "minimum": 0, "maximum": 1}, False)["max"]
    1
    """
    out: dict[str, Any] = {
        "name": name,
        "title": name.replace("_", " "),
        "doc": prop.get("description", ""),
        "default": prop.get("default"),
        "required": required,
    }
    options = prop.get("anyOf", [prop])
    core = [p for p in options if p.get("type") != "null"]
    out["optional"] = len(core) < len(options)
    types = {p.get("type") for p in core}
    first = core[0] if core else prop
    if "oneOf" in prop or "$ref" in prop:
        return out | {"kind": "mask"}
    if first.get("type") == "array" and "oneOf" in first.get("items", {}):
        return out | {"kind": "masks", "min_items": first.get("minItems", 0)}
    if name in FILE_FIELDS:
        return out | {"kind": "file"}
    if name == "colorspace":
        from lookdev.materials import colour

        return out | {"kind": "space", "choices": colour.spaces()}
    if types == {"integer", "string"}:
        return out | {"kind": "channel"}
    if first.get("type") == "boolean":
        return out | {"kind": "switch"}
    if "enum" in first or "const" in first:
        return out | {"kind": "choice", "choices": list(first.get("enum", [first.get("const")]))}
    if first.get("type") == "array" and "prefixItems" in first:
        items = first["prefixItems"]
        return out | {"kind": "pair", **_bounds(items[0]), "count": len(items)}
    if first.get("type") in ("number", "integer"):
        return out | {"kind": "number", "integer": first["type"] == "integer", **_bounds(first)}
    return out | {"kind": "text"}


def _bounds(prop: dict[str, Any]) -> dict[str, Any]:
    return {
        "min": prop.get("minimum", prop.get("exclusiveMinimum")),
        "max": prop.get("maximum", prop.get("exclusiveMaximum")),
    }
