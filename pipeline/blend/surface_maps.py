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

from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library.textures import udim_tiles as find_tiles
from lookdev.materials.layers import TextureMask
from lookdev.materials.textures import UDIM_TOKEN, tile_uv

from .errors import TextureError
from .resample import as_float, read_channels, resample, taps
from .result import BlendedMaterial

__all__ = ["attach", "udim_tiles"]


def udim_tiles(pattern: str | Path, *, where: str | None = None) -> dict[tuple[int, int], Path]:
    """``{(u, v): file}`` of a ``<UDIM>`` pattern's tiles on disk (1001 + u + 10·v), found
    by the library's one tile lookup (:func:`lookdev.library.textures.udim_tiles`)."""
    pattern = Path(pattern)
    if UDIM_TOKEN not in pattern.name:
        return {(0, 0): pattern}
    found = {tile_uv(t): path for t, path in find_tiles(pattern).items()}
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


def read_tiled(
    pattern: str | Path,
    count: int,
    shape: tuple[int, int],
    *,
    where: str,
    grid: tuple[int, int] | None = None,
):
    """A (tile set of) image(s) at ``shape`` texels per tile: ((nv·h, nu·w, count), (nu, nv));
    ``grid`` (nu, nv) is the hub's when its other maps already span more tiles."""
    tiles = udim_tiles(pattern, where=where)
    nu = max(max(u for u, _ in tiles) + 1, grid[0] if grid else 1)
    nv = max(max(v for _, v in tiles) + 1, grid[1] if grid else 1)
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
    # hub.resolution spans its UDIM extent (the engine widened it to these sets' tiles too)
    grid = hub.map_tiles
    width, h = hub.resolution[0] // grid[0], hub.resolution[1] // grid[1]
    where = str(getattr(material, "source", None) or hub.name)
    if height is not None:
        pixels, tiles = read_tiled(height.texture, 1, (h, width), where=where, grid=grid)
        value = pixels[..., 0]
        if height.range is not None:
            lo, hi = height.range
            value = (value - lo) / (hi - lo)
        hub.height_map = (value * height.scale + height.offset).astype(np.float32)
        hub.map_tiles = tiles
        hub.textures["height"] = height
    if normal is not None and hub.normal_map is None:
        pixels, tiles = read_tiled(normal.path, 3, (h, width), where=where, grid=grid)
        n = 2.0 * pixels - 1.0
        if any("DirectX" in note for note in getattr(material, "notes", [])):
            n[..., 1] = -n[..., 1]
        n /= np.maximum(np.linalg.norm(n, axis=-1, keepdims=True), 1e-12)
        hub.normal_map = n.astype(np.float32)
        hub.map_tiles = tiles
    return hub
