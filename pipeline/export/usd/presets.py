"""Imported materials as preset files (TOML), written safely.

A parameter a texture fed in the USD file becomes its
:class:`~lookdev.materials.textures.TextureInput` (the table a preset writes for a
texture-driven parameter: file, channel, colour space, scale/offset, wrap). A lookdev
export carries its preset whole (:mod:`.record`): that document is written back as it was.
Names must not clash, with each other or with a preset of the library: such a material
is refused in one line, or renamed with ``rename``.
"""

from __future__ import annotations

import re
from pathlib import Path

from lookdev.library import PresetFile, dump_preset, files
from lookdev.library.preset import parse_preset
from lookdev.materials.errors import LookdevError

from .network import ExportError
from .reader import Imported

__all__ = ["check_preset", "import_names", "preset_name", "preset_toml", "screen", "write_presets"]


def preset_name(name: str) -> str:
    """A valid preset name for an imported material name.

    >>> preset_name("Car Paint (red)")
    'Car_Paint_red'
    """
    safe = re.sub(r"[^A-Za-z0-9_-]+", "_", name).strip("_-")[:100]
    return safe or "imported"


def preset_toml(material: Imported, name: str | None = None) -> str:
    """The preset file text of one imported material (named ``name`` if given)."""
    name = name or preset_name(material.name)
    if material.document is not None:
        return dump_preset(PresetFile(**{**material.document, "name": name}))
    params = dict(material.params)
    for key, texture in material.maps.items():  # a texture-driven parameter (TextureInput)
        params[key] = {"texture": texture.texture} | texture.model_dump(
            mode="json", exclude_defaults=True, exclude={"texture"}
        )
    preset = PresetFile(
        name=name,
        model=material.model,
        description=f"Imported from USD ({', '.join(material.contexts)}).",
        params=params,
    )
    text = dump_preset(preset)
    notes = []
    notes += [f"# loss: {line}" for line in material.loss]
    return text + ("\n" + "\n".join(notes) + "\n" if notes else "")


def import_names(
    found: list[Imported], taken: set[str] | frozenset[str] = frozenset(), *, rename: bool = False
) -> list[str]:
    """Preset names for ``found``: unique among themselves and not in ``taken`` (the
    library's presets). A clash raises one line naming both, unless ``rename``, which
    appends ``_imported`` (then a number) until the name is free."""
    names: list[str] = []
    used = set(taken)
    for m in found:
        name = preset_name(m.name)
        if name in used:
            if not rename:
                what = "another material in the file" if name in names else "a library preset"
                raise ExportError(
                    f"material {m.name!r} would be preset {name!r}, which {what} already is; "
                    "give --rename to import it under a new name",
                    where=m.name,
                )
            base, n = f"{name}_imported", 1
            name = base
            while name in used:
                n += 1
                name = f"{base}{n}"
        used.add(name)
        names.append(name)
    return names


def write_presets(
    found: list[Imported],
    output: Path | None,
    *,
    force: bool = False,
    names: list[str] | None = None,
) -> list[Path]:
    """Write each material to ``output`` (a .toml for one, a folder for several).

    ``names`` (from :func:`import_names`) name the presets; by default each material's
    own, refused when two collide. Every preset is validated as ``presets validate``
    would before anything is written (one line naming the file and field when one is not
    valid), and an existing preset file is replaced only with ``force``.
    """
    names = names if names is not None else import_names(found)
    if output is None:
        for m, name in zip(found, names, strict=True):
            check_preset(preset_toml(m, name), f"{name}.toml")
        return []
    output = output.expanduser()
    if output.suffix == ".toml":
        if len(found) != 1:
            raise ExportError(
                f"the file holds {len(found)} materials; give a folder with -o", where=str(output)
            )
        targets = [output]
    else:
        if output.exists() and not output.is_dir():
            raise ExportError(
                "is a file, not a folder (give a folder or a .toml file)", where=str(output)
            )
        targets = [output / f"{name}.toml" for name in names]
    texts = [preset_toml(m, name) for m, name in zip(found, names, strict=True)]
    for path, text in zip(targets, texts, strict=True):
        check_preset(text, str(path), stem=path.stem)
    for path in targets:
        try:
            files.check_folder(path.parent)
        except files.WriteError as exc:
            raise ExportError(exc.message, where=str(path)) from None
        if path.exists() and not force:
            raise ExportError(
                "a preset file of that name exists; give --force to replace it", where=str(path)
            )
    with files.Transaction() as staged:  # all or none, the folder made as `mkdir -p`
        for path, text in zip(targets, texts, strict=True):
            staged.folder(path.parent)
            staged.temp_for(path).write_bytes(text.encode("utf-8"))
    return targets


def screen(found: list[Imported], refused: list[str]) -> list[Imported]:
    """The materials whose preset validates as ``presets validate`` would; each other one
    is refused in one line naming its prim, the field and the value (appended to
    ``refused``), so one bad value never stops the rest of a file."""
    from .reader import refusal

    kept = []
    for m in found:
        try:
            check_preset(preset_toml(m), f"{preset_name(m.name)}.toml")
        except LookdevError as exc:
            refused.append(refusal(m.prim or m.name, exc))
            continue
        kept.append(m)
    return kept


def check_preset(text: str, where: str, stem: str | None = None) -> None:
    """Raise the one line ``presets validate`` would print if ``text`` is not a valid preset
    (its own parameters: references are not resolved here)."""
    parse_preset(text.encode("utf-8"), where=where, stem=stem)
