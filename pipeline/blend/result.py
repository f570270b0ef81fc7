"""The result of :func:`.engine.blend`: :class:`BlendedMaterial`, the hub every consumer
takes (DESIGN.md), and the tile size the blending paths share."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookdev.materials.params import DisneyParams

from .errors import BlendError
from .stack import Decision

TILE_TEXELS = 1 << 16
"""Texels per tile: a tile's temporaries (a few channels) stay within a CPU cache."""


@dataclass
class BlendedMaterial:
    """A blended material: constants where uniform, maps where varying (see :mod:`.engine`)."""

    name: str
    model: str
    resolution: tuple[int, int]
    """(width, height) of the maps, whether or not any exist."""
    constants: dict[str, Any]
    maps: dict[str, np.ndarray] = field(default_factory=dict)
    normal_map: np.ndarray | None = None
    specular_normal_map: np.ndarray | None = None
    decisions: list[Decision] = field(default_factory=list)
    representation: str = "params"
    """``"params"``: constants and maps are the model's parameters. ``"lobe_weights"``:
    a layered Pixar material, composited into Smits' lobe weights (see :mod:`.pixar`)."""

    @property
    def arrays(self) -> dict[str, np.ndarray]:
        """Every array of the result by name: the maps and any normal maps."""
        out = dict(self.maps)
        for name in ("normal_map", "specular_normal_map"):
            if getattr(self, name) is not None:
                out[name] = getattr(self, name)
        return out

    @property
    def nbytes(self) -> int:
        """Bytes held by the maps (the size of the output)."""
        return sum(a.nbytes for a in self.arrays.values())

    def params_at(self, row: int, col: int):
        """The model's parameters at texel ``(row, col)`` (UV order; see :mod:`.engine`).

        For ``representation = "lobe_weights"`` the values by name, as a dict.
        """
        values = dict(self.constants)
        for name, a in self.maps.items():
            v = a[row, col]
            values[name] = tuple(float(x) for x in v) if np.ndim(v) else float(v)
        if self.representation != "params":
            return values
        return _params_type(self.model).parse(values, where=f"{self.name} texel {row},{col}")

    def to_params(self):
        """The parameters of a uniform result; a :class:`BlendError` if anything varies."""
        if self.representation != "params":
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
        return _params_type(self.model).parse(dict(self.constants), where=self.name)


def _params_type(model: str):
    if model == "disney":
        return DisneyParams
    from lookdev.materials.pixar import PixarParams

    return PixarParams
