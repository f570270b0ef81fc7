"""``lookdev bench depth``: what following the material's path depth saves, and loses.

For each preset, the proof shader ball (a sphere and a cup on a ground plane, under one
IBL) is rendered at the depth :func:`~lookdev.pipeline.export.mitsuba.max_depth_for`
chooses and at a deep reference, at equal samples per pixel, in interleaved rounds after
one warm-up render each (so compilation is not counted and a busy machine slows both
alike). Reported per preset: both times and the speed-up, and what the shorter paths lose
against the reference: the mean radiance and the 99th-percentile pixel (luminance).

Both depths render with the same seeds, so their paths agree up to the cut and the loss
is measured nearly free of noise.
"""

from __future__ import annotations

import time
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from lookdev.materials.colour import luminance
from lookdev.materials.errors import LookdevError

__all__ = ["BenchDepthError", "DEFAULT_PRESETS", "Settings", "loss", "measure", "run"]

DEFAULT_PRESETS = ("plastic_matte", "gold", "leaf", "glass_thin", "glass_clear")
"""One preset per depth class: dark opaque, bright opaque, diffuse and glossy thin
transmission, solid glass."""


class BenchDepthError(LookdevError):
    """The depth benchmark cannot run as asked."""


@dataclass(frozen=True)
class Settings:
    presets: tuple[str, ...] = DEFAULT_PRESETS
    ibl: str = "studio"
    spp: int = 64
    resolution: tuple[int, int] = (160, 80)
    reference_depth: int = 32
    repeat: int = 3
    ibl_width: int = 256


def measure(preset: str, s: Settings) -> dict[str, Any]:
    """Times and image loss of one preset at its chosen depth against the reference."""
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba as mi

    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.export.mitsuba import bsdf_dict, max_depth_for
    from lookdev.pipeline.proof import batch, ibl, shaderball
    from lookdev.pipeline.proof.turntable import material_interior

    hub = blend(load_material(preset), batch.MAP_RESOLUTION)
    depth = max_depth_for(hub)
    bsdf = bsdf_dict(hub)
    env = ibl.load(s.ibl, s.ibl_width)
    if s.reference_depth <= depth:
        raise BenchDepthError(
            f"{s.reference_depth} must exceed the depth {depth} chosen for {preset}",
            field="--reference-depth",
        )
    depths = (depth, s.reference_depth)
    inside = material_interior(hub)
    scenes = {
        d: mi.load_dict(shaderball.scene_dict(bsdf, env.pixels, s.resolution, d, interior=inside))
        for d in depths
    }
    for scene in scenes.values():
        mi.render(scene, spp=s.spp, seed=0)
    seconds: dict[int, list[float]] = {d: [] for d in depths}
    images: dict[int, list[np.ndarray]] = {d: [] for d in depths}
    for r in range(s.repeat):
        for d, scene in scenes.items():
            t0 = time.perf_counter()
            images[d].append(np.array(mi.render(scene, spp=s.spp, seed=1 + r)))
            seconds[d].append(time.perf_counter() - t0)
    chosen, reference = (np.mean(images[d], axis=0) for d in depths)
    return {
        "preset": preset,
        "depth": depth,
        "reference_depth": depths[1],
        "seconds": min(seconds[depths[0]]),
        "reference_seconds": min(seconds[depths[1]]),
        "speedup": min(seconds[depths[1]]) / min(seconds[depths[0]]),
        **loss(chosen, reference),
    }


def loss(image: np.ndarray, reference: np.ndarray) -> dict[str, float]:
    """How much darker ``image`` is than ``reference``: mean and 99th-percentile pixel.

    >>> ref = np.ones((2, 50, 3), np.float32)
    >>> img = ref.copy(); img[0, 0] = 0.5
    >>> {k: round(v, 3) for k, v in loss(img, ref).items()}
    {'mean_loss': 0.005, 'p99_pixel_loss': 0.005}
    """
    y_img, y_ref = luminance(image), luminance(reference)
    pixel = (y_ref - y_img) / np.maximum(y_ref, 1e-3)
    return {
        "mean_loss": float(1.0 - y_img.mean() / max(float(y_ref.mean()), 1e-12)),
        "p99_pixel_loss": float(np.percentile(pixel, 99)),
    }


def run(s: Settings, progress: Any = None) -> dict[str, Any]:
    rows = []
    for preset in s.presets:
        rows.append(measure(preset, s))
        if progress is not None:
            progress()
    return {"settings": asdict(s), "presets": rows}
