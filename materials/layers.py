"""Layer stacks as data: masks and layer entries of a layered preset (no I/O).

A layered preset lists its layers bottom to top; each layer names a material (another
preset, or a model with inline parameters), a :data:`Mask` saying where it shows, and for
Pixar stacks a ``presence``. Masks are a tree discriminated on ``kind``, so an artist can
build "rust only in the cavities of the scratches" from parts::

    [layers.mask]
    kind = "multiply"
    inputs = [{ kind = "texture", path = "cavity.exr" },
              { kind = "levels", input = { kind = "noise", scale = 8, seed = 3 }, low = 0.4 }]

A bare number where a mask is expected is a constant mask. Evaluation (textures, noise,
filtering) lives in :mod:`lookdev.pipeline.blend.masks`; this module only validates.

>>> LayerSpec.parse({"preset": "rust", "mask": 0.5}).mask
ConstantMask(kind='constant', value=0.5)
>>> m = mask_adapter().validate_python({"kind": "invert", "input": {"kind": "ramp"}})
>>> type(m.input).__name__
'RampMask'
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from functools import cache
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BeforeValidator, Field, TypeAdapter, model_validator

from .params import Params, register_schema

__all__ = [
    "CombineMask",
    "ConstantMask",
    "InvertMask",
    "LayerSpec",
    "LevelsMask",
    "Mask",
    "NoiseMask",
    "RAMP_MAX",
    "RAMP_MIN_SPAN",
    "RampMask",
    "SEED_MAX",
    "TextureMask",
    "UV",
    "UV_MAX",
    "Wrap",
    "check_texture_reference",
    "children",
    "map_textures",
    "mask_adapter",
    "textures",
]

UV_MAX = 4096.0
"""Ceiling of ``|uv_scale|`` and ``|uv_offset|`` of a texture (repeats of the UV square)."""
UV = Annotated[float, Field(ge=-UV_MAX, le=UV_MAX)]


def check_texture_reference(path: str, uv_scale: tuple[float, float]) -> None:
    """What every texture reference must be, as a ``ValueError`` (pydantic's one line):
    a file name an operating system can open (no NUL byte), and a UV scale that spreads
    the image over the surface (a zero scale would show one texel everywhere).

    >>> try:
    ...     check_texture_reference("wood.png", (0.0, 1.0))
    ... except ValueError as exc:
    ...     print(str(exc)[:35])
    uv_scale [0.0, 1.0] is zero along u
    """
    if "\x00" in path:
        raise ValueError(f"texture path {path!r} holds a NUL byte; no file can have that name")
    for axis, s in zip("uv", uv_scale, strict=True):
        if s == 0:
            raise ValueError(
                f"uv_scale {list(uv_scale)} is zero along {axis}; a texture needs a nonzero "
                "scale (a constant is one value everywhere)"
            )


SEED_MAX = 2**32 - 1
"""Largest noise seed: the lattice hash is 32-bit."""
RAMP_MAX = 1024.0
RAMP_MIN_SPAN = 1e-6
"""Bounds of a ramp's ``start`` and ``end`` (UV units) and their least separation."""

Wrap = Literal["periodic", "clamp", "black", "mirror"]
"""How UVs outside 0..1 read a texture: repeat, edge texel, zero, or mirrored repeat."""


def _number_is_constant(value: Any) -> Any:
    """A bare number where a mask is expected means ``{kind = "constant", value = x}``."""
    if isinstance(value, int | float) and not isinstance(value, bool):
        return {"kind": "constant", "value": float(value)}
    return value


class ConstantMask(Params):
    """The same coverage everywhere."""

    kind: Literal["constant"] = "constant"
    value: float = Field(
        1.0, strict=True, ge=0.0, le=1.0, description="Coverage, 0 (absent) .. 1 (full)."
    )


class TextureMask(Params):
    """One channel of an image, read as linear data (no colour conversion).

    ``path`` is relative to the preset file as written; the library makes it absolute
    on load. Texel (0, 0) of the image is its top-left as stored; UV (0, 0) is the
    bottom-left of the image (the USD/OpenGL convention), so v runs up the image.
    For a normal map, ``channel`` is the first of the three channels holding x, y, z.
    """

    kind: Literal["texture"] = "texture"
    path: Path = Field(description="Image file (any format OpenImageIO reads).")
    channel: int | str = Field(
        0, description="Channel index from 0, or its name ('R', 'G', 'B', 'A', 'Y', 'mask.R')."
    )
    invert: bool = Field(False, strict=True, description="Use 1 - value.")
    uv_scale: tuple[UV, UV] = Field(
        (1.0, 1.0),
        description=f"Repeats across the UV square, each within ±{UV_MAX:g}: beyond it a "
        "texel of the largest blend spans a whole repeat and u·scale loses its float32 fraction.",
    )
    uv_offset: tuple[UV, UV] = Field(
        (0.0, 0.0), description=f"Shift in UV, after scaling; each within ±{UV_MAX:g}."
    )
    wrap: Wrap = Field("periodic", description="Lookup outside 0..1: periodic|clamp|black|mirror.")

    @model_validator(mode="after")
    def _channel_not_negative(self) -> TextureMask:
        check_texture_reference(str(self.path), self.uv_scale)
        if isinstance(self.channel, int) and self.channel < 0:
            raise ValueError(f"channel {self.channel} is negative; use an index from 0 or a name")
        return self


class NoiseMask(Params):
    """Fractal value noise (fBm), deterministic in ``seed`` and tileable over the UV square.

    Octave k has ``round(scale · lacunarity^k)`` lattice cells across the unit square (at
    least 1), so the mask repeats seamlessly with period 1 in u and v.
    """

    kind: Literal["noise"] = "noise"
    scale: float = Field(
        4.0, strict=True, gt=0.0, le=4096.0, description="Lattice cells of the first octave."
    )
    octaves: int = Field(4, strict=True, ge=1, le=16, description="Number of octaves summed.")
    seed: int = Field(
        0,
        strict=True,
        ge=0,
        le=SEED_MAX,
        description="A non-negative integer below 2³²; same seed, same mask (the lattice hash "
        "is 32-bit, so a larger seed would repeat a smaller one).",
    )
    lacunarity: float = Field(
        2.0, strict=True, ge=1.0, le=8.0, description="Frequency ratio of octaves."
    )
    gain: float = Field(0.5, strict=True, ge=0.0, le=1.0, description="Amplitude ratio of octaves.")


class RampMask(Params):
    """A gradient across UV: along u, along v, or radial from the centre (0.5, 0.5)."""

    kind: Literal["ramp"] = "ramp"
    axis: Literal["u", "v", "radial"] = Field("u", description="Direction of the gradient.")
    start: float = Field(
        0.0,
        strict=True,
        ge=-RAMP_MAX,
        le=RAMP_MAX,
        description=f"Coordinate where the ramp is 0; within ±{RAMP_MAX:g} UV squares.",
    )
    end: float = Field(
        1.0,
        strict=True,
        ge=-RAMP_MAX,
        le=RAMP_MAX,
        description=f"Coordinate where the ramp is 1 (radial: radius); within ±{RAMP_MAX:g}, "
        f"at least {RAMP_MIN_SPAN:g} from start so its slope 1/(end − start) stays finite.",
    )
    interpolation: Literal["linear", "smooth"] = Field(
        "linear", description="Linear, or smoothstep (C1 at both ends)."
    )

    @model_validator(mode="after")
    def _start_differs_from_end(self) -> RampMask:
        if abs(self.end - self.start) < RAMP_MIN_SPAN:
            raise ValueError(
                f"ramp start {self.start:g} and end {self.end:g} are closer than "
                f"{RAMP_MIN_SPAN:g}; the ramp would be a step"
            )
        return self


class CombineMask(Params):
    """Combine several masks per texel: multiply, screen ``1 - Π(1 - m)``, max or min."""

    kind: Literal["multiply", "screen", "max", "min"]
    inputs: list[Mask] = Field(min_length=1, description="The masks to combine.")


class InvertMask(Params):
    """``1 - input``."""

    kind: Literal["invert"] = "invert"
    input: Mask


class LevelsMask(Params):
    """Photoshop-style levels: input range, gamma, contrast about 0.5, output range.

    ``v = ((clamp01((m - low) / (high - low)))^(1/gamma) - 0.5) · contrast + 0.5``,
    then mapped to ``out_low .. out_high`` and clamped to 0..1.
    """

    kind: Literal["levels"] = "levels"
    input: Mask
    low: float = Field(0.0, strict=True, ge=0.0, le=1.0, description="Input black point.")
    high: float = Field(1.0, strict=True, ge=0.0, le=1.0, description="Input white point.")
    gamma: float = Field(
        1.0, strict=True, gt=0.0, le=10.0, description="Midtone gamma; >1 brightens."
    )
    contrast: float = Field(
        1.0, strict=True, ge=0.0, le=100.0, description="Slope about 0.5; 1 is neutral."
    )
    out_low: float = Field(0.0, strict=True, ge=0.0, le=1.0, description="Output black point.")
    out_high: float = Field(1.0, strict=True, ge=0.0, le=1.0, description="Output white point.")

    @model_validator(mode="after")
    def _low_below_high(self) -> LevelsMask:
        if self.low >= self.high:
            raise ValueError(f"levels low {self.low} must be below high {self.high}")
        return self


Mask = Annotated[
    ConstantMask | TextureMask | NoiseMask | RampMask | CombineMask | InvertMask | LevelsMask,
    Field(discriminator="kind"),
    BeforeValidator(_number_is_constant),
]
"""Any mask; discriminated on ``kind``; a bare number is a constant mask."""

for _cls in (CombineMask, InvertMask, LevelsMask):
    _cls.model_rebuild()


class LayerSpec(Params):
    """One entry of a layered preset's bottom-to-top ``[[layers]]`` array.

    Either ``preset`` (a reference, optionally with ``params`` overrides) or ``model`` with
    inline ``params``; not both.
    """

    name: str | None = Field(None, description="Label shown in errors and reports.")
    preset: str | None = Field(None, description="Name of another preset to use as this layer.")
    model: Literal["disney", "pixar"] | None = Field(None, description="Model of inline params.")
    params: dict[str, Any] = Field(default_factory=dict, description="Inline params/overrides.")
    mask: Mask = Field(default_factory=ConstantMask, description="Where the layer shows.")
    presence: float = Field(
        1.0, strict=True, ge=0.0, le=1.0, description="Pixar layer presence (opacity)."
    )
    normal_map: TextureMask | None = Field(None, description="Tangent-space normal map.")
    specular_normal_map: TextureMask | None = Field(
        None, description="Separate normal for the specular lobes (Burley §6)."
    )

    @model_validator(mode="after")
    def _preset_or_model(self) -> LayerSpec:
        if (self.preset is None) == (self.model is None):
            raise ValueError("a layer needs exactly one of 'preset' (a reference) or 'model'")
        return self


for _cls in (ConstantMask, TextureMask, NoiseMask, RampMask, LevelsMask, LayerSpec):
    register_schema(_cls)


@cache
def mask_adapter() -> TypeAdapter:
    """A pydantic adapter for a bare :data:`Mask` (``validate_python``, ``json_schema``)."""
    return TypeAdapter(Mask)


def children(mask: Mask) -> list[Mask]:
    """The masks a combination is built from (empty for leaves)."""
    if isinstance(mask, CombineMask):
        return list(mask.inputs)
    if isinstance(mask, InvertMask | LevelsMask):
        return [mask.input]
    return []


def textures(mask: Mask) -> Iterator[TextureMask]:
    """Every texture leaf of a mask tree, depth first."""
    if isinstance(mask, TextureMask):
        yield mask
    for child in children(mask):
        yield from textures(child)


def map_textures(mask: Mask, fn: Callable[[TextureMask], TextureMask]) -> Mask:
    """A copy of ``mask`` with every texture leaf replaced by ``fn(leaf)``.

    The library uses this to make texture paths absolute (relative to the preset file).
    """
    if isinstance(mask, TextureMask):
        return fn(mask)
    if isinstance(mask, CombineMask):
        return mask.model_copy(update={"inputs": [map_textures(m, fn) for m in mask.inputs]})
    if isinstance(mask, InvertMask | LevelsMask):
        return mask.model_copy(update={"input": map_textures(mask.input, fn)})
    return mask
