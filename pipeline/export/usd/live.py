"""Live layering for the MaterialX context: mask images drive ``ND_mix_*`` chains.

Burley §5.7 blends the *parameters* of layers under masks, bottom to top:
``p = mix(p_below, p_layer, mask)``. The MaterialX network does the same per parameter,
so a DCC can repaint or swap a mask without re-exporting. What is folded or baked:

- a constant mask folds: mask 0 drops the layer, mask 1 drops every layer below, and a
  constant between mixes with a constant weight (two constants mix to one constant);
- a texture mask read as it is (first channel, no inversion or UV transform) is
  referenced directly;
- any other mask (noise, ramp, levels, combinations, transforms) is evaluated by the
  blending engine and baked to a mask image beside the file: UsdPreviewSurface has no
  noise node and MaterialX's noise is not ours, so only pixels reproduce it exactly.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials.colour import RAW
from lookdev.materials.layers import TextureMask

from .lobes import canonical
from .names import Slot
from .network import Connection, Image, Node, same_or_eq

__all__ = ["LiveLayer", "live_stack", "mixed_input"]


@dataclass
class LiveLayer:
    """One layer as the live network sees it: its values and its mask (image or weight)."""

    name: str
    values: dict[str, Any]
    mask: Image | float


def live_stack(hub: Any, texture_dir: Path) -> list[LiveLayer]:
    """The layers the blend kept (:attr:`BlendedMaterial.layers`), bottom first, with
    their coverage (mask × presence) as a weight, a texture read as it is, or a bake."""
    out = []
    for i, entry in enumerate(hub.layers):
        mask = 1.0 if i == 0 else _coverage(entry, hub, i, texture_dir)
        out.append(LiveLayer(entry.label, canonical(entry.params), mask))
    return out


def _coverage(entry: Any, hub: Any, index: int, texture_dir: Path) -> Image | float:
    if entry.uniform:
        return float(entry.low)
    if entry.presence == 1.0 and _plain_texture(entry.mask):
        # the mask file itself, read as data (collected with --collect)
        return Image(Path(entry.mask.path), colorspace=RAW, reference=True)
    from lookdev.pipeline.blend import MaskSampler

    width, height = hub.resolution
    sampler = MaskSampler((height, width))
    uv_order = np.asarray(entry.coverage(sampler, slice(0, height)), dtype=np.float32)
    path = texture_dir / f"{hub.name}_mask{index}.exr"
    return Image(path, np.flipud(uv_order), write=True)


def _plain_texture(mask: Any) -> bool:
    """A texture mask MaterialX's ``image`` node reads as our sampler does."""
    return (
        isinstance(mask, TextureMask)
        and mask.channel in (0, "R", "r", "Y", "y")
        and not mask.invert
        and tuple(mask.uv_scale) == (1.0, 1.0)
        and tuple(mask.uv_offset) == (0.0, 0.0)
        and mask.wrap == "periodic"
    )


def mixed_input(
    nodes: list[Node], slot: Slot, layers: list[LiveLayer], prefix: str
) -> tuple[str, Any] | None:
    """The chain of mixes of ``slot`` over ``layers``; None when every layer agrees."""
    values = [slot.to_target(layer.values[slot.param]) for layer in layers]
    if all(same_or_eq(v, values[0]) for v in values):
        return None
    current: Any = values[0]
    kind = "color3" if slot.type == "color3f" else "float"
    for i, (layer, value) in enumerate(zip(layers, values, strict=True)):
        if i == 0 or (not isinstance(current, Connection) and same_or_eq(value, current)):
            continue
        if isinstance(layer.mask, float) and not isinstance(current, Connection):
            current = _lerp(current, value, layer.mask)
            continue
        name = f"{prefix}_mix_{slot.param}_{i}"
        inputs = {
            "bg": (slot.type, current),
            "fg": (slot.type, value),
            "mix": ("float", _mask_input(nodes, layer.mask, prefix, i)),
        }
        nodes.append(Node(name, f"ND_mix_{kind}", inputs, {"out": slot.type}))
        current = Connection(name, "out")
    return slot.type, current


def _lerp(a: Any, b: Any, t: float) -> Any:
    if isinstance(a, tuple):
        return tuple(x + (y - x) * t for x, y in zip(a, b, strict=True))
    return a + (b - a) * t


def _mask_input(nodes: list[Node], mask: Image | float, prefix: str, index: int) -> Any:
    """A constant weight, or the (shared) image node reading the layer's mask."""
    if isinstance(mask, float):
        return mask
    name = f"{prefix}_mask_{index}"
    if not any(n.name == name for n in nodes):
        nodes.append(Node(name, "ND_image_float", {"file": ("asset", mask)}, {"out": "float"}))
    return Connection(name, "out")
