"""Conty-Kulla sheen over a blended base (Conty Estevez & Kulla 2017, §5).

A layer stack blends *parameters* (:mod:`.disney`), so the sheen parameters are blended
like the rest and the sheen then lies over the *blended* base: the base under the sheen
is scaled by ``1 − F · max(E(μi), E(μo))`` (:func:`lookdev.materials.sheen.base_scale`),
per texel where the sheen varies, with that texel's sheen colour, amount and roughness.
The Disney model does exactly this at render time from the blended maps; this module
gives the same factor as an image for consumers that cannot evaluate the lobe (preview
exporters, plots), at a chosen incidence.

Scaling a blend is not blending the scaled layers: at a texel half velvet, half plastic,
the base is scaled by the sheen of the *mixed* parameters (half the sheen), not by the
mean of "velvet's scaling" and "plastic's 1".
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lookdev.materials import disney as disney_model
from lookdev.materials import sheen
from lookdev.materials.arrays import NumpyOps

from .errors import BlendError
from .result import BlendedMaterial

__all__ = ["base_scale"]


def base_scale(blended: BlendedMaterial, cos_theta: float = 1.0) -> Any:
    """The factor on the base under a Conty-Kulla sheen, light and view at ``cos_theta``.

    An (H, W, 3) float32 map where the sheen varies, an RGB tuple where it is uniform,
    and 1 where the material has no Conty-Kulla sheen.
    """
    if blended.model != "disney" or blended.representation != "params":
        raise BlendError("the Conty-Kulla sheen applies to Disney materials", where=blended.name)
    if blended.constants.get("sheen_model", "disney") != "conty_kulla":
        return (1.0, 1.0, 1.0)
    xp = NumpyOps(np.float64)
    height, width = blended.resolution[1], blended.resolution[0]
    maps = {k: _elements(v) for k, v in blended.maps.items()}
    params = disney_model.DisneyParams.parse(_uniform_part(blended), where=blended.name)
    prepared = disney_model.MODEL.prepare(xp, params, **maps)
    if "sheen" not in prepared.lobes:
        return (1.0, 1.0, 1.0)
    color = xp.color(prepared.sheen * prepared.sheen_color)
    mu = np.float64(cos_theta)
    r, exact = xp.asarray(prepared.sheen_r), prepared.sheen_exact
    scale = np.maximum(sheen.base_scale(xp, mu, mu, r, color, exact=exact), 0.0)
    scale = np.broadcast_to(scale, (3, np.size(scale) // 3))
    if scale.shape[1] == 1:
        return tuple(float(x) for x in scale[:, 0])
    return np.ascontiguousarray(scale.T.reshape(height, width, 3), dtype=np.float32)


def _elements(a: np.ndarray) -> np.ndarray:
    """A map as the model takes it: scalars (N,), colours channel-first (3, N)."""
    return a.reshape(-1, 3).T.astype(np.float64) if a.ndim == 3 else a.reshape(-1).astype(float)


def _uniform_part(blended: BlendedMaterial) -> dict[str, Any]:
    """Constants, with each mapped parameter at its first texel (the maps override it)."""
    values = dict(blended.constants)
    for name, a in blended.maps.items():
        v = a[0, 0]
        values[name] = tuple(float(x) for x in v) if np.ndim(v) else float(v)
    return values
