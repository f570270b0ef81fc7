"""The names of the models a preset file may name, known without importing the models.

:mod:`.registry` holds the models themselves and re-exports this; reading a library's
headers (``lookdev presets list``) needs only the names.
"""

from __future__ import annotations

__all__ = ["PRESET_MODELS"]

PRESET_MODELS: tuple[str, ...] = ("disney", "pixar", "openpbr")
"""Models a preset file may name (besides ``layered``, a stack of them); ``openpbr``
holds an imported OpenPBR material as itself."""
