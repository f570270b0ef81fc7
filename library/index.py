"""Fast listing of a library folder: preset headers, kept in an mtime-keyed index.

``presets list`` needs each preset's name, model, description and tags, not its
parameters. Each folder keeps ``.lookdev-index.json``: for every preset file its
``(mtime_ns, size, inode)`` and its header. A listing stats the files (one ``scandir``
per folder) and re-reads only those whose stat changed, so over an unchanged library it
costs a directory walk and one small JSON read instead of opening every file.

A file changed twice within the filesystem's timestamp granularity could keep its stat;
as in git's "racy" check, headers of files modified less than :data:`RACY_S` before the
index is written are not stored, so they are re-read until they settle. The index is a
cache: it is rewritten atomically, silently skipped where the folder is read-only, and
deleting it is always safe.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from lookdev.materials.errors import LookdevError

from .errors import PresetError
from .preset import MODELS, NAME_RE, parse_toml

INDEX_NAME = ".lookdev-index.json"
INDEX_VERSION = 1
RACY_S = 2.0
SUFFIX = ".toml"


@dataclass(frozen=True)
class Header:
    """What ``presets list`` shows of one preset file (model may be inherited: None)."""

    name: str
    path: Path
    model: str | None = None
    description: str = ""
    tags: tuple[str, ...] = ()
    extends: str | None = None
    error: str | None = None  # set when the file cannot be read as a preset

    def row(self) -> list[Any]:
        return [self.model, self.description, list(self.tags), self.extends, self.error]


@dataclass(frozen=True)
class _Stat:
    key: list[int]  # (mtime_ns, size, inode): a changed file changes it
    path: Path
    rel: str
    mtime_ns: int


def scan_folder(folder: Path, *, cache: bool = True, skip: tuple[str, ...] = ()) -> list[Header]:
    """Headers of every preset file under ``folder``, sorted by relative path.

    Hidden files and folders (``.name``) are skipped: they are temporaries and caches.
    ``cache=False`` neither reads nor writes the index (the built-in library, which is
    small and must not grow files inside a checkout or an installed package). ``skip``
    names top-level sub-folders that hold other data (the built-in ``ibl/``).
    """
    stats = _walk(folder, skip)
    cached = _read_index(folder) if cache else {}
    headers, fresh, misses = [], {}, 0
    for s in stats:
        header = _from_row(s, cached.get(s.rel))
        if header is None:
            header, misses = read_header(s.path), misses + 1
        headers.append(header)
        fresh[s.rel] = [s.key, header.row()]
    if cache and (misses or len(cached) != len(fresh)):
        _write_index(folder, stats, fresh)
    return headers


def read_header(path: Path) -> Header:
    """The header of one preset file; a file that is not a preset gets ``error`` set."""
    name = path.name[: -len(SUFFIX)]
    try:
        doc = parse_toml(_header_bytes(path), where=str(path))
        return _header_from_doc(doc, name, path)
    except (LookdevError, OSError) as exc:
        return Header(name=name, path=path, error=str(exc))


def _header_bytes(path: Path) -> bytes:
    """The top-level key/values of a preset: everything before the first table header.

    If the cut lands inside a multi-line string or array the prefix is not valid TOML,
    and the whole file is used instead.
    """
    data = path.read_bytes()
    cut = data.find(b"\n[")
    if cut < 0:
        return data
    head = data[: cut + 1]
    try:
        parse_toml(head, where=str(path))
    except PresetError:
        return data
    return head


def _header_from_doc(doc: dict[str, Any], name: str, path: Path) -> Header:
    where = str(path)
    got = {k: doc.get(k) for k in ("name", "model", "description", "tags", "extends")}
    if got["name"] != name:
        raise PresetError(f"name {got['name']!r} differs from the file name", where=where)
    if got["model"] is not None and got["model"] not in (*MODELS, "layered"):
        raise PresetError(f"unknown model {got['model']!r}", where=where, field="model")
    if got["model"] is None and not isinstance(got["extends"], str):
        raise PresetError("'model' is required unless 'extends' is given", where=where)
    if got["extends"] is not None and not (
        isinstance(got["extends"], str) and NAME_RE.match(got["extends"])
    ):
        raise PresetError("'extends' is not a preset name", where=where, field="extends")
    tags = got["tags"] or []
    if not isinstance(tags, list) or not all(isinstance(t, str) for t in tags):
        raise PresetError("'tags' must be a list of strings", where=where, field="tags")
    description = got["description"] or ""
    if not isinstance(description, str):
        raise PresetError("'description' must be a string", where=where, field="description")
    return Header(name, path, got["model"], description, tuple(tags), got["extends"])


def _walk(folder: Path, skip: tuple[str, ...] = ()) -> list[_Stat]:
    out: list[_Stat] = []
    stack = [(folder, "")]
    while stack:
        here, prefix = stack.pop()
        with os.scandir(here) as it:
            for e in it:
                if e.name.startswith(".") or (not prefix and e.name in skip):
                    continue
                if e.is_dir():
                    stack.append((Path(e.path), f"{prefix}{e.name}/"))
                elif e.name.endswith(SUFFIX):
                    st = e.stat()
                    key = [st.st_mtime_ns, st.st_size, st.st_ino]
                    out.append(_Stat(key, Path(e.path), prefix + e.name, st.st_mtime_ns))
    out.sort(key=lambda s: s.rel)
    return out


def _from_row(s: _Stat, entry: Any) -> Header | None:
    """The cached header if the index has one for this exact stat, else None."""
    try:
        key, (model, description, tags, extends, error) = entry
    except (TypeError, ValueError):
        return None
    if key != s.key or not isinstance(tags, list):
        return None
    name = s.path.name[: -len(SUFFIX)]
    return Header(name, s.path, model, description, tuple(tags), extends, error)


def _read_index(folder: Path) -> dict[str, Any]:
    try:
        doc = json.loads((folder / INDEX_NAME).read_bytes())
    except (OSError, ValueError):
        return {}
    if not isinstance(doc, dict) or doc.get("version") != INDEX_VERSION:
        return {}
    entries = doc.get("entries")
    return entries if isinstance(entries, dict) else {}


def _write_index(folder: Path, stats: list[_Stat], fresh: dict[str, Any]) -> None:
    settled = time.time_ns() - int(RACY_S * 1e9)
    entries = {s.rel: fresh[s.rel] for s in stats if s.mtime_ns < settled}
    data = json.dumps({"version": INDEX_VERSION, "entries": entries}, separators=(",", ":"))
    tmp = folder / f"{INDEX_NAME}.{os.getpid()}.tmp"
    try:
        tmp.write_text(data, encoding="utf-8")
        os.replace(tmp, folder / INDEX_NAME)
    except OSError:
        # A read-only library (an installed wheel, a shared mount) just lists uncached.
        tmp.unlink(missing_ok=True)
