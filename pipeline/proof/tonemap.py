"""The view transform: scene-linear Rec.709 → display sRGB without hue shifts.

The one way lookdev shows scene-linear values: proofs and contact sheets, the plots'
images (BRDF slices, spheres) and the review page's frame thumbnails all go through
:func:`view`, so one material looks the same on every page.

Burley 2012 §6.2: clipping highlights "introduces banding as each color channel clips at
a different location, and forces the core to always go to white"; Disney's operator
"preserves color values for most of the display range and rolls off the top end while
preserving color and contrast". This one does that with a curve on the *maximum channel*:
identity below a knee, an exponential shoulder above it that approaches 1, and every
pixel's RGB scaled by the same ratio ``curve(m)/m``. The ratios between channels (the hue
and saturation) are kept exactly and no channel can exceed 1, so nothing clips. The sRGB
encoding (IEC 61966-2-1, :func:`lookdev.materials.colour.srgb_encode`) encodes the result
for an 8-bit PNG.
"""

from __future__ import annotations

import numpy as np

from lookdev.materials import colour

DEFAULT_KNEE = 0.6
EXPOSURE_MAX = 32.0
"""Largest |exposure| in stops (proofs, plots): 2³² scales any float32 radiance of a
proof or a plot without overflow worth showing, and a display needs far less."""


def shoulder(m: np.ndarray, knee: float = DEFAULT_KNEE) -> np.ndarray:
    """Identity up to ``knee``, then ``k + (1 − k)(1 − exp(−(m − k)/(1 − k)))``.

    The shoulder meets the line with equal value and slope (C¹) and tends to 1.

    >>> [round(float(v), 4) for v in shoulder(np.array([0.3, 0.6, 1.0, 100.0]))]
    [0.3, 0.6, 0.8528, 1.0]
    """
    m = np.asarray(m, dtype=np.float64)
    over = np.maximum(m - knee, 0.0) / (1.0 - knee)
    return np.where(m <= knee, m, knee + (1.0 - knee) * -np.expm1(-over))


def view(rgb: np.ndarray, exposure: float = 0.0, knee: float = DEFAULT_KNEE) -> np.ndarray:
    """Display-referred sRGB (…, 3) in [0, 1] of scene-linear ``rgb`` at ``exposure`` stops.

    NaN, infinite and negative values show black; the maximum channel rolls off through
    :func:`shoulder` with every channel scaled by the same ratio; then sRGB encoding.

    >>> out = view(np.array([[8.0, 4.0, 2.0]]))
    >>> bool(out.max() <= 1.0), round(float(out[0, 0] / out[0, 1]), 3) > 1.0
    (True, True)
    """
    rgb = np.nan_to_num(np.asarray(rgb, dtype=np.float64)[..., :3], nan=0.0, posinf=0.0)
    rgb = np.maximum(rgb, 0.0) * 2.0**exposure
    m = rgb.max(axis=-1, keepdims=True)
    scale = np.divide(shoulder(m, knee), m, out=np.ones_like(m), where=m > 0)
    encoded = colour.convert(rgb * scale, colour.working_space(), colour.SRGB_TEXTURE)
    return np.clip(encoded, 0.0, 1.0)


def to_8bit(display: np.ndarray) -> np.ndarray:
    """Display values in [0, 1] quantised to uint8 (rounded, not truncated)."""
    return np.clip(np.rint(display * 255.0), 0, 255).astype(np.uint8)
