"""Fast listing of a library folder: preset headers, kept in an mtime-keyed index.

``presets list`` needs each preset's name, model, description and tags, not its
parameters. Each folder keeps ``.lookdev-index.json``: for every preset file its
``(mtime_ns, size, inode)`` and its header. A listing stats the files (one ``scandir``
per folder) and re-reads only those whose stat changed, so over an unchanged library it
costs a directory walk and one JSON read instead of opening every file.

A file changed twice within the filesystem's timestamp granularity could keep its stat;
as in git's "racy" check, headers of files modified less than :data:`RACY_S` before the
index is written are not stored, so they are re-read until they settle. The index is a
cache: it is rewritten atomically; a folder that cannot be written keeps its cache under
``$LOOKDEV_CACHE/index/`` instead (:func:`index_file`); deleting it is always safe.
"""

from __future__ import annotations

import contextlib
import errno
import json
import os
import re
import stat
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any, NamedTuple

from lookdev.materials.errors import LookdevError
from lookdev.materials.model_names import PRESET_MODELS

from . import files
from .errors import PresetError
from .toml_file import NAME_RE, parse_toml

__all__ = [
    "Header",
    "find_file",
    "INDEX_NAME",
    "INDEX_VERSION",
    "RACY_S",
    "SUFFIX",
    "index_file",
    "read_header",
    "read_only_index_file",
    "scan_folder",
    "simple_header",
    "warn",
]

INDEX_NAME = ".lookdev-index.json"
INDEX_VERSION = 3
RACY_S = 2.0
SUFFIX = ".toml"


class Header(NamedTuple):
    """What ``presets list`` shows of one preset file (``model`` None: inherited).

    A tuple of plain strings, not of ``Path`` objects: a listing builds tens of thousands.
    """

    name: str
    file: str  # the preset file
    library: str  # the library folder it was found in
    model: str | None = None
    description: str = ""
    tags: tuple[str, ...] = ()
    extends: str | None = None
    error: str | None = None  # set when the file cannot be read as a preset

    @property
    def path(self) -> Path:
        return Path(self.file)

    def to_json(self, library: str | None = None) -> dict[str, Any]:
        """What ``presets list --json`` prints of it; ``library`` names where it was found
        (default: its folder)."""
        return {
            "name": self.name,
            "model": self.model,
            "description": self.description,
            "tags": list(self.tags),
            "extends": self.extends,
            "file": self.file,
            "library": self.library if library is None else library,
        }


def scan_folder(folder: Path, *, cache: bool = True, skip: tuple[str, ...] = ()) -> list[Header]:
    """Headers of every preset file under ``folder``: shallowest first, then by path.

    Hidden files and folders (``.name``) are skipped: they are temporaries and caches.
    ``cache=False`` neither reads nor writes the index (the built-in library, which is
    small and must not grow files inside a checkout or an installed package). ``skip``
    names top-level sub-folders that hold other data (the built-in ``ibl/``).
    """
    root = os.fspath(folder)
    found = _walk(root, skip)
    cached = _read_index(folder) if cache else {}
    headers, misses, sep = [], 0, os.sep
    for rel, mtime, size, ino in found:
        e = cached.get(rel)
        try:
            if e[1] != mtime or e[2] != size or e[3] != ino or not _well_typed(e):
                raise LookupError("changed")
            header = Header(e[4], f"{root}{sep}{rel}", root, e[5], e[6], tuple(e[7]), e[8], e[9])
        except (LookupError, TypeError):  # not indexed, changed, or a malformed entry
            header, misses = read_header(f"{root}{sep}{rel}", library=root), misses + 1
        headers.append(header)
    if cache and (misses or len(cached) != len(found)):
        _write_index(folder, found, headers)
    return headers


def find_file(folder: Path, name: str, *, skip: tuple[str, ...] = ()) -> str | None:
    """The file :func:`scan_folder` would give first for the preset ``name`` (a header's
    name is its file's), found from the folder listing alone: no preset file is read, so
    finding one preset in a folder of hundreds costs their stats, not their headers."""
    root, target = os.fspath(folder), name + SUFFIX
    for rel, *_ in _walk(root, skip):
        if os.path.basename(rel) == target:
            return f"{root}{os.sep}{rel}"
    return None


def read_header(path: str | Path, *, library: str | None = None) -> Header:
    """The header of one preset file; a file that is not a preset gets ``error`` set."""
    file = os.fspath(path)  # plain strings: a first listing reads thousands
    name = os.path.basename(file)[: -len(SUFFIX)]
    library = os.path.dirname(file) if library is None else library
    try:
        doc = _header_doc(file)
        return Header(name, file, library, *_header_fields(doc, name, file))
    except (LookdevError, OSError) as exc:
        return Header(name, file, library, error=str(exc))


def _header_doc(file: str) -> dict[str, Any]:
    """The top-level key/values of a preset, parsed from what precedes its first table.

    Plain header lines take a fast path (:func:`simple_header`). If the cut lands inside
    a multi-line string or array the prefix is not valid TOML, and the whole file is
    parsed instead (so its errors are the file's own).
    """
    with open(file, "rb") as f:
        data = f.read()
    cut = data.find(b"\n[")
    head = data if cut < 0 else data[: cut + 1]
    try:
        doc = simple_header(head.decode("utf-8").removeprefix("\ufeff"))
    except UnicodeDecodeError:
        doc = None
    if doc is not None:
        return doc
    if cut >= 0:
        try:
            return parse_toml(head, where=file)
        except PresetError:
            pass
    return parse_toml(data, where=file)


_TEXT = r"[^\x00-\x08\x0a-\x1f\x7f{q}]*"  # TOML forbids control characters but tab
_BASIC = _TEXT.format(q='"\\\\')  # inside "…", without escapes: those go the slow way
_LITERAL = _TEXT.format(q="'")  # inside '…'
_ARRAY = rf'(?:[ \t]*"{_BASIC}"[ \t]*,)*[ \t]*(?:"{_BASIC}"[ \t]*)?'  # ["a", "b",]
_LINE = re.compile(
    r"[ \t]*(?:(?P<key>name|model|description|source|extends|tags)[ \t]*=[ \t]*"
    rf"""(?:"(?P<basic>{_BASIC})"|'(?P<literal>{_LITERAL})'|\[(?P<array>{_ARRAY})\]))?"""
    rf"[ \t]*(?:#{_TEXT.format(q='')})?"
)
_ITEM = re.compile(f'"({_BASIC})"')


def simple_header(text: str) -> dict[str, Any] | None:
    r"""The header keys of ``text`` if every line is plain, else None (use tomllib).

    Plain: blank lines, comments, and ``key = "string"`` / ``'string'`` / ``["a", "b"]``
    for the header keys, strings without escapes. On those, the result equals
    ``tomllib.loads(text)`` (a property test checks it); about ten times faster, which
    is what makes a library's first listing cheap.

    >>> simple_header('name = "gold"  # comment\ntags = ["metal", "polished"]\n')
    {'name': 'gold', 'tags': ['metal', 'polished']}
    >>> simple_header('name = "g\\u00f6ld"\n') is None
    True
    """
    doc: dict[str, Any] = {}
    for line in text.split("\n"):
        m = _LINE.fullmatch(line)
        if m is None or m["key"] in doc:  # not plain, or a duplicate for tomllib to report
            return None
        if m["key"] is None:
            continue
        if m["array"] is not None:
            doc[m["key"]] = _ITEM.findall(m["array"])
        else:
            doc[m["key"]] = m["basic"] if m["basic"] is not None else m["literal"]
    return doc


def _header_fields(doc: dict[str, Any], name: str, where: str) -> tuple:
    """(model, description, tags, extends) of a parsed preset, checked just enough to list."""
    got = {k: doc.get(k) for k in ("name", "model", "description", "tags", "extends")}
    if not doc:
        raise PresetError("empty preset file: it needs at least name and model", where=where)
    if got["name"] is None:
        raise PresetError(f"no name; add name = {name!r}", where=where, field="name")
    if got["name"] != name or not NAME_RE.fullmatch(name):
        raise PresetError(f"name {got['name']!r} differs from the file name", where=where)
    if got["model"] is not None and got["model"] not in (*PRESET_MODELS, "layered"):
        raise PresetError(f"unknown model {got['model']!r}", where=where, field="model")
    if got["model"] is None and not isinstance(got["extends"], str):
        raise PresetError("'model' is required unless 'extends' is given", where=where)
    if got["extends"] is not None and not (
        isinstance(got["extends"], str) and NAME_RE.fullmatch(got["extends"])
    ):
        raise PresetError("'extends' is not a preset name", where=where, field="extends")
    tags = got["tags"] or []
    if not isinstance(tags, list) or not all(isinstance(t, str) for t in tags):
        raise PresetError("'tags' must be a list of strings", where=where, field="tags")
    description = got["description"] or ""
    if not isinstance(description, str):
        raise PresetError("'description' must be a string", where=where, field="description")
    return got["model"], description, tuple(tags), got["extends"]


def _walk(root: str, skip: tuple[str, ...] = ()) -> list[tuple[str, int, int, int]]:
    """``(relative path, mtime_ns, size, inode)`` of every visible preset file, sorted.

    Each folder is scanned through a descriptor, so a stat is an ``fstatat`` relative
    to it rather than a walk of the whole path (a third cheaper on Linux). Reads follow
    symlinks; a link that dangles, loops (``loopdir -> ..``) or leads to a folder already
    walked is skipped with a one-line warning on stderr (:func:`warn`).
    """
    out: list[tuple[str, int, int, int]] = []
    top = os.stat(root)
    seen = {(top.st_dev, top.st_ino)}
    stack = [(root, "")]
    while stack:
        here, prefix = stack.pop()
        with _scandir(here) as it:
            for e in it:
                name = e.name
                if name.startswith(".") or (not prefix and name in skip):
                    continue
                is_preset = name.endswith(SUFFIX)
                if e.is_symlink():
                    st = _link_stat(os.path.join(here, name), is_preset)
                    if st is None:
                        continue
                    if stat.S_ISDIR(st.st_mode):
                        key = (st.st_dev, st.st_ino)
                        if key in seen:
                            warn(
                                f"{os.path.join(here, name)}: skipped: a symlink loop "
                                f"(-> {os.readlink(os.path.join(here, name))})"
                            )
                            continue
                        seen.add(key)
                        stack.append((os.path.join(here, name), f"{prefix}{name}/"))
                    elif is_preset and stat.S_ISREG(st.st_mode):
                        out.append((prefix + name, st.st_mtime_ns, st.st_size, st.st_ino))
                elif is_preset and e.is_file(follow_symlinks=False):
                    st = e.stat()
                    out.append((prefix + name, st.st_mtime_ns, st.st_size, st.st_ino))
                elif e.is_dir(follow_symlinks=False):
                    st = e.stat(follow_symlinks=False)
                    seen.add((st.st_dev, st.st_ino))
                    stack.append((os.path.join(here, name), f"{prefix}{name}/"))
    out.sort(key=lambda f: (f[0].count("/"), f[0]))  # shallowest first: it wins a name
    return out


def _link_stat(path: str, is_preset: bool) -> os.stat_result | None:
    """What a symlink leads to, or None (with a warning) when it dangles or loops."""
    try:
        return os.stat(path)
    except OSError as exc:
        try:
            target = os.readlink(path)
        except OSError:
            target = "?"
        if is_preset or exc.errno == errno.ELOOP:
            what = "a symlink loop" if exc.errno == errno.ELOOP else "a dangling symlink"
            warn(f"{path}: skipped: {what} (-> {target})")
        return None


_warned: set[str] = set()
_held: list[list[str]] = []


def warn(message: str) -> None:
    """One line on stderr, ``lookdev: warning: …``, once per message and process (inside
    :func:`held_warnings`, when it ends)."""
    if message in _warned:
        return
    if _held:
        if message not in _held[-1]:
            _held[-1].append(message)
        return
    _warned.add(message)
    with contextlib.suppress(OSError, ValueError):
        sys.stderr.write(f"lookdev: warning: {message}\n")
        sys.stderr.flush()


@contextlib.contextmanager
def held_warnings() -> Iterator[None]:
    """Hold the warnings given inside until it ends: printed when it ends normally,
    dropped when it ends in an error, whose one line is then all that is printed (bad
    input is one line; a warning about a map comes back on the run after the error is
    fixed). Nested holds pass theirs to the outer one."""
    _held.append([])
    try:
        yield
    except BaseException:
        _held.pop()
        raise
    for message in _held.pop():
        warn(message)


@contextlib.contextmanager
def _scandir(folder: str) -> Iterator[Iterator[os.DirEntry]]:
    if os.scandir not in os.supports_fd:  # Windows
        with os.scandir(folder) as it:
            yield it
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        with os.scandir(fd) as it:
            yield it
    finally:
        os.close(fd)


_TEXT_OR_NONE = (str, type(None))


def _well_typed(e: list[Any]) -> bool:
    """An index row that is safe to show: a damaged or hand-edited index must not crash."""
    return (
        len(e) == 10
        and type(e[4]) is str
        and type(e[6]) is str
        and isinstance(e[5], _TEXT_OR_NONE)
        and isinstance(e[8], _TEXT_OR_NONE)
        and isinstance(e[9], _TEXT_OR_NONE)
        and type(e[7]) is list
        and all(type(t) is str for t in e[7])
    )


def index_file(folder: Path) -> Path:
    """Where ``folder``'s header cache lives: inside it, or under ``$LOOKDEV_CACHE``.

    A library that cannot be written (a read-only mount, a shared folder without write
    permission) is used read-only: its cache goes to ``$LOOKDEV_CACHE/index/``, keyed by the
    folder's real path, so every user and every link to it share one entry per machine.
    """
    if os.access(folder, os.W_OK | os.X_OK):
        return folder / INDEX_NAME
    return read_only_index_file(folder)


def read_only_index_file(folder: Path) -> Path:
    import hashlib  # only for a read-only library: a writable one keeps its index inside

    key = hashlib.sha256(os.fsencode(os.path.realpath(folder))).hexdigest()[:32]
    return files.cache_root() / "index" / f"{key}.json"


def _read_index(folder: Path) -> dict[str, list[Any]]:
    """``{relative path: [path, mtime_ns, size, inode, *header]}`` from the index, or ``{}``."""
    try:
        doc = json.loads(index_file(folder).read_bytes())
        if doc.get("version") != INDEX_VERSION:
            return {}
        return {e[0]: e for e in doc["entries"]}
    except (OSError, ValueError, TypeError, LookupError, AttributeError):
        return {}


def _write_index(folder: Path, found: list[tuple], headers: list[Header]) -> None:
    """Store the stats and headers of settled files, one flat list per file."""
    settled = time.time_ns() - int(RACY_S * 1e9)
    entries = [
        [*st, h.name, h.model, h.description, list(h.tags), h.extends, h.error]
        for st, h in zip(found, headers, strict=True)
        if st[1] < settled
    ]
    data = json.dumps({"version": INDEX_VERSION, "entries": entries}, separators=(",", ":"))
    target = index_file(folder)
    try:
        if target.parent != folder:
            target.parent.mkdir(parents=True, exist_ok=True)
        files.atomic_write(target, data)
        return
    except (files.WriteError, OSError):
        pass  # root on a chmod-0555 folder passes os.access, a read-only mount does not
    # The folder refused: the library is read-only, so the cache goes under $LOOKDEV_CACHE.
    with contextlib.suppress(files.WriteError, OSError):
        cached = read_only_index_file(folder)
        if cached != target:
            cached.parent.mkdir(parents=True, exist_ok=True)
            files.atomic_write(cached, data)
