"""Imported materials as preset files (TOML), written safely.

A preset holds constants; a parameter a texture fed in the USD file is kept as a
comment naming the map, so nothing read is silently dropped.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

from lookdev.library import PresetFile, dump_preset, files
from lookdev.library.preset import parse_preset

from .network import ExportError
from .reader import Imported


def preset_name(name: str) -> str:
    """A valid preset name for an imported material name.

    >>> preset_name("Car Paint (red)")
    'Car_Paint_red'
    """
    safe = re.sub(r"[^A-Za-z0-9_-]+", "_", name).strip("_-")[:100]
    return safe or "imported"


def preset_toml(material: Imported) -> str:
    """The preset file text of one imported material."""
    preset = PresetFile(
        name=preset_name(material.name),
        model=material.model,
        description=f"Imported from USD ({', '.join(material.contexts)}).",
        params=dict(material.params),
    )
    text = dump_preset(preset)
    notes = [
        f"# map: {k} = {str(v)!r} (constant here: the map's mean is not known)"
        for k, v in sorted(material.maps.items())
    ]
    notes += [f"# loss: {line}" for line in material.loss]
    return text + ("\n" + "\n".join(notes) + "\n" if notes else "")


def write_presets(found: list[Imported], output: Path | None, *, force: bool = False) -> list[Path]:
    """Write each material to ``output`` (a .toml for one, a folder for several).

    Every preset is validated as ``presets validate`` would before anything is written
    (one line naming the file and field when one is not valid), and an existing preset
    file is replaced only with ``force``.
    """
    if output is None:
        for m in found:
            check_preset(preset_toml(m), f"{preset_name(m.name)}.toml")
        return []
    output = output.expanduser()
    if output.suffix == ".toml":
        if len(found) != 1:
            raise ExportError(
                f"the file holds {len(found)} materials; give a folder with -o", where=str(output)
            )
        targets = [output]
    else:
        if not output.is_dir():
            what = "is a file, not a folder" if output.exists() else "folder does not exist"
            raise ExportError(f"{what} (give a folder or a .toml file)", where=str(output))
        targets = [output / f"{preset_name(m.name)}.toml" for m in found]
    texts = [preset_toml(m) for m in found]
    for path, text in zip(targets, texts, strict=True):
        check_preset(text, str(path), stem=path.stem)
    for path in targets:
        if not path.parent.is_dir() or not os.access(path.parent, os.W_OK):
            raise ExportError("folder does not exist or is not writable", where=str(path))
        if path.exists() and not force:
            raise ExportError(
                "a preset file of that name exists; give --force to replace it", where=str(path)
            )
    for path, text in zip(targets, texts, strict=True):
        _write_atomic(path, text)
    return targets


def check_preset(text: str, where: str, stem: str | None = None) -> None:
    """Raise the one line ``presets validate`` would print if ``text`` is not a valid preset
    (its own parameters: references are not resolved here)."""
    parse_preset(text.encode("utf-8"), where=where, stem=stem)


def _write_atomic(path: Path, text: str) -> None:
    files.atomic_write(path, text)
