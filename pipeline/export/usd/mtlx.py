"""The ``mtlx`` context: MaterialX networks inside USD, and standalone ``.mtlx`` documents.

The surface per model is chosen in :mod:`.names`; a Disney material's is OpenPBR Surface
(:mod:`.mtlx_openpbr`) unless ``ND_disney_principled`` is asked for.
Maps are ``ND_image_*`` nodes reading the default texture coordinates. Layered
materials exported live become ``ND_mix_*`` chains driven by mask images: Burley §5.7
blends *parameters*, so each parameter that differs between layers gets its own chain
``mix(bg = below, fg = layer, mix = mask)``, feeding one surface.

The same :class:`~.network.Network` objects are written into a MaterialX document with
the ``MaterialX`` package and checked with its own ``validate``; usd-core cannot check
MaterialX ids (it ships without UsdMtlx).
"""

from __future__ import annotations

import os
from functools import cache
from pathlib import Path
from typing import Any

from lookdev.materials import colour

from .live import mixed_input
from .names import SURFACE_IDS, Slot, mapped_params, table_for
from .network import (
    LOCAL,
    Connection,
    ExportError,
    Image,
    MaterialSpec,
    Network,
    Node,
    Source,
    local_subsurface,
    loss_note,
    plain_value,
    prim_name,
    subsurface_radius,
    surface_inputs,
)
from .textures import MTLX_ADDRESS, affine, converted, output_of

__all__ = [
    "EXTRA_LOSS",
    "MX_TYPES",
    "SURFACE",
    "build",
    "document",
    "fixed_transmission_roughness",
    "mtlx_color_space",
    "mtlx_version",
    "node_defaults",
    "validate_document",
    "write_document",
]

SURFACE = "mtlx_surface"
BLEND_KEY = "blend"
"""The surface's customData marking a layered Pixar blend's OpenPBR (its lobe weights
composited: no preset to import)."""
MX_TYPES = {
    "float": "float",
    "color3f": "color3",
    "color4f": "color4",
    "float3": "color3",
    "vector3f": "vector3",
    "normal3f": "vector3",
    "float2": "vector2",
    "int": "integer",
    "bool": "boolean",
    "string": "string",
    "asset": "filename",
    "token": "string",
}
"""USD value type → MaterialX type."""


@cache
def _library():
    import MaterialX as mx

    lib = mx.createDocument()
    mx.loadLibraries(mx.getDefaultDataLibraryFolders(), mx.getDefaultDataSearchPath(), lib)
    return lib


@cache
def _mtlx_spaces() -> frozenset[str]:
    """MaterialX's colour-space names: its ``cmlib`` conversions' sources, and the
    default working space ``lin_rec709``."""
    names = {"lin_rec709"}
    for nodedef in _library().getNodeDefs():
        n = nodedef.getName()
        if n.startswith("ND_") and "_to_" in n:
            names.add(n[3:].split("_to_")[0])
    return frozenset(names)


def mtlx_color_space(space: str | None) -> str | None:
    """The MaterialX ``colorspace`` of a file in OCIO ``space`` (None for data): the
    space's name or an alias MaterialX knows, else the OCIO name (read by MaterialX's
    OCIO colour management)."""
    if space is None or colour.is_data(space):
        return None
    cs = colour.config().getColorSpace(colour.canonical(space))
    known = {n.lower(): n for n in _mtlx_spaces()}
    for name in (cs.getName(), *cs.getAliases()):
        if name.lower() in known:
            return known[name.lower()]
    return cs.getName()


@cache
def mtlx_version() -> str:
    """The MaterialX document version of the installed libraries (which define
    ``ND_disney_principled``): what ``config:mtlx:version`` records."""
    return _library().getVersionString()


@cache
def node_defaults(node_id: str) -> dict[str, Any]:
    """Input defaults of a MaterialX node definition, as plain Python values."""
    nodedef = _library().getNodeDef(node_id)
    out: dict[str, Any] = {}
    for inp in nodedef.getActiveInputs():
        value = inp.getValue()
        if value is None:
            continue
        out[inp.getName()] = tuple(value.asTuple()) if hasattr(value, "asTuple") else value
    return out


def build(source: Source, meters_per_unit: float = 1.0, surface: str = "openpbr") -> Network:
    """The MaterialX network of ``source`` (surface plus image nodes); lengths in scene
    units of ``meters_per_unit`` (:func:`.network.subsurface_radius`). ``surface``: a
    Disney material's surface, ``openpbr`` (:mod:`.mtlx_openpbr`) or ``disney``
    (``ND_disney_principled``)."""
    if source.model == "disney" and surface == "openpbr":
        import sys

        from .mtlx_openpbr import build_disney

        return build_disney(source, meters_per_unit, sys.modules[__name__])
    nodes: list[Node] = []
    node_id = SURFACE_IDS[("mtlx", source.model)]
    table = table_for("mtlx", source.model)
    inputs = surface_inputs(source, table, node_defaults(node_id), nodes, _live_or_baked(source))
    extra = [EXTRA_LOSS[source.model]] if source.model in EXTRA_LOSS else []
    if source.model == "disney":
        radius = subsurface_radius(source, inputs, "subsurfaceDistance", meters_per_unit)
        extra.append(radius)
        extra.append(_frosted(source))
        extra = [e for e in extra if e]
    if source.normal_map is not None and source.model == "disney":
        extra.append(f"{node_id} has no normal input: the normal map is not applied")
    elif source.normal_map is not None:
        inputs["geometry_normal"] = _normal(nodes, source.normal_map)
    mapped = mapped_params("mtlx", source.model)
    if source.model == "disney" and source.lobes["sheen"]:
        mapped |= _sheen(source.live_values, extra)
    displacement = None
    if source.height is not None:
        displacement = _displacement(nodes, source.height)
    note = loss_note(source, node_id, mapped, "; ".join(extra))
    surface = Node(SURFACE, node_id, inputs, {"out": "token"}, {"loss": note})
    if source.model == "pixar_weights":  # an OpenPBR does not tell a blend from a preset
        surface.custom[BLEND_KEY] = source.model
    if source.model == "disney" and local_subsurface(source):
        surface.custom["subsurface_radius"] = LOCAL
    return Network("mtlx", Connection(SURFACE, "out"), [surface, *nodes], displacement)


def _displacement(nodes: list[Node], image: Image) -> Connection:
    """``ND_displacement_float``: the height (scene units) along the normal, scale 1."""
    kind, height = _image(nodes, "mtlx_height", image, "float", (image.scale, image.bias))
    node = Node(
        "mtlx_displacement",
        "ND_displacement_float",
        {"displacement": (kind, height)},
        {"out": "token"},
    )
    nodes.append(node)
    return Connection(node.name, "out")


EXTRA_LOSS = {
    "pixar_weights": "OpenPBR in its metallic workflow: one highlight lobe (the blend's "
    "energy-weighted roughness, Schlick's edge, not its grazing weights), its F0 and "
    "diffuse solved per texel for base_color and base_metalness; no transmitted lobes; "
    "Smits' layers are composited into the maps it reads (his layering is not a mask mix "
    "of surfaces): a repainted mask needs a re-export",
    "pixar": "OpenPBR has one specular lobe: Smits' specular and reflection lobes share "
    "their energy-weighted roughness (the lobe carrying more light sets the width; the "
    "other's own width is lost); no transmitted diffuse; lobe scales fold into colours "
    "only where a colour exists",
}


@cache
def fixed_transmission_roughness() -> str | None:
    """The transmission roughness ``ND_disney_principled``'s graph fixes (its
    ``dielectric_bsdf`` in mode T reads a constant, not an input), or None when the
    installed MaterialX exposes it."""
    graph = _library().getNodeDef("ND_disney_principled").getImplementation()
    for node in graph.getNodes():
        if node.getCategory() == "dielectric_bsdf":
            rough = node.getInput("roughness")
            if rough is not None and not rough.getInterfaceName() and not rough.getNodeName():
                return rough.getValueString()
    return None


def _frosted(source: Source) -> str:
    """Frosted glass: the loss sentence when transmission is live and rough."""
    fixed = fixed_transmission_roughness()
    rough = source.live_values["roughness"]
    if (
        fixed is None
        or not source.lobes["spec_trans"]
        or ("roughness" not in source.maps and rough <= 0.0)
    ):
        return ""
    return (
        f"ND_disney_principled refracts with a fixed roughness ({fixed}): "
        f"frosted transmission (roughness={rough:g}) renders clear"
    )


def _sheen(values: dict[str, Any], extra: list[str]) -> set[str]:
    """What ``ND_disney_principled`` does with a live sheen; returns the params it keeps.

    Its node graph (MaterialX ``libraries/bxdf/disney_principled.mtlx``) builds the
    sheen from ``sheen_bsdf`` with that node's defaults: ``mode`` conty_kulla and a
    fixed ``roughness``, neither exposed as an input of ``ND_disney_principled``.
    """
    sheen = node_defaults("ND_sheen_bsdf")
    mode, rough = sheen.get("mode", "conty_kulla"), float(sheen.get("roughness", 0.3))
    why = (
        f"ND_disney_principled's sheen is sheen_bsdf in mode {mode} with roughness "
        f"{rough:g}, and it has no input for either"
    )
    if values["sheen_model"] != mode:
        extra.append(f"{why}: the {values['sheen_model']} sheen renders as {mode}")
        return set()
    kept = {"sheen_model"}
    if abs(values["sheen_roughness"] - rough) < 1e-6:
        kept.add("sheen_roughness")
    else:
        extra.append(f"{why}: sheen_roughness={values['sheen_roughness']:g} renders as {rough:g}")
    return kept


def _normal(nodes: list[Node], image: Image) -> tuple[str, Any]:
    """A tangent-space normal map through ``ND_normalmap_float`` (0..1 encoded)."""
    node = Node(
        "mtlx_normal_image", "ND_image_vector3", {"file": ("asset", image)}, {"out": "vector3f"}
    )
    if image.wrap != "periodic":
        node.inputs["uaddressmode"] = ("string", MTLX_ADDRESS[image.wrap])
        node.inputs["vaddressmode"] = ("string", MTLX_ADDRESS[image.wrap])
    nodes.append(node)
    nodes.append(
        Node(
            "mtlx_normal_map",
            "ND_normalmap_float",
            {"in": ("vector3f", Connection("mtlx_normal_image", "out"))},
            {"out": "vector3f"},
        )
    )
    return "vector3f", Connection("mtlx_normal_map", "out")


def _live_or_baked(source: Source):
    """The texture factory: a live mix chain where the layers are known, else the map."""

    def texture(nodes: list[Node], slot: Slot, image: Image) -> tuple[str, Any]:
        if source.layers:
            chain = mixed_input(nodes, slot, source.layers, "mtlx")
            if chain is not None:
                return chain
        return _texture(nodes, slot, image)

    return texture


def _texture(nodes: list[Node], slot: Slot, image: Image) -> tuple[str, Any]:
    linear = affine(image, slot)
    if linear is None:
        image, linear = converted(image, slot), (1.0, 0.0)
    return _image(nodes, f"mtlx_{slot.param}", image, slot.type, linear)


def _image(
    nodes: list[Node], name: str, image: Image, slot_type: str, linear: tuple[float, float]
) -> tuple[str, Any]:
    """``ND_image_*`` reading ``image`` (colour space, address mode, default = the
    parameter's mean), a channel picked by ``ND_extract_color4`` when it is not the
    first, and the affine part of the value rule as ``ND_multiply``/``ND_add``."""
    colour = slot_type == "color3f"
    output = output_of(image, slot_type)
    scale, bias = linear
    raw = (lambda x: x) if scale == 0 else (lambda x: (x - bias) / scale)
    inputs: dict[str, tuple[str, Any]] = {"file": ("asset", image)}
    if image.wrap != "periodic":
        inputs["uaddressmode"] = ("string", MTLX_ADDRESS[image.wrap])
        inputs["vaddressmode"] = ("string", MTLX_ADDRESS[image.wrap])
    picked = output in ("g", "b", "a")
    kind = "color3" if colour else ("color4" if picked else "float")
    if image.fallback is not None and not picked:
        f = image.fallback
        inputs["default"] = (
            ("color3f", tuple(raw(x) for x in f) if isinstance(f, tuple) else (raw(f),) * 3)
            if colour
            else ("float", raw(f[0] if isinstance(f, tuple) else f))
        )
    reader = Node(name, f"ND_image_{kind}", inputs, {"out": "color4f" if picked else slot_type})
    space = mtlx_color_space(image.colorspace)
    if space is not None:
        reader.color_spaces["file"] = space
    nodes.append(reader)
    out = Connection(name, "out")
    if picked:
        index = ("int", "rgba".index(output))
        extract = Node(
            f"{name}_{output}",
            "ND_extract_color4",
            {"in": ("color4f", out), "index": index},
            {"out": "float"},
        )
        nodes.append(extract)
        out = Connection(extract.name, "out")
    suffix = "color3FA" if colour else "float"
    for step, node_def, value, identity in (
        ("scale", "multiply", scale, 1.0),
        ("bias", "add", bias, 0.0),
    ):
        if value != identity:  # texel · scale + bias, each node only where it changes the value
            node = Node(
                f"{name}_{step}",
                f"ND_{node_def}_{suffix}",
                {"in1": (slot_type, out), "in2": ("float", float(value))},
                {"out": slot_type},
            )
            nodes.append(node)
            out = Connection(node.name, "out")
    return slot_type, out


def document(specs: list[MaterialSpec], relative_to: Path):
    """A MaterialX document holding the mtlx network of every spec.

    Asset paths are written relative to ``relative_to`` (the ``.mtlx`` file's folder).
    """
    import MaterialX as mx

    doc = mx.createDocument()
    # the document's colour space: every value and image in it is in the working space
    # unless an input says otherwise (MaterialX names: lin_rec709, acescg)
    doc.setColorSpace(mtlx_color_space(colour.working_space()))
    for spec in specs:
        for net in spec.networks:
            if net.context == "mtlx":
                _add_network(doc, spec.name, net, relative_to)
    return doc


def _add_network(doc, material: str, net: Network, relative_to: Path) -> None:
    lib = _library()
    material = prim_name(material)
    prefix = f"{material}_"
    for node in net.nodes:
        nodedef = lib.getNodeDef(node.id)
        mx_node = doc.addNode(nodedef.getNodeString(), prefix + node.name, nodedef.getType())
        mx_node.setNodeDefString(node.id)
        for name, (kind, value) in node.inputs.items():
            value = plain_value(value)
            inp = mx_node.addInput(name, MX_TYPES[kind])
            if isinstance(value, Connection):
                inp.setNodeName(prefix + value.node)
            elif isinstance(value, Image):
                inp.setValueString(_relative(value.path, relative_to))
                if name in node.color_spaces:
                    inp.setColorSpace(node.color_spaces[name])
            else:
                inp.setValueString(_mx_value(value))
    mat = doc.addNode("surfacematerial", material, "material")
    shader = mat.addInput("surfaceshader", "surfaceshader")
    shader.setNodeName(prefix + net.terminal.node)
    if net.displacement is not None:
        disp = mat.addInput("displacementshader", "displacementshader")
        disp.setNodeName(prefix + net.displacement.node)


def _mx_value(value: Any) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, tuple):
        return ", ".join(repr(float(x)) for x in value)
    return str(value)


def _relative(path: Path, base: Path) -> str:
    return Path(os.path.relpath(path, base)).as_posix()


def validate_document(doc) -> list[str]:
    """MaterialX's own validation of ``doc`` against the standard libraries: messages."""
    doc.setDataLibrary(_library())
    ok, message = doc.validate()
    return [] if ok else [line for line in message.splitlines() if line.strip()]


def write_document(specs: list[MaterialSpec], path: Path, *, where: Path | None = None) -> None:
    """Write the mtlx networks of ``specs`` as a standalone ``.mtlx`` file, validated."""
    import MaterialX as mx

    doc = document(specs, path.parent)
    problems = validate_document(doc)
    if problems:
        raise ExportError(
            f"MaterialX rejects the document: {problems[0]}", where=str(where or path)
        )
    mx.writeToXmlFile(doc, str(path))
