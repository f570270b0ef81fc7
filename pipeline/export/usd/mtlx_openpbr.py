"""The ``mtlx`` context's OpenPBR Surface network for a Disney material.

The mapping is :mod:`.openpbr_map`'s; this module writes it: the single-parameter inputs
through the name-table machinery (a map becomes an image node, a live layer stack a mix
chain, :mod:`.live`), the derived ones as constants (per layer under a live stack, mixed
by the same masks), a tangent-space normal map through ``normalmap`` into
``geometry_normal``, and the loss note naming every term of :data:`.openpbr_map.LOSSES`
that applies.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from .live import mixed_input
from .names import Slot
from .network import Connection, Network, Node, Source, loss_note, same_or_eq, surface_inputs
from .openpbr_map import (
    DERIVED_SOURCES,
    DIRECT,
    GATES,
    MAPPED,
    SURFACE_ID,
    losses_of,
    openpbr_values,
)

__all__ = ["MAPPING", "MAPPING_KEY", "MTLX_SURFACES", "build_disney", "mapped_from_disney"]

MTLX_SURFACES = ("openpbr", "disney")
"""``--mtlx-surface``: the ``mtlx`` surface of a Disney material (OpenPBR by default;
``disney`` keeps ``ND_disney_principled``). Other models' surfaces do not change."""

_TYPES = {bool: "bool", float: "float", tuple: "color3f"}
MAPPING_KEY = "mapping"
MAPPING = "disney_to_openpbr"
"""The surface's customData marking lookdev's mapping (an import reads Burley's
parameters from the other contexts instead of inverting it)."""


def mapped_from_disney(node: Node) -> bool:
    """True for an OpenPBR surface lookdev wrote from a Disney material."""
    return node.custom.get(MAPPING_KEY) == MAPPING


def build_disney(source: Source, meters_per_unit: float, helpers: Any) -> Network:
    """The OpenPBR network of a Disney ``source``; ``helpers`` is :mod:`.mtlx` (its image,
    normal and displacement nodes and the library's defaults)."""
    nodes: list[Node] = []
    defaults = helpers.node_defaults(SURFACE_ID)
    texture = helpers._live_or_baked(source)
    inputs = surface_inputs(source, DIRECT, defaults, nodes, texture)
    values = openpbr_values(source.live_values, source.lobes)
    direct = {s.input for s in DIRECT}
    extra = [loss.why for loss in losses_of(source.live_values, source.lobes)]
    if meters_per_unit != 1.0 and "subsurface_radius" in values:
        values["subsurface_radius"] = values["subsurface_radius"] / meters_per_unit
    layers = _derived_layers(source) if source.layers else []
    averaged = []
    for name, value in values.items():
        if name in direct or not source.lobes.get(GATES.get(name, ""), True):
            continue
        slot = Slot(name, name, _TYPES[type(value)])
        if layers:
            chain = mixed_input(nodes, slot, layers, "mtlx")
            if chain is not None:
                inputs[name] = chain
                continue
        if any(p in source.maps for p in DERIVED_SOURCES.get(name, ())):
            averaged.append(name)
        if not same_or_eq(value, defaults.get(name)):
            inputs[name] = (slot.type, value)
    if averaged:
        extra.append(f"{', '.join(averaged)} made from mapped parameters: their mean value")
    if source.layers:
        extra.append("derived inputs mixed after mapping each layer (not mapped after mixing)")
    if source.normal_map is not None:
        inputs["geometry_normal"] = helpers._normal(nodes, source.normal_map)
    displacement = None
    if source.height is not None:
        displacement = helpers._displacement(nodes, source.height)
    note = loss_note(source, SURFACE_ID, set(MAPPED), "; ".join(extra))
    custom = {"loss": note, MAPPING_KEY: MAPPING}
    surface = Node(helpers.SURFACE, SURFACE_ID, inputs, {"out": "token"}, custom)
    return Network("mtlx", Connection(helpers.SURFACE, "out"), [surface, *nodes], displacement)


def _derived_layers(source: Source) -> list[Any]:
    """The live layers with each one's derived OpenPBR values added to its values."""
    from .lobes import active_lobes, effective

    out = []
    for layer in source.layers:
        lobes = active_lobes(layer.values)
        derived = openpbr_values(effective(layer.values, "disney", lobes), lobes)
        out.append(replace(layer, values={**layer.values, **derived}))
    return out
