"""OpenPBR materials as themselves: ``ND_open_pbr_surface_surfaceshader`` values → an
``openpbr`` preset (:class:`lookdev.materials.openpbr.OpenPBRParams`).

The OpenPBR input names are the model's parameter names, so reading is a copy of the
authored values over the specification's defaults; what cannot be a constant (a
connected input, an unknown name) is returned as a note, never dropped silently. Used for
``lookdev import usd`` (an OpenPBR shader in a UsdShade network, read by
:func:`.reader.import_as_openpbr`)
and for standalone ``.mtlx`` documents such as the specification's example materials.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from lookdev.materials.openpbr import OpenPBRParams

from .network import Connection, ExportError, Node, plain_value

__all__ = [
    "AS_OPENPBR_IDS",
    "OPENPBR_IDS",
    "STANDARD_SURFACE_ID",
    "openpbr_preset",
    "openpbr_values",
    "params_from_values",
    "read_mtlx",
]

OPENPBR_IDS = ("ND_open_pbr_surface_surfaceshader",)
"""Shader ids read as OpenPBR Surface."""
STANDARD_SURFACE_ID = "ND_standard_surface_surfaceshader"
AS_OPENPBR_IDS = (*OPENPBR_IDS, STANDARD_SURFACE_ID)
"""Shader ids read as OpenPBR Surface: OpenPBR itself, and Standard Surface through
MaterialX's translation (:mod:`.mtlx_translate`)."""
VIA_TRANSLATION = (
    "Standard Surface read as OpenPBR Surface by MaterialX's translation graph "
    "ND_standard_surface_to_open_pbr_surface"
)
"""The note every Standard Surface read as OpenPBR carries."""


def openpbr_values(surface: Node) -> tuple[dict[str, Any], list[str]]:
    """The constant OpenPBR Surface inputs of an OpenPBR or Standard Surface ``surface``
    (one of :data:`AS_OPENPBR_IDS`) and the notes on what is not read: a connected input
    (its default is used), and for Standard Surface what MaterialX's translation does not
    carry (:func:`.mtlx_translate.standard_surface_to_openpbr`)."""
    from .mtlx_translate import CONNECTED, standard_surface_to_openpbr

    standard = surface.id == STANDARD_SURFACE_ID
    values, notes = {}, []
    for name, (_, value) in surface.inputs.items():
        value = plain_value(value)
        if isinstance(value, Connection):
            if standard:
                values[name] = CONNECTED
            else:
                notes.append(f"mtlx: {name} is a connected network (not imported): its default")
            continue
        values[name] = tuple(value) if isinstance(value, tuple | list) else value
    values.pop("geometry_normal", None)
    if not standard:
        return values, notes
    translated, more = standard_surface_to_openpbr(_live(values))
    notes.append(f"mtlx: {VIA_TRANSLATION}")
    notes.extend(f"mtlx: {line}" for line in more)
    fed = sorted(k for k, v in translated.items() if v is CONNECTED)
    if fed:
        notes.append(
            "mtlx: " + ", ".join(fed) + ": computed from a connected network of the Standard "
            "Surface (not imported), at OpenPBR's defaults"
        )
    return {k: v for k, v in translated.items() if v is not CONNECTED}, notes


def _live(values: dict[str, Any]) -> dict[str, Any]:
    """Standard Surface ``values`` without the inputs of a dead lobe (every weight that
    reads them 0: :data:`.foreign.GATES`, the rule the Disney reading follows): at weight
    0 a value shows nothing, and the translation then carries Standard Surface's default
    instead (a velvet's ``specular_IOR = 0`` on a specular of weight 0, which OpenPBR's
    ``specular_ior > 0`` would refuse)."""
    from .foreign import GATES, TABLES
    from .mtlx import node_defaults

    defaults = node_defaults(STANDARD_SURFACE_ID)
    out = dict(values)
    for param, weights in GATES[STANDARD_SURFACE_ID].items():
        given = [values.get(w, defaults.get(w)) for w in weights]
        if all(isinstance(v, int | float) and v == 0.0 for v in given):
            for name in TABLES[STANDARD_SURFACE_ID][param][:2]:
                out.pop(name, None)
    return out


def params_from_values(values: dict[str, Any], where: str = "") -> tuple[OpenPBRParams, list[str]]:
    """The OpenPBR parameters of authored input ``values`` and the notes on what was not
    read (inputs the model has no field for). Values out of the specification's range
    raise a :class:`~lookdev.materials.errors.ParameterError` naming the input."""
    fields = OpenPBRParams.model_fields
    notes = [
        f"{name} is not an OpenPBR Surface input: ignored" for name in values if name not in fields
    ]
    given = {}
    for name, value in values.items():
        if name not in fields:
            continue
        if name == "geometry_thin_walled":
            value = bool(value)
        elif isinstance(value, tuple | list):
            value = tuple(float(v) for v in value)
        else:
            value = float(value)
        given[name] = value
    return OpenPBRParams.parse(given, where=where or None), notes


def read_mtlx(path: Path) -> dict[str, tuple[OpenPBRParams, list[str]]]:
    """Every material of a MaterialX document whose surface is ``open_pbr_surface``:
    material name → (parameters, notes). Colours are taken as the numbers written (the
    document's colour space is not converted)."""
    import MaterialX as mx

    doc = mx.createDocument()
    try:
        mx.readFromXmlFile(doc, str(path))
    except mx.Exception as exc:  # MaterialX's own error type: one line
        raise ExportError(f"MaterialX cannot read it: {exc}", where=str(path)) from None
    out = {}
    for material in doc.getMaterialNodes():
        for shader in mx.getShaderNodes(material):
            if shader.getCategory() != "open_pbr_surface":
                continue
            values, notes = {}, []
            for inp in shader.getInputs():
                if inp.getNodeName() or inp.getOutputString() or inp.getInterfaceName():
                    notes.append(f"{inp.getName()} is connected: its default is used")
                    continue
                value = inp.getValue()
                if value is None:
                    continue
                values[inp.getName()] = (
                    tuple(value.asTuple()) if hasattr(value, "asTuple") else value
                )
            params, more = params_from_values(values, f"{path}: {material.getName()}")
            out[material.getName()] = (params, notes + more)
    return out


def openpbr_preset(name: str, params: OpenPBRParams, description: str = "") -> dict[str, Any]:
    """A preset document of model ``openpbr`` holding ``params`` (non-default values)."""
    data = params.model_dump(exclude_defaults=True)
    data = {k: list(v) if isinstance(v, tuple) else v for k, v in data.items()}
    preset: dict[str, Any] = {"name": name, "model": "openpbr", "params": data}
    if description:
        preset["description"] = description
    return preset
