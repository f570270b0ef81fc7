"""Authoring material networks into an Sdf layer: the specs, values and metadata of
each material, fast.

Authoring is Sdf-level (``Sdf.ChangeBlock``, ``Sdf.PrimSpec``, ``Sdf.AttributeSpec``):
one change notification per material instead of one per attribute, each spec made by
the cheapest call that makes it. The text written is the one the high-level ``UsdShade``
API writes for the same networks, byte for byte.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from pxr import Gf, Sdf

from lookdev.materials import colour

from . import mtlx
from .network import (
    CONTEXT_OUTPUT,
    DISPLACEMENT_OUTPUT,
    Connection,
    Image,
    Interface,
    MaterialSpec,
    Network,
    Node,
    prim_name,
)

__all__ = [
    "COLOUR_SPACE_API",
    "COLOUR_SPACE_ATTR",
    "DCC_LOSS",
    "FULLY",
    "MEASURED",
    "MTLX_CONFIG_API",
    "author",
    "converter",
    "dcc_loss_note",
    "loss_doc",
    "network_notes",
    "new_layer",
    "relative_asset",
    "usd_value",
    "value_types",
]

MTLX_CONFIG_API = "MaterialXConfigAPI"
COLOUR_SPACE_API = "ColorSpaceAPI"
COLOUR_SPACE_ATTR = "colorSpace:name"


def network_notes(spec: MaterialSpec) -> list[tuple[str, str]]:
    """``(context, note)`` per network of ``spec``, in order: what its nodes could not
    express, joined (``""``: nothing)."""
    return [
        (net.context, "; ".join(n.custom["loss"] for n in net.nodes if n.custom.get("loss")))
        for net in spec.networks
    ]


def loss_doc(spec: MaterialSpec, notes: list[tuple[str, str]] | None = None) -> str:
    """The Material's ``doc``: what each render context could not express, one per line
    (``notes``: :func:`network_notes` of ``spec``, when the caller has them)."""
    notes = network_notes(spec) if notes is None else notes
    lines = [f"{context}: {note}" for context, note in notes if note]
    if not lines:
        return "lookdev: every render context expresses this material fully."
    return "lookdev: what each render context cannot express.\n" + "\n".join(lines)


def value_types() -> dict[str, Any]:
    t = Sdf.ValueTypeNames
    return {
        "float": t.Float,
        "float2": t.Float2,
        "float3": t.Float3,
        "float4": t.Float4,
        "color4f": t.Color4f,
        "color3f": t.Color3f,
        "normal3f": t.Normal3f,
        "vector3f": t.Vector3f,
        "int": t.Int,
        "bool": t.Bool,
        "token": t.Token,
        "string": t.String,
        "asset": t.Asset,
    }


def usd_value(kind: str, value: Any, base: Path) -> Any:
    """A Python value as USD stores it; asset paths relative to ``base`` (a folder)."""
    return converter(kind, base)(value)


_VECTORS = {
    **dict.fromkeys(("color3f", "float3", "normal3f", "vector3f"), Gf.Vec3f),
    "float2": Gf.Vec2f,
    **dict.fromkeys(("float4", "color4f"), Gf.Vec4f),
}


def converter(kind: str, base: Path) -> Callable[[Any], Any]:
    """The function turning a value of ``kind`` into what USD stores (asset paths
    relative to the folder ``base``): made once per kind, applied per value."""
    if kind == "asset":
        return lambda value: Sdf.AssetPath(
            relative_asset(value.path if isinstance(value, Image) else Path(value), base)
        )
    if kind in _VECTORS:
        vector = _VECTORS[kind]
        return lambda value: vector(*value)
    if kind == "float":
        return float
    return lambda value: value


def relative_asset(path: Path, base: Path) -> str:
    """``path`` relative to the folder ``base``, as a ``./``-anchored posix string."""
    rel = Path(os.path.relpath(Path(path).resolve(), Path(base).resolve())).as_posix()
    return rel if rel.startswith("../") else f"./{rel}"


def new_layer(default_prim: str = "Materials", meters_per_unit: float = 1.0):
    """An empty anonymous layer with the stage metadata validators expect; lengths
    written into it are in units of ``meters_per_unit`` metres."""
    layer = Sdf.Layer.CreateAnonymous(".usda")
    layer.defaultPrim = default_prim
    layer.pseudoRoot.SetInfo("upAxis", "Y")
    layer.pseudoRoot.SetInfo("metersPerUnit", float(meters_per_unit))
    # The stage's colour management system (UsdStage colorManagementSystem). The config is
    # recorded as data, not as colorConfiguration: that is an asset path, which would make
    # a built-in ocio:// config (or a file on this machine) an unresolvable dependency.
    layer.pseudoRoot.SetInfo("colorManagementSystem", "OpenColorIO")
    layer.customLayerData = {"lookdev": {"ocioConfig": colour.settings().config_name}}
    return layer


def author(layer, specs: list[MaterialSpec], base: Path) -> list[str]:
    """Author ``specs`` under ``/Materials`` of ``layer``; returns their prim paths.

    One ``Sdf.ChangeBlock`` per material, not one around them all: a block's change list
    holds an entry for every spec it made, and one block over 1,000 materials (≈ 50,000
    entries) took 1.2–1.3× the CPU time of a block each (usd-core 0.26, lookdev bench
    usd). The layers written are new, with no stage composed on them, so no block's
    notices recompose anything.
    """
    with Sdf.ChangeBlock():
        scope = layer.GetPrimAtPath("/Materials") or Sdf.CreatePrimInLayer(layer, "/Materials")
        scope.specifier = Sdf.SpecifierDef
        scope.typeName = "Scope"
    write = _Author(layer, base)
    paths = []
    for spec in specs:
        with Sdf.ChangeBlock():
            paths.append(str(write.material(scope, spec)))
    return paths


# Per attribute, authoring is a few usd-core calls, and they are most of the time (70–80 %
# of it, sampled): _Author does no work twice around them. The names of properties, the
# converters of values, the colour space's name (an OCIO lookup), the MaterialX version
# and the two apiSchemas list ops are taken once per call of author(), not per material
# or attribute; a material's interface values are converted once and reused by the
# shader inputs that read them. Each spec is made by the cheapest call that makes it: an
# attribute with a value or a connection by Sdf.CreatePrimAttributeInLayer, which
# returns the spec (≈ 0.1–0.4 µs fewer than Sdf.JustCreatePrimAttributeInLayer and
# Layer.GetAttributeAtPath; an Sdf.AttributeSpec constructed is ≈ 0.5 µs more), one with
# neither (shader outputs) by Sdf.JustCreatePrimAttributeInLayer alone (≈ 1.4 µs). A
# connection, assigned as the list proxy's explicit items, costs ≈ 2.3 µs more than its
# attribute (usd-core makes a connection spec for the target; the connectionPaths field
# cannot be set otherwise, SetInfo refuses it as read-only). usd-core 0.26, CPU time.


class _Author:
    """Authors materials into one layer (see :func:`author`), reusing what every material
    shares: value types, converters, property names, list ops."""

    def __init__(self, layer, base: Path):
        self.layer = layer
        self.base = base
        self.types = value_types()
        self.space = colour.interop_id()
        self.version = mtlx.mtlx_version()
        self.inputs = _Names("inputs:")
        self.outputs = _Names("outputs:")
        self.convert = {kind: converter(kind, base) for kind in self.types}
        # UsdMtlx reads the MaterialX version of the networks from MaterialXConfigAPI.
        self.schemas = {
            mtlx_: Sdf.TokenListOp.Create(
                prependedItems=[COLOUR_SPACE_API, MTLX_CONFIG_API][: 1 + mtlx_]
            )
            for mtlx_ in (False, True)
        }
        self.terminals = {
            context: (
                self.outputs[CONTEXT_OUTPUT[context]],
                self.outputs[DISPLACEMENT_OUTPUT[context]],
            )
            for context in CONTEXT_OUTPUT
        }

    def material(self, scope, spec: MaterialSpec):
        """Author one material under ``scope``; returns its path."""
        layer, types, convert, inputs = self.layer, self.types, self.convert, self.inputs
        create = Sdf.CreatePrimAttributeInLayer
        prim = Sdf.PrimSpec(scope, prim_name(spec.name), Sdf.SpecifierDef, "Material")
        prim.SetInfo("customData", {"lookdev": dict(spec.custom)})
        notes = network_notes(spec)
        prim.documentation = loss_doc(spec, notes)
        path = prim.path
        append = path.AppendProperty
        _dcc_loss(layer, spec, path, types, notes)
        # Every colour value and map of the material is in the working space:
        # UsdColorSpaceAPI names it by USD's canonical name (lin_rec709_scene,
        # lin_ap1_scene) for the material and everything under it; textures that differ
        # say so on their own inputs.
        uniform = Sdf.VariabilityUniform
        create(layer, append(COLOUR_SPACE_ATTR), types["token"], uniform).default = self.space
        has_mtlx = any(net.context == "mtlx" for net in spec.networks)
        if has_mtlx:
            version = append("config:mtlx:version")
            create(layer, version, types["string"], uniform).default = self.version
        prim.SetInfo("apiSchemas", self.schemas[has_mtlx])
        interface = {}  # name → (its path, type, the value it holds, that value converted)
        for name, (kind, value) in spec.interface().items():
            where = append(inputs[name])
            held = convert[kind](value)
            create(layer, where, types[kind]).default = held
            interface[name] = (where, kind, value, held)
        for net in spec.networks:
            self.outputs_of(path, net)
            for node in net.nodes:
                self.shader(prim, path, node, interface)
        return path

    def outputs_of(self, path, net: Network) -> None:
        """The Material's terminal outputs of ``net``, connected to its shaders."""
        token = self.types["token"]
        surface, displacement = self.terminals[net.context]
        output = Sdf.CreatePrimAttributeInLayer(self.layer, path.AppendProperty(surface), token)
        output.connectionPathList.explicitItems = [self.output_path(path, net.terminal)]
        if net.displacement is not None:
            where = path.AppendProperty(displacement)
            output = Sdf.CreatePrimAttributeInLayer(self.layer, where, token)
            output.connectionPathList.explicitItems = [self.output_path(path, net.displacement)]

    def output_path(self, material_path, conn: Connection):
        """The path of the output ``conn`` names, in the material at ``material_path``."""
        return material_path.AppendChild(conn.node).AppendProperty(self.outputs[conn.output])

    def shader(self, prim, path, node: Node, interface: dict[str, tuple]) -> None:
        """One shader of a network under the Material ``prim`` (at ``path``)."""
        layer, types, convert, inputs = self.layer, self.types, self.convert, self.inputs
        create = Sdf.CreatePrimAttributeInLayer
        shader = Sdf.PrimSpec(prim, node.name, Sdf.SpecifierDef, "Shader")
        if any(node.custom.values()):
            shader.SetInfo("customData", {"lookdev": {k: v for k, v in node.custom.items() if v}})
        at = shader.path.AppendProperty
        create(layer, at("info:id"), types["token"], Sdf.VariabilityUniform).default = node.id
        spaces = node.color_spaces
        for name, (kind, value) in node.inputs.items():
            attr = create(layer, at(inputs[name]), types[kind])
            if type(value) is Connection:
                attr.connectionPathList.explicitItems = [self.output_path(path, value)]
            elif type(value) is Interface:
                # Connected to the Material's interface (which wins); the value stays
                # here too for readers that do not follow connections.
                where, held_kind, held, converted = interface[value.name]
                attr.connectionPathList.explicitItems = [where]
                same = value.value is held and kind == held_kind
                attr.default = converted if same else convert[kind](value.value)
            else:
                attr.default = convert[kind](value)
            if spaces and name in spaces:
                attr.SetInfo("colorSpace", spaces[name])
        for name, kind in node.outputs.items():
            Sdf.JustCreatePrimAttributeInLayer(layer, at(self.outputs[name]), types[kind])


class _Names(dict):
    """``prefix + name`` for every name asked, each made once."""

    def __init__(self, prefix: str):
        super().__init__()
        self.prefix = prefix

    def __missing__(self, name: str) -> str:
        self[name] = out = self.prefix + name
        return out


DCC_LOSS = "userProperties:lookdev:loss"
"""The universal network's loss note, where Blender shows it: its USD importer makes every
``userProperties:`` attribute of a Material a custom property of the material (Blender
4.5.15 and 5.0.1, observed); it shows neither ``doc`` nor ``displayName``."""


FULLY = "UsdPreviewSurface expresses this material fully"
MEASURED = "measured against the material"


def dcc_loss_note(spec: MaterialSpec, notes: list[tuple[str, str]] | None = None) -> str | None:
    """The universal network's loss note as :data:`DCC_LOSS` holds it; None without one.

    The named losses, then (when the export measured it, ``spec.size``) by how much:
    ``…; measured against the material: albedo −74.6 %, highlight +9 %, albedo RMS 0.19``.
    :data:`FULLY` only where nothing is named and the figures are within what the
    measurement resolves (:attr:`.fidelity.Fidelity.fully`). ``notes``: as
    :func:`loss_doc` takes them.
    """
    for context, note in network_notes(spec) if notes is None else notes:
        if context == "universal":
            size = spec.size
            if size is None or size.unavailable:
                return note or FULLY
            if not note and size.fully:
                return f"{FULLY} ({MEASURED}: {size.size()})"
            named = note or "UsdPreviewSurface's BRDF is not the material's"
            return f"{named}; {MEASURED}: {size.size()}"
    return None


def _dcc_loss(layer, spec: MaterialSpec, path, types: dict[str, Any], notes) -> None:
    note = dcc_loss_note(spec, notes)
    if note is None:
        return
    where = path.AppendProperty(DCC_LOSS)
    # Custom (not a schema property): Blender imports only custom attributes.
    varying = Sdf.VariabilityVarying
    Sdf.CreatePrimAttributeInLayer(layer, where, types["string"], varying, True).default = note
