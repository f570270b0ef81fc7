"""Small builders for the blending tests: images written with OpenImageIO, materials."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import OpenImageIO as oiio

from lookdev.library import Layer, Material
from lookdev.materials.layers import ConstantMask
from lookdev.materials.params import DisneyParams


def write_image(path: Path, pixels: np.ndarray, fmt=oiio.FLOAT, names=None) -> Path:
    """Write ``pixels`` (rows as stored in the file: top row first; (H, W) or (H, W, C))."""
    pixels = np.ascontiguousarray(pixels, dtype=np.float32)
    if pixels.ndim == 2:
        pixels = pixels[..., None]
    height, width, channels = pixels.shape
    spec = oiio.ImageSpec(width, height, channels, fmt)
    if names:
        spec.channelnames = tuple(names)
    spec.attribute("oiio:UnassociatedAlpha", 1)  # store channels as given, even beside alpha
    buf = oiio.ImageBuf(spec)
    assert buf.set_pixels(oiio.ROI(0, width, 0, height, 0, 1, 0, channels), pixels)
    assert buf.write(str(path)), buf.geterror()
    return path


def disney(name: str = "m", **params: Any) -> Material:
    return Material(name=name, model="disney", params=DisneyParams.parse(params))


def layer(material: Material, mask: Any = None, **kw: Any) -> Layer:
    return Layer(material=material, mask=mask if mask is not None else ConstantMask(), **kw)


def layered(*layers: Layer, name: str = "stack") -> Material:
    return Material(name=name, model="layered", layers=list(layers))
