"""Errors of the blending engine: one line naming the layer, the file and what is allowed."""

from __future__ import annotations

from lookdev.materials.errors import LookdevError


class BlendError(LookdevError):
    """A layer stack cannot be blended (mixed models, disagreeing discrete parameters …)."""


class TextureError(BlendError):
    """A mask or normal-map texture is missing, unreadable, undecodable or not finite."""
