"""Blending engine: masks, Disney parameter blending, Pixar lobe compositing.

>>> from lookdev.library import Library
>>> blended = blend(Library(use_env=False).load("gold"), 64)
>>> blended.maps, blended.to_params().metallic
({}, 1.0)
"""

from .bake import bake
from .engine import blend
from .errors import BlendError, TextureError
from .masks import MaskSampler
from .result import BlendedMaterial

__all__ = ["BlendError", "BlendedMaterial", "MaskSampler", "TextureError", "bake", "blend"]
