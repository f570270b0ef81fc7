"""The names of the models, and where each lives, known without importing the models.

The one table of model names (:data:`HOMES`): :mod:`.registry` imports a model's module
the first time the model is asked for, so reading a library's headers (``lookdev presets
list``) or showing a Disney preset imports no model at all. :data:`PARAMS` says where the
parameter schema of each preset model lives, so a preset is validated without importing
its model's evaluation (``tests/materials/test_registry.py`` checks both tables against
the models themselves).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, MutableMapping
from importlib import import_module
from typing import Any

__all__ = ["HOMES", "PARAMS", "PRESET_MODELS", "Imported"]

HOMES: dict[str, str] = {
    "disney": "disney:MODEL",
    "sheen": "sheen:MODEL",
    "pixar": "pixar:MODEL",
    "pixar_layered": "pixar:LAYERED_MODEL",
    "measured": "measured:MODEL",
    "openpbr": "openpbr:MODEL",
}
"""Every model by name → ``module:attribute`` of its :class:`~.bsdf.Model`, relative to
:mod:`lookdev.materials`; each renders in Mitsuba as the plugin ``lookdev_<name>``."""

PRESET_MODELS: tuple[str, ...] = ("disney", "pixar", "openpbr")
"""Models a preset file may name (besides ``layered``, a stack of them); ``openpbr``
holds an imported OpenPBR material as itself."""

PARAMS: dict[str, str] = {
    "disney": "params:DisneyParams",
    "pixar": "pixar_params:PixarParams",
    "openpbr": "openpbr_params:OpenPBRParams",
}
"""Each preset model → ``module:class`` of its parameter schema (the model's
``params_type``), relative to :mod:`lookdev.materials`."""


class Imported(MutableMapping[str, Any]):
    """A table of homes read as a mapping: each entry imported when first asked for.

    ``name in table`` and iteration need no import; an entry set at run time (the tests'
    toy models) is held as given.

    >>> params = Imported(PARAMS)
    >>> list(params), params["disney"].__name__
    (['disney', 'pixar', 'openpbr'], 'DisneyParams')
    """

    def __init__(self, homes: Mapping[str, str]) -> None:
        self._homes = dict(homes)
        self._loaded: dict[str, Any] = {}

    def __getitem__(self, name: str) -> Any:
        if name not in self._loaded and name in self._homes:
            module, _, attribute = self._homes[name].partition(":")
            self._loaded[name] = getattr(import_module(f".{module}", __package__), attribute)
        return self._loaded[name]

    def __setitem__(self, name: str, value: Any) -> None:
        self._loaded[name] = value

    def __delitem__(self, name: str) -> None:
        if name not in self:
            raise KeyError(name)
        self._loaded.pop(name, None)
        self._homes.pop(name, None)

    def __iter__(self) -> Iterator[str]:
        yield from self._homes
        yield from (name for name in self._loaded if name not in self._homes)

    def __len__(self) -> int:
        return len(self._homes.keys() | self._loaded.keys())

    def __contains__(self, name: object) -> bool:
        return name in self._homes or name in self._loaded
