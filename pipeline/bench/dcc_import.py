"""What Blender shows of an exported file, compared input by input with what it says.

Two readers of one file: usd-core resolves each ``UsdPreviewSurface`` input as UsdShade
defines it (``UsdShadeInput.GetValueProducingAttributes``, the Sdr default where nothing
is authored) — :func:`file_view`; Blender's importer builds a Principled BSDF from it —
:func:`.blender.run` ``read``. :func:`compare` says, per material and Principled input,
whether Blender got the value (or the texture, with its colour space) the file holds;
:func:`faithful_counts` counts that per input over a set of materials.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["SOCKETS", "Feed", "compare", "faithful_counts", "file_view"]

SOCKETS = {
    "diffuseColor": "Base Color",
    "metallic": "Metallic",
    "roughness": "Roughness",
    "ior": "IOR",
    "opacity": "Alpha",
    "clearcoat": "Coat Weight",
    "clearcoatRoughness": "Coat Roughness",
    "emissiveColor": "Emission Color",
    "normal": "Normal",
}
"""UsdPreviewSurface input → the Principled BSDF input Blender's importer sets from it
(Blender 4.5's ``usd_reader_material.cc``; observed in its ``bpy``)."""

COLOUR_SOCKETS = frozenset(("Base Color", "Emission Color"))
"""Where Blender reads a texture whose colour space is ``auto`` as sRGB (else data)."""

TOLERANCE = 1e-6
"""Both sides hold float32: a value arrives bit-exact or not at all; this absorbs only
the float32 → float64 round trip of the JSON answer."""


@dataclass(frozen=True)
class Feed:
    """What the file gives one surface input: a constant, or a texture file."""

    value: Any = None
    file: str | None = None
    color_space: str | None = None


def file_view(path: Path) -> dict[str, dict[str, Feed]]:
    """Material name → UsdPreviewSurface input → :class:`Feed`, as usd-core resolves the
    universal surface (every input Blender reads, unauthored ones at their Sdr default)."""
    from pxr import Sdr, Usd, UsdShade

    node = Sdr.Registry().GetShaderNodeByIdentifier("UsdPreviewSurface")
    stage = Usd.Stage.Open(str(path))
    out: dict[str, dict[str, Feed]] = {}
    for prim in stage.Traverse():
        if not prim.IsA(UsdShade.Material):
            continue
        surface = UsdShade.Material(prim).ComputeSurfaceSource()[0]
        if not surface or surface.GetIdAttr().Get() != "UsdPreviewSurface":
            continue
        feeds = {}
        for name in SOCKETS:
            feeds[name] = _feed(surface.GetInput(name), node.GetShaderInput(name))
        out[prim.GetName()] = feeds
    return out


def _feed(inp: Any, sdr_input: Any) -> Feed:
    from pxr import UsdShade

    if inp:
        for attr in inp.GetValueProducingAttributes(shaderOutputsOnly=False):
            if UsdShade.Utils.GetType(attr.GetName()) == UsdShade.AttributeType.Output:
                texture = UsdShade.Shader(attr.GetPrim())
                asset = texture.GetInput("file").Get()
                space = texture.GetInput("sourceColorSpace")
                return Feed(
                    file=asset.resolvedPath or asset.path,
                    color_space=str(space.Get()) if space else "auto",
                )
            if attr.HasAuthoredValue():
                return Feed(value=_plain(attr.Get()))
    return Feed(value=_plain(sdr_input.GetDefaultValue()))


def _plain(value: Any) -> Any:
    try:
        return tuple(float(x) for x in value)
    except TypeError:
        return float(value)


def _blender_space(usd_space: str, socket: str) -> str:
    if usd_space == "sRGB":
        return "sRGB"
    if usd_space == "raw":
        return "Non-Color"
    return "sRGB" if socket in COLOUR_SOCKETS else "Non-Color"


def _same_file(a: str, b: str) -> bool:
    def norm(p: str) -> str:
        return os.path.normcase(os.path.realpath(p.replace("<UDIM>", "1001")))

    return norm(a) == norm(b) or Path(a).name == Path(b).name


def compare(feeds: dict[str, Feed], inputs: dict[str, Any]) -> dict[str, str]:
    """Principled input → ``""`` if Blender holds what the file gives, else why not.

    ``inputs`` is one material's ``inputs`` of a Blender ``read`` answer."""
    out = {}
    for name, socket in SOCKETS.items():
        feed, got = feeds[name], inputs.get(socket, {})
        if feed.file is not None:
            image = got.get("image")
            if image is None:
                out[socket] = f"no texture (file has {Path(feed.file).name})"
            elif not _same_file(image["file"], feed.file):
                out[socket] = f"texture {image['file']}, file has {feed.file}"
            elif image["colorspace"] != _blender_space(feed.color_space or "auto", socket):
                out[socket] = (
                    f"colour space {image['colorspace']} for the file's {feed.color_space}"
                )
            else:
                out[socket] = ""
            continue
        if name == "clearcoatRoughness" and feeds["clearcoat"].value == 0.0:
            # No coat: its roughness shows nowhere (Blender keeps its own default).
            out[socket] = ""
            continue
        if name == "normal":
            # An unconnected normal is the geometry's; Blender leaves the socket unlinked.
            out[socket] = "" if "value" in got else "linked"
            continue
        if "value" not in got:
            out[socket] = "linked to a node, the file holds a constant"
            continue
        want = np.atleast_1d(np.asarray(feed.value, np.float64))
        have = np.atleast_1d(np.asarray(got["value"], np.float64))[: want.size]
        if name == "emissiveColor" and not np.any(want):
            strength = inputs.get("Emission Strength", {}).get("value", 0.0)
            out[socket] = "" if strength == 0.0 else f"emission strength {strength}, file has none"
            continue
        close = have.size == want.size and np.allclose(have, want, rtol=0, atol=TOLERANCE)
        out[socket] = "" if close else f"{_fmt(have)}, file has {_fmt(want)}"
    return out


def _fmt(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.4g}" for x in v) + ")" if v.size > 1 else f"{v[0]:.4g}"


def faithful_counts(
    view: dict[str, dict[str, Feed]], answer: dict[str, Any], names: list[str]
) -> dict[str, dict[str, Any]]:
    """Principled input → {``faithful``: count, ``of``: len(names), ``wrong``: {name: why}}."""
    counts: dict[str, dict[str, Any]] = {
        s: {"faithful": 0, "of": len(names), "wrong": {}} for s in SOCKETS.values()
    }
    for name in names:
        got = answer["materials"].get(name)
        result = (
            compare(view[name], got["inputs"])
            if got is not None
            else dict.fromkeys(SOCKETS.values(), "material not imported")
        )
        for socket, why in result.items():
            if why:
                counts[socket]["wrong"][name] = why
            else:
                counts[socket]["faithful"] += 1
    return counts
