"""The ``ri`` context: RenderMan's ``PxrDisneyBsdf`` (Disney) and ``PxrSurface`` (Pixar).

usd-core has no Sdr description of RenderMan's nodes, so only the defaults that are
certain are relied on (a lobe weight of 0 and RenderMan's zero metallic, anisotropy and
tint); every other input of a live lobe is written. Maps are ``PxrTexture`` nodes
(``resultRGB``/``resultR``), the normal map a ``PxrNormalMap`` into ``bumpNormal``.

RenderMan ignores an input it does not know, silently. The input names of the nodes
written here are kept as data, ``renderman_inputs.json`` (with the sources they were
read from), and every network is checked against it before it is written: an unknown
name is a bug in the name table and raises.
"""

from __future__ import annotations

import json
from functools import cache
from pathlib import Path
from typing import Any

from .names import SURFACE_IDS, Slot, mapped_params, table_for
from .network import (
    LOCAL,
    Connection,
    ExportError,
    Image,
    Network,
    Node,
    Source,
    local_subsurface,
    loss_note,
    subsurface_radius,
    surface_inputs,
)
from .textures import affine, converted, output_of, preview_color_space

__all__ = [
    "EXTRA_LOSS",
    "GLASS_REFLECTION",
    "INPUTS_FILE",
    "PIXAR_LOSS",
    "PXR_SURFACE_GAINS",
    "PXR_SURFACE_MODELS",
    "PXR_SURFACE_WITH",
    "RESULTS",
    "RI_DEFAULTS",
    "SURFACE",
    "build",
    "check_network",
    "renderman_inputs",
    "unknown_inputs",
]

INPUTS_FILE = Path(__file__).with_name("renderman_inputs.json")


@cache
def renderman_inputs() -> dict[str, frozenset[str]]:
    """RenderMan node id → its documented input names (``renderman_inputs.json``)."""
    data = json.loads(INPUTS_FILE.read_text(encoding="utf-8"))
    return {node: frozenset(d["inputs"]) for node, d in data["nodes"].items()}


def unknown_inputs(node_id: str, names) -> list[str] | None:
    """Names that ``node_id`` does not have; ``None`` when the node is not in the data."""
    known = renderman_inputs().get(node_id)
    if known is None:
        return None
    return sorted(n for n in names if n not in known)


def check_network(net: Network, material: str) -> None:
    """Raise when a node of ``net`` has an input RenderMan does not define."""
    for node in net.nodes:
        bad = unknown_inputs(node.id, node.inputs)
        if bad is None:
            raise ExportError(f"no input definitions for RenderMan node {node.id}", where=material)
        if bad:
            raise ExportError(
                f"{node.id} has no input {', '.join(bad)} (renderman_inputs.json): "
                "a name-table bug",
                where=material,
            )


SURFACE = "ri_surface"
RI_DEFAULTS = {"metallic": 0.0, "anisotropic": 0.0, "specularTint": 0.0}


def build(source: Source, meters_per_unit: float = 1.0) -> Network:
    """The RenderMan network of ``source``; lengths in scene units of ``meters_per_unit``."""
    nodes: list[Node] = []
    table = table_for("ri", source.model)
    inputs = surface_inputs(source, table, RI_DEFAULTS, nodes, _texture)
    radius = ""
    if source.model == "disney":
        radius = subsurface_radius(source, inputs, "scatterDistances", meters_per_unit)
    if source.normal_map is not None:
        nodes.append(
            Node(
                "ri_normal_map",
                "PxrNormalMap",
                {"filename": ("asset", source.normal_map)},
                {"resultN": "normal3f"},
            )
        )
        inputs["bumpNormal"] = ("normal3f", Connection("ri_normal_map", "resultN"))
    node_id = SURFACE_IDS[("ri", source.model)]
    extra = [EXTRA_LOSS[source.model]] if source.model in EXTRA_LOSS else []
    if radius:
        extra.append(radius)
    displacement = None
    if source.height is not None:
        displacement = _displacement(nodes, source.height)
    if source.model in PXR_SURFACE_MODELS:
        inputs.update(_pixar_gains(source.lobes))
        if source.lobes["reflection_t"]:
            extra.append(GLASS_REFLECTION)
    note = loss_note(source, node_id, mapped_params("ri", source.model), "; ".join(extra))
    surface = Node(SURFACE, node_id, inputs, {"bxdf_out": "token"}, {"loss": note})
    if source.model == "disney" and local_subsurface(source):
        surface.custom["subsurface_radius"] = LOCAL
    net = Network("ri", Connection(SURFACE, "bxdf_out"), [surface, *nodes], displacement)
    check_network(net, source.name)
    return net


PXR_SURFACE_GAINS = {
    # lobe: (gain input, PxrSurface's default gain): a gain on by default must be
    # written 0 for a dead lobe, one off by default written 1 for a live one.
    "diffuse": ("diffuseGain", 1.0),
    "diffuse_t": ("diffuseTransmitGain", 0.0),
    "reflection_t": ("refractionGain", 0.0),
}
PXR_SURFACE_WITH = {
    # lobe: inputs PxrSurface needs besides the gain for that lobe to act.
    # Diffuse transmission is computed only on a double-sided diffuse lobe (PxrSurface
    # docs, Diffuse: "This only applies when Double-Sided is on"); hdPrman sets it too.
    "diffuse_t": {"diffuseDoubleSided": ("int", 1)},
    # The glass lobe splits energy by Fresnel between its reflection and refraction;
    # with reflectionGain at its default 0 the reflected share (total internal
    # reflection included) is dropped.
    "reflection_t": {"reflectionGain": ("float", 1.0)},
}
GLASS_REFLECTION = (
    "PxrSurface's glass lobe reflects too (reflectionGain 1, which keeps its Fresnel "
    "split and internal reflection): at the front that adds to Smits' reflection lobe, "
    "written as the primary specular"
)
PIXAR_LOSS = (
    "PxrSurface has no transmitted specular lobe (Smits' specT); the diffuse weight is "
    "its normal-incidence colour, without Smits' view-dependent Fresnel shape"
)
EXTRA_LOSS = {
    "pixar": PIXAR_LOSS,
    "pixar_weights": PIXAR_LOSS + "; a blend carries no IOR: refraction uses the default",
}
PXR_SURFACE_MODELS = tuple(EXTRA_LOSS)


def _pixar_gains(lobes: dict[str, bool]) -> dict[str, tuple[str, Any]]:
    out = {}
    for lobe, (name, default) in PXR_SURFACE_GAINS.items():
        wanted = 1.0 if lobes[lobe] else 0.0
        if wanted != default:
            out[name] = ("float", wanted)
        if lobes[lobe]:
            out.update(PXR_SURFACE_WITH.get(lobe, {}))
    return out


RESULTS = {"r": "resultR", "g": "resultG", "b": "resultB", "a": "resultA", "rgb": "resultRGB"}
"""Texture output → PxrTexture's output (renderman_inputs.json, PxrTexture outputs)."""


def _texture(nodes: list[Node], slot: Slot, image: Image) -> tuple[str, Any]:
    linear = affine(image, slot)
    if linear is None:
        image, linear = converted(image, slot), (1.0, 0.0)
    output = RESULTS[output_of(image, slot.type)]
    name = f"ri_{slot.param}"
    if any(n.name == name for n in nodes):  # one map feeding two inputs (subsurfaceColor)
        return slot.type, Connection(name, output)
    nodes.append(_pxr_texture(name, image, output, slot.type, linear))
    return slot.type, Connection(name, output)


def _pxr_texture(
    name: str, image: Image, output: str, kind: str, linear: tuple[float, float]
) -> Node:
    """``PxrTexture``: ``linearize`` for an sRGB-encoded file, the affine value rule as
    ``colorScale``/``colorOffset`` and the parameter's mean as ``missingColor`` (the
    names hdPrman's and Gaffer's UsdUVTexture conversions write)."""
    inputs: dict[str, tuple[str, Any]] = {"filename": ("asset", image)}
    if preview_color_space(image.colorspace)[0] == "sRGB":
        inputs["linearize"] = ("int", 1)
    scale, bias = linear
    if (scale, bias) != (1.0, 0.0):
        inputs["colorScale"] = ("color3f", (scale,) * 3)
        inputs["colorOffset"] = ("color3f", (bias,) * 3)
    if image.fallback is not None:  # before colorScale/colorOffset, as UsdUVTexture's
        f = image.fallback
        raw = (lambda x: x) if scale == 0 else (lambda x: (x - bias) / scale)
        inputs["missingColor"] = (
            "color3f",
            tuple(raw(x) for x in f) if isinstance(f, tuple) else (raw(f),) * 3,
        )
    # A UDIM set keeps USD's <UDIM> token in `filename`, as Foundry's Mari exporter for
    # PxrTexture writes it (renderman_inputs.json names the source).
    return Node(name, "PxrTexture", inputs, {output: kind})


def _displacement(nodes: list[Node], image: Image) -> Connection:
    """``PxrDisplace`` (hdPrman's conversion of UsdPreviewSurface displacement):
    ``dispAmount`` 1 scene unit times ``dispScalar``, the height in scene units."""
    texture = _pxr_texture("ri_height", image, "resultR", "float", (image.scale, image.bias))
    if image.fallback is None:
        texture.inputs["missingColor"] = ("color3f", (0.0, 0.0, 0.0))
    nodes.append(texture)
    node = Node(
        "ri_displacement",
        "PxrDisplace",
        {
            "dispAmount": ("float", 1.0),
            "dispScalar": ("float", Connection(texture.name, "resultR")),
        },
        {"displacement": "token"},
    )
    nodes.append(node)
    return Connection(node.name, "displacement")
