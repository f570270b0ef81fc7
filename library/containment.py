"""Relative texture paths stay inside their library.

A preset names its textures relative to its own file, so a library folder can be copied,
moved, zipped or mounted elsewhere and still find them. A relative path that climbs out
of the library (``../../outside/wood.png``) breaks that silently: the copy reads another
folder's file, or none, and on shared storage it may be another show's. So it is refused
when the preset is read, in one line naming the file, the field and where the path leads.

A texture kept outside the library on purpose (a studio's texture server) is named by an
absolute path: that is a deliberate choice, visible in the file, and is accepted. A
preset file read on its own, outside every library folder, has no library to stay in.
The path is judged as written (``..`` resolved lexically), so a symlink the library's
owner placed inside it may still lead elsewhere.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

from .errors import PresetError

__all__ = ["check_contained", "texture_references"]


def texture_references(preset: Any) -> Iterator[tuple[str, str]]:
    """``(field, path as written)`` of every texture a preset file names itself."""
    from lookdev.materials.layers import textures
    from lookdev.materials.textures import TextureInput, is_texture_input

    def params(values: dict[str, Any], prefix: str) -> Iterator[tuple[str, str]]:
        for key, value in values.items():
            if isinstance(value, TextureInput):
                yield f"{prefix}.{key}", value.texture
            elif isinstance(value, dict) and is_texture_input(value):
                yield f"{prefix}.{key}", str(value["texture"])

    yield from params(preset.params or {}, "params")
    if preset.height is not None:
        yield "height", preset.height.texture
    if preset.textures is not None:
        yield "textures", str(preset.textures)
    for i, layer in enumerate(preset.layers or []):
        where = f"layers[{i}]"
        yield from params(layer.params or {}, f"{where}.params")
        for tex in textures(layer.mask):
            yield f"{where}.mask", str(tex.path)
        for name in ("normal_map", "specular_normal_map"):
            tex = getattr(layer, name)
            if tex is not None:
                yield f"{where}.{name}", str(tex.path)


def check_contained(preset: Any, path: Path, root: Path | None) -> None:
    """Refuse a relative texture path of ``preset`` (read from ``path``) that leads out of
    the library folder ``root``; nothing to check when ``root`` is None."""
    if root is None:
        return
    top = os.path.abspath(root)
    for field, written in texture_references(preset):
        given = Path(written).expanduser()
        if given.is_absolute():
            continue
        lands = os.path.normpath(os.path.join(os.path.abspath(path.parent), given))
        if os.path.commonpath([top, lands]) != top:
            raise PresetError(
                f"texture {written!r} leads out of the library {root} (to {lands}); a "
                "relative path must stay inside it, so the library can be copied or moved "
                "whole: move the file in, or name it by an absolute path",
                where=str(path),
                field=field,
            )
