"""The preset an export came from, carried in the Material's ``customData`` so that
``lookdev import usd`` gives it back exactly (every lookdev export round-trips).

The networks say what each renderer can express; this record says what the preset *was*:
its model, description, tags, citation and the parameters it gave (a plain preset, after
``extends`` is resolved) or its layer document as the file wrote it (a layered preset:
the layers name their presets and mask files as the file did). It is a JSON string under
``customData["lookdev"]["record"]``: USD keeps a string exactly, floats included.

A record is only trusted while the networks are the ones exported with it: beside it the
Material carries :func:`network_digest` of its networks, and an import whose networks
hash differently (someone edited the file in a DCC) reads the networks instead.
"""

from __future__ import annotations

import hashlib
import json
import struct
import tomllib
from pathlib import Path
from typing import Any

__all__ = ["RECORD_KEY", "network_digest", "preset_record", "read_record"]

RECORD_KEY = "record"


def preset_record(hub: Any) -> str:
    """The JSON record of the blended material ``hub`` (``""`` when nothing is known)."""
    origin = getattr(hub, "origin", None)
    doc: dict[str, Any] = {"name": hub.name}
    if getattr(hub, "layered", False):
        path = getattr(origin, "source", None)
        if path is None or not Path(path).is_file():
            return ""
        doc = tomllib.loads(Path(path).read_text(encoding="utf-8"))
        if not doc.get("layers"):  # inherited through `extends`: the file alone is not it
            return ""
        doc["name"] = hub.name
        doc.pop("extends", None)  # its own layers replace the parent's whole (library rules)
        return json.dumps(doc, sort_keys=True)
    params = getattr(origin, "params", None)
    if params is None:
        params = hub.params
    doc["model"] = hub.model
    doc["params"] = _preset_space(
        type(params), params.model_dump(mode="json", exclude_unset=True, exclude_none=True)
    )
    for key, value in (
        ("description", hub.description or getattr(origin, "description", "")),
        ("tags", list(getattr(origin, "tags", []) or [])),
        ("source", getattr(origin, "citation", None)),
    ):
        if value:
            doc[key] = value
    return json.dumps(doc, sort_keys=True)


def _preset_space(params_type: type, values: dict[str, Any]) -> dict[str, Any]:
    """Colours from the working space (where loaded presets hold them) back to the space a
    preset's ``[r, g, b]`` is written in, so the record reads as the preset file does."""
    from lookdev.materials import colour
    from lookdev.materials.registry import is_color_field

    source = colour.working_space()
    if colour.canonical(source) == colour.canonical(colour.PRESET_LINEAR):
        return values
    out = dict(values)
    for key, value in values.items():
        if key in params_type.model_fields and is_color_field(params_type, key):
            converted = colour.convert(tuple(value), source, colour.PRESET_LINEAR)
            out[key] = [float(c) for c in converted]
    return out


def read_record(custom: dict[str, Any]) -> dict[str, Any] | None:
    """The preset document a lookdev export carried, or None (another tool's file)."""
    text = custom.get(RECORD_KEY)
    if not isinstance(text, str) or not text:
        return None
    try:
        doc = json.loads(text)
    except ValueError:
        return None
    return doc if isinstance(doc, dict) and "name" in doc else None


def network_digest(networks: list[Any]) -> str:
    """SHA-256 of what renderers read of ``networks`` (:class:`~.network.Network`): each
    node's id and inputs, values as USD stores them (float32), asset paths left out (they
    move with the file), connections by node and output. The same for the networks an
    export authors and for those read back from its file."""
    from .network import Connection, Image, plain_value

    def plain(value: Any) -> Any:
        value = plain_value(value)  # an interface input: the value it holds
        if isinstance(value, Connection):
            return f"->{value.node}.{value.output}"
        if isinstance(value, Image) or hasattr(value, "resolvedPath"):
            return "asset"
        if isinstance(value, bool):
            return int(value)
        if isinstance(value, float):
            return repr(struct.unpack("f", struct.pack("f", value))[0])
        if isinstance(value, tuple | list):
            return [plain(v) for v in value]
        return value if isinstance(value, int | str) else str(value)

    rows = []
    for net in networks:
        terminal = f"{net.terminal.node}.{net.terminal.output}"
        by_name = {n.name: n for n in net.nodes}
        todo, seen = [net.terminal.node], set()
        while todo:  # the nodes the surface reads (what an import collects), once each
            name = todo.pop()
            node = by_name.get(name)
            if node is None or name in seen:
                continue
            seen.add(name)
            inputs = sorted((k, plain(v)) for k, (_, v) in node.inputs.items())
            rows.append([net.context, terminal, node.name, node.id, inputs])
            todo += [v.node for _, v in node.inputs.values() if isinstance(v, Connection)]
    text = json.dumps(sorted(rows, key=lambda r: (r[0], r[2])), sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()
