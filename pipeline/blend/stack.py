"""A material's layer stack as the engine sees it, and the pruning of layers it can skip.

Stacks run bottom to top. Each :class:`Entry` is one layer: a resolved disney or pixar
material, its mask and presence (their product is the layer's *coverage*), its normal
maps, and the coverage bounds known before any texel is evaluated.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookdev.materials import registry
from lookdev.materials.layers import ConstantMask, Mask, TextureMask

from .errors import BlendError
from .masks import MaskSampler

__all__ = ["Decision", "Entry", "prune_stack", "stack_of"]


@dataclass(frozen=True)
class Decision:
    """What the engine did with one layer of the stack, and why."""

    layer: str
    kept: bool
    reason: str


@dataclass
class Entry:
    """One layer of a stack (see module doc)."""

    label: str
    model: str
    params: Any
    mask: Mask
    presence: float = 1.0
    normal_map: TextureMask | None = None
    specular_normal_map: TextureMask | None = None
    source: str | None = None
    low: float = 1.0
    high: float = 1.0
    per_texel: bool = False
    """Evaluate the mask per texel even when its bounds say it is uniform (no pruning)."""
    textures: dict[str, Any] = field(default_factory=dict)
    """Parameters driven by textures (:class:`~lookdev.materials.textures.TextureInput`)."""
    decoded: dict[str, Any] = field(default_factory=dict)
    """The non-uniform ones opened (:class:`~lookdev.library.textures.ParamTexture`), by
    :func:`.textures.open_textures`; uniform ones are folded into ``params``."""

    @property
    def where(self) -> str:
        return f"layer {self.label!r}"

    @property
    def uniform(self) -> bool:
        """True when the coverage is one number everywhere (``low == high``)."""
        return self.low == self.high and not self.per_texel

    def coverage(self, sampler: MaskSampler, rows: slice) -> np.ndarray | np.float32:
        """Mask × presence on output ``rows``: a scalar when uniform, else (n, W) float32."""
        if self.uniform:
            return np.float32(self.low)
        m = sampler.evaluate(self.mask, rows, where=self.where)
        return m if self.presence == 1.0 else m * np.float32(self.presence)

    def normals(self, sampler: MaskSampler, tex: TextureMask, rows: slice) -> np.ndarray:
        """Tangent-space normals of ``tex`` on ``rows``: (n, W, 3), not yet renormalised.

        Files hold the usual 0..1 encoding ``(n + 1)/2`` of OpenGL-convention normals
        (y up the image); ``invert = true`` flips y, for DirectX-convention maps.
        """
        n = 2.0 * sampler.lookup(tex, 3, rows, where=self.where) - 1.0
        if tex.invert:
            n[..., 1] *= -1.0
        return n


def stack_of(material: Any) -> list[Entry]:
    """The entries of a library ``Material``, bottom first; one entry if not layered.

    Raises :class:`BlendError` for an empty stack or layers of different models.
    """
    source = str(material.source) if getattr(material, "source", None) else None
    if material.model != "layered":
        textures = dict(getattr(material, "textures", {}))
        return [
            Entry(
                material.name,
                material.model,
                material.params,
                ConstantMask(),
                source=source,
                textures=textures,
            )
        ]
    if not material.layers:
        raise BlendError("a layered material needs at least one layer", where=source)
    entries = [_entry(i, layer) for i, layer in enumerate(material.layers)]
    for entry in entries[1:]:
        if entry.model != entries[0].model:
            raise BlendError(
                f"is {entry.model} ({entry.source or 'inline'}) but layer {entries[0].label!r} "
                f"is {entries[0].model}; all layers of one material share one model",
                where=entry.where,
            )
    return entries


def _entry(index: int, layer: Any) -> Entry:
    mat = layer.material
    if mat.model not in registry.PRESET_MODELS:
        allowed = " or ".join(registry.PRESET_MODELS)
        raise BlendError(f"material {mat.name!r} is {mat.model}, not {allowed}")
    return Entry(
        label=layer.name or mat.name or f"#{index}",
        model=mat.model,
        params=mat.params,
        mask=layer.mask,
        presence=float(layer.presence),
        normal_map=layer.normal_map,
        specular_normal_map=layer.specular_normal_map,
        source=str(mat.source) if getattr(mat, "source", None) else None,
        textures=dict(getattr(mat, "textures", {})),
    )


def prune_stack(
    entries: list[Entry],
    sampler: MaskSampler,
    *,
    base_opaque: bool = True,
    hides: Callable[[Entry], bool] = lambda entry: True,
    enabled: bool = True,
) -> tuple[list[Entry], list[Decision]]:
    """Bound every layer's coverage, then drop the layers the result cannot show.

    ``base_opaque``: the bottom layer covers everything (Disney: there is nothing to blend
    its parameters with, so its mask is not used). ``hides(entry)``: a full-coverage
    ``entry`` hides everything below it (always for Disney; Pixar only when opaque).
    Every texture is opened here, so a bad file is reported even on a dropped layer.
    ``enabled=False`` keeps every layer and evaluates every mask per texel (the naive
    engine, for measuring what pruning saves and for testing that it changes nothing).
    """
    for i, entry in enumerate(entries):
        if i == 0 and base_opaque:
            continue
        lo, hi = sampler.bounds(entry.mask, where=entry.where)
        entry.low, entry.high = lo * entry.presence, hi * entry.presence
        for tex in (entry.normal_map, entry.specular_normal_map):
            if tex is not None:
                sampler.image(tex, 3, where=entry.where)
    if not enabled:
        for entry in entries:
            entry.per_texel = True
        if base_opaque:
            entries[0].low = entries[0].high = 1.0
        return list(entries), [Decision(e.label, True, "pruning off") for e in entries]
    decisions: list[Decision] = []
    bottom = 0
    for i in range(len(entries) - 1, 0, -1):
        if entries[i].low >= 1.0 and hides(entries[i]):
            bottom = i
            break
    for entry in entries[:bottom]:
        decisions.append(Decision(entry.label, False, f"under {entries[bottom].label!r}"))
    kept = []
    for i, entry in enumerate(entries[bottom:]):
        if entry.high <= 0.0 and not (i == 0 and base_opaque):
            decisions.append(Decision(entry.label, False, "coverage is zero everywhere"))
            continue
        kept.append(entry)
        decisions.append(Decision(entry.label, True, _why_kept(entry, i == 0 and base_opaque)))
    if not kept:
        raise BlendError("every layer has zero coverage", where=entries[-1].where)
    if base_opaque:
        kept[0].low = kept[0].high = 1.0
    return kept, decisions


def _why_kept(entry: Entry, is_base: bool) -> str:
    if is_base:
        unused = entry.mask != ConstantMask() or entry.presence != 1.0
        return "base (its mask is not used: nothing lies below)" if unused else "base"
    if entry.uniform:
        return f"uniform coverage {entry.low:g}"
    return f"coverage {entry.low:g}..{entry.high:g}"
