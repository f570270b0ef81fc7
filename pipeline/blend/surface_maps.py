"""A preset's own height and normal maps on the hub (not blended: a plain preset has one).

A preset's ``height = { texture = …, scale = … }`` (or the height channel of its texture
set) becomes :attr:`~.result.BlendedMaterial.height_map`: float32 (H, W) heights in scene
units, value = ``texel · scale + offset`` (the :class:`~lookdev.materials.textures.
TextureInput` rule; heights are data, never colour-converted), and
``textures["height"]`` so exporters reference the file. A texture set's normal map
becomes :attr:`~.result.BlendedMaterial.normal_map` (unit vectors; a DirectX map's
green channel flipped to OpenGL's +Y).

UDIM sets: the maps cover the tiles' bounding box in UV, ``u ∈ [0, nu)``, ``v ∈ [0, nv)``
(tile 1001 + u + 10·v), at H×W texels per tile;
:attr:`~.result.BlendedMaterial.map_tiles` records ``(nu, nv)``. A missing tile inside
the box reads as the set's mean.
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials.layers import TextureMask
from lookdev.materials.textures import UDIM_TOKEN

from .errors import TextureError
from .resample import as_float, read_channels, resample, taps
from .result import BlendedMaterial

__all__ = ["attach", "udim_tiles"]


def udim_tiles(pattern: str | Path, *, where: str | None = None) -> dict[tuple[int, int], Path]:
    """``{(u, v): file}`` of a ``<UDIM>`` pattern's tiles on disk (1001 + u + 10·v)."""
    pattern = Path(pattern)
    if UDIM_TOKEN not in pattern.name:
        return {(0, 0): pattern}
    head, tail = pattern.name.split(UDIM_TOKEN, 1)
    regex = re.compile(re.escape(head) + r"(1\d{3})" + re.escape(tail) + r"\Z")
    found: dict[tuple[int, int], Path] = {}
    if pattern.parent.is_dir():
        for path in pattern.parent.iterdir():
            m = regex.match(path.name)
            if m:
                n = int(m.group(1)) - 1001
                found[(n % 10, n // 10)] = path
    if not found:
        raise TextureError(f"no UDIM tiles match {pattern}", where=where)
    return found


def _read(path: Path, count: int, shape: tuple[int, int], where: str) -> np.ndarray:
    """``count`` channels of one file resampled to ``shape`` (h, w), UV order."""
    src = read_channels(TextureMask(path=path), count, where=where)
    h, w = shape
    return resample(
        src,
        taps(h, src.shape[0], 1.0, 0.0, "periodic"),
        taps(w, src.shape[1], 1.0, 0.0, "periodic"),
    )


def read_tiled(pattern: str | Path, count: int, shape: tuple[int, int], *, where: str):
    """A (tile set of) image(s) at ``shape`` texels per tile: ((nv·h, nu·w, count), (nu, nv))."""
    tiles = udim_tiles(pattern, where=where)
    nu = max(u for u, _ in tiles) + 1
    nv = max(v for _, v in tiles) + 1
    h, w = shape
    out = np.empty((nv * h, nu * w, count), dtype=np.float32)
    filled = np.zeros((nv, nu), dtype=bool)
    for (u, v), path in tiles.items():
        out[v * h : (v + 1) * h, u * w : (u + 1) * w] = as_float(_read(path, count, shape, where))
        filled[v, u] = True
    if not filled.all():
        mean = np.mean(
            [out[v * h : (v + 1) * h, u * w : (u + 1) * w].mean(axis=(0, 1)) for (u, v) in tiles],
            axis=0,
        )
        for v, u in zip(*np.nonzero(~filled), strict=True):
            out[v * h : (v + 1) * h, u * w : (u + 1) * w] = mean
    return out, (nu, nv)


def attach(hub: BlendedMaterial, material: Any) -> BlendedMaterial:
    """Put ``material``'s height and normal map (if any) on ``hub``; returns ``hub``."""
    height = getattr(material, "height", None)
    normal = getattr(material, "normal_map", None)
    if height is None and normal is None:
        return hub
    width, h = hub.resolution
    where = str(getattr(material, "source", None) or hub.name)
    if height is not None:
        pixels, tiles = read_tiled(height.texture, 1, (h, width), where=where)
        value = pixels[..., 0]
        if height.range is not None:
            lo, hi = height.range
            value = (value - lo) / (hi - lo)
        hub.height_map = (value * height.scale + height.offset).astype(np.float32)
        hub.map_tiles = tiles
        hub.textures["height"] = height
    if normal is not None and hub.normal_map is None:
        pixels, tiles = read_tiled(normal.path, 3, (h, width), where=where)
        n = 2.0 * pixels - 1.0
        if any("DirectX" in note for note in getattr(material, "notes", [])):
            n[..., 1] = -n[..., 1]
        n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)
        hub.normal_map = n.astype(np.float32)
        hub.map_tiles = tiles
    return hub
