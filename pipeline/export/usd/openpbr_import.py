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

from .network import ExportError

__all__ = [
    "OPENPBR_IDS",
    "openpbr_preset",
    "params_from_values",
    "read_mtlx",
]

OPENPBR_IDS = ("ND_open_pbr_surface_surfaceshader",)
"""Shader ids read as OpenPBR Surface."""


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
