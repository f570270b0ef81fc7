"""What a lookdev BSDF plugin reads: its Mitsuba properties, and how ``prepare`` is fed.

Parameters arrive as Mitsuba properties, one per schema field: a constant (float, bool,
string, ``rgb``) or a texture (``bitmap`` …). Constants are handed to ``prepare`` as Python
values, so a lobe whose weight is a constant zero is pruned while the kernel is traced;
textures are evaluated at ``si`` and handed to ``prepare`` as ``maps``. With the boolean
property ``force_all_lobes`` every numeric parameter is handed over as an opaque Dr.Jit
value instead: no weight is then a *known* zero and every lobe is traced (the benchmark
baseline). With ``live`` (the Material Designer's truth mode) those opaque values are the
traversed parameters themselves, defaults included: ``mi.traverse`` edits of any of them
change memory the kernel reads, never the kernel; only a switch (``thin``, a model name)
needs a new BSDF.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookdev.materials.bsdf import Model
from lookdev.materials.errors import LookdevError
from lookdev.materials.registry import is_color_field

__all__ = [
    "FORCE_ALL_LOBES",
    "Inputs",
    "LIVE",
    "MitsubaExportError",
    "ONLY_LOBES",
    "PLUGIN_PREFIX",
    "WEIGHT_SCALE",
    "opaque_inputs",
    "plugin_name",
    "read_properties",
    "texture_maps",
    "texture_placeholders",
    "traversed_values",
    "updated_constants",
]

PLUGIN_PREFIX = "lookdev_"
FORCE_ALL_LOBES = "force_all_lobes"
LIVE = "live"
"""Boolean property: every continuous parameter is a traversed, opaque Dr.Jit value read
by the kernel from memory, so an edit through ``mi.traverse`` needs no new kernel (the
designer's truth mode); every lobe a value can switch on is traced."""
ONLY_LOBES = "only_lobes"
"""Comma-separated lobe names: the plugin evaluates and samples only these (Model.restrict)."""
WEIGHT_SCALE = "weight_scale"
"""A factor on f and on sampled weights, not on pdfs: halves of a split material carry 2."""


class MitsubaExportError(LookdevError):
    """A material cannot become a Mitsuba BSDF or scene as asked."""


def plugin_name(model: Model) -> str:
    """The Mitsuba plugin name of a model: ``lookdev_<model.name>``."""
    return PLUGIN_PREFIX + model.name


@dataclass
class Inputs:
    """A plugin's properties, sorted: the plugin's own switches, the model's constants
    (Python values for its schema) and its textures (``mi.Texture`` by field)."""

    force_all_lobes: bool = False
    live: bool = False
    only_lobes: tuple[str, ...] | None = None
    weight_scale: float = 1.0
    constants: dict[str, Any] = field(default_factory=dict)
    textures: dict[str, Any] = field(default_factory=dict)


def read_properties(props: Any, model: Model) -> Inputs:
    """Sort ``props`` (an ``mi.Properties``) into :class:`Inputs`; an unknown name is a
    :class:`MitsubaExportError` naming the allowed ones."""
    import mitsuba as mi

    fields = model.params_type.model_fields
    inputs = Inputs()
    for key in props.keys():
        value = props[key]
        if key == FORCE_ALL_LOBES:
            inputs.force_all_lobes = bool(value)
        elif key == LIVE:
            inputs.live = bool(value)
        elif key == ONLY_LOBES:
            inputs.only_lobes = tuple(n.strip() for n in str(value).split(",") if n.strip())
        elif key == WEIGHT_SCALE:
            inputs.weight_scale = float(value)
        elif key not in fields:
            raise MitsubaExportError(
                f"unknown parameter; allowed: {', '.join(fields)}",
                where=plugin_name(model),
                field=key,
            )
        elif isinstance(value, mi.Texture):
            inputs.textures[key] = value
        else:
            inputs.constants[key] = _python_value(value)
    return inputs


def traversed_values(model: Model, inputs: Inputs) -> dict[str, Any]:
    """The Dr.Jit values a plugin exposes to ``mi.traverse``: its numeric constants, or in
    ``live`` mode every continuous parameter, defaults included (:func:`opaque_inputs`).

    Numbers and colours can change after load; switches (``thin``, a model name) shape the
    traced kernel, so a new BSDF is the way to change them.
    """
    if inputs.live:
        params = model.params_type.parse(inputs.constants, where=plugin_name(model))
        return opaque_inputs(model, params, skip=inputs.textures)
    return {k: _drjit_value(v) for k, v in inputs.constants.items() if isinstance(v, float | tuple)}


def updated_constants(inputs: Inputs, traversed: dict[str, Any], keys: list[str]) -> bool:
    """Copy the traversed values named in ``keys`` back into ``inputs.constants`` (the
    plugin then prepares anew); whether any changed. Not for ``live`` plugins, whose
    kernel reads the traversed values themselves."""
    changed = [k for k in keys if k in traversed]
    for key in changed:
        inputs.constants[key] = _from_drjit(traversed[key], inputs.constants[key])
    return bool(changed)


def texture_placeholders(xp: Any, model: Model, textures: dict[str, Any]) -> dict[str, Any]:
    """One opaque 0.5 per textured field, for the ``prepare`` that decides the lobes: a
    texture may be non-zero somewhere, and an opaque value keeps its lobe alive."""
    import drjit as dr
    import mitsuba as mi

    out = {}
    for key in textures:
        value = dr.opaque(mi.Float, 0.5)
        out[key] = xp.Array3(value) if is_color_field(model.params_type, key) else value
    return out


def texture_maps(xp: Any, model: Model, textures: dict[str, Any], si: Any, active: Any):
    """Each texture evaluated at ``si``: the ``maps`` of ``prepare`` at a hit."""
    maps = {}
    for key, tex in textures.items():
        if is_color_field(model.params_type, key):
            maps[key] = xp.Array3(tex.eval(si, active))
        else:
            maps[key] = tex.eval_1(si, active)
    return maps


def opaque_inputs(model: Model, params: Any, skip: Any = ()) -> dict[str, Any]:
    """Every continuous parameter of ``params`` (the schema's texturable fields that hold
    a value, defaults included) as an opaque Dr.Jit value, for ``model.prepare``'s maps.

    ``known_zero`` cannot see through an opaque value, so no lobe weight derived from one
    (``spec_trans``, or ``1 − metallic`` of a metal) is pruned, and a kernel traced with
    these inputs reads them from memory: new values need no new kernel. Fields in ``skip``
    (textures) are left out.
    """
    import drjit as dr
    import mitsuba as mi

    from lookdev.materials.textures import texturable

    weights = texturable(model.params_type)  # not choices such as specular_gamma
    skip = set(skip)
    out: dict[str, Any] = {}
    for key, value in params.model_dump().items():
        if key in skip or isinstance(value, bool) or key not in weights:
            continue
        if isinstance(value, int | float):
            out[key] = dr.opaque(mi.Float, float(value))
        elif isinstance(value, tuple):
            out[key] = mi.Vector3f(*(dr.opaque(mi.Float, float(c)) for c in value))
    return out


def _python_value(value: Any) -> Any:
    """A Mitsuba property as a plain value for the pydantic schema; numbers as the
    float32 the kernel computes in (so a lobe is pruned exactly where its stored weight is
    0, as :func:`lookdev.materials.registry.live_lobes` judges)."""
    if isinstance(value, bool | str):
        return value
    if isinstance(value, int | float):
        return float(np.float32(value))
    try:
        return tuple(float(c) for c in value)  # ScalarColor3f / ScalarColor3d
    except TypeError:
        return value


def _drjit_value(value: float | tuple[float, ...]) -> Any:
    """A numeric constant as the Dr.Jit value ``mi.traverse`` exposes."""
    import mitsuba as mi

    return mi.Color3f(*value) if isinstance(value, tuple) else mi.Float(value)


def _from_drjit(value: Any, old: float | tuple[float, ...]) -> float | tuple[float, ...]:
    """The updated traversed value back as the constant's Python type."""
    if isinstance(old, tuple):
        return tuple(float(value[i][0]) for i in range(3))
    return float(value[0])
