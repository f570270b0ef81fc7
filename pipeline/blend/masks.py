"""Evaluate any :data:`~lookdev.materials.layers.Mask` at any resolution.

A mask evaluates to float32 (H, W) coverage in 0..1, in UV order: row ``r``, column ``c``
is the texel centred on ``(u, v) = ((c + ½)/W, (r + ½)/H)``, so row 0 is v ≈ 0, the bottom
of the image (see :mod:`.resample`).

**The clamp.** Every mask is clamped to 0..1 *after* filtering. Filtering is linear and
sees the data as stored, so a minified mask is the true average of the file; the clamp
then keeps coverage meaningful: a blend ``lerp(below, layer, m)`` with ``m`` outside 0..1
would extrapolate parameters past both layers (negative roughness, colours brighter than
either). Float images (EXR) can hold values outside 0..1, and levels/contrast can push
values out; both are clamped the same way.

**Bounds before pixels.** :meth:`MaskSampler.bounds` gives a conservative (low, high) of a
mask from its sources alone (a texture's min and max, interval arithmetic through the
combinations), so the engine can fold uniform masks, drop zero layers and prune layers
under full coverage without evaluating a single texel.

>>> from lookdev.materials.layers import RampMask
>>> MaskSampler((1, 4)).evaluate(RampMask(axis="u")).tolist()
[[0.125, 0.375, 0.625, 0.875]]
"""

from __future__ import annotations

import math
from functools import reduce
from typing import Any

import numpy as np

from lookdev.materials.layers import (
    ConstantMask,
    InvertMask,
    LevelsMask,
    Mask,
    NoiseMask,
    RampMask,
    TextureMask,
)

from .resample import TextureFile, as_float, resample, taps

__all__ = [
    "BoxReduced",
    "MaskSampler",
    "WHOLE_BUDGET",
    "combine",
    "fractal_noise",
    "levels",
    "ramp",
]

WHOLE_BUDGET = 0.5
"""Share of the output's bytes that textures decoded whole may take; the rest stream."""


class MaskSampler:
    """Evaluates masks for one output resolution, reading each texture once.

    ``resolution`` is ``(height, width)``. ``images`` is a cache of decoded texture
    channels, ``{key: (source, (min, max))}``; pass one dict to several samplers (other
    resolutions, other materials sharing masks) to decode each file once, whole.

    Without ``images``, a sampler decodes textures whole only while they fit in
    :data:`WHOLE_BUDGET` of the output, ``output_channels`` float32 channels at its
    resolution (the engine's bound on what a blend writes); larger ones stay in their
    files (:class:`.resample.TextureFile`) and each tile reads the rows it needs, so a
    4096² float mask that varies one 2048² map costs rows, not 64 MB. A file whose format
    cannot be read by rows (PNG, JPEG: :data:`lookdev.library.images.RANDOM_ACCESS`) is
    held whole as stored, a byte per 8-bit channel, whatever its size.
    """

    def __init__(
        self,
        resolution: tuple[int, int],
        images: dict | None = None,
        output_channels: float = math.inf,
        extent: tuple[int, int, int, int] = (0, 0, 1, 1),
    ):
        """``extent`` (u0, v0, u1, v1) is the UV region the output covers, in whole UV
        squares (a UDIM set's tiles, see :class:`.result.BlendedMaterial`); texel centres
        are ``u = u0 + (c + ½)/W · (u1 − u0)`` and likewise in v."""
        self.height, self.width = resolution
        self.extent = extent
        output_bytes = output_channels * self.height * self.width * 4
        self._budget = math.inf if images is not None else WHOLE_BUDGET * output_bytes
        self._images: dict[tuple, Any] = {} if images is None else images
        self._tap_cache: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
        self._mips: dict[tuple, np.ndarray] = {}
        self._bounds: dict[tuple, tuple[float, float]] = {}

    def image(self, tex: TextureMask, count: int = 1, *, where: str | None = None) -> Any:
        """The source channels of ``tex``, as stored (see :func:`.read_channels`): an array
        when decoded whole, else a :class:`.TextureFile` indexed by rows the same way."""
        key = (str(tex.path), tex.channel, count)
        return self.source(key, lambda: TextureFile(tex, count, where=where))

    def source(self, key: tuple, opener: Any, *, lazy: bool = False) -> Any:
        """The source cached under ``key`` (``opener()`` makes it: a :class:`.TextureFile`
        or anything indexed by rows like one), decoded whole while it fits the budget;
        ``lazy`` keeps it as it is (a view that decodes rows of a source held here)."""
        if key not in self._images:
            source = opener()
            fits = self._whole_bytes() + source.nbytes <= self._budget
            # A file that cannot be read rows at a time is held whole, as stored (a byte per
            # 8-bit channel): streaming it would decode it again from the top for every tile.
            if not lazy and (fits or not getattr(source, "random_access", True)):
                source = source[np.arange(source.shape[0])]
            self._images[key] = source
        return self._images[key]

    def extent_map(self, scale: tuple[float, float], offset: tuple[float, float]):
        """A texture's UV scale and offset as seen from the output's 0..1 texel grid:
        ``s = (e0 + t·Δe)·scale + offset`` = ``t·(scale·Δe) + (e0·scale + offset)``."""
        u0, v0, u1, v1 = self.extent
        (su, sv), (ou, ov) = scale, offset
        return (su * (u1 - u0), sv * (v1 - v0)), (u0 * su + ou, v0 * sv + ov)

    def lookup(
        self, tex: TextureMask, count: int = 1, rows: slice | None = None, *, where=None
    ) -> np.ndarray:
        """Filtered texture values at the output texels of ``rows``: (n, W, count)."""
        key = (str(tex.path), tex.channel, count)
        self.image(tex, count, where=where)
        scale, offset = self.extent_map(tex.uv_scale, tex.uv_offset)
        shape = (self.height, self.width)
        return self.filtered(key, shape, scale, offset, tex.wrap, rows or slice(0, self.height))

    def filtered(self, key, shape, scale, offset, wrap, rows: slice) -> np.ndarray:
        """The source cached under ``key`` filtered onto a ``shape`` (h, w) grid covering the
        source's UV square ``scale``·t + ``offset``, output rows ``rows``: (n, w, count).

        Where an output texel covers more than 4 source texels along an axis (strong
        minification, or many repeats), the source is first box-reduced along it by a
        power of two (a mip level) that leaves a footprint of 2 to 4 texels, so the cost
        does not grow with the footprint.
        """
        src = self._images[key]
        (su, sv), (ou, ov) = scale, offset
        kv = _mip_factor(src.shape[0], sv, shape[0])
        ku = _mip_factor(src.shape[1], su, shape[1])
        if kv > 1 or ku > 1:
            src = self._reduced(key, kv, ku)
        h, w = src.shape[:2]
        v_idx, v_w = self._taps(shape[0], h, sv, ov, wrap)
        u_taps = self._taps(shape[1], w, su, ou, wrap)
        return resample(src, (v_idx[rows], v_w[rows]), u_taps)

    def _reduced(self, key: tuple, kv: int, ku: int) -> Any:
        """The source averaged over kv × ku blocks (float32, cached): whole while it fits
        the budget, else rows reduced when a tile asks for them."""
        mip = (*key, kv, ku)
        if mip not in self._mips:
            reduced = BoxReduced(self._images[key], kv, ku)
            if self._whole_bytes() + reduced.nbytes <= self._budget:
                reduced = reduced[np.arange(reduced.shape[0])]
            self._mips[mip] = reduced
        return self._mips[mip]

    def _whole_bytes(self) -> int:
        """Bytes of the textures and reductions this sampler holds decoded whole."""
        held = list(self._images.values()) + list(self._mips.values())
        return sum(a.nbytes for a in held if isinstance(a, np.ndarray))

    def _taps(self, *key) -> tuple[np.ndarray, np.ndarray]:
        """Taps of a whole axis (:func:`.resample.taps`), computed once per sampler."""
        if key not in self._tap_cache:
            self._tap_cache[key] = taps(*key)
        return self._tap_cache[key]

    def evaluate(self, mask: Mask, rows: slice | None = None, *, where=None) -> np.ndarray:
        """Coverage of ``mask`` on output rows ``rows`` (all rows by default), float32 (n, W)."""
        rows = rows or slice(0, self.height)
        n = len(range(*rows.indices(self.height)))
        out = self._node(mask, rows, n, where)
        if np.ndim(out) == 0:
            return np.full((n, self.width), out, dtype=np.float32)
        return np.clip(out, 0.0, 1.0, out=out).astype(np.float32, copy=False)

    def _node(self, mask: Mask, rows: slice, n: int, where) -> np.ndarray | float:
        """One node's values before the final clamp; constants stay scalars."""
        if isinstance(mask, ConstantMask):
            return np.float32(mask.value)
        if isinstance(mask, TextureMask):
            value = np.clip(self.lookup(mask, 1, rows, where=where)[..., 0], 0.0, 1.0)
            return 1.0 - value if mask.invert else value
        if isinstance(mask, NoiseMask):
            u, v = self._uv(rows)
            return fractal_noise(mask, u, v, self.height, self.width)
        if isinstance(mask, RampMask):
            u, v = self._uv(rows)
            return np.broadcast_to(ramp(mask, u, v), (n, self.width)).astype(np.float32)
        if isinstance(mask, InvertMask):
            return 1.0 - self._node(mask.input, rows, n, where)
        if isinstance(mask, LevelsMask):
            return levels(mask, self._node(mask.input, rows, n, where))
        values = [self._node(m, rows, n, where) for m in mask.inputs]
        return combine(mask.kind, values)

    def _uv(self, rows: slice) -> tuple[np.ndarray, np.ndarray]:
        """Texel-centre UVs of ``rows`` over the extent: u as (1, W), v as (n, 1), float64."""
        u0, v0, u1, v1 = self.extent
        u = u0 + (np.arange(self.width) + 0.5) / self.width * (u1 - u0)
        v = v0 + (np.arange(self.height)[rows] + 0.5) / self.height * (v1 - v0)
        return u[None, :], v[:, None]

    def bounds(self, mask: Mask, *, where=None) -> tuple[float, float]:
        """A conservative (low, high) of the mask's values at this resolution.

        Exact for constants and combinations of constants; a texture's range is that of
        its stored texels (clamped, inverted; 0 included where ``wrap="black"`` reads past
        the edge). Reads textures, never evaluates a full mask.
        """
        if isinstance(mask, ConstantMask):
            return mask.value, mask.value
        if isinstance(mask, TextureMask):
            return self._texture_bounds(mask, where)
        if isinstance(mask, NoiseMask):
            return 0.0, 1.0
        if isinstance(mask, RampMask):
            u, v = self._uv(slice(0, self.height))
            return _ramp_bounds(mask, u[0], v[:, 0])
        if isinstance(mask, InvertMask):
            lo, hi = self.bounds(mask.input, where=where)
            return 1.0 - hi, 1.0 - lo
        if isinstance(mask, LevelsMask):
            lo, hi = self.bounds(mask.input, where=where)
            return float(levels(mask, np.float64(lo))), float(levels(mask, np.float64(hi)))
        parts = [self.bounds(m, where=where) for m in mask.inputs]
        lows, highs = zip(*parts, strict=True)
        return float(combine(mask.kind, list(lows))), float(combine(mask.kind, list(highs)))

    def _texture_bounds(self, tex: TextureMask, where) -> tuple[float, float]:
        key = (str(tex.path), tex.channel, 1)
        source = self.image(tex, 1, where=where)
        if key not in self._bounds:
            whole = isinstance(source, np.ndarray)
            self._bounds[key] = _min_max([source] if whole else (a for _, a in source.chunks()))
        lo, hi = (min(max(x, 0.0), 1.0) for x in self._bounds[key])
        if tex.wrap == "black" and self._reads_outside(tex):
            lo = 0.0
        return (1.0 - hi, 1.0 - lo) if tex.invert else (lo, hi)

    def _reads_outside(self, tex: TextureMask) -> bool:
        h, w = self.image(tex).shape[:2]
        (su, sv), (ou, ov) = self.extent_map(tex.uv_scale, tex.uv_offset)
        v_w = taps(self.height, h, sv, ov, "black")[1].sum(axis=1)
        u_w = taps(self.width, w, su, ou, "black")[1].sum(axis=1)
        return bool((v_w < 1 - 1e-6).any() or (u_w < 1 - 1e-6).any())


class BoxReduced:
    """A source (array or :class:`.TextureFile`) averaged over kv × ku texel blocks, the
    rows computed when indexed (``reduced[rows]``), from the source rows under them."""

    def __init__(self, source: Any, kv: int, ku: int):
        h, w, count = source.shape
        self.source, self.kv, self.ku = source, kv, ku
        self.shape = (h // kv, w // ku, count)
        self.dtype = np.dtype(np.float32)
        self.nbytes = self.shape[0] * self.shape[1] * count * 4

    def __getitem__(self, rows: np.ndarray) -> np.ndarray:
        rows = np.asarray(rows, dtype=np.int64)
        wanted = np.unique(rows)
        under = (wanted[:, None] * self.kv + np.arange(self.kv)).ravel()
        a = as_float(self.source[under])
        n, (_, w, count) = len(wanted), self.shape
        blocks = a.reshape(n, self.kv, w, self.ku, count)
        out = blocks.mean(axis=(1, 3), dtype=np.float64).astype(np.float32)
        return out[np.searchsorted(wanted, rows)]


def _min_max(chunks) -> tuple[float, float]:
    """The smallest and largest texel over ``chunks`` (as stored), normalised like
    :func:`.as_float`."""
    lo, hi = math.inf, -math.inf
    for a in chunks:
        if a.size:
            bounds = as_float(np.array([a.min(), a.max()], dtype=a.dtype))
            lo, hi = min(lo, float(bounds[0])), max(hi, float(bounds[1]))
    return lo, hi


def _mip_factor(n_src: int, scale: float, n_out: int) -> int:
    """Largest power of two dividing ``n_src`` that keeps the footprint ≥ 2 texels.

    >>> _mip_factor(1024, 32.0, 256), _mip_factor(1024, 1.0, 512), _mip_factor(1000, 1.0, 10)
    (64, 1, 8)
    """
    footprint = abs(scale) * n_src / n_out
    k = 1
    while footprint / (2 * k) >= 2.0 and n_src % (2 * k) == 0:
        k *= 2
    return k


def combine(kind: str, values: list):
    """Per-texel combination of masks; monotone in every input, so bounds map to bounds.

    ``screen`` is ``1 − Π(1 − m)`` (Photoshop's screen, lighter than either input).

    >>> combine("screen", [0.5, 0.5]), combine("multiply", [0.5, 0.5])
    (0.75, 0.25)
    """
    if kind == "multiply":
        return reduce(lambda a, b: a * b, values)
    if kind == "screen":
        return 1.0 - reduce(lambda a, b: a * b, [1.0 - v for v in values])
    if kind == "max":
        return reduce(np.maximum, values)
    return reduce(np.minimum, values)


def levels(mask: LevelsMask, m):
    """Photoshop-style levels (see :class:`~lookdev.materials.layers.LevelsMask`).

    >>> float(levels(LevelsMask(input=1.0, low=0.25, high=0.75), np.float64(0.5)))
    0.5
    """
    v = np.clip((m - mask.low) / (mask.high - mask.low), 0.0, 1.0) ** (1.0 / mask.gamma)
    v = np.clip((v - 0.5) * mask.contrast + 0.5, 0.0, 1.0)
    return mask.out_low + (mask.out_high - mask.out_low) * v


def ramp(mask: RampMask, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Gradient from 0 at ``start`` to 1 at ``end`` along u, v or the radius from (½, ½)."""
    if mask.axis == "radial":
        return _ramp_profile(mask, np.hypot(u - 0.5, v - 0.5))
    return _ramp_profile(mask, u if mask.axis == "u" else v)


def _ramp_profile(mask: RampMask, t: np.ndarray) -> np.ndarray:
    """The ramp as a function of its coordinate; ``smooth`` is smoothstep ``3t² − 2t³``."""
    t = np.clip((t - mask.start) / (mask.end - mask.start), 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t) if mask.interpolation == "smooth" else t


def _ramp_bounds(mask: RampMask, u: np.ndarray, v: np.ndarray) -> tuple[float, float]:
    """Exact range of a ramp over the texel centres ``u`` and ``v`` (it is monotone in its
    coordinate; radially, the nearest centre to (½, ½) and the farthest corner)."""
    if mask.axis == "radial":
        du, dv = np.abs(u - 0.5), np.abs(v - 0.5)
        t = np.array([np.hypot(du.min(), dv.min()), np.hypot(du.max(), dv.max())])
    else:
        t = np.array([u.min(), u.max()] if mask.axis == "u" else [v.min(), v.max()])
    values = _ramp_profile(mask, t)
    return float(values.min()), float(values.max())


def fractal_noise(mask: NoiseMask, u: np.ndarray, v: np.ndarray, height: int, width: int):
    """Tileable fractal value noise (fBm), float32 in 0..1, deterministic in ``seed``.

    Octave k is value noise on a lattice of ``P_k = max(1, round(scale · lacunarity^k))``
    cells per unit (periodic in P_k, hence tileable with period 1), quintic-interpolated,
    weighted ``gain^k``; the sum is divided by Σ gain^k so it stays in 0..1. Octaves
    whose lattice is finer than the output can resolve (P_k > min(H, W)/2, the Nyquist
    limit) are replaced by their mean ½: that is the filtered value of an octave that
    would only alias.
    """
    nyquist = min(height, width) / 2.0
    total = np.zeros(np.broadcast_shapes(u.shape, v.shape), dtype=np.float32)
    norm = 0.0
    for k in range(mask.octaves):
        amp = mask.gain**k
        period = max(1, round(mask.scale * mask.lacunarity**k))
        octave = 0.5 if period > nyquist else _value_noise(u, v, period, mask.seed, k)
        total += np.float32(amp) * octave
        norm += amp
    return total * np.float32(1.0 / norm)


def _value_noise(u: np.ndarray, v: np.ndarray, period: int, seed: int, octave: int):
    """Periodic value noise at a row of u (1, W) and a column of v (n, 1): (n, W).

    The lattice (period² hashed values) is built once; bilinear interpolation with the
    quintic fade is separable, so rows are mixed in v first (n × period), then in u.
    """
    cells = np.arange(period)
    lattice = _hash01(cells[None, :], cells[:, None], seed, octave).astype(np.float32)
    x0, fx = _cell(u[0], period)
    y0, fy = _cell(v[:, 0], period)
    rows = lattice[y0] * (1.0 - fy[:, None]) + lattice[(y0 + 1) % period] * fy[:, None]
    return rows[:, x0] * (1.0 - fx) + rows[:, (x0 + 1) % period] * fx


def _cell(t: np.ndarray, period: int) -> tuple[np.ndarray, np.ndarray]:
    """Lattice cell (wrapped) and faded position inside it of coordinates ``t``."""
    x = t * period
    x0 = np.floor(x)
    return x0.astype(np.int64) % period, _fade(x - x0).astype(np.float32)


def _fade(t: np.ndarray) -> np.ndarray:
    """Perlin's quintic ``6t⁵ − 15t⁴ + 10t³`` (C2 across lattice cells)."""
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def _hash01(ix: np.ndarray, iy: np.ndarray, seed: int, octave: int) -> np.ndarray:
    """Lattice value in [0, 1) from integer coordinates: a 32-bit integer avalanche hash.

    Platform independent (wrapping uint32 arithmetic), so a seed means the same mask on
    every machine.
    """
    h = np.uint32((seed * 0x9E3779B1 ^ octave * 0x85EBCA77) & 0xFFFFFFFF)
    h = h ^ (ix.astype(np.uint32) * np.uint32(0xC2B2AE3D))
    h = h ^ (iy.astype(np.uint32) * np.uint32(0x27D4EB2F))
    for shift, mul in ((16, 0x7FEB352D), (15, 0x846CA68B)):
        h = (h ^ (h >> np.uint32(shift))) * np.uint32(mul)
    h = h ^ (h >> np.uint32(16))
    return h.astype(np.float64) / 4294967296.0
