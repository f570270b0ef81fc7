"""Shading normals of a material in Mitsuba: one for all lobes, or one per lobe group.

A layered material may carry two normal maps: Smits keeps "two, one for all diffuse, one
for all highlights" when compositing (:mod:`lookdev.pipeline.blend.pixar_composite`), and a
Disney layer may give its specular lobes their own (Burley 2012 §6). A :class:`Model`
evaluates one shading frame, so such a material becomes two restricted instances of its
plugin (:attr:`~lookdev.materials.bsdf.Model.restrict`), each under Mitsuba's
``normalmap`` with its group's normal, mixed by ``blendbsdf`` at weight ½ with each
instance's values doubled: f = ½·2 f_diffuse + ½·2 f_highlight, the sum of the groups,
sampled by picking either half with probability ½. A group without live lobes is left out.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from lookdev.materials.bsdf import Model

from .inputs import ONLY_LOBES, WEIGHT_SCALE

__all__ = ["Texture", "with_normals"]

Texture = Callable[[np.ndarray, str], dict[str, Any]]
"""(unit normals (H, W, 3), a name for the file) → a Mitsuba texture dict."""


def with_normals(
    plugin: dict[str, Any],
    model: Model,
    lobes: tuple[str, ...],
    normals: tuple[np.ndarray | None, np.ndarray | None],
    texture: Texture,
) -> dict[str, Any]:
    """``plugin`` (rendering ``lobes`` of ``model``) under its shading normals
    ``(diffuse, highlight)``; either may be None. Lobe groups are the registry's
    (:attr:`lookdev.materials.bsdf.Lobe.highlight`)."""
    diffuse, highlight = normals
    if highlight is None or (diffuse is not None and np.array_equal(diffuse, highlight)):
        return _under(plugin, diffuse, "normal", texture)
    groups = [
        ([k for k in lobes if not model.lobe(k).highlight], diffuse, "normal"),
        ([k for k in lobes if model.lobe(k).highlight], highlight, "specular_normal"),
    ]
    halves = [(lobes, normal, name) for lobes, normal, name in groups if lobes]
    if len(halves) == 1:
        _, normal, name = halves[0]
        return _under(plugin, normal, name, texture)
    parts = [
        _under({**plugin, ONLY_LOBES: ",".join(lobes), WEIGHT_SCALE: 2.0}, normal, name, texture)
        for lobes, normal, name in halves
    ]
    return {"type": "blendbsdf", "weight": 0.5, "bsdf_0": parts[0], "bsdf_1": parts[1]}


def _under(
    bsdf: dict[str, Any], normal: np.ndarray | None, name: str, texture: Texture
) -> dict[str, Any]:
    if normal is None:
        return bsdf
    return {"type": "normalmap", "normalmap": texture(normal, name), "bsdf": bsdf}
