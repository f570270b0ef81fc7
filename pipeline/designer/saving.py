"""Saving a designer session through the library's own safe writes.

Two ways, as an artist expects them:

- **Save as new**: a preset that ``extends`` the one opened and writes only what the
  session changed (a reset override writes the value the parent chain gives, so the new
  preset looks like what was on screen). A new layered preset has no parent and is
  written whole.
- **Save**: over the file itself, if the library holding it is writable and the file has
  not changed on disk since the session opened it; otherwise the save says so.

Both go through :meth:`lookdev.library.Library.save` (atomic write, umask modes, no
write through a link out of the library, read-only and built-in libraries refused with
one line), which also checks that the preset resolves before writing it.
"""

from __future__ import annotations

import copy
import hashlib
import os
from pathlib import Path
from typing import Any

from lookdev.library import LibraryError
from lookdev.library.preset import build_preset, check_name
from lookdev.materials.layers import TextureMask
from lookdev.materials.textures import is_texture_input

__all__ = ["changes", "save_new", "save_over", "stamp"]

METADATA = ("description", "tags", "source", "textures", "height")


def stamp(path: Path | None) -> tuple[int, int, str] | None:
    """(mtime ns, size, SHA-256) of a file: what "changed on disk" compares."""
    if path is None:
        return None
    try:
        data = path.read_bytes()
        st = path.stat()
    except OSError:
        return None
    return st.st_mtime_ns, st.st_size, hashlib.sha256(data).hexdigest()


def changes(original: dict[str, Any], current: dict[str, Any], parent_values: dict) -> dict:
    """The document of a child of ``original`` that makes it ``current``: changed fields
    only (``parent_values``: what ``original``'s parent gives a field it stops setting)."""
    out: dict[str, Any] = {}
    for key in METADATA:
        if current.get(key) != original.get(key) and key in current:
            out[key] = current[key]
    before, after = original.get("params", {}), current.get("params", {})
    params = {}
    for key in dict.fromkeys([*before, *after]):
        if key in after and after[key] != before.get(key):
            params[key] = after[key]
        elif key not in after and key in parent_values:
            params[key] = parent_values[key]
    if params:
        out["params"] = params
    if current.get("layers") != original.get("layers") and current.get("layers"):
        out["layers"] = current["layers"]
    return out


def save_new(session: Any, name: str, folder: Path | None) -> Path:
    """Write the session as the new preset ``name``; returns its path."""
    check_name(name)
    library = session.library
    target = library.target(folder)
    if session.parent_name is None:  # a new layered preset: written whole
        doc = dict(copy.deepcopy(session.doc), name=name)
    else:
        layered = bool(session.doc.get("layers"))
        parent_values = {} if layered else session.base_params(None)[1]
        doc = {"name": name, "extends": session.parent_name}
        doc |= changes(session.original, session.doc, parent_values)
    doc = _moved(doc, session.base_folder(), target)
    preset = build_preset(doc, where=str(target / f"{name}.toml"))
    inside = Path(os.path.abspath(target))
    if any(Path(os.path.abspath(p)).is_relative_to(inside) for p in library.definitions(name)):
        raise LibraryError(
            f"preset {name!r} already exists in this library; choose another name",
            where=str(target),
        )
    return library.save(preset, folder=target)


def save_over(session: Any) -> Path:
    """Write the session over the file it came from; refused if that file changed."""
    path = session.path
    if path is None:
        raise LibraryError("this preset has no file yet; use 'Save as new'")
    if stamp(path) != session.stamp:
        raise LibraryError(
            "the file changed on disk since it was opened; not overwritten (save as new, "
            "or reopen it to see the other change)",
            where=str(path),
        )
    library = session.library
    plain = Path(os.path.abspath(path))
    root = next((f for f in library.user_folders if plain.is_relative_to(os.path.abspath(f))), None)
    if root is None:
        if library.builtin is not None and path.resolve().is_relative_to(library.builtin.resolve()):
            root = library.builtin  # Library.save refuses it with its own message
        else:
            root = path.parent
    preset = build_preset(session.doc, where=str(path))
    written = library.save(preset, folder=root, force=True)
    if Path(os.path.realpath(written)) != Path(os.path.realpath(path)):
        raise LibraryError(f"saved to {written}, not over {path}", where=str(root))
    return written


def _moved(doc: dict[str, Any], old: Path, new: Path) -> dict[str, Any]:
    """``doc`` with relative file paths rewritten for a preset written in ``new``."""
    if Path(os.path.abspath(old)) == Path(os.path.abspath(new)):
        return doc

    def move(p: str) -> str:
        if os.path.isabs(p):
            return p
        return Path(os.path.relpath(os.path.abspath(old / p), os.path.abspath(new))).as_posix()

    def walk(node: Any, key: str | None = None) -> Any:
        if isinstance(node, list):
            return [walk(n) for n in node]
        if not isinstance(node, dict):
            return node
        out = {k: walk(v, k) for k, v in node.items()}
        if is_texture_input(node) and isinstance(node.get("texture"), str):
            out["texture"] = move(node["texture"])
        if node.get("kind") == TextureMask.model_fields["kind"].default and "path" in node:
            out["path"] = move(node["path"])
        return out

    return walk(doc)
