"""Texture sets: the channel names painting tools write, and what each drives.

Substance Painter and Mari export one image per channel, named
``<asset>_<channel>.<UDIM>.<ext>`` (Painter's "$mesh_$textureSet_$channel(.$udim)"
templates, Mari's "$ENTITY_$CHANNEL.$UDIM" export). :data:`CHANNELS` is the one table
of those channel names → the preset parameter each drives and the colour space the file
is read in by default. A preset may name the set with one pattern,

    textures = "hero/asset_<channel>.<UDIM>.png"

and :func:`expand` turns it into one texture input per parameter found on disk (paths
absolute; an explicit ``[params]`` entry wins over the set). ``lookdev presets new NAME --textures
'maps/asset_*.png'`` builds a preset from a folder of maps the same way
(:func:`from_files`).

Normal maps: lookdev's normal maps are OpenGL convention (+Y up, "green up", the
convention of MaterialX's ``normalmap``, USD and Mitsuba). ``Normal_DirectX`` maps have Y
down; :func:`expand` marks them ``flip_y`` so the reader negates the green channel.
Channels with no parameter in lookdev's models (emission, ambient occlusion) are kept
out of the preset and named in :attr:`TextureSet.unused` with the reason.

>>> CHANNELS["basecolor"].param, CHANNELS["basecolor"].colorspace
('base_color', 'sRGB - Texture')
>>> channel_of("asset_Base_Color.1001.png", "asset_<channel>.<UDIM>.png")
'Base_Color'
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lookdev.materials.colour import RAW, SRGB_TEXTURE
from lookdev.materials.textures import UDIM_TOKEN

from .errors import PresetError

__all__ = [
    "CHANNELS",
    "CHANNEL_TOKEN",
    "Channel",
    "TextureSet",
    "channel_of",
    "expand",
    "from_files",
]

CHANNEL_TOKEN = "<channel>"
"""Stands for the channel name in a texture-set pattern."""


@dataclass(frozen=True)
class Channel:
    """What one painted channel drives: a preset key, its default colour space."""

    param: str | None
    colorspace: str = RAW
    flip_y: bool = False
    why_unused: str = ""


def _unused(why: str) -> Channel:
    return Channel(None, RAW, why_unused=why)


_SRGB = SRGB_TEXTURE
CHANNELS: dict[str, Channel] = {
    # Colour: painted in display-referred sRGB (Painter's and Mari's 8-bit default).
    "basecolor": Channel("base_color", _SRGB),
    "base_color": Channel("base_color", _SRGB),
    "albedo": Channel("base_color", _SRGB),
    "diffuse": Channel("base_color", _SRGB),
    "diffusecolor": Channel("base_color", _SRGB),
    "color": Channel("base_color", _SRGB),
    # Data: read as stored.
    "roughness": Channel("roughness"),
    "metallic": Channel("metallic"),
    "metalness": Channel("metallic"),
    "specular": Channel("specular"),
    "specularlevel": Channel("specular"),
    "anisotropy": Channel("anisotropic"),
    "anisotropylevel": Channel("anisotropic"),
    "sheen": Channel("sheen"),
    "coat": Channel("clearcoat"),
    "clearcoat": Channel("clearcoat"),
    "transmission": Channel("spec_trans"),
    "opacity": Channel("spec_trans"),  # see expand(): 1 − opacity, and only a note
    "subsurface": Channel("subsurface"),
    "scattering": Channel("subsurface"),
    "normal": Channel("normal_map"),
    "normal_opengl": Channel("normal_map"),
    "normalgl": Channel("normal_map"),
    "normal_directx": Channel("normal_map", flip_y=True),
    "normaldx": Channel("normal_map", flip_y=True),
    "height": Channel("height"),
    "displacement": Channel("height"),
    "bump": Channel("height"),
    # Painted, but no lookdev model has the parameter.
    "emissive": _unused("no model has emission: the Disney and Pixar BSDFs do not emit"),
    "emission": _unused("no model has emission: the Disney and Pixar BSDFs do not emit"),
    "ambientocclusion": _unused("ambient occlusion is baked lighting, not a material input"),
    "ao": _unused("ambient occlusion is baked lighting, not a material input"),
    "mixed_ao": _unused("ambient occlusion is baked lighting, not a material input"),
}
"""Channel name, lower case with spaces and dashes as ``_`` → :class:`Channel`."""

OPACITY_NOTE = (
    "Opacity is a cut-out (alpha) in Painter and Mari; lookdev has no cut-out, and "
    "transmission is not alpha: the map is not used"
)


def _key(name: str) -> str:
    return re.sub(r"[\s\-]+", "_", name.strip()).lower()


def lookup(name: str) -> Channel | None:
    """The table's entry for a channel as a tool spells it (case, ``_`` and ``-`` free)."""
    key = _key(name)
    return CHANNELS.get(key) or CHANNELS.get(key.replace("_", ""))


def _pattern_regex(pattern: str) -> re.Pattern[str]:
    parts = re.split(f"({re.escape(CHANNEL_TOKEN)}|{re.escape(UDIM_TOKEN)}|\\*)", pattern)
    out = []
    for part in parts:
        if part in (CHANNEL_TOKEN, "*"):
            out.append(r"(?P<channel>[A-Za-z][A-Za-z0-9 _\-]*?)")
        elif part == UDIM_TOKEN:
            out.append(r"(?P<udim>1\d{3})")
        else:
            out.append(re.escape(part))
    return re.compile("".join(out) + r"\Z")


def channel_of(file_name: str, pattern: str) -> str | None:
    """The channel part of ``file_name`` under ``pattern`` (``<channel>`` or ``*``)."""
    m = _pattern_regex(Path(pattern).name).match(Path(file_name).name)
    return m.group("channel") if m else None


@dataclass
class TextureSet:
    """The texture inputs a set gives, by parameter, and the channels it left out."""

    inputs: dict[str, dict[str, Any]] = field(default_factory=dict)
    """Parameter → ``{texture, colorspace}`` (a texture input as a preset writes it)."""
    height: dict[str, Any] | None = None
    """The height channel as a texture input (scene units: scale 1 until the preset says)."""
    normal_map: dict[str, Any] | None = None
    """The normal map: ``{path, flip_y}`` (OpenGL convention after the flip)."""
    unused: dict[str, str] = field(default_factory=dict)
    """File channel → why it drives nothing."""

    @property
    def notes(self) -> list[str]:
        """One line per channel left out, for the preset's readers."""
        return [f"texture channel {c!r} not used: {why}" for c, why in sorted(self.unused.items())]


def _scan(pattern: str, folder: Path) -> dict[str, tuple[str, bool]]:
    """``channel → (file name as a pattern, is UDIM)`` for files matching ``pattern``."""
    regex = _pattern_regex(Path(pattern).name)
    where = (folder / pattern).parent
    found: dict[str, tuple[str, bool]] = {}
    if not where.is_dir():
        return found
    for path in sorted(where.iterdir()):
        m = regex.match(path.name)
        if m is None or not path.is_file():
            continue
        channel = m.group("channel")
        udim = m.groupdict().get("udim")
        name = path.name
        if udim is not None:
            start, end = m.span("udim")
            name = name[:start] + UDIM_TOKEN + name[end:]
        found.setdefault(channel, (str(Path(pattern).parent / name), udim is not None))
    return found


def expand(pattern: str, folder: Path, *, where: str | None = None) -> TextureSet:
    """The texture inputs of a texture-set ``pattern`` (relative to ``folder``).

    ``pattern`` holds ``<channel>`` (and optionally ``<UDIM>``); each file it matches
    whose channel is in :data:`CHANNELS` becomes ``{texture, colorspace}`` for its
    parameter (path absolute: ``folder`` joined), the height channel
    :attr:`TextureSet.height`, the normal map :attr:`TextureSet.normal_map`. Two files for one
    parameter (``Normal`` and ``Normal_OpenGL``) are a one-line error. A pattern that
    matches no channel is a one-line error too.
    """
    if CHANNEL_TOKEN not in pattern and "*" not in pattern:
        raise PresetError(
            f"textures = {pattern!r} names no channel; put {CHANNEL_TOKEN} where the "
            "channel name goes, e.g. 'asset_<channel>.<UDIM>.png'",
            where=where,
            field="textures",
        )
    found = _scan(pattern.replace("*", CHANNEL_TOKEN), folder)
    out = TextureSet()
    owner: dict[str, str] = {}
    for channel, (file_pattern, _udim) in found.items():
        entry = lookup(channel)
        if entry is None:
            out.unused[channel] = "not a channel name lookdev knows (see texture_sets.CHANNELS)"
            continue
        if entry.param is None:
            out.unused[channel] = entry.why_unused
            continue
        if _key(channel) == "opacity":
            out.unused[channel] = OPACITY_NOTE
            continue
        if entry.param in owner:
            raise PresetError(
                f"channels {owner[entry.param]!r} and {channel!r} both drive "
                f"{entry.param}; keep one of the files",
                where=where,
                field="textures",
            )
        owner[entry.param] = channel
        path = str(folder / file_pattern)
        if entry.param == "normal_map":
            out.normal_map = {"path": path, "flip_y": entry.flip_y}
        elif entry.param == "height":
            out.height = {"texture": path, "colorspace": RAW}
        else:
            out.inputs[entry.param] = {"texture": path, "colorspace": entry.colorspace}
    if not (out.inputs or out.height or out.normal_map):
        raise PresetError(
            f"textures = {pattern!r} matches no texture-set channel in {folder}"
            + (f" (found {', '.join(sorted(found))})" if found else ""),
            where=where,
            field="textures",
        )
    return out


def from_files(files: Iterable[Path]) -> tuple[str, Path]:
    """The pattern (with ``<channel>`` and ``<UDIM>``) shared by a texture set's files,
    and their folder: what ``presets new --textures`` writes as ``textures =``.

    The channel is the text after the last ``_`` of the file's stem (before a UDIM
    number); every file must share the rest.

    >>> from_files([Path("m/a_BaseColor.1001.png"), Path("m/a_Roughness.1002.png")])[0]
    'a_<channel>.<UDIM>.png'
    """
    files = [Path(f) for f in files]
    if not files:
        raise PresetError("--textures matched no files", field="--textures")
    folders = {f.parent for f in files}
    if len(folders) > 1:
        raise PresetError(
            "--textures files are in several folders; give one texture set",
            field="--textures",
        )
    shapes = set()
    for f in files:
        m = re.fullmatch(
            r"(?P<stem>.+?)_(?P<channel>[A-Za-z][A-Za-z0-9]*(?:_(?:OpenGL|DirectX|"
            r"Color|AO|GL|DX))?)(?:\.(?P<udim>1\d{3}))?(?P<ext>\.[^.]+)",
            f.name,
        )
        if m is None:
            raise PresetError(
                f"{f.name} is not named asset_<channel>[.<UDIM>].ext", field="--textures"
            )
        udim = "." + UDIM_TOKEN if m.group("udim") else ""
        shapes.add(f"{m.group('stem')}_{CHANNEL_TOKEN}{udim}{m.group('ext')}")
    if len(shapes) > 1:
        raise PresetError(
            f"--textures files follow several patterns ({', '.join(sorted(shapes))}); "
            "give one texture set",
            field="--textures",
        )
    return shapes.pop(), folders.pop()
