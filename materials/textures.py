"""A parameter driven by an image: what a preset writes in place of a constant (no I/O).

Any parameter of any model may be a texture as well as a constant (DESIGN.md, Textures)::

    roughness = { texture = "asset_Roughness.<UDIM>.png", channel = "r" }
    base_color = { texture = "asset_BaseColor.<UDIM>.png", colorspace = "sRGB - Texture" }

The value a texel gives the parameter is ``remap(convert(image[channel]))·scale + offset``:
the stored channel(s), converted from ``colorspace`` to the working space by OpenColorIO
(:mod:`.colour`; a data space such as ``Raw`` passes through), remapped from ``range``
to 0..1 when a range is given, then scaled and offset. Reading, UDIM tile lookup and
filtering live in :mod:`lookdev.pipeline.blend`; the library validates the file, the
channel and the range of the values at load.

>>> TextureInput.parse({"texture": "rough.png", "channel": "r"}).channel
'r'
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import Field, model_validator

from .layers import UV, Wrap
from .params import Params

__all__ = ["UDIM_TOKEN", "TextureInput", "is_texture_input"]

UDIM_TOKEN = "<UDIM>"
"""Stands for the four-digit tile number (1001 + u + 10·v) in a texture's file name."""

Finite = Annotated[float, Field(ge=-1e6, le=1e6)]


class TextureInput(Params):
    """One parameter read from an image (see the module doc for the value rule)."""

    texture: str = Field(
        description="Image file, relative to the preset file as written (absolute after "
        "load); any format OpenImageIO reads; '<UDIM>' in the name stands for the tile."
    )
    channel: str | int | None = Field(
        None,
        description="Channel name ('r', 'g', 'b', 'a', 'rgb', a layer name such as "
        "'diffuse.R') or index from 0; default: the first one or three channels, as the "
        "parameter needs.",
    )
    colorspace: str | None = Field(
        None,
        description="Colour space the file is encoded in, by the OCIO config's names; "
        "default by file rule (8-bit colour maps 'sRGB - Texture', data 'Raw').",
    )
    scale: Finite = Field(1.0, description="Multiplies the value after colour conversion.")
    offset: Finite = Field(0.0, description="Added after scaling.")
    range: tuple[Finite, Finite] | None = Field(
        None, description="Input range remapped to 0..1 before scale and offset."
    )
    uv_scale: tuple[UV, UV] = Field((1.0, 1.0), description="Repeats across the UV square.")
    uv_offset: tuple[UV, UV] = Field((0.0, 0.0), description="Shift in UV, after scaling.")
    wrap: Wrap = Field("periodic", description="Lookup outside 0..1: periodic|clamp|black|mirror.")

    @model_validator(mode="after")
    def _range_not_empty(self) -> TextureInput:
        if self.range is not None and self.range[0] == self.range[1]:
            raise ValueError(f"range {list(self.range)} is empty; give two different values")
        if isinstance(self.channel, int) and self.channel < 0:
            raise ValueError(f"channel {self.channel} is negative; use an index from 0 or a name")
        return self

    @property
    def udim(self) -> bool:
        """True when the file name is a UDIM tile pattern."""
        return UDIM_TOKEN in self.texture


def is_texture_input(value: Any) -> bool:
    """True for what a preset writes to drive a parameter by a texture (a table with
    ``texture``) or an already parsed :class:`TextureInput`."""
    return isinstance(value, TextureInput) or (isinstance(value, dict) and "texture" in value)
