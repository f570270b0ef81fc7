"""Images an export writes itself: maps converted for a target, baked masks.

A target input that is not an affine function of our parameter (a clearcoat roughness
from Burley's gloss, a colour from a scalar) cannot be expressed by a texture node's
scale and bias, so the exporter writes a converted copy of the map beside it.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from lookdev.library import files
from lookdev.pipeline.exr import colour_space_of, write_exr

from .names import Slot
from .network import ExportError, Image


def converted(image: Image, slot: Slot) -> Image:
    """``image`` with ``slot.to_target`` applied per texel, to be written beside it."""
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
    path = image.path.with_name(f"{image.path.stem}.{slot.input}.exr")
    return Image(path, out.astype(np.float32), write=True)


def write_image(path: Path, pixels: np.ndarray, shown: Path | None = None, *, data: bool) -> None:
    """Write float32 ``pixels`` ((H, W) or (H, W, C), row 0 = top) as an EXR naming its
    colour space: the working space for RGB colour, ``Raw`` for data (``data``, one channel)."""
    try:
        write_exr(path, pixels, colour_space_of(pixels, data=data), shown=shown or path)
    except files.WriteError as exc:
        raise ExportError(exc.message) from None
