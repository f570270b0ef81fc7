"""Preset files and libraries: load, resolve, validate, save.

>>> from lookdev.library import Library
>>> Library(use_env=False).load("gold").params.metallic
1.0
"""

from __future__ import annotations

import importlib

from .errors import LibraryError, PresetError, PresetNotFoundError

__all__ = [
    "ENV_PATH",
    "MODELS",
    "Layer",
    "Library",
    "LibraryError",
    "Material",
    "PresetError",
    "PresetFile",
    "PresetNotFoundError",
    "builtin_folder",
    "dump_preset",
    "load_material",
    "parse_preset",
    "read_preset",
    "resolve",
]

_HOMES = {
    "ENV_PATH": "library",
    "Library": "library",
    "builtin_folder": "library",
    "load_material": "library",
    "read_preset": "library",
    "Layer": "material",
    "Material": "material",
    "resolve": "material",
    "MODELS": "preset",
    "PresetFile": "preset",
    "dump_preset": "preset",
    "parse_preset": "preset",
}
"""Where each name lives: imported on first use, so that listing a library's headers
(``lookdev presets list``) does not import the schemas, pydantic and the models."""


def __getattr__(name: str) -> object:
    if name in _HOMES:
        value = getattr(importlib.import_module(f".{_HOMES[name]}", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
