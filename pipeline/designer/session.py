"""One designer session's edit state: the preset document, edits checked by its schema,
undo/redo, and the blended material the viewport shows.

The document is the preset file as written (:func:`~lookdev.library.preset.preset_document`
form): the parameters *this* file sets, its ``extends``, its layers. An edit builds a
candidate document, validates it with the same Pydantic models and the same resolver
the library loads presets with, and only then replaces the current one; a refused edit
changes nothing and returns the schema's one-line message. Every accepted edit can be
undone.

Each parameter is shown against what it would be without this file's say: the parent's
value for a preset that ``extends`` another, the referenced preset's for a layer, the
model's default otherwise; "reset" removes the override.

The blend (:func:`lookdev.blend`) reruns only for a material not blended before
(undo and redo hit the cache), and decoded textures are shared across blends.
"""

from __future__ import annotations

import copy
import threading
from collections import OrderedDict
from pathlib import Path
from typing import Any

from lookdev.library import Library, Material, resolve
from lookdev.library.library import read_preset
from lookdev.library.preset import MODELS, build_preset, preset_document
from lookdev.materials.errors import LookdevError

from . import saving
from .edits import EditRefused, apply, check_new_files

__all__ = ["BLEND_RESOLUTION", "EditRefused", "Session"]

BLEND_RESOLUTION = 256
"""Texels a side of the designer's blends: enough for the viewport's few hundred pixels."""
BLEND_CACHE = 16
UNDO_DEPTH = 200
NEW_NAME = "untitled"


class Session:
    """The edit state of one open preset, shared by every tab of one server."""

    def __init__(self, library: Library, preset: str | Path | None = None, *, roots=None):
        self.library = library
        self.roots = roots
        self.lock = threading.RLock()
        self.version = 0
        self.hidden: set[int] = set()
        self._blends: OrderedDict[str, Any] = OrderedDict()
        self._images: dict = {}
        self.blend_log: list[tuple[str, float]] = []
        self.save_messages: list[str] = []
        """What the last save copied into the library (files that would have been left
        outside it), one line each, for the page to show."""
        self.open(preset or "plastic_glossy")

    # -- opening ---------------------------------------------------------------------------
    def open(self, preset: str | Path) -> None:
        """Open a preset by name (on the library path) or by file."""
        text = str(preset)
        path = Path(text) if text.endswith(".toml") else self.library.find(text)
        doc = preset_document(read_preset(path))
        with self.lock:
            self.path: Path | None = path
            self.stamp = saving.stamp(path)
            self.original = doc
            self.parent_name: str | None = doc["name"]
            self.doc = copy.deepcopy(doc)
            self.undo_stack: list[tuple] = []
            self.redo_stack: list[tuple] = []
            self.hidden = set()
            self.version += 1

    @property
    def name(self) -> str:
        return self.doc["name"]

    def base_folder(self) -> Path:
        """The folder the document's relative texture paths start from."""
        if self.path is not None:
            return self.path.parent
        return self.library.target()

    @property
    def dirty(self) -> bool:
        return self.doc != self.original

    # -- reading ---------------------------------------------------------------------------
    def material(self, doc: dict | None = None, *, hide: bool = True) -> Material:
        """The resolved material of ``doc`` (default: the current one), hidden layers out."""
        doc = self.doc if doc is None else doc
        if hide and self.hidden and doc.get("layers"):
            doc = dict(
                doc, layers=[la for i, la in enumerate(doc["layers"]) if i not in self.hidden]
            )
            if not doc["layers"]:
                doc["layers"] = [{"model": "disney", "mask": 0.0}]
        where = str(self.path or NEW_NAME)
        preset = build_preset(doc, where=where)
        path = self.path or self.base_folder() / f"{preset.name}.toml"

        def lookup(name: str):
            return (preset, path) if name == preset.name else self.library.read(name)

        return resolve(preset.name, lookup)

    def reference(self, against: str = "opened") -> Material:
        """What the A/B split compares against: the preset as opened, or (``"parent"``)
        the preset it ``extends`` (as opened when it extends nothing)."""
        parent = self.original.get("extends")
        if against == "parent" and parent:
            return self.library.load(parent)
        return self.material(self.original, hide=False)

    def hub(self, material: Material | None = None):
        """The blended material (cached by content; textures decoded once)."""
        import time

        import lookdev

        material = self.material() if material is None else material
        key = material.model_dump_json()
        with self.lock:
            if key in self._blends:
                self._blends.move_to_end(key)
                self.blend_log.append(("cached", 0.0))
                return self._blends[key]
        start = time.process_time()
        blended = lookdev.blend(material, BLEND_RESOLUTION, images=self._images)
        with self.lock:
            self.blend_log.append(("blended", time.process_time() - start))
            self._blends[key] = blended
            while len(self._blends) > BLEND_CACHE:
                self._blends.popitem(last=False)
        return blended

    def base_params(self, target: int | None) -> tuple[str | None, dict[str, Any], dict]:
        """(model, values without this target's overrides, those overrides)."""
        doc = self.doc
        if target is None:
            overrides = doc.get("params", {})
            if doc.get("extends"):
                parent = self.library.load(doc["extends"])
                return parent.model, _values(parent), overrides
            model = doc.get("model")
            return model, _defaults(model), overrides
        layer = doc["layers"][target]
        overrides = layer.get("params", {})
        if layer.get("preset"):
            ref = self.library.load(layer["preset"])
            return ref.model, _values(ref), overrides
        return layer.get("model"), _defaults(layer.get("model")), overrides

    def state(self) -> dict[str, Any]:
        """What the page draws: the document, each target's fields, undo/redo, dirty."""
        from .controls import controls_for

        with self.lock:
            targets = []
            if self.doc.get("layers"):
                for i, layer in enumerate(self.doc["layers"]):
                    targets.append(self._target(i, layer.get("name") or layer.get("preset")))
            else:
                targets.append(self._target(None, self.name))
            models = {t["model"] for t in targets if t["model"] in MODELS}
            return {
                "version": self.version,
                "name": self.name,
                "path": str(self.path) if self.path else None,
                "doc": self.doc,
                "dirty": self.dirty,
                "can_undo": bool(self.undo_stack),
                "can_redo": bool(self.redo_stack),
                "hidden": sorted(self.hidden),
                "layered": bool(self.doc.get("layers")) or self.doc.get("model") == "layered",
                "targets": targets,
                "controls": {m: controls_for(m) for m in models},
            }

    def _target(self, index: int | None, label: str | None) -> dict[str, Any]:
        model, base, overrides = self.base_params(index)
        values = dict(base)
        for key, value in overrides.items():
            values[key] = value
        if model in MODELS:
            # unset optionals out: a dump holds ``ior = None`` beside ``specular``, and the
            # model refuses the pair (then overrides such as a hex colour stayed raw)
            constants = {
                k: v for k, v in values.items() if not isinstance(v, dict) and v is not None
            }
            constants = {k: list(v) if isinstance(v, tuple) else v for k, v in constants.items()}
            try:
                canon = MODELS[model].model_validate(_plain(constants)).model_dump(mode="json")
                values = {
                    k: (v if isinstance(v, dict) else canon.get(k, v)) for k, v in values.items()
                }
            except Exception:  # a stored document always validates; keep the raw values
                pass
        values = _jsonable(values)
        return {
            "index": index,
            "label": label,
            "model": model,
            "values": values,
            "hex": _hexes(model, values),
            "base": _jsonable(base),
            "overridden": sorted(overrides),
        }

    def target_values(self, index: int | None) -> dict[str, Any]:
        """The values ``index`` (None: the preset's own parameters) shows, maps included."""
        with self.lock:
            return self._target(index, None)["values"]

    # -- editing ---------------------------------------------------------------------------
    def edit(self, op: dict[str, Any]) -> None:
        """Apply one edit (see :func:`.edits.apply`); refused edits raise :class:`EditRefused`."""
        with self.lock:
            candidate = apply(copy.deepcopy(self.doc), op, self)
            check_new_files(self.doc, candidate, self)  # before any file is opened
            self._check(candidate)
            self._push(candidate, self.path, self.parent_name)

    def set_hidden(self, index: int, hidden: bool) -> None:
        with self.lock:
            (self.hidden.add if hidden else self.hidden.discard)(index)
            self.version += 1

    def replace(self, doc: dict[str, Any]) -> None:
        """Start a new preset from ``doc`` (a new layered one): undoable like an edit."""
        with self.lock:
            self._check(doc)
            self._push(doc, None, None)
            self.hidden = set()

    def _snapshot(self) -> tuple[dict, Path | None, str | None]:
        return self.doc, self.path, self.parent_name

    def _push(self, doc: dict, path: Path | None, parent: str | None) -> None:
        self.undo_stack.append(self._snapshot())
        del self.undo_stack[:-UNDO_DEPTH]
        self.redo_stack.clear()
        self.doc, self.path, self.parent_name = doc, path, parent
        self.version += 1

    def undo(self) -> None:
        with self.lock:
            if self.undo_stack:
                self.redo_stack.append(self._snapshot())
                self.doc, self.path, self.parent_name = self.undo_stack.pop()
                self.version += 1

    def redo(self) -> None:
        with self.lock:
            if self.redo_stack:
                self.undo_stack.append(self._snapshot())
                self.doc, self.path, self.parent_name = self.redo_stack.pop()
                self.version += 1

    def _check(self, doc: dict[str, Any]) -> None:
        try:
            self.material(doc, hide=False)
        except LookdevError as exc:
            raise EditRefused(_without_where(str(exc))) from None

    # -- saving ----------------------------------------------------------------------------
    def save_new(self, name: str, folder: Path | None = None) -> Path:
        """Save as a new preset extending the one opened, writing only what changed."""
        with self.lock:
            path, self.save_messages = saving.save_new(self, name, folder)
            self.path, self.stamp = path, saving.stamp(path)
            self.doc = preset_document(read_preset(path))
            self.original = copy.deepcopy(self.doc)
            self.parent_name = name
            self.version += 1
            return path

    def save_over(self) -> Path:
        """Write the document over the file it came from, if nobody changed that file."""
        with self.lock:
            path, self.save_messages = saving.save_over(self)
            self.stamp = saving.stamp(path)
            self.doc = preset_document(read_preset(path))  # copies brought in: their paths
            self.original = copy.deepcopy(self.doc)
            self.version += 1
            return path


def _values(material: Material) -> dict[str, Any]:
    if material.params is None:
        return {}
    values = material.params.model_dump(mode="json")
    values |= {
        k: t.model_dump(mode="json", exclude_defaults=True) for k, t in material.textures.items()
    }
    return values


def _defaults(model: str | None) -> dict[str, Any]:
    if model not in MODELS:
        return {}
    return MODELS[model]().model_dump(mode="json")


def _hexes(model: str | None, values: dict[str, Any]) -> dict[str, str]:
    """``"#rrggbb"`` (sRGB) of each constant colour, for the page's colour picker."""
    from lookdev.materials import colour

    from .controls import controls_for

    if model not in MODELS:
        return {}
    colours = [c["name"] for c in controls_for(model) if c["kind"] == "colour"]
    return {k: colour.encode_hex(values[k]) for k in colours if isinstance(values.get(k), list)}


def _plain(values: dict[str, Any]) -> dict[str, Any]:
    return {k: tuple(v) if isinstance(v, list) else v for k, v in values.items()}


def _jsonable(values: dict[str, Any]) -> dict[str, Any]:
    return {k: list(v) if isinstance(v, tuple) else v for k, v in values.items()}


def _without_where(message: str) -> str:
    """The schema's message without the file prefix (the page shows it beside the field)."""
    return message.split(": ", 1)[1] if message.startswith(("untitled", "/")) else message
