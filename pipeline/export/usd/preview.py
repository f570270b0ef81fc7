"""The universal context: a ``UsdPreviewSurface`` network every DCC reads.

Maps are ``UsdUVTexture`` nodes reading ``st`` through one ``UsdPrimvarReader_float2``;
affine conversions (the clearcoat scale, ``opacity = 1 - spec_trans`` when asked) ride on the
texture's ``scale``/``bias`` so the baked image is shared with the other contexts.
What the surface cannot express is named in the surface shader's ``customData``
(``lookdev:loss``), and an importer reads only what is there. The surface's constants
sit on its own inputs, not on connections to the Material's interface: Blender's
importer (and others that rebuild the surface as their own shader) reads only those.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np

from .names import Slot, mapped_params, table_for
from .network import (
    ST_PRIMVAR,
    Connection,
    Image,
    Network,
    Node,
    Source,
    loss_note,
    plain_value,
    surface_inputs,
)
from .textures import (
    USD_WRAP,
    affine,
    converted,
    fallback4,
    output_of,
    preview_color_space,
    usd_color_space,
)

__all__ = [
    "KEPT_OPAQUE",
    "SHAPE_NOTES",
    "ST_READER",
    "SURFACE",
    "TRANSMISSION_LOBES",
    "build",
    "preview_defaults",
]

SURFACE = "preview_surface"
ST_READER = "preview_st"
SHAPE_NOTES = {
    "disney": {
        "clearcoat": "the clearcoat is GGX here, Burley's GTR1 (App. B.2) there",
        "diffuse": "the diffuse has no retro-reflection (Burley §5.3)",
        "scatter": "UsdPreviewSurface has no subsurface: the solid's interior medium "
        "renders as an opaque diffuse of its base colour (no light bleeds or shows through)",
    },
    "pixar": {
        "highlights": "Smits' specular and reflection lobes become one GGX lobe",
        "diffuse": "the diffuse loses Smits' Fresnel-shaped darkening (PDiffuse)",
        "diffuse_t": "no transmitted diffuse lobe",
    },
    "pixar_weights": {
        "highlights": "the blend's specular and reflection lobes become one GGX lobe with "
        "their energy-weighted roughness and Schlick's edge, not their grazing weights; "
        "their F0 colour and the diffuse are solved per texel for a base colour and a "
        "metallic (metallic workflow: a dielectric F0 other than the ior's shifts to metallic)",
        "diffuse": "the diffuse is its weight at normal incidence",
        "diffuse_t": "no transmitted diffuse lobe",
        "transmission": "no refraction: a blend's transmitted lobes are not expressed",
    },
}
"""model → lobe → what the surface changes about it when that lobe is live."""

TRANSMISSION_LOBES = {"disney": ("spec_trans",), "pixar": ("specular_t", "reflection_t")}
KEPT_OPAQUE = (
    "transmission is not expressible; opacity kept at 1 so DCCs do not read it as alpha "
    "(--preview-opacity transmission writes the spec's opacity = 1 - transmission)"
)


@cache
def preview_defaults() -> dict[str, Any]:
    """UsdPreviewSurface's input defaults, as the Sdr registry of usd-core knows them."""
    from pxr import Sdr

    node = Sdr.Registry().GetShaderNodeByIdentifier("UsdPreviewSurface")
    return {n: _plain(node.GetShaderInput(n).GetDefaultValue()) for n in node.GetShaderInputNames()}


def _plain(value: Any) -> Any:
    if isinstance(value, str) or not hasattr(value, "__len__"):
        return value
    return tuple(float(x) for x in value)


def build(source: Source, preview_opacity: str = "keep") -> Network:
    """The UsdPreviewSurface network of ``source``.

    ``preview_opacity`` (:data:`.names.PREVIEW_OPACITY`): ``keep`` leaves ``opacity`` at
    1 for transmissive materials and names the loss; ``transmission`` writes the spec's
    ``opacity = 1 − spec_trans`` (``1 − clear`` for Pixar).
    """
    nodes: list[Node] = []
    table = table_for("universal", source.model, preview_opacity)
    inputs = surface_inputs(source, table, preview_defaults(), nodes, _texture)
    # The surface holds its constants itself, unconnected: DCC importers that build
    # their own shader from a UsdPreviewSurface (Blender's among them) read an input's
    # value only when it has no connection, and follow a connection only to a shader
    # output, so an input connected to the Material's interface arrives as their
    # default. The interface stays, read by the MaterialX and RenderMan networks.
    inputs = {name: (kind, plain_value(value)) for name, (kind, value) in inputs.items()}
    if source.normal_map is not None:
        inputs["normal"] = _normal(nodes, source.normal_map)
    refit = _fractional_metal(source, inputs) if source.model == "disney" else ""
    displacement = None
    if source.height is not None:
        # UsdPreviewSurface displaces along the normal by `displacement` scene units.
        inputs["displacement"] = _height(nodes, source.height)
        displacement = Connection(SURFACE, "displacement")
    lobes = source.lobes
    notes = SHAPE_NOTES[source.model]
    shapes = [text for lobe, text in notes.items() if lobes[lobe]]
    transmissive = any(lobes[lobe] for lobe in TRANSMISSION_LOBES.get(source.model, ()))
    if transmissive and preview_opacity == "keep":
        shapes.insert(0, KEPT_OPAQUE)
    if refit:
        shapes.append(refit)
    mapped = mapped_params("universal", source.model, preview_opacity)
    shapes += [n.custom.pop("space_note") for n in nodes if n.custom.get("space_note")]
    note = loss_note(source, "UsdPreviewSurface", mapped, "; ".join(shapes))
    outputs = {"surface": "token"}
    if displacement is not None:
        outputs["displacement"] = "token"
    surface = Node(SURFACE, "UsdPreviewSurface", inputs, outputs)
    surface.custom["loss"] = note
    return Network("universal", Connection(SURFACE, "surface"), [surface, *nodes], displacement)


def _fractional_metal(source: Source, inputs: dict[str, tuple[str, Any]]) -> str:
    """A constant metallic strictly between 0 and 1, refitted; the note, or ``""``.

    UsdPreviewSurface interpolates F0 towards a *white* colour (``mix(1, diffuseColor,
    metallic)``), Burley towards the base colour (§5.4): car paint's metallic 0.4 on a
    dark red reads F0 ≈ 0.25 grey there instead of ≈ 0.03 red (measured by ``export usd
    --report``: albedo off by 0.22). So diffuseColor and metallic are solved for Burley's
    F0 and diffuse (:func:`.pixar.metallic_workflow`, the layered Pixar export's solver).
    A mapped base colour or metallic is written as it is.
    """
    from lookdev.materials.colour import luminance

    from .pixar import metallic_workflow

    values = source.live_values
    m = float(values["metallic"])
    if not 0.0 < m < 1.0 or {"metallic", "base_color"} & set(source.maps):
        return ""
    base = np.asarray(values["base_color"], np.float64)
    y = luminance(base)
    tint = base / y if y > 0.0 else np.ones(3)
    dielectric = 0.08 * values["specular"] * (1.0 + (tint - 1.0) * values["specular_tint"])
    f0 = dielectric + (base - dielectric) * m  # Burley §5.4: mix(Cspec0, base, metallic)
    front = base * (1.0 - m) * (1.0 - np.clip(f0, 0.0, 1.0))
    colour, metal = metallic_workflow(front, f0, values["ior"])
    inputs["diffuseColor"] = ("color3f", tuple(float(c) for c in colour))
    inputs["metallic"] = ("float", float(metal))
    return (
        f"metallic={m:g} is refitted to metallic {float(metal):.3g} and diffuseColor "
        f"({', '.join(f'{c:.3g}' for c in colour)}): the surface interpolates F0 towards "
        "white, Burley towards the base colour; F0's tint is lost"
    )


def _st(nodes: list[Node]) -> Connection:
    """The one ``st`` reader; its primvar name is the Material's interface input."""
    if not any(n.name == ST_READER for n in nodes):
        reader = Node(ST_READER, "UsdPrimvarReader_float2", {"varname": ("string", ST_PRIMVAR)})
        reader.outputs["result"] = "float2"
        nodes.append(reader)
    return Connection(ST_READER, "result")


def _uv_texture(
    nodes: list[Node],
    name: str,
    image: Image,
    output: str,
    kind: str,
    scale_bias: tuple[tuple[float, ...], tuple[float, ...]] | None = None,
    slot_type: str = "float",
) -> Node:
    """A ``UsdUVTexture`` reading ``image``: colour space, wrap, scale/bias, fallback."""
    space, note = preview_color_space(image.colorspace)
    wrap = USD_WRAP[image.wrap]
    node = Node(
        name,
        "UsdUVTexture",
        {
            "file": ("asset", image),
            "st": ("float2", _st(nodes)),
            "sourceColorSpace": ("token", space),
            "wrapS": ("token", wrap),
            "wrapT": ("token", wrap),
        },
        {output: kind},
    )
    metadata = usd_color_space(image, slot_type)
    if metadata is not None:
        node.color_spaces["file"] = metadata
    if note:
        node.custom["space_note"] = note
    if scale_bias is not None:
        scale, bias = scale_bias
        if scale != (1.0, 1.0, 1.0, 1.0) or bias != (0.0, 0.0, 0.0, 0.0):
            node.inputs["scale"] = ("float4", scale)
            node.inputs["bias"] = ("float4", bias)
    nodes.append(node)
    return node


def _texture(nodes: list[Node], slot: Slot, image: Image) -> tuple[str, Any]:
    linear = affine(image, slot)
    if linear is None:  # not affine: a converted copy, read as it is
        image = converted(image, slot)
        linear = (1.0, 0.0)
    output = output_of(image, slot.type)
    kind = "float3" if output == "rgb" else "float"
    scale, bias = linear
    node = _uv_texture(
        nodes,
        f"preview_{slot.param}",
        image,
        output,
        kind,
        ((scale, scale, scale, 1.0), (bias, bias, bias, 0.0)),
        slot.type,
    )
    fallback = fallback4(image, output, scale, bias)
    if fallback is not None:
        node.inputs["fallback"] = ("float4", fallback)
    return slot.type, Connection(node.name, output)


def _normal(nodes: list[Node], image: Image) -> tuple[str, Any]:
    """A tangent-space normal map: texel 0..1 ↦ -1..1 by scale 2, bias -1 (spec 5.4);
    a DirectX map (green down) gets −2, +1 on green. A missing file reads as the
    unperturbed normal (0, 0, 1)."""
    g = (-2.0, 1.0) if image.flip_y else (2.0, -1.0)
    scale_bias = ((2.0, g[0], 2.0, 1.0), (-1.0, g[1], -1.0, 0.0))
    node = _uv_texture(nodes, "preview_normal_map", image, "rgb", "float3", scale_bias)
    node.inputs["fallback"] = ("float4", (0.5, 0.5, 1.0, 1.0))
    return "normal3f", Connection(node.name, "rgb")


def _height(nodes: list[Node], image: Image) -> tuple[str, Any]:
    """Heights in scene units: the file's value times the height scale, plus offset; a
    missing file reads as height 0 (no displacement)."""
    s, b = image.scale, image.bias
    node = _uv_texture(
        nodes, "preview_height", image, "r", "float", ((s, s, s, 1.0), (b, b, b, 0.0))
    )
    node.inputs["fallback"] = ("float4", (0.0 if s == 0 else -b / s, 0.0, 0.0, 1.0))
    return "float", Connection(node.name, "r")
