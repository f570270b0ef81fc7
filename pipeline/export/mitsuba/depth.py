"""How long the paths of a material's proof must be (the path tracer's ``max_depth``).

Mitsuba's ``max_depth`` counts path segments: 2 is direct lighting only. Light that
bounces inside the proof's concavities (the cup) or passes through a transmissive element
needs more, and every extra segment costs render time, so the depth follows the material:
which lobes it keeps (the blend's live lobes) and, for opaque ones, how much light each bounce
keeps (:func:`albedo_for`).

The depths were chosen on the proof shader ball under the ``studio`` IBL, as the smallest
whose 99th-percentile pixel loses less than about 5 % against a 24–32-segment reference
(160×80, 2 × 64 spp, same seeds at every depth); ``lookdev bench depth`` repeats the
measurement:

=====================  =====  ===============================================
material               depth  99th-percentile pixel deficit
=====================  =====  ===============================================
dark opaque            4      plastic_matte 0.5 %, rubber 0.1 %
bright opaque          6      gold 3.6 % (27 % at 4), plaster 3.6 % (13.8 % at 4),
                              copper 3.0 %, plastic_white 3.6 %
diffuse transmission   6      leaf 0.5 % (3.1 % at 4)
thin glossy            10     glass_thin 0.3 % (7.9 % at 8, 32 % at 6)
solid glossy           16     glass_clear 0.0 % (8.2 % at 12, 54 % at 8)
solid subsurface       64     skin (medium albedo ≤ 0.96) 0.03 % (4.1 % at 32, 16.5 % at
                              16, 59 % at 6), against 256: volpath counts every
                              scattering event in the medium as a segment
bright subsurface      128    marble (medium albedo > 0.99): 0.0 % mean and p99 against
                              512 (16 spp); at 64 the mean loses 3.6 %, and against 256
                              at 32 spp the p99 pixel lost 11 % (49 % at 32)
=====================  =====  ===============================================

What the shorter paths save in time is small on this scene: Mitsuba's Russian roulette
(from depth 5) already ends most long paths, and ``lookdev bench depth`` measured the
chosen depths within timing noise of depth 32 (speed-ups 0.66–1.07 on a shared 2-core
machine). The rule's value is the other way round: a fixed shallow depth (4) would have
darkened gold's cavities by 27 %.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lookdev.materials.bsdf import draw
from lookdev.materials.subsurface import has_interior, interior
from lookdev.pipeline.blend.result import as_hub

from .components import lobe_kinds

__all__ = [
    "BRIGHT_ALBEDO",
    "BRIGHT_MEDIUM",
    "DEPTH_BRIGHT",
    "DEPTH_DARK",
    "DEPTH_SOLID_GLOSSY",
    "DEPTH_SUBSURFACE",
    "DEPTH_SUBSURFACE_BRIGHT",
    "DEPTH_THIN_DIFFUSE",
    "DEPTH_THIN_GLOSSY",
    "albedo_for",
    "max_depth_for",
]

DEPTH_DARK = 4
DEPTH_BRIGHT = 6
DEPTH_THIN_DIFFUSE = 6
DEPTH_THIN_GLOSSY = 10
DEPTH_SOLID_GLOSSY = 16
DEPTH_SUBSURFACE = 64
DEPTH_SUBSURFACE_BRIGHT = 128
BRIGHT_MEDIUM = 0.99
"""Above this single-scattering albedo (any channel) a walk in the medium is long."""
BRIGHT_ALBEDO = 0.5
"""Above this directional albedo (any channel, anywhere) interreflections show."""


def albedo_for(hub: Any, *, samples: int = 256, texels: int = 64) -> float:
    """The largest directional albedo at normal incidence, over channels and texels.

    The mean of the model's own sample weights f·cos θ/pdf over stratified uniforms
    (reflection only), at up to ``texels`` texels spread evenly over the maps.
    """
    hub = as_hub(hub)
    model, params = hub.bsdf_model, hub.params
    maps, count = {}, 1
    for key, value in hub.maps.items():
        rows = value.reshape(-1, 3) if value.ndim == 3 else value.reshape(-1)
        pick = np.linspace(0, len(rows) - 1, min(texels, len(rows))).astype(int)
        maps[key] = rows[pick][:, None]  # (K, 1) or (K, 1, 3): one row of samples per texel
        count = len(pick)  # maps share one resolution
    side = math.isqrt(samples)
    grid = (np.stack(np.meshgrid(np.arange(side), np.arange(side)), -1).reshape(-1, 2) + 0.5) / side
    u = np.concatenate([np.random.default_rng(0).random((side * side, 1)), grid], axis=1)
    normal = np.broadcast_to(np.array([0.0, 0.0, 1.0]), (count, 1, 3))
    wi, weight, pdf = draw(model, params, normal, u[None], **maps)
    keep = (pdf > 0) & (wi[..., 2] > 0) & np.all(np.isfinite(weight), axis=-1)
    return float(np.max(np.where(keep[..., None], weight, 0.0).mean(axis=-2)))


def max_depth_for(hub: Any) -> int:
    """The path depth a blended material needs (see the table in the module docstring):
    by the kinds of its live lobes, and for opaque ones by its albedo."""
    hub = as_hub(hub)
    if hub.bsdf_model.name == "disney" and has_interior(hub.params):
        bright = interior(hub.params)[1].max() > BRIGHT_MEDIUM
        return DEPTH_SUBSURFACE_BRIGHT if bright else DEPTH_SUBSURFACE
    kinds = lobe_kinds(hub.live_lobes, hub.bsdf_model)
    if "GlossyTransmission" in kinds:
        return DEPTH_THIN_GLOSSY if hub.constants.get("thin", False) else DEPTH_SOLID_GLOSSY
    if "DiffuseTransmission" in kinds:
        return DEPTH_THIN_DIFFUSE
    return DEPTH_BRIGHT if albedo_for(hub) >= BRIGHT_ALBEDO else DEPTH_DARK
