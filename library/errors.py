"""Errors of the preset library, all one-line :class:`LookdevError` subclasses."""

from __future__ import annotations

import difflib
from collections.abc import Iterable

from lookdev.materials.errors import LookdevError

__all__ = ["LibraryError", "PresetError", "PresetNotFoundError", "TextureError", "did_you_mean"]


class PresetError(LookdevError):
    """A preset file is malformed, invalid, or cannot be resolved."""


class PresetNotFoundError(PresetError):
    """No library defines a preset of that name."""


class LibraryError(LookdevError):
    """A library folder cannot be read or written, or a write would lose data."""


def did_you_mean(name: str, candidates: Iterable[str]) -> str:
    """A ``"; did you mean 'x'?"`` suffix naming the closest candidates, or ``""``.

    >>> did_you_mean("gld", ["gold", "glass", "silver"])
    "; did you mean 'gold'?"
    """
    close = difflib.get_close_matches(name, list(candidates), n=3, cutoff=0.6)
    if not close:
        return ""
    return "; did you mean " + " or ".join(repr(c) for c in close) + "?"


class TextureError(LookdevError):
    """A texture (mask, normal map or parameter map) is missing, unreadable, undecodable,
    not finite, lacks the channel asked for, or holds values outside its parameter's range."""
