"""Preset libraries: a search path of folders, lookup with "did you mean", safe edits.

The search path is, in order: the folders given to :class:`Library` (``--library``),
then those in ``LOOKDEV_LIBRARY_PATH`` (``os.pathsep``-separated), then the built-in
``presets/``. A name defined in several folders resolves to the first; the others are
shadowed (``lookdev presets show`` names them). Presets are ``NAME.toml`` files anywhere
below a folder; hidden files and folders are ignored.

Writes go to one user folder (the first on the path unless another is named) and never
to the built-in library; see :mod:`lookdev.library.store` for how they stay safe.
"""

from __future__ import annotations

import os
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import lookdev.presets
from lookdev.materials.errors import LookdevError

from . import store
from .errors import LibraryError, PresetError, PresetNotFoundError, did_you_mean
from .index import SUFFIX, Header, find_file, scan_folder
from .toml_file import check_name

if TYPE_CHECKING:
    from .material import Material
    from .preset import PresetFile

__all__ = [
    "BUILTIN_OTHER_DATA",
    "ENV_PATH",
    "Library",
    "apply_changes",
    "builtin_folder",
    "links_on_the_way",
    "load_material",
    "read_preset",
    "refuse_links_out",
]

# The schemas (.preset) and materials (.material) bring pydantic and the models: they are
# imported where a preset is parsed, so listing headers (`presets list`) needs neither.

ENV_PATH = "LOOKDEV_LIBRARY_PATH"
BUILTIN_OTHER_DATA = ("ibl", "measured")
"""Sub-folders of the built-in ``presets/`` that hold other data, not material presets."""


def builtin_folder() -> Path:
    """The built-in ``presets/`` folder, from a checkout or an installed wheel."""
    for entry in lookdev.presets.__path__:
        if Path(entry).is_dir():
            return Path(entry)
    raise LibraryError("the built-in presets folder is missing from this installation")


def read_preset(path: Path) -> PresetFile:
    """Parse one preset file (:func:`.preset.read_preset`, imported when first needed)."""
    from .preset import read_preset as read

    return read(path)


class Library:
    """The preset search path: user folders first, the built-in library last."""

    def __init__(
        self,
        paths: Iterable[str | Path] | None = None,
        *,
        use_env: bool = True,
        builtin: bool = True,
    ):
        user = [Path(p).expanduser() for p in paths or ()]
        if use_env:
            user += [
                Path(p).expanduser() for p in os.environ.get(ENV_PATH, "").split(os.pathsep) if p
            ]
        self.builtin = builtin_folder() if builtin else None
        builtin_key = self.builtin.resolve() if self.builtin else None
        self.user_folders: list[Path] = [
            f for f in dict.fromkeys(user) if not builtin_key or f.resolve() != builtin_key
        ]
        self.builtin_str = str(self.builtin) if builtin else None
        self.folders = [*self.user_folders, *([self.builtin] if self.builtin else [])]
        self._builtin_headers: list[Header] | None = None

    # -- reading -----------------------------------------------------------------------

    def headers(self) -> list[Header]:
        """Every preset file on the path, in search order (shadowed ones included)."""
        out: list[Header] = []
        for folder in self.folders:
            if not folder.is_dir():
                what = "is a file, not a folder" if folder.exists() else "does not exist"
                raise LibraryError(f"library folder {what}", where=str(folder))
            try:
                out += self._scan(folder)
            except OSError as exc:
                raise LibraryError(
                    f"cannot read ({exc.strerror or exc})", where=str(folder)
                ) from None
        return out

    def entries(self) -> list[Header]:
        """The preset each name resolves to (first on the path), sorted by name.

        A header whose ``model`` is inherited through ``extends`` gets its parent's.
        """
        winners: dict[str, Header] = {}
        for h in self.headers():
            winners.setdefault(h.name, h)
        return [_with_model(winners[n], winners) for n in sorted(winners)]

    def _scan(self, folder: Path) -> list[Header]:
        if folder != self.builtin:
            return scan_folder(folder)
        # Read-only and small: scanned once per Library, never indexed on disk.
        if self._builtin_headers is None:
            self._builtin_headers = scan_folder(folder, cache=False, skip=self._skip(folder))
        return self._builtin_headers

    def _skip(self, folder: Path) -> tuple[str, ...]:
        """The top-level sub-folders of ``folder`` that hold other data than presets: the
        built-in library's (however ``folder`` spells its path)."""
        builtin = self.builtin
        same = builtin is not None and (folder == builtin or folder.resolve() == builtin.resolve())
        return BUILTIN_OTHER_DATA if same else ()

    def _find_in(self, folder: Path, name: str) -> Path | None:
        """The file defining ``name`` in one library folder, or None."""
        direct = folder / f"{name}{SUFFIX}"
        if direct.is_file():
            return direct
        if not folder.is_dir():
            return None
        if folder == self.builtin and self._builtin_headers is not None:
            return next((h.path for h in self._builtin_headers if h.name == name), None)
        found = find_file(folder, name, skip=self._skip(folder))
        return None if found is None else Path(found)

    def names(self) -> list[str]:
        """All preset names on the path, sorted."""
        return [h.name for h in self.entries()]

    def definitions(self, name: str) -> list[Path]:
        """Every file defining ``name``, the winner first; ``[]`` when none does."""
        return [h.path for h in self.headers() if h.name == name]

    def find(self, name: str) -> Path:
        """The file that ``name`` resolves to, or an error with "did you mean"."""
        check_name(name, field=None)
        for folder in self.folders:
            hit = self._find_in(folder, name)
            if hit is not None:
                return hit
        raise PresetNotFoundError(
            f"{name!r} not found in {self._where()}{did_you_mean(name, self.names())}"
        )

    def read(self, name: str) -> tuple[PresetFile, Path]:
        """The parsed file that ``name`` resolves to, and its path; its relative texture
        paths stay inside its library (:mod:`.containment`)."""
        path = self.find(name)
        return self._contained(read_preset(path), path), path

    def _contained(self, preset: PresetFile, path: Path) -> PresetFile:
        from .containment import check_contained

        plain = Path(os.path.abspath(path))
        root = next((f for f in self.folders if plain.is_relative_to(os.path.abspath(f))), None)
        check_contained(preset, path, root)
        return preset

    def load(self, name: str) -> Material:
        """The resolved material ``name`` (extends chains and layer references followed)."""
        from .material import resolve

        return resolve(name, self.read)

    def load_file(self, path: Path) -> Material:
        """Resolve a preset file that need not be on the path; its parents are looked up."""
        from .material import resolve

        preset = self._contained(read_preset(path), path)
        return resolve(preset.name, self._lookup_with(preset, path))

    # -- writing -----------------------------------------------------------------------

    def target(self, folder: str | Path | None = None) -> Path:
        """The folder a write goes to: ``folder``, else the first user library."""
        if folder is not None:
            return Path(folder).expanduser()
        if not self.user_folders:
            raise LibraryError(
                "no user library to write to (the built-in one is read-only); "
                f"pass --library DIR or set {ENV_PATH}"
            )
        return self.user_folders[0]

    def save(
        self, preset: PresetFile, *, folder: str | Path | None = None, force: bool = False
    ) -> Path:
        """Write ``preset`` into a user library, checked to resolve first.

        An existing preset of that name in that folder is replaced only with ``force``.
        """
        check_name(preset.name)
        target = self.target(folder)
        self._refuse_builtin(target, preset.name)
        store.make_folder(target)
        _refuse_read_only(target)
        path = self._find_in(target, preset.name) or target / f"{preset.name}{SUFFIX}"
        refuse_links_out(path, target)
        with store.locked(target):
            path = self._find_in(target, preset.name)
            if path is not None and not force:
                raise LibraryError(
                    f"preset {preset.name!r} already exists ({path}); pass --force to replace it",
                    where=str(target),
                )
            path = path or target / f"{preset.name}{SUFFIX}"
            refuse_links_out(path, target)
            self._write(preset, path)
        return path

    def update(self, name: str, changes: dict[str, Any]) -> Path:
        """Change some fields of the preset ``name`` where it is defined (``presets set``).

        Keys in :data:`~lookdev.library.preset.METADATA` set those fields; any other key is
        a parameter. A value of ``None`` removes the key, so it is inherited again.
        """
        path = self.find(name)
        self._refuse_builtin(path, name)
        root = self._writable_root(path)
        with store.locked(root):
            refuse_links_out(path, root)
            preset = read_preset(path)
            self._write(apply_changes(preset, changes, where=str(path)), path)
        return path

    def remove(self, name: str, *, force: bool = False) -> Path:
        """Delete the preset ``name`` resolves to; presets that build on it block this."""
        path = self.find(name)
        self._refuse_builtin(path, name)
        users = self.dependants(name) if len(self.definitions(name)) == 1 else []
        if users and not force:
            raise LibraryError(
                f"{', '.join(users)} build on {name!r}; pass --force to remove it anyway",
                where=str(path),
            )
        root = self._writable_root(path)
        with store.locked(root):
            refuse_links_out(path, root)
            store.remove(path)  # a link (inside the library) is removed, not its target
        return path

    def dependants(self, name: str) -> list[str]:
        """Names of presets that extend ``name`` or use it as a layer."""
        out = []
        for h in self.entries():
            if h.extends == name:
                out.append(h.name)
            elif h.model == "layered" and h.error is None and _layer_refs(h.path, name):
                out.append(h.name)
        return out

    # -- checking ----------------------------------------------------------------------

    def files_under(self, paths: Iterable[Path]) -> list[Path]:
        """Preset files named by ``paths``: files as given, folders walked as libraries are."""
        out: list[Path] = []
        for p in paths:
            if p.is_dir():
                out += [h.path for h in scan_folder(p, cache=False, skip=self._skip(p))]
            elif p.exists():
                out.append(p)
            else:
                raise PresetError("no such file or folder", where=str(p))
        return out

    def validate(self, files: Iterable[Path] | None = None) -> list[tuple[Path, str | None]]:
        """Each file (default: every one on the path) with its one-line problem, or None.

        A file is valid when it parses, resolves, and is not hidden by another file of
        the same name in its own library (which would make it dead).
        """
        hidden = self._hidden_in_own_library()
        return [
            (f, hidden.get(f) or self._problem(f))
            for f in files or [h.path for h in self.headers()]
        ]

    def _hidden_in_own_library(self) -> dict[Path, str]:
        first: dict[tuple[str, str], Header] = {}
        out = {}
        for h in self.headers():
            winner = first.setdefault((h.library, h.name), h)
            if winner is not h:
                out[h.path] = f"{h.file}: {h.name!r} is also defined by {winner.file}, which wins"
        return out

    def _problem(self, path: Path) -> str | None:
        try:
            self.load_file(path)
        except LookdevError as exc:
            return str(exc)
        return None

    def _write(self, preset: PresetFile, path: Path) -> None:
        """Check that ``preset`` resolves in place at ``path``, then write it atomically."""
        from .material import resolve
        from .preset import dump_preset

        resolve(preset.name, self._lookup_with(preset, path))
        store.atomic_write(path, dump_preset(preset).encode("utf-8"))

    def _lookup_with(self, preset: PresetFile, path: Path):
        def lookup(name: str) -> tuple[PresetFile, Path]:
            return (preset, path) if name == preset.name else self.read(name)

        return lookup

    def read_through(self, path: Path) -> list[tuple[Path, Path]]:
        """The symlinks (and where they lead) a preset file is read through, below the root
        of the library holding it (for a file outside the path: the file itself)."""
        plain = Path(os.path.abspath(path))
        root = next((f for f in self.folders if plain.is_relative_to(os.path.abspath(f))), None)
        return links_on_the_way(path, root if root is not None else plain.parent)

    def _writable_root(self, path: Path) -> Path:
        """The library folder holding ``path``, checked to lead nowhere outside and to be
        writable, before its lock is taken (so no ``.lookdev.lock`` lands outside)."""
        root = _library_root(path, self.user_folders)
        refuse_links_out(path, root)
        _refuse_read_only(root)
        return root

    def _refuse_builtin(self, path: Path, name: str) -> None:
        if self.builtin is not None and path.resolve().is_relative_to(self.builtin.resolve()):
            raise LibraryError(
                f"{name!r} is a built-in preset and read-only; make your own with "
                f"`lookdev presets new my_{name} --from {name} --library DIR`",
                where=str(path),
            )

    def _where(self) -> str:
        return ", ".join(str(f) for f in self.folders) or "no library"


def load_material(name_or_path: str | Path, library: Library | None = None) -> Material:
    """A resolved material from a preset name, or from a ``.toml`` file's path."""
    library = library or Library()
    text = str(name_or_path)
    if isinstance(name_or_path, Path) or text.endswith(SUFFIX) or os.sep in text or "/" in text:
        return library.load_file(Path(name_or_path))
    return library.load(text)


def apply_changes(preset: PresetFile, changes: dict[str, Any], *, where: str) -> PresetFile:
    """``preset`` with ``--set``-style changes; keys outside METADATA are parameters.

    A value of ``None`` removes the key (a parameter is then inherited again).
    """
    from .preset import METADATA, build_preset, preset_document

    data = preset_document(preset)
    params = dict(preset.params)
    for key, value in changes.items():
        if key in ("name", "model", "layers"):
            raise PresetError(
                f"{key!r} cannot be set; use `presets new` for a new name or model",
                where=where,
                field=key,
            )
        bucket, field = (data, key) if key in METADATA else (params, key.removeprefix("params."))
        if value is None:
            bucket.pop(field, None)
        else:
            bucket[field] = value
    data["params"] = params
    return build_preset(data, where=where)


def _with_model(h: Header, winners: dict[str, Header]) -> Header:
    seen = {h.name}
    parent = h
    while parent.model is None and parent.extends in winners and parent.extends not in seen:
        seen.add(parent.extends)
        parent = winners[parent.extends]
    if parent is h:
        return h
    return h._replace(model=parent.model)


def _library_root(path: Path, folders: Sequence[Path]) -> Path:
    """The library folder ``path`` was found in: by its path as written (a link inside the
    library may lead elsewhere), else by its real path, else its own folder."""
    plain = Path(os.path.abspath(path))
    for f in folders:
        if plain.is_relative_to(os.path.abspath(f)):
            return f
    resolved = path.resolve()
    return next((f for f in folders if resolved.is_relative_to(f.resolve())), path.parent)


def links_on_the_way(path: Path, root: Path | None = None) -> list[tuple[Path, Path]]:
    """``(link, where it leads)`` for each symlink ``path`` is reached through below ``root``
    (default: every component of ``path``), the file itself included."""
    plain = Path(os.path.abspath(path))
    base = Path(os.path.abspath(root)) if root is not None else Path(plain.anchor)
    if not plain.is_relative_to(base):
        return []
    out, here = [], base
    for part in plain.relative_to(base).parts:
        here = here / part
        if here.is_symlink():
            out.append((here, Path(os.path.realpath(here))))
    return out


def refuse_links_out(path: Path, root: Path) -> None:
    """Refuse a write or delete at ``path`` through a symlink that leads out of ``root``.

    The rule (:doc:`/design`, Files on shared storage): a library never writes or deletes
    through a link out of its root; reads may. A link to a file *inside* the root is
    edited in place: the write goes through to its target and the link stays a link;
    ``presets rm`` removes the link itself. The root folder may itself be a link.
    """
    real_root = Path(os.path.realpath(root))
    for link, dest in links_on_the_way(path, root):
        if not dest.is_relative_to(real_root):
            raise LibraryError(
                f"refusing to write through {link}: it is a symlink that leads out of the "
                f"library to {dest}",
                where=str(root),
            )


def _refuse_read_only(root: Path) -> None:
    """A library folder this process cannot write is used read-only: say so, in one line."""
    if root.is_dir() and not os.access(root, os.W_OK | os.X_OK):
        reason = "Read-only file system" if _on_read_only_mount(root) else "Permission denied"
        raise store.read_only(root, reason)


def _on_read_only_mount(folder: Path) -> bool:
    try:
        return bool(os.statvfs(folder).f_flag & os.ST_RDONLY)
    except (OSError, AttributeError):
        return False


def _layer_refs(path: Path, name: str) -> bool:
    try:
        preset = read_preset(path)
    except PresetError:
        return False
    return any(layer.preset == name for layer in preset.layers)
