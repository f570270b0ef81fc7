"""Colour constants and the sRGB transfer curve: the one home of each (no I/O).

* :data:`REC709_LUMINANCE` and :func:`luminance`: the Y row of the linear Rec.709 → CIE XYZ
  matrix (ITU-R BT.709-6 item 3.3; IEC 61966-2-1 eq. 5), the luminance of scene-linear
  Rec.709 pixels (noise estimates, importance sampling by luminance, plots).
* :func:`srgb_decode` / :func:`srgb_encode`: the IEC 61966-2-1 piecewise transfer curve,
  used for ``"#rrggbb"`` preset colours and for display images. A later change moves colour
  management to OpenColorIO; this pair is the one place that swaps over.

Burley's tint weights ``(0.3, 0.6, 0.1)`` (:data:`lookdev.materials.disney_prepare.
TINT_WEIGHTS`) are not these: they are a rough hue normaliser inside the Disney BRDF
(Burley 2012, BRDF Explorer's ``Cdlum``), part of the model, not a measure of luminance.

>>> luminance((1.0, 1.0, 1.0))
1.0
>>> round(srgb_decode(srgb_encode(0.18)), 12)
0.18
"""

from __future__ import annotations

from typing import Any

import numpy as np

REC709_LUMINANCE = (0.2126, 0.7152, 0.0722)
"""Weights of linear R, G, B in CIE Y for Rec.709 primaries and a D65 white (sum 1)."""
_REC709_LUMINANCE = np.array(REC709_LUMINANCE)

SRGB_DECODE_BREAK = 0.04045
"""Encoded value at which the sRGB decoding switches from the line to the power law."""
SRGB_ENCODE_BREAK = 0.0031308
"""Linear value at which the sRGB encoding switches from the line to the power law."""


def _like(out: Any, given: Any) -> Any:
    """A Python float for a scalar input, the array otherwise."""
    return float(out) if np.ndim(out) == 0 and not isinstance(given, np.ndarray) else out


def luminance(rgb: Any) -> Any:
    """Rec.709 luminance Y of linear RGB over the last axis (length 3); 0 for black.

    Summed in float64 (float32 images too); a plain triple gives a float.

    >>> luminance((0.0, 0.0, 0.0)), luminance((0.0, 1.0, 0.0))
    (0.0, 0.7152)
    >>> luminance(np.ones((2, 4, 3), np.float32)).shape
    (2, 4)
    """
    return _like(np.asarray(rgb) @ _REC709_LUMINANCE, rgb)


def srgb_decode(v: Any) -> Any:
    """IEC 61966-2-1 sRGB decoding (encoded 0..1 → linear 0..1), per element.

    ``v / 12.92`` up to 0.04045, ``((v + 0.055) / 1.055)^2.4`` above; values outside 0..1
    (the curve's domain) are clipped to it.

    >>> round(srgb_decode(0.5), 6), srgb_decode(0.0), srgb_decode(1.0)
    (0.214041, 0.0, 1.0)
    """
    x = np.clip(v, 0.0, 1.0)
    lin = np.where(x <= SRGB_DECODE_BREAK, x / 12.92, ((x + 0.055) / 1.055) ** 2.4)
    return _like(lin, v)


def srgb_encode(x: Any) -> Any:
    """IEC 61966-2-1 sRGB encoding (linear 0..1 → encoded 0..1), per element.

    ``12.92 x`` up to 0.0031308, ``1.055 x^(1/2.4) − 0.055`` above; values outside 0..1
    are clipped to it (a display cannot show them; a view transform rolls them off first).

    >>> [round(float(v), 4) for v in srgb_encode(np.array([0.0, 0.0031308, 0.18, 1.0]))]
    [0.0, 0.0404, 0.4614, 1.0]
    """
    c = np.clip(x, 0.0, 1.0)
    enc = np.where(c <= SRGB_ENCODE_BREAK, 12.92 * c, 1.055 * np.power(c, 1.0 / 2.4) - 0.055)
    return _like(enc, x)
