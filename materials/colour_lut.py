"""The view transform baked into a 3D LUT: the display transform's fast path.

:func:`.colour.to_display` runs the config's ``DisplayViewTransform`` exactly or through
this bake of it. ACES 2.0's output transform is analytic and costly (≈ 0.6 µs a pixel on
one core, ≈ 40 ms a 480×240 proof frame); OCIO applies a 65³ LUT behind a log shaper in
≈ 3.4 ms. The bake runs the exact processor on the LUT's vertices, so it is that
transform sampled, not a second one: the shaper is ``log2(x + 2**LO)`` scaled so that
``[0, 2**HI]`` fills the cube (OCIO's ``ALLOCATION_LG2``), and OCIO interpolates
tetrahedrally between vertices. Inputs above ``2**HI`` clamp to the cube's face, so the
bake is used only for a view that reaches its top by then (:func:`saturates`): ACES 2.0
SDR shows any Rec.709 colour with a channel at 2¹⁰ as white, and code 0.013 of 255 at
2⁻¹⁰ grey.

Measured against the exact processor (studio config, ``sRGB - Display`` / ``ACES 2.0 -
SDR 100 nits (Rec.709)``, linear Rec.709), in 8-bit code values: over the 96 frames (raw
and denoised, 11.1 M pixels) of ``lookdev proof gold glass_clear skin --ibl sky --ibl
studio``, mean difference 0.11 a channel, 29 % of pixels differ by 1 in some channel,
0.006 % by 2–3, never more; over a sweep of 200 000 random colours, log-uniform in
2⁻²⁴…2²⁴ a channel (a tenth of the channels 0), the worst is 17, at saturated blues at the
display gamut's edge (``(0, 0, 1.85)``: exact ``(3, 0, 255)``, the bake ``(14, 17, 251)``),
0.4 % of them by more than 1. Grey from 0 to 1e30 is within 1. A bigger cube buys little
for its build: 97³ reaches at most 2 on the frames, but its bake costs 0.54 s a process
against 0.14 s for 65³.

OCIO shares processors between equal transforms through a config's cache; the bake
builds its processor from a raw config of its own (the LUT names no colour space).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import PyOpenColorIO as ocio

__all__ = ["SIZE", "LO", "HI", "vertices", "saturates", "bake"]

SIZE = 65
"""Vertices a side of the cube (65³ = 274 625 exact evaluations per bake)."""
LO = -12.0
"""log2 of the shaper's offset: values below ``2**LO`` share its first cells, linearly."""
HI = 12.0
"""log2 of the largest value the cube holds; above, a channel clamps to the face."""

_HUES = np.array(
    [(1, 1, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (0, 1, 1), (1, 0, 1), (1, 0.1, 0.05)],
    np.float32,
)


def _axis() -> np.ndarray:
    t = np.linspace(0.0, 1.0, SIZE)
    return (2.0 ** (LO + t * (HI - LO)) - 2.0**LO).astype(np.float32)


def vertices() -> np.ndarray:
    """The scene-linear values (SIZE³, 3) at the cube's vertices, red slowest (OCIO's order)."""
    g = _axis()
    return np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3).copy()


def saturates(apply: Any) -> bool:
    """Whether ``apply(pixels (…, 3)) -> display values`` shows every probe hue with a channel
    at ``2**HI`` as it shows it at 2¹²⁸ (within 0.1 code value of 255): then the cube's face
    is right for everything above it."""
    top = apply(_HUES * np.float32(2.0**HI))
    far = apply(_HUES * np.float32(2.0**120))
    return bool(np.max(np.abs(top - far)) * 255.0 <= 0.1)


def bake(values: np.ndarray) -> Any:
    """An OCIO CPU processor: the shaper, then the LUT of ``values`` (SIZE³, 3), the display
    values of :func:`vertices`, interpolated tetrahedrally."""
    shaper = ocio.AllocationTransform(allocation=ocio.ALLOCATION_LG2, vars=[LO, HI, 2.0**LO])
    lut = ocio.Lut3DTransform(gridSize=SIZE)
    lut.setData(np.ascontiguousarray(values, dtype=np.float32).reshape(-1))
    lut.setInterpolation(ocio.INTERP_TETRAHEDRAL)
    processor = ocio.Config.CreateRaw().getProcessor(ocio.GroupTransform([shaper, lut]))
    return processor.getOptimizedCPUProcessor(ocio.OPTIMIZATION_LOSSLESS)
