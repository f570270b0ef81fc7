"""The swatch of a material's notebook view: a small sphere lit by the built-in studio
IBL, path-sampled on the numpy backend (:func:`lookdev.pipeline.analysis.sphere.ibl_sphere`,
the lit-sphere plot's own code) and shown through the OCIO view, as a PNG.

Registered with :func:`lookdev.library.display.register_swatch` when the API is imported,
so ``lookdev.load("gold")`` in a notebook shows its sphere beside its parameters.
"""

from __future__ import annotations

import io
from typing import Any

__all__ = ["SWATCH_SIZE", "swatch_png"]

SWATCH_SIZE = 96
"""Pixels a side: big enough to read highlight and colour, a few milliseconds to draw."""
SWATCH_SPP = 32
"""Samples a pixel: a metal reads as its colour, at about half a CPU-second."""
SWATCH_IBL = "studio"
SWATCH_MAP_RESOLUTION = 64
"""Texels a side at which a layered or textured material is blended for its swatch."""


def swatch_png(material: Any, size: int = SWATCH_SIZE) -> bytes:
    """PNG bytes of ``material`` on a sphere under :data:`SWATCH_IBL` (black surround)."""
    from matplotlib.image import imsave

    from lookdev.pipeline.analysis.plots import load_environment
    from lookdev.pipeline.analysis.sphere import ibl_sphere
    from lookdev.pipeline.proof.tonemap import to_8bit, view

    from .materials import hub

    blended = hub(material, SWATCH_MAP_RESOLUTION)
    image = ibl_sphere(
        blended.bsdf_model,
        blended.centre_params,
        load_environment(SWATCH_IBL, 128),
        resolution=size,
        spp=SWATCH_SPP,
        maps=blended.maps or None,
    )
    buffer = io.BytesIO()
    imsave(buffer, to_8bit(view(image)), format="png")
    return buffer.getvalue()
