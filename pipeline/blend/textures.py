"""Parameter textures in the blending engine: opened once, folded when uniform, sampled per tile.

A layer's parameter may be a texture (:class:`~lookdev.materials.textures.TextureInput`,
opened as a :class:`~lookdev.library.textures.ParamTexture`). The engine treats its
values exactly as a constant's, per texel: Disney layers lerp them under the masks,
Pixar layers turn them into lobe weights texel by texel.

- A texture whose values are one number (its bounds, read once at load, are equal)
  folds into that constant before anything is planned: it costs no map.
- The output covers the UV region of the material's UDIM tiles (:func:`extent_of`), in
  whole UV squares; a plain texture repeats over it by its own wrap, a UDIM tile fills
  its own square (filtered with ``clamp`` at the tile's edges: its neighbour is
  another image) and a square no tile covers takes the layer's constant (the schema
  default).
- Values are decoded (colour-converted, remapped, clamped) a run of rows at a time by
  the reader and filtered after decoding, so filtering averages linear values.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lookdev.library.textures import Decoded, ParamTexture, udim_tiles
from lookdev.materials import colour
from lookdev.materials.fresnel import ior_to_specular
from lookdev.materials.textures import UDIM_TOKEN, tile_uv, udim_tile

from .masks import MaskSampler
from .stack import Decision, Entry

__all__ = ["extent_of", "open_textures", "sample"]


def open_textures(entries: list[Entry]) -> list[Decision]:
    """Open every layer's parameter textures into ``entry.decoded``; fold uniform ones
    into ``entry.params`` (a varying one leaves its largest value there, never read as
    the parameter's value). Returns a decision per folded texture."""
    decisions = []
    for entry in entries:
        entry.decoded = {}
        for key, tex in entry.textures.items():
            texture = ParamTexture(tex, key, type(entry.params), where=entry.where)
            value = texture.uniform()
            if value is None:
                entry.decoded[key] = texture
                if key != "ior":  # ior stays unset: its layer blends in the specular spelling
                    # The largest value stands in the constants, so rules that ask whether a
                    # parameter is ever non-zero (sheen votes on sheen_model) see it.
                    high = texture.bounds_after_clamp()[1]
                    top = float(high[0]) if texture.count == 1 else tuple(map(float, high))
                    entry.params = entry.params.model_copy(update={key: top})
                continue
            entry.params = entry.params.model_copy(update={key: value})
            reason = f"{key}: texture {tex.texture} is uniform, folded to {value!r}"
            decisions.append(Decision(entry.label, True, reason))
    return decisions


def extent_of(entries: list[Entry], patterns: list[str] = ()) -> tuple[int, int, int, int]:
    """(0, 0, u1, v1): the UV squares from tile 1001 to the far corner of the UDIM textures
    of ``entries`` (and of the UDIM ``patterns``: a texture set's height and normal maps);
    (0, 0, 1, 1) when there are none."""
    extents = [t.extent for e in entries for t in e.decoded.values() if None not in t.tiles]
    for pattern in patterns:
        uvs = [tile_uv(t) for t in udim_tiles(pattern)] if UDIM_TOKEN in pattern else []
        if uvs:
            extents.append((0, 0, max(u for u, _ in uvs) + 1, max(v for _, v in uvs) + 1))
    if not extents:
        return (0, 0, 1, 1)
    u0, v0, u1, v1 = zip(*extents, strict=True)
    return (min(u0), min(v0), max(u1), max(v1))


def sample(sampler: MaskSampler, entry: Entry, key: str, rows: slice) -> np.ndarray:
    """The values of ``entry``'s texture ``key`` on output ``rows``: (n, W, count) float32.

    ``key`` ``"specular"`` of a layer whose ``ior`` is textured gives the specular that
    IOR spells (Burley's blending space, :func:`~lookdev.materials.fresnel.ior_to_specular`).
    """
    if key == "specular" and "ior" in entry.decoded and "specular" not in entry.decoded:
        return ior_to_specular(sample(sampler, entry, "ior", rows)).astype(np.float32)
    texture = entry.decoded[key]
    n = len(range(*rows.indices(sampler.height)))
    if None in texture.tiles:  # a plain texture repeats over the extent by its wrap
        tex = texture.tex
        cache = _decoded(sampler, texture, None)
        scale, offset = sampler.extent_map(tex.uv_scale, tex.uv_offset)
        shape = (sampler.height, sampler.width)
        return sampler.filtered(cache, shape, scale, offset, tex.wrap, rows)
    u0, v0, u1, v1 = sampler.extent
    per_v, per_u = sampler.height // (v1 - v0), sampler.width // (u1 - u0)
    out = np.empty((n, sampler.width, texture.count), dtype=np.float32)
    fallback = np.asarray(getattr(entry.params, key), dtype=np.float32)
    start = rows.start or 0
    for v in range(v0, v1):
        lo, hi = (v - v0) * per_v, (v - v0 + 1) * per_v
        local = slice(max(lo, start) - lo, min(hi, start + n) - lo)
        if local.start >= local.stop:
            continue
        dest = slice(local.start + lo - start, local.stop + lo - start)
        for u in range(u0, u1):
            cols = slice((u - u0) * per_u, (u - u0 + 1) * per_u)
            tile = udim_tile(u, v)
            if tile not in texture.files:
                out[dest, cols] = fallback
                continue
            cache = _decoded(sampler, texture, tile)
            block = (per_v, per_u)
            out[dest, cols] = sampler.filtered(cache, block, (1, 1), (0, 0), "clamp", local)
    return out


def _decoded(sampler: MaskSampler, texture: ParamTexture, tile: int | None) -> tuple[Any, ...]:
    """The cache key under which ``sampler`` holds one tile's values, made ready: the file's
    texels as stored (whole while they fit the sampler's budget, a uint8 texel costing a
    byte, else streamed by rows), decoded to float32 a run of rows at a time as tiles of
    the output ask for them (so an 8-bit 4K tile costs 16 MB a channel, not 64)."""
    file = texture.files[tile]
    stored = ("stored", str(file.path), file.first, file.count)
    sampler.source(stored, lambda: file)
    key = ("param", texture.tex, texture.count, texture.bounds, tile, colour.settings())
    sampler.source(key, lambda: Decoded(texture, sampler.source(stored, None)), lazy=True)
    return key
