"""The blended material: the one hub every consumer takes (:doc:`/design`, Data flow).

The library resolves a preset; :func:`lookdev.pipeline.blend.blend` runs once per material
and resolution and returns a :class:`BlendedMaterial`; the USD exporter, the Mitsuba scene
builder, the plots, the stability sweep and the proofs read it and never blend or look a
preset up themselves. It holds each parameter as a constant where it is uniform and as a
map where it varies, the shading normals, the layers kept (for exporters that mix layers
live), and asks the model registry (:mod:`lookdev.materials.registry`) which model renders
it and which of its lobes are live.

Maps are float32 ``(H, W)`` scalars and ``(H, W, 3)`` colours and normals, in UV order:
``map[r, c]`` is the texel centred on ``(u, v) = (u0 + (c + ½)/W · (u1 − u0),
v0 + (r + ½)/H · (v1 − v0))`` over :attr:`BlendedMaterial.uv_extent` ``(u0, v0, u1, v1)``,
which is the unit square ``(0, 0, 1, 1)`` unless the material's textures are UDIM tile
sets: then the maps span every UV square the tiles cover (a 2 × 2 set: ``(0, 0, 2, 2)``,
each tile's square ``W/2 × H/2`` texels, tile 1001 bottom-left). Normal maps are unit
tangent-space vectors (decoded, not 0..1 encoded).
"""

from __future__ import annotations

import functools
import hashlib
import json
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookdev.materials import registry
from lookdev.materials.bsdf import Model
from lookdev.materials.params import Params

from .errors import BlendError

__all__ = ["BlendedMaterial", "LOBE_WEIGHTS", "PARAMS", "TILE_TEXELS", "as_hub"]

TILE_TEXELS = 1 << 16
"""Texels per tile: a tile's temporaries (a few channels) stay within a CPU cache."""

PARAMS = "params"
LOBE_WEIGHTS = "lobe_weights"


@dataclass(eq=False)
class BlendedMaterial:
    """A blended material: constants where uniform, maps where varying (see module doc)."""

    name: str
    model: str
    """The preset's model (``disney`` or ``pixar``); :attr:`bsdf_model` renders it."""
    resolution: tuple[int, int]
    """(width, height) of the maps, whether or not any exist."""
    constants: dict[str, Any]
    maps: dict[str, np.ndarray] = field(default_factory=dict)
    normal_map: np.ndarray | None = None
    specular_normal_map: np.ndarray | None = None
    decisions: list[Any] = field(default_factory=list)
    representation: str = PARAMS
    """``"params"``: constants and maps are the model's parameters. ``"lobe_weights"``:
    a layered Pixar material, composited into Smits' lobe weights."""
    layers: list[Any] = field(default_factory=list)
    """The layers kept, bottom first (:class:`.stack.Entry`), for live layer mixing."""
    description: str = ""
    layered: bool = False
    """True when the preset was a layer stack (``model = "layered"``)."""
    origin: Any = None
    """What was blended (the resolved library material), for exporters that carry it."""
    textures: dict[str, Any] = field(default_factory=dict)
    """Parameters read straight from one image that blending did not change, by name →
    :class:`lookdev.materials.textures.TextureInput` (path absolute, ``<UDIM>`` kept, its
    ``colorspace`` the one it was read in, by the config's name): exporters reference
    the original file (and its colour space) instead of baking :attr:`maps`, which still
    holds the decoded values for every other consumer."""
    uv_extent: tuple[int, int, int, int] = (0, 0, 1, 1)
    """(u0, v0, u1, v1), whole UV squares every map spans (see module doc): parameter maps,
    :attr:`normal_map` and :attr:`height_map` alike."""
    tiles: tuple[int, ...] = ()
    """The UDIM tiles the material's textures cover (1001, 1002, …); empty when none is a
    UDIM set. A square of :attr:`uv_extent` with no tile holds the layer constants."""
    height_map: np.ndarray | None = None
    """Heights in scene units (float32 (H, W), UV order, over :attr:`uv_extent`) for bump
    and displacement: the preset's ``height`` texture after its scale/offset
    (:mod:`.surface_maps`)."""

    @property
    def map_tiles(self) -> tuple[int, int]:
        """UV squares ``(nu, nv)`` the maps span, from tile 1001: :attr:`uv_extent`'s size
        when it starts at (0, 0) (UDIM sets do)."""
        u0, v0, u1, v1 = self.uv_extent
        return (u1 - u0, v1 - v0)

    @map_tiles.setter
    def map_tiles(self, tiles: tuple[int, int]) -> None:
        self.uv_extent = (0, 0, int(tiles[0]), int(tiles[1]))

    @classmethod
    def of_params(cls, params: Any, name: str | None = None) -> BlendedMaterial:
        """A uniform material straight from a model's parameters (nothing to blend).

        Only the fields the parameters were given are constants: the schema's defaults
        stand for the rest, on every side.
        """
        model = registry.model_of_params(params).name
        preset_model = next((k for k, v in registry.LAYERED.items() if v == model), model)
        given = params.model_dump(exclude_unset=True)
        constants = {k: v for k, v in given.items() if v is not None}
        representation = LOBE_WEIGHTS if preset_model != model else PARAMS
        hub = cls(name or type(params).__name__, preset_model, (1, 1), constants)
        hub.representation = representation
        hub.__dict__["params"] = params  # already validated: not parsed again
        return hub

    # -- what renders it --------------------------------------------------------------
    @property
    def bsdf_model(self) -> Model:
        """The registry's model that takes these constants and maps."""
        name = self.model
        if self.representation == LOBE_WEIGHTS:
            name = registry.LAYERED.get(name, name)
        return registry.model_named(name)

    @functools.cached_property
    def params(self) -> Any:
        """The constants as the model's parameters (mapped fields at the schema default).

        Built without validating again: every constant is a blend of validated layers.
        """
        fields = self.bsdf_model.params_type.model_fields
        return self.bsdf_model.params_type.model_construct(
            **{k: _plain(v) for k, v in self.constants.items() if k in fields}
        )

    @functools.cached_property
    def centre_params(self) -> Any:
        """The model's parameters at the centre texel (:attr:`params` if nothing varies)."""
        if not self.maps:
            return self.params
        height, width = next(iter(self.maps.values())).shape[:2]
        fields = self.bsdf_model.params_type.model_fields
        values = self.values_at(height // 2, width // 2)
        return self.bsdf_model.params_type.model_construct(
            **{k: v for k, v in values.items() if k in fields}
        )

    @functools.cached_property
    def live_lobes(self) -> tuple[str, ...]:
        """The model's lobes whose weight is not zero everywhere (the registry's rule)."""
        return registry.live_lobes(self.bsdf_model, self.params, self.maps)

    @property
    def preset_model(self) -> str:
        """The model the preset named: ``layered`` for a stack, else :attr:`model`."""
        return "layered" if self.layered else self.model

    def digest(self) -> str:
        """A SHA-256 of everything that shapes the material's look (resumable proofs)."""
        h = hashlib.sha256()
        head = [self.name, self.model, self.representation, self.resolution, self.uv_extent]
        head.append(sorted((k, repr(_plain(v))) for k, v in self.constants.items()))
        h.update(json.dumps(head).encode())
        for name, array in sorted(self.arrays.items()):
            h.update(name.encode())
            h.update(np.ascontiguousarray(array, dtype=np.float32).tobytes())
        return h.hexdigest()

    # -- arrays -------------------------------------------------------------------------
    @property
    def arrays(self) -> dict[str, np.ndarray]:
        """Every array of the result by name: the maps and any normal maps."""
        out = dict(self.maps)
        for name in ("normal_map", "specular_normal_map", "height_map"):
            if getattr(self, name) is not None:
                out[name] = getattr(self, name)
        return out

    @property
    def nbytes(self) -> int:
        """Bytes held by the maps (the size of the output)."""
        return sum(a.nbytes for a in self.arrays.values())

    def texel(self, uv: Any) -> tuple[np.ndarray, np.ndarray]:
        """(rows, cols) of the texels under ``uv`` (…, 2), nearest texel. Over the unit
        square the maps repeat (a bitmap's ``repeat``); over a UDIM extent each (u, v)
        picks its own tile's square and is clamped to the extent outside it."""
        uv = np.asarray(uv, dtype=np.float64)
        width, height = self.resolution
        u0, v0, u1, v1 = self.uv_extent
        cols = np.floor((uv[..., 0] - u0) / (u1 - u0) * width).astype(np.intp)
        rows = np.floor((uv[..., 1] - v0) / (v1 - v0) * height).astype(np.intp)
        if tuple(self.uv_extent) == (0, 0, 1, 1):
            return rows % height, cols % width
        return np.clip(rows, 0, height - 1), np.clip(cols, 0, width - 1)

    def params_at_uv(self, u: float, v: float):
        """The model's parameters at UV ``(u, v)`` (see :meth:`texel`, :meth:`params_at`)."""
        if not self.maps:
            return self.params if self.representation == PARAMS else dict(self.constants)
        row, col = self.texel((u, v))
        return self.params_at(int(row), int(col))

    def values_at(self, row: int, col: int) -> dict[str, Any]:
        """Every constant and map value at texel ``(row, col)``, by name (plain Python)."""
        values = dict(self.constants)
        for name, a in self.maps.items():
            v = a[row, col]
            values[name] = tuple(float(x) for x in v) if np.ndim(v) else float(v)
        return values

    def params_at(self, row: int, col: int):
        """The model's parameters at texel ``(row, col)`` (UV order; see module doc).

        For ``representation = "lobe_weights"`` the values by name, as a dict.
        """
        values = self.values_at(row, col)
        if self.representation != PARAMS:
            return values
        return self.bsdf_model.params_type.parse(values, where=f"{self.name} texel {row},{col}")

    def to_params(self):
        """The parameters of a uniform result; a :class:`BlendError` if anything varies."""
        if self.representation != PARAMS:
            raise BlendError(
                "a layered Pixar material is composited lobe weights, not parameters",
                where=self.name,
            )
        if self.maps:
            raise BlendError(
                f"parameters vary across the surface ({', '.join(sorted(self.maps))}); "
                "use params_at(row, col) or the maps",
                where=self.name,
            )
        return self.bsdf_model.params_type.parse(dict(self.constants), where=self.name)

    def mean(self, name: str) -> Any:
        """A parameter's constant, or its map's mean (a fallback value for exporters)."""
        if name not in self.maps:
            return self.constants.get(name)
        a = np.asarray(self.maps[name], dtype=np.float64)
        m = a.reshape(-1, *a.shape[2:]).mean(axis=0)
        return tuple(float(x) for x in m) if np.ndim(m) else float(m)


def as_hub(material: Any) -> BlendedMaterial:
    """A :class:`BlendedMaterial` as it is, or a model's parameters as a uniform one.

    Consumers call this on what they are given; anything else (a library material) must
    be blended first: ``lookdev.blend(material)``.
    """
    if isinstance(material, BlendedMaterial):
        return material
    if isinstance(material, Params):
        return BlendedMaterial.of_params(material)
    raise BlendError(
        f"expected a blended material (lookdev.blend) or a model's parameters, "
        f"not a {type(material).__name__}",
        where=getattr(material, "name", None),
    )


def _plain(value: Any) -> Any:
    """numpy scalars and arrays as the Python values a schema holds."""
    if isinstance(value, np.ndarray | list | tuple):
        return tuple(float(c) for c in np.asarray(value).ravel())
    return value.item() if isinstance(value, np.generic) else value
