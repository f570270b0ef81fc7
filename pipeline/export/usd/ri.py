"""The ``ri`` context: RenderMan's ``PxrDisneyBsdf`` (Disney) and ``PxrSurface`` (Pixar).

usd-core has no Sdr description of RenderMan's nodes, so only the defaults that are
certain are relied on (a lobe weight of 0 and RenderMan's zero metallic, anisotropy and
tint); every other input of a live lobe is written. Maps are ``PxrTexture`` nodes
(``resultRGB``/``resultR``), the normal map a ``PxrNormalMap`` into ``bumpNormal``.
"""

from __future__ import annotations

from typing import Any

from .names import SURFACE_IDS, Slot, mapped_params, table_for
from .network import Connection, Image, Network, Node, Source, loss_note, surface_inputs
from .textures import converted

SURFACE = "ri_surface"
RI_DEFAULTS = {"metallic": 0.0, "anisotropic": 0.0, "specularTint": 0.0}


def build(source: Source) -> Network:
    """The RenderMan network of ``source``."""
    nodes: list[Node] = []
    table = table_for("ri", source.model)
    inputs = surface_inputs(source, table, RI_DEFAULTS, nodes, _texture)
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
    if source.model in PXR_SURFACE_MODELS:
        inputs.update(_pixar_gains(source.lobes))
    extra = EXTRA_LOSS.get(source.model, "")
    note = loss_note(source, node_id, mapped_params("ri", source.model), extra)
    surface = Node(SURFACE, node_id, inputs, {"bxdf_out": "token"}, {"loss": note})
    return Network("ri", Connection(SURFACE, "bxdf_out"), [surface, *nodes])


PXR_SURFACE_GAINS = {
    # lobe: (gain input, PxrSurface's default gain): a gain on by default must be
    # written 0 for a dead lobe, one off by default written 1 for a live one.
    "diffuse": ("diffuseGain", 1.0),
    "diffuse_t": ("diffuseTransmitGain", 0.0),
    "reflection_t": ("refractionGain", 0.0),
}
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
    return out


def _texture(nodes: list[Node], slot: Slot, image: Image) -> tuple[str, Any]:
    if slot.texture_linear != (1.0, 0.0):
        image = converted(image, slot)
    output = "resultRGB" if slot.type == "color3f" else "resultR"
    name = f"ri_{slot.param}"
    nodes.append(Node(name, "PxrTexture", {"filename": ("asset", image)}, {output: slot.type}))
    return slot.type, Connection(name, output)
