"""One preset file: its schema, strict parsing into one-line errors, and TOML output.

A preset file is small TOML::

    name = "brushed_steel"
    model = "disney"                      # or "pixar", or "layered"
    description = "Steel brushed along the tangent."
    tags = ["metal", "anisotropic"]
    source = "F0 of iron: Hoffman 2015, Physics and Math of Shading, table of F0 values"
    extends = "iron"                      # optional: inherit, then override
    [params]
    roughness = 0.35
    anisotropic = 0.8

What is checked here is what one file can know: TOML syntax, the fields, their types,
and each given parameter against its model's schema. What needs other files (``extends``
chains, layer references) is resolved in :mod:`lookdev.library.material`.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any, Literal

import tomli_w
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from lookdev.materials.errors import ParameterError, one_line, register_schema, short_repr
from lookdev.materials.layers import ConstantMask, LayerSpec
from lookdev.materials.model_names import PARAMS, Imported
from lookdev.materials.params import Params
from lookdev.materials.textures import TextureInput, is_texture_input, texturable

from .errors import PresetError
from .index import SUFFIX
from .toml_file import MAX_BYTES as MAX_BYTES  # re-exported
from .toml_file import NAME_RE as NAME_RE
from .toml_file import check_name as check_name
from .toml_file import parse_toml as parse_toml

__all__ = [
    "METADATA",
    "MODELS",
    "PresetFile",
    "build_preset",
    "check_params",
    "dump_preset",
    "parse_preset",
    "parse_value",
    "preset_document",
    "read_preset",
    "split_params",
]

MODELS: Mapping[str, type[Params]] = Imported(PARAMS)
"""Parameter schema of each reflectance model a preset may name, imported when first asked
for (its model's module is not: validating a preset needs no evaluation)."""

METADATA = ("description", "tags", "source", "extends")
"""Top-level fields that ``--set`` may change (everything else it sets is a parameter)."""


@register_schema
class PresetFile(BaseModel):
    """The fields of one preset file, as written (before ``extends`` is resolved)."""

    model_config = ConfigDict(extra="forbid", frozen=True, title="lookdev preset")

    name: str = Field(description="Preset name; must equal the file name without '.toml'.")
    model: Literal["disney", "pixar", "openpbr", "layered"] | None = Field(
        None, description="Reflectance model; may be left out when 'extends' names the parent."
    )
    description: str = Field("", description="One sentence for people browsing the library.")
    tags: list[str] = Field(default_factory=list, description="Keywords for `presets list --tag`.")
    source: str | None = Field(
        None, description="Where the values come from: the published measurement or reference."
    )
    extends: str | None = Field(None, description="Parent preset: inherit, then override.")
    params: dict[str, Any] = Field(
        default_factory=dict, description="Model parameters (disney or pixar presets)."
    )
    layers: list[LayerSpec] = Field(
        default_factory=list, description="Layered presets: layers from bottom to top."
    )
    textures: str | None = Field(
        None,
        description="A texture set: 'asset_<channel>.<UDIM>.png' (relative to the preset) "
        "fills every parameter whose Substance Painter / Mari channel is found; [params] "
        "entries win (lookdev.library.texture_sets).",
    )
    height: TextureInput | None = Field(
        None,
        description="Height map for bump (proofs) and displacement (USD): the value after "
        "scale and offset is a height in scene units (metres at metersPerUnit = 1), e.g. "
        "{ texture = 'h.png', scale = 0.01 } for a map whose white is 1 cm.",
    )

    @field_validator("name", "extends")
    @classmethod
    def _safe_name(cls, value: str | None) -> str | None:
        if value is not None and not NAME_RE.fullmatch(value):
            raise ValueError(
                f"{short_repr(value)} is not a preset name; use 1-100 letters, digits, '_' or '-'"
            )
        return value

    @model_validator(mode="after")
    def _fields_fit_the_model(self) -> PresetFile:
        if self.model is None and self.extends is None:
            raise ValueError(
                "'model' is required (disney, pixar or layered) unless 'extends' is given"
            )
        if self.model == "layered" and self.textures is not None:
            raise ValueError("a layered preset has no texture set; give it to a layer's preset")
        if self.model == "layered" and self.params:
            raise ValueError("a layered preset has no [params]; give each layer its own")
        if self.model in MODELS and self.layers:
            raise ValueError(f'a {self.model} preset has no [[layers]]; use model = "layered"')
        if self.model == "layered" and not self.layers and self.extends is None:
            raise ValueError("a layered preset needs at least one [[layers]] entry")
        return self


def references_files(preset: PresetFile) -> bool:
    """True when resolving ``preset`` reads a file besides its own: a parent, a layer's
    preset, a texture set, a height map or a parameter's texture."""
    return bool(
        preset.extends is not None
        or preset.layers
        or preset.textures is not None
        or preset.height is not None
        or any(is_texture_input(v) for v in preset.params.values())
    )


def parse_preset(data: bytes, *, where: str, stem: str | None = None) -> PresetFile:
    """Parse and check one preset file's bytes; every problem is one :class:`PresetError`.

    ``where`` names the file in messages; ``stem``, when given, is the file name the
    preset's ``name`` must equal.
    """
    doc = parse_toml(data, where=where)
    if not doc:
        raise PresetError("empty preset file: it needs at least name and model", where=where)
    return build_preset(doc, where=where, stem=stem)


def build_preset(doc: dict[str, Any], *, where: str, stem: str | None = None) -> PresetFile:
    """Check a preset document (a parsed TOML table) as :func:`parse_preset` does."""
    preset = _validate(doc, where=where)
    if stem is not None and preset.name != stem:
        raise PresetError(
            f"name {preset.name!r} differs from the file name {stem!r}; they must agree",
            where=where,
            field="name",
        )
    if preset.model in MODELS:
        check_params(preset.model, preset.params, where=where)
    for i, layer in enumerate(preset.layers):
        if layer.model is not None:
            check_params(layer.model, layer.params, where=where, prefix=f"layers[{i}].params")
    return preset


def check_params(model: str, params: dict[str, Any], *, where: str | None, prefix: str = "params"):
    """Validate ``params`` against ``model``'s schema; errors name ``prefix.field``.

    Strictly, as TOML is typed: ``roughness = "0.5"`` or ``roughness = true`` is a typo,
    not 0.5 or 1.0 (pydantic's lax mode would take both). TOML arrays become the tuples
    that strict validation wants for colours. Parameters given as textures are checked as
    :class:`~lookdev.materials.textures.TextureInput` (see :func:`split_params`).
    """
    return split_params(model, params, where=where, prefix=prefix)[0]


def split_params(
    model: str, params: dict[str, Any], *, where: str | None, prefix: str = "params"
) -> tuple[Params, dict[str, TextureInput]]:
    """(the constants as ``model``'s parameters, the textures by parameter name).

    A parameter written as a table with ``texture`` is a texture; it must be one the model
    lets a texture drive (:func:`~lookdev.materials.textures.texturable`); the schema
    checks the rest as constants, so a textured field is left at its default there.
    Files are not opened here (see :mod:`lookdev.library.textures`).
    """
    params_type = MODELS[model]
    allowed = texturable(params_type)
    textures: dict[str, TextureInput] = {}
    for key, value in params.items():
        if not is_texture_input(value):
            continue
        if key not in allowed:
            why = "no such parameter" if key not in params_type.model_fields else "not continuous"
            raise ParameterError(
                f"{key!r} cannot be a texture ({why}); textures drive {', '.join(allowed)}",
                where=where,
                field=f"{prefix}.{key}",
            )
        textures[key] = _texture_input(value, where=where, field=f"{prefix}.{key}")
    if {"specular", "ior"} <= set(params) and "specular" in params_type.model_fields:
        raise ParameterError(
            "give either 'specular' or 'ior', not both: they are one parameter",
            where=where,
            field=prefix,
        )
    data = {
        k: tuple(v) if isinstance(v, list) else v for k, v in params.items() if k not in textures
    }
    try:
        return params_type.model_validate(data, strict=True), textures
    except ValidationError as exc:
        raise one_line(exc, ParameterError, where=where, prefix=prefix) from None


def _texture_input(value: Any, *, where: str | None, field: str) -> TextureInput:
    if isinstance(value, TextureInput):
        return value
    data = {k: tuple(v) if isinstance(v, list) else v for k, v in value.items()}
    try:
        return TextureInput.model_validate(data, strict=True)
    except ValidationError as exc:
        raise one_line(exc, ParameterError, where=where, prefix=field) from None


def _validate(doc: dict[str, Any], *, where: str) -> PresetFile:
    try:
        return PresetFile.model_validate(doc)
    except ValidationError as exc:
        raise one_line(exc, PresetError, where=where) from None


def dump_preset(preset: PresetFile) -> str:
    """The preset as TOML, fields in the documented order, empty fields left out.

    >>> print(dump_preset(PresetFile(name="a", model="disney", params={"roughness": 0.3})))
    name = "a"
    model = "disney"
    <BLANKLINE>
    [params]
    roughness = 0.3
    <BLANKLINE>
    """
    doc = preset_document(preset)
    return _compact_arrays(_inline_textures(doc) or tomli_w.dumps(doc))


def _inline_textures(doc: dict[str, Any]) -> str | None:
    """The document with each texture of ``[params]`` as one inline table, as people write
    it (``roughness = { texture = "r.png", channel = "r" }``; tomli_w would write a
    ``[params.roughness]`` section; layers keep their sections); None when there is none,
    or when the rewrite would not read back as the same document."""
    tables: list[dict[str, Any]] = []

    def mark(params: dict[str, Any]) -> dict[str, Any]:
        out = {}
        for key, value in params.items():
            if isinstance(value, dict) and is_texture_input(value):
                tables.append(value)
                value = f"\x00texture{len(tables) - 1}\x00"
            out[key] = value
        return out

    marked = dict(doc)
    if "params" in doc:
        marked["params"] = mark(doc["params"])
    if not tables:
        return None
    text = tomli_w.dumps(marked)
    for i, table in enumerate(tables):
        items = [tomli_w.dumps({k: v}).strip() for k, v in table.items()]
        text = text.replace(f'"\\u0000texture{i}\\u0000"', "{ " + ", ".join(items) + " }")
    try:
        return text if tomllib.loads(text) == doc else None
    except tomllib.TOMLDecodeError:
        return None


def preset_document(preset: PresetFile) -> dict[str, Any]:
    """The preset as the TOML table it is written as (ordered, no empty fields).

    >>> preset_document(PresetFile(name="a", extends="gold"))
    {'name': 'a', 'extends': 'gold'}
    """
    data = preset.model_dump(mode="json", exclude_none=True, exclude_defaults=True)
    data["name"] = preset.name
    if preset.layers:
        data["layers"] = [_layer_doc(layer) for layer in preset.layers]
    return {k: data[k] for k in PresetFile.model_fields if k in data}


def _layer_doc(layer: LayerSpec) -> dict[str, Any]:
    maps = ("mask", "normal_map", "specular_normal_map")
    doc = layer.model_dump(mode="json", exclude_none=True, exclude_defaults=True, exclude=set(maps))
    for key in maps:
        value = getattr(layer, key)
        if value is not None and value != ConstantMask():
            doc[key] = _mask_doc(value)
    return doc


def _mask_doc(mask: Any) -> dict[str, Any]:
    """A mask tree as TOML data; ``kind`` always written, since it selects the type."""
    nested = ("input", "inputs")
    doc = {"kind": mask.kind}
    doc |= mask.model_dump(mode="json", exclude_defaults=True, exclude={"kind", *nested})
    if "inputs" in type(mask).model_fields:
        doc["inputs"] = [_mask_doc(m) for m in mask.inputs]
    elif "input" in type(mask).model_fields:
        doc["input"] = _mask_doc(mask.input)
    return doc


_SCALAR_ARRAY = re.compile(r"\[\n((?:[ ]+[^\[\]{}\n]+,\n)+)[ ]*\]")


def _compact_arrays(text: str) -> str:
    """Arrays of scalars on one line (``base_color = [1.0, 0.78, 0.34]``), as people write them.

    tomli_w writes every array one item per line; the rewrite is kept only if the
    document still parses to the same values.
    """

    def one_line(m: re.Match[str]) -> str:
        items = [line.strip().removesuffix(",") for line in m.group(1).splitlines()]
        return "[" + ", ".join(items) + "]"

    compact = _SCALAR_ARRAY.sub(one_line, text)
    return compact if tomllib.loads(compact) == tomllib.loads(text) else text


def parse_value(text: str) -> Any:
    """A ``--set`` value: any TOML value, or else the text itself as a string.

    >>> parse_value("0.3"), parse_value('"#aa8844"'), parse_value("[0.9, 0.6, 0.2]")
    (0.3, '#aa8844', [0.9, 0.6, 0.2])
    >>> parse_value("conty_kulla")
    'conty_kulla'
    """
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        return text


def read_preset(path: Path) -> PresetFile:
    """Parse one preset file (its name must match the file name)."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise PresetError(f"cannot read ({exc.strerror or exc})", where=str(path)) from None
    return parse_preset(data, where=str(path), stem=path.name.removesuffix(SUFFIX))
