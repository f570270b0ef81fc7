"""A parameter driven by an image: what a preset writes in place of a constant (no I/O).

Any parameter of any model may be a texture as well as a constant (:doc:`/design`, Textures)::

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

import math
import types
import typing
from typing import TYPE_CHECKING, Annotated, Any

from annotated_types import Ge, Gt, Le
from pydantic import Field, model_validator

from .layers import UV, Wrap, check_texture_reference
from .params import Params

if TYPE_CHECKING:
    import numpy as np

__all__ = [
    "UDIM_TOKEN",
    "TextureInput",
    "apply_rule",
    "field_range",
    "is_texture_input",
    "texturable",
    "udim_tile",
    "tile_uv",
]

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
        check_texture_reference(self.texture, self.uv_scale)
        if self.range is not None and self.range[0] == self.range[1]:
            raise ValueError(f"range {list(self.range)} is empty; give two different values")
        if isinstance(self.channel, int) and self.channel < 0:
            raise ValueError(f"channel {self.channel} is negative; use an index from 0 or a name")
        return self

    @property
    def udim(self) -> bool:
        """True when the file name is a UDIM tile pattern."""
        return UDIM_TOKEN in self.texture

    def values(self, texels: Any, space: str, bounds: tuple[float, float]) -> np.ndarray:
        """The parameter's values from decoded ``texels`` (…, C) read in colour space
        ``space``: converted to the working space (C = 3 only; a data space passes
        through), remapped from :attr:`range`, scaled, offset, and clamped to ``bounds``
        (the parameter's range: the library has already refused a texture that leaves it
        by more than :data:`CLAMP_TOLERANCE`, so the clamp only trims filtering and
        rounding noise). Float32, a new array."""
        return apply_rule(self, texels, space, bounds)


CLAMP_TOLERANCE = 0.01
"""How far (as a share of ``min(range span, 1)``) a texture's values may leave the parameter's
range and be clamped with a warning; further out the preset is refused. Compression, float
rounding and a colour conversion into a narrower gamut leave values a little outside (a
saturated sRGB red in ACEScg → Rec.709 goes to −1e-3); a map painted for another
parameter's range does not."""


def apply_rule(
    tex: TextureInput, texels: Any, space: str, bounds: tuple[float, float] | None = None
) -> np.ndarray:
    """``clamp(remap(convert(texels))·scale + offset)`` (the module doc's value rule).

    >>> import numpy as np
    >>> t = TextureInput(texture="r.png", range=(0.2, 0.6), scale=0.5)
    >>> apply_rule(t, np.array([[0.4]]), "Raw", (0.0, 1.0)).tolist()
    [[0.25]]
    """
    import numpy as np  # only when maps are read: a preset's check imports no numpy

    from . import colour

    a = np.asarray(texels, dtype=np.float32)
    if a.shape[-1:] == (3,) and not colour.is_data(space):
        a = colour.convert(a, space)
    else:
        a = np.array(a, dtype=np.float32, copy=True)
    if tex.range is not None:
        lo, hi = tex.range
        a -= np.float32(lo)
        a *= np.float32(1.0 / (hi - lo))
    if tex.scale != 1.0:
        a *= np.float32(tex.scale)
    if tex.offset != 0.0:
        a += np.float32(tex.offset)
    if bounds is not None:
        np.clip(a, bounds[0], bounds[1], out=a)
    return a


def _float_bounds(metadata: list[Any]) -> tuple[float, float]:
    # an exclusive floor (gt) bounds the range as well: the schema refuses the value itself
    lo = next(
        (m.ge if isinstance(m, Ge) else m.gt for m in metadata if isinstance(m, Ge | Gt)), -math.inf
    )
    hi = next((m.le for m in metadata if isinstance(m, Le)), math.inf)
    return float(lo), float(hi)


def _core(annotation: Any) -> Any:
    """``float | None`` → ``float``; Annotated and Optional peeled."""
    while typing.get_origin(annotation) in (typing.Union, types.UnionType):
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        annotation = args[0]
    return annotation


def texturable(params_type: type[Params]) -> dict[str, int]:
    """The parameters of a model a texture may drive, by name → channels (1 or 3): the
    continuous ones (floats and colours), not switches (``thin``) or choices (``sheen_model``).

    >>> from lookdev.materials.params import DisneyParams
    >>> t = texturable(DisneyParams)
    >>> t["base_color"], t["roughness"], "thin" in t, "sheen_model" in t, "specular_gamma" in t
    (3, 1, False, False, False)
    """
    out = {}
    for name, info in params_type.model_fields.items():
        extra = info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}
        if extra.get("texturable") is False:  # e.g. specular_gamma: a per-material choice
            continue
        core = _core(info.annotation)
        if core is float:
            out[name] = 1
        elif typing.get_origin(core) is tuple and len(typing.get_args(core)) == 3:
            out[name] = 3
    return out


def field_range(params_type: type[Params], name: str) -> tuple[float, float]:
    """(lowest, highest) value the schema allows for a texturable parameter (per channel).

    >>> from lookdev.materials.params import DisneyParams
    >>> field_range(DisneyParams, "specular"), field_range(DisneyParams, "base_color")
    ((0.0, 12.5), (0.0, 1.0))
    """
    info = params_type.model_fields[name]
    core = _core(info.annotation)
    if typing.get_origin(core) is tuple:
        channel = typing.get_args(core)[0]
        meta = [m for a in typing.get_args(channel)[1:] for m in getattr(a, "metadata", [a])]
        return _float_bounds(meta)
    return _float_bounds(info.metadata)


def udim_tile(u: int, v: int) -> int:
    """The UDIM tile number of the UV square whose lower-left corner is (u, v), u in 0..9.

    >>> udim_tile(0, 0), udim_tile(1, 0), udim_tile(0, 1)
    (1001, 1002, 1011)
    """
    return 1001 + u + 10 * v


def tile_uv(tile: int) -> tuple[int, int]:
    """(u, v) of the lower-left corner of UDIM ``tile`` (the inverse of :func:`udim_tile`).

    >>> tile_uv(1012)
    (1, 1)
    """
    return (tile - 1001) % 10, (tile - 1001) // 10


def is_texture_input(value: Any) -> bool:
    """True for what a preset writes to drive a parameter by a texture (a table with
    ``texture``) or an already parsed :class:`TextureInput`."""
    return isinstance(value, TextureInput) or (isinstance(value, dict) and "texture" in value)
