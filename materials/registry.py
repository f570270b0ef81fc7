"""The one registry of reflectance models and their lobes, and the one rule of liveness.

Every table elsewhere (the library's model names, the exporters' lobe notes, the Mitsuba
plugins' flags, the normals' lobe groups, the stability sweep, the plots) asks this module
instead of keeping its own list. A model publishes itself in its module as a
:class:`~.bsdf.Model` with its :class:`~.bsdf.Lobe` s; this module only collects them.

Whether a lobe is *live* is decided by one function, :func:`live_lobes`, which runs the
model's own ``prepare`` on the numpy backend: a lobe lives where its weight is not zero
everywhere, exactly as the model prunes it when it evaluates, samples and renders.

>>> sorted(MODELS)
['disney', 'measured', 'openpbr', 'pixar', 'pixar_layered', 'sheen']
>>> from .params import DisneyParams
>>> live_lobes(MODELS["disney"], DisneyParams(metallic=1.0, sheen=0.5))
('specular',)
>>> live_lobes(MODELS["disney"], DisneyParams(spec_trans=1.0, sheen=0.5))
('specular', 'spec_trans')
"""

from __future__ import annotations

import types
import typing
from collections.abc import Mapping, MutableMapping
from typing import Any

import numpy as np

from .arrays import NumpyOps
from .bsdf import Model
from .errors import LookdevError
from .model_names import HOMES, PRESET_MODELS, Imported

__all__ = [
    "LAYERED",
    "MODELS",
    "PRESET_MODELS",
    "UnknownModelError",
    "dead_parameters",
    "is_color_field",
    "live_lobes",
    "model_named",
    "model_of_params",
    "parameter_lobes",
]

MODELS: MutableMapping[str, Model] = Imported(HOMES)
"""Every model by name, imported on first use; each renders in Mitsuba as the plugin
``lookdev_<name>``. A new model adds its row to :data:`~.model_names.HOMES` (tests add toy
models by setting an item)."""


LAYERED: Mapping[str, str] = types.MappingProxyType({"pixar": "pixar_layered"})
"""Preset model → the model that takes its composited layer stack where blending does not
give the model's own parameters (Smits' lobe weights, not a parameter mix)."""


class UnknownModelError(LookdevError, KeyError):
    """A model name that is not in :data:`MODELS`."""

    def __str__(self) -> str:  # KeyError would quote the message
        return LookdevError.__str__(self)


def model_named(name: str) -> Model:
    """The model called ``name``; an :class:`UnknownModelError` listing the known ones."""
    try:
        return MODELS[name]
    except KeyError:
        known = ", ".join(MODELS)
        raise UnknownModelError(f"unknown model {name!r}; known: {known}", field="model") from None


def model_of_params(params: Any) -> Model:
    """The model whose parameter type ``params`` is."""
    for model in MODELS.values():
        if type(params) is model.params_type:
            return model
    raise UnknownModelError(f"no model takes parameters of type {type(params).__name__}")


def is_color_field(params_type: type, field: str) -> bool:
    """True when a schema field holds an RGB triple (its map is (H, W, 3))."""
    annotation = params_type.model_fields[field].annotation
    while typing.get_origin(annotation) in (typing.Annotated, typing.Union, types.UnionType):
        annotation = typing.get_args(annotation)[0]  # Colour | None: the colour
    return typing.get_origin(annotation) is tuple


def live_lobes(model: Model, params: Any, maps: Mapping[str, Any] | None = None) -> tuple[str, ...]:
    """The lobes of ``model`` whose weight is not zero everywhere, in the model's order.

    ``params`` are the constants; ``maps`` override fields with per-texel arrays ((H, W)
    scalars, (H, W, 3) colours, all of one size). The model's own ``prepare`` decides, on
    the numpy backend, so this is the rule its evaluation, sampling and plugin follow.
    Values are judged as every consumer stores them, in float32: a weight of 1e-50 is 0
    in a Mitsuba kernel and in a USD file alike.
    """
    flat = _flattened(model.params_type, maps or {})
    with np.errstate(all="ignore"):
        prepared = model.prepare(NumpyOps(), _stored(params), **flat)
    return tuple(prepared.lobes)


def _stored(params: Any) -> Any:
    """``params`` with every number rounded to float32 (the type of a scene or a stage)."""
    update = {}
    for name in type(params).model_fields:
        value = getattr(params, name)
        if isinstance(value, float):
            update[name] = float(np.float32(value))
        elif isinstance(value, tuple) and all(isinstance(v, float) for v in value):
            update[name] = tuple(float(np.float32(v)) for v in value)
    return params.model_copy(update=update)


def _flattened(params_type: type, maps: Mapping[str, Any]) -> dict[str, np.ndarray]:
    """Maps as ``prepare`` takes them: scalars (N,), colours channel-first (3, N)."""
    out = {}
    for name, value in maps.items():
        a = np.asarray(value, dtype=np.float64)
        a = a.astype(np.float32).astype(np.float64)
        out[name] = a.reshape(-1, 3).T if is_color_field(params_type, name) else a.reshape(-1)
    return out


def parameter_lobes(model: Model) -> dict[str, tuple[str, ...]]:
    """Parameter → the lobes it acts through, for the parameters lobes name (Lobe.params)."""
    out: dict[str, tuple[str, ...]] = {}
    for lobe in model.lobes:
        for name in lobe.params:
            out[name] = (*out.get(name, ()), lobe.name)
    return out


def dead_parameters(model: Model, live: tuple[str, ...]) -> frozenset[str]:
    """Parameters with no effect because every lobe they act through is dead."""
    return frozenset(
        name
        for name, lobes in parameter_lobes(model).items()
        if not any(lobe in live for lobe in lobes)
    )
