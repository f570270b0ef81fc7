"""The view transform: scene-linear working-space pixels → display code values, via OCIO.

The one way lookdev shows scene-linear values: proofs' PNG frames and contact sheets, the
plots' images (BRDF slices, spheres) and the review page's frame thumbnails all go through
:func:`view`, so one material looks the same on every page. :func:`view` is the OCIO
``DisplayViewTransform`` of the one config (:func:`lookdev.materials.colour.to_display`):
from the working space to the display and view in force (``--display``, ``--view``,
``--look``, or ``lookdev.colour_settings(display=, view=, look=)``), after ``exposure``.

Default: the config's default display and view, for the built-in ACES 2.0 studio config
``sRGB - Display`` / ``ACES 2.0 - SDR 100 nits (Rec.709)``. Proof frames put suns and
soft boxes in speculars and glass caustics at tens to hundreds of times diffuse white;
through ``Un-tone-mapped`` (the sRGB curve, no tone scale) those clip channel by channel,
so a hot saturated highlight turns orange then white and its shape is lost (Burley 2012
§6.2: clipping "forces the core to always go to white"). The ACES 2.0 view rolls highlights
off, keeps their hue through the shoulder and reaches white only near the top; BRDF slice
plots, whose peaks are thousands of times their tails, read the same way. The price is
mid-tone contrast (18 % grey shows at code 0.35 instead of 0.46): judge albedo against the
grey ball, or switch to ``--view Un-tone-mapped`` for values near diffuse white.
"""

from __future__ import annotations

import numpy as np

from lookdev.materials import colour

__all__ = ["EXPOSURE_MAX", "view", "to_8bit"]

EXPOSURE_MAX = 32.0
"""Largest |exposure| in stops (proofs, plots): 2³² scales any float32 radiance of a
proof or a plot without overflow worth showing, and a display needs far less."""


def view(rgb: np.ndarray, exposure: float = 0.0, *, exact: bool = False) -> np.ndarray:
    """Display code values (…, 3) in [0, 1] of scene-linear ``rgb`` at ``exposure`` stops.

    NaN, infinite and negative values show black; see
    :func:`lookdev.materials.colour.to_display`. What is shown (PNGs, sheets, thumbnails,
    plots) takes its baked LUT, within 1 8-bit code value on 99.99 % of proof pixels;
    ``exact=True`` is OCIO's processor itself, for display values that are measured
    (noise estimates, their differences) rather than shown.

    >>> out = view(np.array([[8.0, 4.0, 2.0]]))
    >>> bool(out.max() <= 1.0), bool(out[0, 0] > out[0, 1] > out[0, 2])
    (True, True)
    """
    return colour.to_display(np.asarray(rgb)[..., :3], exposure, exact=exact).astype(np.float64)


def to_8bit(display: np.ndarray) -> np.ndarray:
    """Display values in [0, 1] quantised to uint8 (rounded, not truncated)."""
    return np.clip(np.rint(display * 255.0), 0, 255).astype(np.uint8)
