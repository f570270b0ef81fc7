"""Mitsuba scene dictionaries as scene XML files a user can open (``mi.load_file``).

The dictionary is the one ``mi.load_dict`` takes (:func:`.scene.scene_dict`); each nested
plugin becomes an element named after its object type, each value a typed property.
When the scene uses our Python BSDF plugins, the first line of the file says how to make
Mitsuba know them. Files are written to a temporary name and renamed, so a failed export
leaves no half-written scene behind.
"""

from __future__ import annotations

import contextlib
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from lookdev.library import files

from .inputs import PLUGIN_PREFIX, MitsubaExportError
from .scene import scene_dict, uses_our_plugins

__all__ = [
    "LOAD_HINT",
    "colour_note",
    "export_scene",
    "orientation_note",
    "to_element",
    "to_xml",
    "write_xml",
]

LOAD_HINT = (
    " lookdev BSDF plugins: in Python, run import lookdev.pipeline.export.mitsuba as m; "
    "m.register_plugins() before mi.load_file(this file) "
)

# Mitsuba object types and the XML tags that declare them.
_TAGS = {
    "Integrator": "integrator",
    "Sensor": "sensor",
    "Film": "film",
    "Sampler": "sampler",
    "ReconstructionFilter": "rfilter",
    "Emitter": "emitter",
    "Shape": "shape",
    "BSDF": "bsdf",
    "Texture": "texture",
    "Medium": "medium",
    "PhaseFunction": "phase",
    "Volume": "volume",
}


def _tag(plugin: str) -> str:
    if plugin.startswith(PLUGIN_PREFIX):
        return "bsdf"  # Python plugins report no type to the plugin manager
    import mitsuba as mi

    kind = mi.PluginManager.instance().plugin_type(plugin).name
    if kind not in _TAGS:
        raise MitsubaExportError(f"cannot write plugin {plugin!r} ({kind}) to XML")
    return _TAGS[kind]


def to_element(tree: Mapping[str, Any], name: str | None = None) -> ET.Element:
    """One plugin dict (and everything nested in it) as an XML element."""
    plugin = tree["type"]
    if plugin == "scene":
        element = ET.Element("scene", version="3.0.0")
    else:
        element = ET.Element(_tag(plugin), type=plugin)
        if name is not None:
            element.set("name", name)
    for key, value in tree.items():
        if key != "type":
            element.append(_property(key, value, top=plugin == "scene"))
    return element


def _property(key: str, value: Any, *, top: bool) -> ET.Element:
    import mitsuba as mi

    if isinstance(value, Mapping):
        if value.get("type") == "rgb":
            rgb = value["value"]
            rgb = [rgb] * 3 if isinstance(rgb, int | float) else rgb
            return ET.Element("rgb", name=key, value=", ".join(_num(c) for c in rgb))
        child = to_element(value, None if top else key)
        if top:
            child.set("id", key)
        return child
    if isinstance(value, bool):
        return ET.Element("boolean", name=key, value="true" if value else "false")
    if isinstance(value, int):
        return ET.Element("integer", name=key, value=str(value))
    if isinstance(value, float):
        return ET.Element("float", name=key, value=_num(value))
    if isinstance(value, str | Path):
        return ET.Element("string", name=key, value=str(value))
    if isinstance(value, mi.ScalarTransform4f):
        transform = ET.Element("transform", name=key)
        rows = [[float(value.matrix[i][j]) for j in range(4)] for i in range(4)]
        ET.SubElement(transform, "matrix", value=" ".join(_num(x) for r in rows for x in r))
        return transform
    raise MitsubaExportError(
        f"cannot write a {type(value).__name__} to XML (in-memory texture data needs a "
        "texture folder)",
        field=key,
    )


def _num(x: float) -> str:
    return repr(float(x))


def to_xml(tree: Mapping[str, Any], *, relative_to: Path | None = None) -> str:
    """The scene as XML text; ``filename`` values under ``relative_to`` become relative."""
    if relative_to is not None:
        tree = _relative_filenames(tree, relative_to)
    root = to_element(tree)
    ET.indent(root)
    body = ET.tostring(root, encoding="unicode")
    if _has_envmap(tree):
        body = f"<!--{orientation_note()}-->\n{body}"
    body = f"<!--{colour_note()}-->\n{body}"
    if uses_our_plugins(tree):
        body = f"<!--{LOAD_HINT}-->\n{body}"
    return body + "\n"


def colour_note() -> str:
    """The comment naming the space every RGB value and map of the scene is in (Mitsuba's
    RGB variants do not convert: the scene renders in the working space)."""
    from lookdev.materials import colour

    return (
        f" lookdev colour: RGB values, maps and the environment are linear "
        f"{colour.working_space()} (OCIO config {colour.settings().config_name}) "
    )


def orientation_note() -> str:
    """The IBL orientation convention, as the comment an exported scene carries."""
    from lookdev.pipeline.proof.ibl import ORIENTATION

    return (
        " lookdev IBL orientation: " + "; ".join(f"{k}: {v}" for k, v in ORIENTATION.items()) + " "
    )


def _has_envmap(tree: Mapping[str, Any]) -> bool:
    if tree.get("type") == "envmap":
        return True
    return any(isinstance(v, Mapping) and _has_envmap(v) for v in tree.values())


def _relative_filenames(tree: Mapping[str, Any], base: Path) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for key, value in tree.items():
        if isinstance(value, Mapping):
            out[key] = _relative_filenames(value, base)
        elif key == "filename" and Path(value).is_absolute():
            path = Path(value)
            out[key] = path.relative_to(base).as_posix() if path.is_relative_to(base) else value
        else:
            out[key] = value
    return out


def write_xml(tree: Mapping[str, Any], path: str | Path) -> Path:
    """Write the scene dict as XML at ``path``, atomically; texture paths made relative."""
    path = Path(path)
    text = to_xml(tree, relative_to=path.parent.resolve())
    _atomic_write(path, text)
    return path


def export_scene(material: Any, path: str | Path, **scene_options: Any) -> dict[str, Any]:
    """Write ``material``'s export scene to ``path``; maps go to ``<stem>_textures/``.

    Returns the scene dict that was written (texture paths absolute).
    """
    path = Path(path)
    files.make_folder(path.parent)
    textures = path.parent.resolve() / f"{path.stem}_textures"
    existed = textures.exists()
    try:
        scene = scene_dict(material, texture_dir=textures, **scene_options)
        write_xml(scene, path)
    except BaseException:
        if not existed:  # a failed export leaves no empty textures folder behind
            with contextlib.suppress(OSError):
                textures.rmdir()
        raise
    return scene


def _atomic_write(path: Path, text: str) -> None:
    files.make_folder(path.parent)
    files.atomic_write(path, text)
