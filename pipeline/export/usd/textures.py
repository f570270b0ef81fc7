"""Texture files in exported networks: the preset's own files, referenced, and images an
export writes itself (maps converted for a target, baked masks).

A parameter read straight from one image (the hub's ``textures``) is referenced where
it lies, with its colour space named (UsdPreviewSurface ``sourceColorSpace`` and
``colorSpace`` metadata, MaterialX ``colorspace``, RenderMan ``linearize``) and the
affine part of its value rule on the texture node's scale and bias; the file is not
re-baked. A target input that is not an affine function of our parameter (a
clearcoat roughness from Burley's gloss, a colour from a scalar) cannot be expressed by
a texture node's scale and bias, so the exporter writes a converted copy of the map.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lookdev.library import files
from lookdev.materials import colour
from lookdev.pipeline.exr import colour_space_of, write_exr

from .names import Slot
from .network import ExportError, Image

__all__ = [
    "MTLX_ADDRESS",
    "OUTPUTS",
    "USD_WRAP",
    "affine",
    "converted",
    "fallback4",
    "output_of",
    "preview_color_space",
    "usd_color_space",
    "write_image",
]

USD_WRAP = {"periodic": "repeat", "clamp": "clamp", "black": "black", "mirror": "mirror"}
"""TextureInput ``wrap`` → UsdUVTexture ``wrapS``/``wrapT`` (UsdPreviewSurface spec)."""
MTLX_ADDRESS = {"periodic": "periodic", "clamp": "clamp", "black": "constant", "mirror": "mirror"}
"""TextureInput ``wrap`` → MaterialX ``uaddressmode``/``vaddressmode`` (``constant``
reads the node's ``default``, the fallback)."""
OUTPUTS = ("r", "g", "b", "a", "rgb")


def output_of(image: Image, slot_type: str) -> str:
    """The texture output carrying the parameter: the image's channel, or by type."""
    if image.channel:
        return image.channel
    return "rgb" if slot_type in ("color3f", "normal3f", "vector3f", "float3") else "r"


def affine(image: Image, slot: Slot | None) -> tuple[float, float] | None:
    """(scale, bias) from the file's decoded value to the target input, or None when
    the target's conversion is not affine. Composes the image's own rule (its
    TextureInput scale/offset/range) with the slot's ``texture_linear``."""
    s0, b0 = (1.0, 0.0) if slot is None else (slot.texture_linear or (None, None))
    if s0 is None:
        return None
    return s0 * image.scale, s0 * image.bias + b0


def preview_color_space(space: str | None) -> tuple[str, str]:
    """UsdUVTexture ``sourceColorSpace`` for a file in OCIO ``space``, and a loss note.

    The spec knows ``sRGB`` (the sRGB curve over Rec.709 primaries) and ``raw`` (no
    transform). A linear file in the working space reads right as ``raw``; a file in any
    other colour space (ACEScg, a log space) is not converted by a UsdPreviewSurface
    reader: the ``colorSpace`` metadata names it for readers that honour it.
    """
    if space is None:
        return "raw", ""
    name = colour.canonical(space)
    if name == colour.canonical(colour.SRGB_TEXTURE):
        return "sRGB", ""
    if colour.is_data(name) or name == colour.canonical(colour.working_space()):
        return "raw", ""
    return "raw", f"a UsdPreviewSurface reader reads {space} as raw (only its colorSpace names it)"


def usd_color_space(image: Image, slot_type: str) -> str | None:
    """The ``colorSpace`` metadata of a file attribute: the file's OCIO space; a colour
    map lookdev wrote is in the working space; data maps name none."""
    if image.colorspace is not None:
        return None if colour.is_data(image.colorspace) else colour.canonical(image.colorspace)
    if slot_type == "color3f":
        return colour.working_space()
    return None


def fallback4(image: Image, output: str, scale: float, bias: float) -> tuple[float, ...] | None:
    """UsdUVTexture ``fallback`` (float4, before scale and bias) so that a missing file
    reads as the parameter's mean, not black (a mirror for roughness)."""
    if image.fallback is None:
        return None
    value = image.fallback
    raw = (lambda x: x) if scale == 0 else (lambda x: (x - bias) / scale)
    if isinstance(value, tuple):
        return (*(float(raw(v)) for v in value[:3]), 1.0)
    v = float(raw(value))
    if output in ("r", "g", "b", "a"):
        out = [0.0, 0.0, 0.0, 1.0]
        out["rgba".index(output)] = v
        return tuple(out)
    return (v, v, v, 1.0)


def converted(image: Image, slot: Slot) -> Image:
    """``image`` with ``slot.to_target`` applied per texel, to be written beside it."""
    if image.udim:
        raise ExportError(
            f"{slot.input!r} is not an affine function of {slot.param!r}, and the UDIM set "
            f"{image.path.name} cannot be converted tile by tile here; give {slot.param} as "
            "one image, or leave out this render context",
            field=slot.param,
        )
    if image.pixels is None:
        raise ExportError(
            f"the map {image.path.name} of {slot.param!r} must be converted for "
            f"{slot.input!r}, but its pixels are not available; export with --bake",
            field=slot.param,
        )
    px = np.asarray(image.pixels, dtype=np.float64)
    if slot.type == "color3f" and px.ndim == 2:
        out = np.repeat(px[..., None], 3, axis=-1)
    else:
        out = np.vectorize(slot.to_target, otypes=[np.float64])(px)
    folder = image.derived_dir or image.path.parent
    path = folder / f"{image.path.stem}.{slot.input}.exr"
    fallback = None
    if image.fallback is not None and not isinstance(image.fallback, tuple):
        fallback = float(slot.to_target(image.fallback))
    if slot.type == "color3f" and fallback is not None:
        fallback = (fallback,) * 3
    return Image(path, out.astype(np.float32), write=True, fallback=fallback)


def write_image(
    path: Path, pixels: np.ndarray, shown: Path | None = None, *, data: bool = False
) -> None:
    """Write float32 ``pixels`` ((H, W) or (H, W, C), row 0 = top) as a scanline EXR
    naming its colour space (:func:`lookdev.pipeline.exr.write_exr`): the working space
    for RGB colour, ``Raw`` for data (``data``, or one channel)."""
    try:
        write_exr(path, pixels, colour_space_of(pixels, data=data), shown=shown or path)
    except files.WriteError as exc:
        raise ExportError(exc.message) from None
