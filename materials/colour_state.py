"""The colour state of the program: which OpenColorIO config, which working space, which
view (:class:`Settings`, :func:`settings`), and the names every conversion starts from.

Kept apart from :mod:`.colour`, which does the conversions, because a preset's check
needs only these names: it converts a colour only when the working space or the
colour's encoding asks for it, and then imports OpenColorIO and numpy through
:mod:`.colour`. :mod:`.colour` re-exports everything here, and :func:`.colour.use`
is the one way to change the settings in force.
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from .errors import LookdevError

__all__ = [
    "DEFAULT_CONFIG",
    "PRESET_LINEAR",
    "RAW",
    "SRGB_TEXTURE",
    "WORKING_SPACES",
    "ColourError",
    "Settings",
    "settings",
]

DEFAULT_CONFIG = "ocio://studio-config-v4.0.0_aces-v2.0_ocio-v2.5"
"""OCIO's built-in ACES 2.0 studio config (OCIO ≥ 2.5), pinned: ``studio-config-latest``
would change every colour a release later."""

WORKING_SPACES = {"lin_rec709": "Linear Rec.709 (sRGB)", "acescg": "ACEScg"}
"""The working spaces lookdev offers, by short name → the studio config's colour space."""

SRGB_TEXTURE = "sRGB - Texture"
"""How a preset's ``"#rrggbb"`` and an 8-bit colour map are encoded by default."""
RAW = "Raw"
"""Data: no conversion (roughness, masks, normals, heights)."""
PRESET_LINEAR = "Linear Rec.709 (sRGB)"
"""The space of a preset's linear ``[r, g, b]`` (and grey scalar) colours: lookdev's
presets were written in linear Rec.709, so an ACEScg working space converts them rather
than reading Rec.709 numbers as AP1 ones (which would shift every hue)."""


class ColourError(LookdevError):
    """An unknown colour space or an OCIO config that cannot be read."""


@dataclass(frozen=True)
class Settings:
    """Which config and which working space: the whole program's colour state."""

    config: str = ""
    """Path or ``ocio://`` name; empty means ``$OCIO``, else :data:`DEFAULT_CONFIG`."""
    working_space: str = "lin_rec709"
    """A key of :data:`WORKING_SPACES`, or any colour-space name of the config."""
    display: str = ""
    """The display of the view transform; empty: the config's default display."""
    view: str = ""
    """The view of :attr:`display`; empty: that display's default view."""
    look: str = ""
    """OCIO looks applied before the view (comma-separated); empty: none."""

    @property
    def config_name(self) -> str:
        return self.config or os.environ.get("OCIO", "") or DEFAULT_CONFIG


_current = [Settings()]


def settings() -> Settings:
    """The colour settings in force."""
    return _current[-1]
