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

Texture paths are relative to the preset file, so both rewrite each one for the folder
the file is written in. A picked file that would then lie outside the library (the
session's scratch folder, removed when the designer stops; the built-in folder; another
library) is copied beside the preset, with the library's atomic write, under a name no
other image there holds (an identical copy is reused); the save says what it copied.
"""

from __future__ import annotations

import copy
import hashlib
import os
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

from lookdev.library import LibraryError, store
from lookdev.library.files import WriteError, atomic_write_with
from lookdev.library.library import refuse_links_out
from lookdev.library.preset import build_preset, check_name
from lookdev.materials.layers import TextureMask
from lookdev.materials.textures import is_texture_input

__all__ = ["changes", "save_new", "save_over", "stamp"]

METADATA = ("description", "tags", "source", "textures", "height")
NORMAL_MAPS = ("normal_map", "specular_normal_map")


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


def save_new(session: Any, name: str, folder: Path | None) -> tuple[Path, list[str]]:
    """Write the session as the new preset ``name``; returns its path and what was copied
    into the library for it."""
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
    build_preset(doc, where=str(target / f"{name}.toml"))  # the schema's refusal first
    inside = Path(os.path.abspath(target))
    if any(Path(os.path.abspath(p)).is_relative_to(inside) for p in library.definitions(name)):
        raise LibraryError(
            f"preset {name!r} already exists in this library; choose another name",
            where=str(target),
        )
    root = _root_of(library, target)
    return _with_copies(
        library, doc, target, root, lambda d: library.save(_built(d, target, name), folder=target)
    )


def _built(doc: dict[str, Any], folder: Path, name: str):
    return build_preset(doc, where=str(folder / f"{name}.toml"))


def _root_of(library: Any, folder: Path) -> Path:
    """The user library folder holding ``folder`` (by its path as written), else itself."""
    plain = Path(os.path.abspath(folder))
    return next(
        (f for f in library.user_folders if plain.is_relative_to(os.path.abspath(f))), folder
    )


def _with_copies(
    library: Any,
    doc: dict[str, Any],
    folder: Path,
    root: Path,
    save: Callable[[dict[str, Any]], Path],
) -> tuple[Path, list[str]]:
    """``save(doc)`` with each file ``doc`` names outside ``root`` copied into ``folder``
    first; the copies made are removed again if the save fails."""
    builtin = library.builtin
    if builtin is not None and folder.resolve().is_relative_to(builtin.resolve()):
        return save(doc), []  # Library.save refuses it with its own line: nothing copied
    created: list[Path] = []
    messages: list[str] = []
    try:
        doc = _map_paths(doc, _copier(folder, root, created, messages))
        return save(doc), messages
    except BaseException:
        for path in created:
            path.unlink(missing_ok=True)
        raise


def _copier(folder: Path, root: Path, created: list[Path], messages: list[str]):
    """The path rewrite of :func:`_with_copies`: a relative path that leads out of ``root``
    (judged as written, as the library judges it when reading) becomes a copy's."""
    top = os.path.abspath(root)
    done: dict[Path, str] = {}

    def bring(written: str) -> str:
        if os.path.isabs(written):
            return written  # named by an absolute path on purpose: left alone
        lands = os.path.normpath(os.path.join(os.path.abspath(folder), written))
        source = Path(os.path.realpath(lands))
        if os.path.commonpath([top, lands]) == top or not source.is_file():
            return written
        if source not in done:
            dest = _free_name(folder, source)
            if not dest.exists():
                store.make_folder(folder)
                refuse_links_out(dest, root)
                try:
                    atomic_write_with(dest, lambda tmp: shutil.copyfile(source, tmp))
                except WriteError as exc:
                    raise LibraryError(exc.message, where=str(folder)) from None
                created.append(dest)
            done[source] = dest.name
            messages.append(f"copied {source.name} into the library as {dest.name}")
        return done[source]

    return bring


def _free_name(folder: Path, source: Path) -> Path:
    """``folder / source.name``, or ``NAME-2``, ``NAME-3``…: the first name free or holding
    the same bytes already."""
    data = source.read_bytes()
    for n in range(1, 10_000):
        name = source.name if n == 1 else f"{source.stem}-{n}{source.suffix}"
        dest = folder / name
        if not dest.exists() or (dest.is_file() and dest.read_bytes() == data):
            return dest
    raise LibraryError(f"no free name for a copy of {source.name}", where=str(folder))


def save_over(session: Any) -> tuple[Path, list[str]]:
    """Write the session over the file it came from; refused if that file changed.
    Returns the path and what was copied into the library for it."""
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
    root = _root_of(library, path.parent)
    build_preset(session.doc, where=str(path))  # the schema's refusal before any copy

    def save(doc: dict[str, Any]) -> Path:
        preset = build_preset(doc, where=str(path))
        written = library.save(preset, folder=root, force=True)
        if Path(os.path.realpath(written)) != Path(os.path.realpath(path)):
            raise LibraryError(f"saved to {written}, not over {path}", where=str(root))
        return written

    return _with_copies(library, session.doc, path.parent, root, save)


def _moved(doc: dict[str, Any], old: Path, new: Path) -> dict[str, Any]:
    """``doc`` with relative file paths rewritten for a preset written in ``new``."""
    if Path(os.path.abspath(old)) == Path(os.path.abspath(new)):
        return doc

    def move(p: str) -> str:
        if os.path.isabs(p):
            return p
        return Path(os.path.relpath(os.path.abspath(old / p), os.path.abspath(new))).as_posix()

    return _map_paths(doc, move)


def _map_paths(doc: dict[str, Any], fn: Callable[[str], str]) -> dict[str, Any]:
    """A copy of ``doc`` with every texture file path ``p`` it names replaced by ``fn(p)``:
    texture inputs (parameters, height), texture masks and normal maps, the texture set."""
    texture_kind = TextureMask.model_fields["kind"].default

    def walk(node: Any, key: str | None = None) -> Any:
        if isinstance(node, list):
            return [walk(n) for n in node]
        if not isinstance(node, dict):
            return node
        out = {k: walk(v, k) for k, v in node.items()}
        if is_texture_input(node) and isinstance(node.get("texture"), str):
            out["texture"] = fn(node["texture"])
        masked = node.get("kind") == texture_kind or key in NORMAL_MAPS
        if masked and isinstance(node.get("path"), str):
            out["path"] = fn(node["path"])
        return out

    out = walk(doc)
    if isinstance(doc.get("textures"), str):
        out["textures"] = fn(doc["textures"])
    return out
