"""The view transform baked into a 3D LUT: the display transform's fast path.

:func:`.colour.to_display` runs the config's ``DisplayViewTransform`` exactly or through
this bake of it. ACES 2.0's output transform is analytic and costly: ≈ 0.55 µs a pixel,
63–70 ms CPU a 480×240 proof frame; through the bake 4.5–8 ms, the numpy around it
included (96 proof frames, two runs each, load 3.2–3.6 from other work). The bake runs the
exact processor on the LUT's vertices, so it is that transform sampled, not a second one:
a 65³ cube behind the shaper ``log2(x + 2**LO)``, scaled so that ``[0, 2**HI]`` fills it
(OCIO's ``ALLOCATION_LG2``), interpolated tetrahedrally by OCIO. A channel above
``2**HI`` clamps to the cube's face, so a view is baked only if it reaches its top by
then (:func:`saturates`): ACES 2.0 SDR shows a Rec.709 colour with a channel at 2¹⁰ as
white, and 2⁻¹⁰ grey at 0.013 of a code value. The vertices hold the transform *without*
its final clamp to [0, 1] (:func:`unclamped`; the caller clips after the LUT), so cells
at the display gamut's edge interpolate a smooth function, not a kink: that halved the
worst differences below. A bake costs 0.18–0.30 s CPU, once per process and view.

Measured against the exact processor (studio config, ``sRGB - Display`` / ``ACES 2.0 -
SDR 100 nits (Rec.709)``, linear Rec.709), in 8-bit code values:

* the 96 frames (raw and denoised, 11.1 M pixels) of ``lookdev proof gold glass_clear
  skin --ibl sky --ibl studio``: mean 0.11 a channel, 29 % of pixels 1 off in some
  channel, 0.004 % 2 off, never more (the clamped cube: 3; a 49³ cube 5, 97³ 2 but a
  0.6 s bake);
* grey from 0 through 1e-8…1e30 (0, 1e-6, 18 % grey and 1e4 equal): at most 1;
* nine saturated hues (primaries, secondaries, orange, a red and a blue tinted) from 1e-6
  to 1e4, 400 steps: at most 7 (pure blue near 1.85, at the gamut's edge; magenta 4,
  orange 3), 0.5 % of them by more than 1;
* 200 000 random colours log-uniform in 2⁻²⁴…2²⁴ a channel (a tenth of channels 0): at
  most 8 (``(0, 3e-5, 1.86)``: exact ``(4, 0, 255)``, the bake ``(10, 8, 252)``), 0.37 % by
  more than 1;
* the same frames in ACEScg with ``acescg`` the working space: at most 4, 0.17 % by more
  than 1; through ``Un-tone-mapped``: at most 1.

OCIO shares processors between equal transforms through a config's cache; the bake's
processors come from a raw config of their own (they name no colour space).
"""

from __future__ import annotations

from typing import Any

import numpy as np
import PyOpenColorIO as ocio

__all__ = ["SIZE", "LO", "HI", "PROBE", "baked", "vertices", "saturates", "unclamped", "bake"]

SIZE = 65
"""Vertices a side of the cube (65³ = 274 625 exact evaluations per bake)."""
LO = -12.0
"""log2 of the shaper's offset: values below ``2**LO`` share its first cells, linearly."""
HI = 12.0
"""log2 of the largest value the cube holds; above, a channel clamps to the face."""

PROBE = 13
"""Every this many vertices checks that :func:`unclamped` differs only where it is clipped."""

_HUES = np.array(
    [(1, 1, 1), (1, 0, 0), (0, 1, 0), (0, 0, 1), (1, 1, 0), (0, 1, 1), (1, 0, 1), (1, 0.1, 0.05)],
    np.float32,
)


def _axis() -> np.ndarray:
    t = np.linspace(0.0, 1.0, SIZE)
    return (2.0 ** (LO + t * (HI - LO)) - 2.0**LO).astype(np.float32)


def baked(processor: Any, exact: Any, apply: Any) -> Any:
    """The bake of OCIO ``processor`` (a display transform; ``exact`` its CPU processor),
    or None when the view does not saturate within the cube (:func:`saturates`).

    ``apply(cpu, pixels (N, 3))`` runs a CPU processor in place (on every core). The
    vertices take :func:`unclamped`'s values, unless a :data:`PROBE` of them, clipped,
    differs from the exact transform's: then the clamped values themselves.
    """

    def run(cpu: Any, pixels: np.ndarray) -> np.ndarray:
        out = np.array(pixels, dtype=np.float32, order="C")
        apply(cpu, out.reshape(-1, 3))
        return out

    if not saturates(lambda pixels: np.clip(run(exact, pixels), 0.0, 1.0)):
        return None
    points = vertices()
    values = run(unclamped(processor), points)
    probe = np.clip(values[::PROBE], 0.0, 1.0) - np.clip(run(exact, points[::PROBE]), 0.0, 1.0)
    if np.max(np.abs(probe)) > 1e-6:  # a clamp does not commute with what follows it
        values = run(exact, points)
    return bake(values)


def vertices() -> np.ndarray:
    """The scene-linear values (SIZE³, 3) at the cube's vertices, red slowest (OCIO's order)."""
    g = _axis()
    return np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3).copy()


def saturates(apply: Any) -> bool:
    """Whether ``apply(pixels (…, 3)) -> display values`` shows every probe hue with a channel
    at ``2**HI`` as it shows it at 2¹²⁰ (within 0.1 of an 8-bit code value): then the cube's
    face is right for everything above it."""
    top = apply(_HUES * np.float32(2.0**HI))
    far = apply(_HUES * np.float32(2.0**120))
    return bool(np.max(np.abs(top - far)) * 255.0 <= 0.1)


def unclamped(processor: Any) -> Any:
    """A CPU processor of OCIO ``processor`` without its clamps to [0, 1] (``RangeTransform``).

    The display transform clamps its output (ACES 2.0: after the output transform, before
    the display's encoding); the bake interpolates the values around the clamp and
    :func:`.colour.to_display` clips after it, so a cube straddling the display gamut's edge
    interpolates a smooth function rather than a kink. That only holds when what follows
    a clamp maps [0, 1] onto itself monotonically (an encoding curve); the caller checks
    it on a :data:`PROBE` of the vertices.
    """
    group = ocio.GroupTransform()
    for transform in processor.getOptimizedProcessor(
        ocio.OPTIMIZATION_LOSSLESS
    ).createGroupTransform():
        if not _clamps_to_unit(transform):
            group.appendTransform(transform)
    return _cpu(group)


def _clamps_to_unit(transform: Any) -> bool:
    if not isinstance(transform, ocio.RangeTransform):
        return False
    ends = (transform.getMinInValue(), transform.getMaxInValue())
    return ends == (0.0, 1.0) == (transform.getMinOutValue(), transform.getMaxOutValue())


def _cpu(transform: Any) -> Any:
    # a raw config of its own: the transform names no colour space
    processor = ocio.Config.CreateRaw().getProcessor(transform)
    return processor.getOptimizedCPUProcessor(ocio.OPTIMIZATION_LOSSLESS)


def bake(values: np.ndarray) -> Any:
    """An OCIO CPU processor: the shaper, then the LUT of ``values`` (SIZE³, 3), the display
    values of :func:`vertices`, interpolated tetrahedrally."""
    shaper = ocio.AllocationTransform(allocation=ocio.ALLOCATION_LG2, vars=[LO, HI, 2.0**LO])
    lut = ocio.Lut3DTransform(gridSize=SIZE)
    lut.setData(np.ascontiguousarray(values, dtype=np.float32).reshape(-1))
    lut.setInterpolation(ocio.INTERP_TETRAHEDRAL)
    return _cpu(ocio.GroupTransform([shaper, lut]))
