"""The edits the page may ask for, applied to a copy of a preset document.

Each edit is a small JSON object, ``{"op": "set", "target": null, "field": "roughness",
"value": 0.3}``; :func:`apply` returns the changed document and the session validates it
before anything is applied (:meth:`.session.Session.edit`). ``target`` is ``null`` for
the preset's own parameters or a layer's index. Files (a texture, a mask image) are named
as ``{"root": ..., "path": ...}`` and resolved by the server's :class:`~.guard.Roots`, so
no edit can point a preset at a file outside the library path and the session's folders.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from lookdev.library.containment import texture_references
from lookdev.library.preset import build_preset, check_name
from lookdev.materials.errors import LookdevError

from .guard import PathRefused

__all__ = ["OPS", "EditRefused", "apply", "check_new_files", "file_refs"]

OPS = (
    "set",
    "reset",
    "meta",
    "layer_add",
    "layer_remove",
    "layer_move",
    "layer_mask",
    "layer_presence",
)
META_FIELDS = ("description", "tags")


class EditRefused(LookdevError):
    """An edit the schema (or the resolver) refuses: nothing was applied."""


def apply(doc: dict[str, Any], op: dict[str, Any], session: Any) -> dict[str, Any]:
    """``doc`` with the edit ``op`` made (``doc`` is the caller's copy)."""
    kind = op.get("op")
    if kind not in OPS:
        raise EditRefused(f"unknown edit {kind!r}; allowed: {', '.join(OPS)}")
    base = session.base_folder()
    if kind in ("set", "reset"):
        params = _params_of(doc, op.get("target"))
        field = op.get("field")
        if not isinstance(field, str) or not field:
            raise EditRefused("an edit names the parameter it changes ('field')")
        if kind == "reset":
            params.pop(field, None)
        else:
            params[field] = file_refs(op.get("value"), session, base)
    elif kind == "meta":
        if op.get("field") not in META_FIELDS:
            raise EditRefused(f"only {', '.join(META_FIELDS)} may be edited here")
        doc[op["field"]] = op.get("value")
    elif kind == "layer_add":
        _to_layered(doc)
        name = op.get("preset")
        check_name(name, field="preset")
        layer: dict[str, Any] = {"name": op.get("name") or name, "preset": name}
        if op.get("mask") is not None:
            layer["mask"] = file_refs(op["mask"], session, base)
        doc["layers"].append(layer)
    else:
        layers = doc.get("layers") or []
        index = op.get("index")
        if not isinstance(index, int) or not 0 <= index < len(layers):
            raise EditRefused(f"no layer {index!r}; the stack has {len(layers)}")
        if kind == "layer_remove":
            if len(layers) == 1:
                raise EditRefused("a layered preset keeps at least one layer")
            layers.pop(index)
        elif kind == "layer_move":
            to = op.get("to")
            if not isinstance(to, int) or not 0 <= to < len(layers):
                raise EditRefused(f"cannot move a layer to {to!r}")
            layers.insert(to, layers.pop(index))
        elif kind == "layer_mask":
            mask = op.get("mask")
            if mask is None:
                layers[index].pop("mask", None)
            else:
                layers[index]["mask"] = file_refs(mask, session, base)
        else:
            layers[index]["presence"] = op.get("value")
    return doc


def _params_of(doc: dict[str, Any], target: Any) -> dict[str, Any]:
    if target is None:
        if doc.get("model") == "layered" or doc.get("layers"):
            raise EditRefused("a layered preset has no parameters of its own; pick a layer")
        return doc.setdefault("params", {})
    layers = doc.get("layers") or []
    if not isinstance(target, int) or not 0 <= target < len(layers):
        raise EditRefused(f"no layer {target!r}; the stack has {len(layers)}")
    return layers[target].setdefault("params", {})


def _to_layered(doc: dict[str, Any]) -> None:
    if doc.get("layers") or doc.get("model") == "layered":
        doc.setdefault("layers", [])
        return
    raise EditRefused("layers go into a layered preset: start one with 'New layered'")


def file_refs(value: Any, session: Any, base: Path) -> Any:
    """``value`` with each ``{"root", "path"}`` file reference made a path relative to
    ``base`` (the folder the preset is written in), as preset files write them."""
    if isinstance(value, list):
        return [file_refs(v, session, base) for v in value]
    if not isinstance(value, dict):
        return value
    if set(value) == {"root", "path"}:
        real = session.roots.resolve(value["root"], value["path"])
        return Path(os.path.relpath(real, base)).as_posix()
    return {k: file_refs(v, session, base) for k, v in value.items()}


def check_new_files(old: dict[str, Any], new: dict[str, Any], session: Any) -> None:
    """Refuse a file ``new`` names as a plain path that ``old`` did not name and that lies
    outside the session's folders: a path typed by hand reaches no further than one picked
    by ``{"root", "path"}``. Checked before the schema's check opens any file; a document
    the schema refuses is left to it."""
    if session.roots is None:
        return
    try:
        given = list(texture_references(build_preset(new, where="designer")))
    except LookdevError:
        return  # refused by the schema next, before a file is read
    known = {w for _, w in texture_references(build_preset(old, where="designer"))}
    base = session.base_folder()
    for field, written in given:
        if written not in known and session.roots.locate(base / written) is None:
            raise PathRefused(f"{field}: {written!r} lies outside the library folders")
