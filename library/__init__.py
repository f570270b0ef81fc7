"""Preset files and libraries: load, resolve, validate, save.

>>> from lookdev.library import Library
>>> Library(use_env=False).load("gold").params.metallic
1.0
"""

from .errors import LibraryError, PresetError, PresetNotFoundError
from .library import ENV_PATH, Library, builtin_folder, load_material, read_preset
from .material import Layer, Material, resolve
from .preset import MODELS, PresetFile, dump_preset, parse_preset

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
