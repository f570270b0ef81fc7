"""Errors of the blending engine: one line naming the layer, the file and what is allowed."""

from __future__ import annotations

from lookdev.library.errors import TextureError
from lookdev.materials.errors import LookdevError

__all__ = ["BlendError", "TextureError"]


class BlendError(LookdevError):
    """A layer stack cannot be blended (mixed models, disagreeing discrete parameters …)."""
