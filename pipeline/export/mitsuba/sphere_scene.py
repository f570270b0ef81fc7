"""The small export scene: a material on a unit sphere under an environment (issue 7).

It is what ``lookdev export mitsuba`` writes (:mod:`.xml`); the BSDF comes from
:func:`.scene.bsdf_dict` and the path depth from :func:`.depth.max_depth_for`.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from .depth import max_depth_for
from .scene import DEFAULT_MAP_RESOLUTION, _ensure_variant, bsdf_dict, flatten


def scene_dict(
    material: Any,
    *,
    resolution: tuple[int, int] = (256, 256),
    spp: int = 64,
    environment: str | Path | None = None,
    texture_dir: str | Path | None = None,
    force_all_lobes: bool = False,
    max_depth: int | None = None,
    map_resolution: int = DEFAULT_MAP_RESOLUTION,
) -> dict[str, Any]:
    """A minimal scene: the material on a unit sphere, framed, under an environment.

    ``environment`` is a lat-long image (``envmap``); without one, a constant white sky
    (the white-furnace set-up). The integrator depth follows the material; the film
    holds RGB only (no alpha, no AOVs).
    """
    import mitsuba as mi

    flat = flatten(material, map_resolution)
    _ensure_variant()
    width, height = resolution
    distance = 4.0
    fov = 2.0 * math.degrees(math.asin(1.0 / distance)) * 1.15  # the ball fills ~87%
    emitter: dict[str, Any]
    if environment is None:
        emitter = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}
    else:
        emitter = {"type": "envmap", "filename": str(environment)}
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth or max_depth_for(flat)},
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "to_world": mi.ScalarTransform4f().look_at(
                origin=[0.0, 0.0, distance], target=[0.0, 0.0, 0.0], up=[0.0, 1.0, 0.0]
            ),
            "film": {
                "type": "hdrfilm",
                "width": int(width),
                "height": int(height),
                "pixel_format": "rgb",
                "rfilter": {"type": "gaussian"},
            },
            "sampler": {"type": "independent", "sample_count": int(spp)},
        },
        "environment": emitter,
        "ball": {
            "type": "sphere",
            "bsdf": bsdf_dict(flat, texture_dir, force_all_lobes=force_all_lobes),
        },
    }
