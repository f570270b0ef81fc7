"""Small previews of a layer's mask and of a parameter's map, as the blend reads them.

A preview is the blend engine's own evaluation (:class:`~lookdev.pipeline.blend.masks.
MaskSampler`) over the UV square, so a mask's channel, invert, levels, noise and
combinations look in the panel as they act in the viewport; a parameter's map shows the
channel it drives (the first of three for a colour), before colour conversion, scale and
offset. Coverage is data, so it is shown as stored: 0 black, 1 white, no display curve.
Only the session's current document is read: the page names a layer and a field, never
a file.
"""

from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library.preset import build_preset
from lookdev.materials.errors import LookdevError
from lookdev.materials.layers import TextureMask, map_textures
from lookdev.materials.textures import UDIM_TOKEN, TextureInput

__all__ = ["PREVIEW_PX", "mask_of", "preview_png"]

PREVIEW_PX = 96
"""Texels a side of a preview: the panel shows it at this size."""


def mask_of(session: Any, target: int | None, field: str) -> Any:
    """The mask ``field`` of ``target`` in the session's document, its files absolute:
    ``"mask"`` of a layer, or the map driving parameter ``field`` read as a mask."""
    base = session.base_folder()
    if field == "mask":
        layers = build_preset(session.doc, where="designer").layers or []
        if not isinstance(target, int) or not 0 <= target < len(layers):
            raise LookdevError(f"no layer {target!r}; the stack has {len(layers)}")
        return map_textures(layers[target].mask, lambda t: _absolute(t, base))
    values = session.target_values(target)
    value = values.get(field)
    if not isinstance(value, dict):
        raise LookdevError(f"{field!r} is not driven by a map")
    tex = TextureInput.model_validate(value)
    if UDIM_TOKEN in tex.texture:
        raise LookdevError(f"{field!r} reads a UDIM set; its tiles have no single preview")
    mask = TextureMask(
        path=Path(tex.texture),
        channel=0 if tex.channel is None else tex.channel,
        uv_scale=tex.uv_scale,
        uv_offset=tex.uv_offset,
        wrap=tex.wrap,
    )
    return _absolute(mask, base)


def preview_png(mask: Any, px: int = PREVIEW_PX) -> bytes:
    """``mask`` evaluated over the UV square as an 8-bit grey PNG, v up (the image's top)."""
    from PIL import Image

    from lookdev.pipeline.blend.masks import MaskSampler

    coverage = MaskSampler((px, px)).evaluate(mask)[::-1]  # row 0 is v ≈ 0, the bottom
    grey = np.round(np.clip(coverage, 0.0, 1.0) * 255.0).astype(np.uint8)
    out = io.BytesIO()
    Image.fromarray(grey, mode="L").save(out, format="PNG")
    return out.getvalue()


def _absolute(tex: TextureMask, base: Path) -> TextureMask:
    return tex.model_copy(update={"path": base / tex.path})
