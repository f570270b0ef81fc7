"""Authoring networks into USD layers: one stage, a split library, a ``.usdz`` package.

Authoring is Sdf-level (``Sdf.ChangeBlock``, ``Sdf.PrimSpec``, ``Sdf.AttributeSpec``):
one change notification per stage instead of one per attribute. Files are written to
temporary names beside their destination and renamed into place only when everything
succeeded, so a failure leaves no partial file (:class:`Staging`).
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pxr import Gf, Sdf

from lookdev.library import files
from lookdev.materials import colour

from . import mtlx, preview, publish, ri
from .mtlx_openpbr import MTLX_SURFACES
from .names import PREVIEW_OPACITY
from .network import (
    CONTEXT_OUTPUT,
    DISPLACEMENT_OUTPUT,
    Connection,
    ExportError,
    Image,
    Interface,
    MaterialSpec,
    Network,
    Node,
    Source,
    prim_name,
)

__all__ = [
    "BUILDERS",
    "COLOUR_SPACE_API",
    "COLOUR_SPACE_ATTR",
    "DCC_LOSS",
    "ExportResult",
    "MTLX_CONFIG_API",
    "ROOT",
    "SWITCH",
    "Staging",
    "USD_SUFFIXES",
    "add_switch",
    "author",
    "check_folder",
    "check_images",
    "check_writable",
    "dcc_loss_note",
    "export_usd",
    "images_of",
    "loss_doc",
    "losses_of",
    "material_spec",
    "network_notes",
    "new_layer",
    "relative_asset",
    "usd_value",
    "value_types",
]

BUILDERS = {"universal": preview.build, "mtlx": mtlx.build, "ri": ri.build}
MTLX_CONFIG_API = "MaterialXConfigAPI"
COLOUR_SPACE_API = "ColorSpaceAPI"
COLOUR_SPACE_ATTR = "colorSpace:name"
SWITCH = "Look"  # the prim whose variant set switches between the exported presets
ROOT = "Materials"  # the default prim: every material, the switch, preview geometry
USD_SUFFIXES = (".usda", ".usdc", ".usd")


def material_spec(
    source: Source,
    contexts: tuple[str, ...],
    preview_opacity: str = "keep",
    meters_per_unit: float = 1.0,
    mtlx_surface: str = "openpbr",
) -> MaterialSpec:
    """The networks of ``source`` for each of ``contexts`` and the material's metadata
    (lengths in scene units of ``meters_per_unit``, the stage's; ``mtlx_surface``: see
    :data:`.mtlx_openpbr.MTLX_SURFACES`)."""
    custom = {
        "preset": source.name,
        "model": source.model,
        "spelling": source.spelling,
        **source.custom,
    }
    networks = [
        preview.build(source, preview_opacity)
        if c == "universal"
        else mtlx.build(source, meters_per_unit, mtlx_surface)
        if c == "mtlx"
        else BUILDERS[c](source, meters_per_unit)
        for c in contexts
    ]
    if source.record:  # the preset, trusted while the networks are these (.record)
        from .record import network_digest

        custom["record"] = source.record
        custom["networks"] = network_digest(networks)
    return MaterialSpec(source.name, networks, custom, source.size)


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


def add_switch(layer, targets: dict[str, tuple[str, str]]) -> None:
    """A ``/Materials/Look`` material (under the default prim, so a reference to the
    file brings it) whose variant set ``preset`` references each target.

    ``targets`` maps a variant name to ``(asset path or "" for this layer, prim path)``.
    """
    with Sdf.ChangeBlock():
        root = layer.GetPrimAtPath(f"/{ROOT}")
        look = Sdf.PrimSpec(root, SWITCH, Sdf.SpecifierDef, "Material")
        look.customData = {"lookdev": {"switch": True}}
        vset = Sdf.VariantSetSpec(look, "preset")
        for name, (asset, prim_path) in targets.items():
            variant = Sdf.VariantSpec(vset, name)
            ref = Sdf.Reference(asset, Sdf.Path(prim_path))
            variant.primSpec.referenceList.prependedItems.append(ref)
        look.variantSetNameList.prependedItems.append("preset")
        look.variantSelections["preset"] = next(iter(targets))


class Staging(files.Transaction):
    """Files written under temporary names, renamed into place together on commit: the one
    write path's transaction (:class:`lookdev.library.files.Transaction`)."""


def check_writable(path: Path) -> None:
    """Raise :class:`ExportError` unless ``path`` can be written, its folder existing or
    creatable (:func:`lookdev.library.files.check_folder`; the write makes it)."""
    try:
        files.check_folder(path.parent)
    except files.WriteError as exc:
        raise ExportError(exc.message, where=str(path)) from None
    if path.exists() and path.is_dir():
        raise ExportError("is a folder; give a file name", where=str(path))


def check_folder(folder: Path) -> None:
    """A folder to write into: existing, or creatable (the write makes it)."""
    if folder.exists() and not folder.is_dir():
        raise ExportError("is a file; --split takes a folder", where=str(folder))
    check_writable(folder / "x.usda")


def images_of(specs: list[MaterialSpec]) -> list[Image]:
    """Every image the networks reference, once each."""
    seen: dict[Path, Image] = {}
    for spec in specs:
        for net in spec.networks:
            for node in net.nodes:
                for kind, value in node.inputs.values():
                    if kind == "asset" and isinstance(value, Image):
                        if value.write or value.path not in seen:
                            seen[value.path] = value
    return list(seen.values())


def check_images(images: list[Image]) -> None:
    """Every image the export reads (a preset's own file, referenced or collected) must
    exist (a UDIM set: at least one tile)."""
    for image in images:
        path = image.origin if image.reference and image.write else image.path
        if image.write and not image.reference:
            continue
        if image.udim and not publish.tile_files(path):
            raise ExportError("no UDIM tile of this texture exists", where=str(path))
        if not image.udim and not path.is_file():
            raise ExportError("texture does not exist", where=str(path))


@dataclass
class ExportResult:
    """What an export wrote: files in place, materials, images referenced, and per
    material and render context what its surface could not express (``""``: nothing)."""

    files: list[Path]
    materials: list[str]
    images: list[Path]
    losses: dict[str, dict[str, str]] = field(default_factory=dict)
    fidelity: dict[str, Any] = field(default_factory=dict)
    """material → :class:`.fidelity.Fidelity` when the export was asked to measure."""
    contexts_fidelity: dict[str, Any] = field(default_factory=dict)
    """material → a :class:`.fidelity.Fidelity` per context (:func:`.fidelity.context_fidelity`)."""


def losses_of(specs: list[MaterialSpec]) -> dict[str, dict[str, str]]:
    """``{material: {context: note}}``: the loss notes the networks carry in customData."""
    return {spec.name: dict(network_notes(spec)) for spec in specs}


def export_usd(
    sources: list[Source],
    out: Path,
    *,
    contexts: tuple[str, ...] = tuple(BUILDERS),
    mtlx_path: Path | None = None,
    package: bool = False,
    split_dir: Path | None = None,
    workdir: Path | None = None,
    preview_opacity: str = "keep",
    meters_per_unit: float = 1.0,
    collect: bool = False,
    preview_geometry: bool = False,
    mtlx_surface: str = "openpbr",
) -> ExportResult:
    """Export ``sources`` to ``out`` (``.usda``/``.usdc``/``.usd``, or ``.usdz`` to package).

    ``split_dir``: one file per material there, ``out`` a library referencing them.
    ``mtlx_path``: also a standalone MaterialX document. ``workdir`` (packages): where the
    stage is staged before packaging; textures below it keep their path relative to it
    inside the ``.usdz``. ``preview_opacity``: see :data:`.names.PREVIEW_OPACITY`.
    ``meters_per_unit``: the stage's ``metersPerUnit``; lengths (the subsurface radius,
    lookdev's ``scatter_distance`` in metres) are written in those units.
    ``collect``: copy the presets' own texture files into ``<out stem>_textures`` beside
    ``out`` (a package always does). ``preview_geometry``: a sphere per material bound
    to it. ``mtlx_surface``: see :data:`.mtlx_openpbr.MTLX_SURFACES`. Nothing is left
    behind on error.
    """
    out = Path(out)
    package = package or out.suffix == ".usdz"
    if package and split_dir is not None:
        raise ExportError("--package and --split exclude each other", where=str(out))
    if mtlx_path is not None and "mtlx" not in contexts:
        raise ExportError("--mtlx writes the mtlx context; add --context mtlx", where=str(out))
    if out.suffix not in (*USD_SUFFIXES, ".usdz"):
        raise ExportError("not a USD file name; use .usda, .usdc, .usd or .usdz", where=str(out))
    out = out.with_suffix(".usdz") if package else out
    for path in (out, mtlx_path):
        if path is not None:
            check_writable(Path(path))
    if split_dir is not None:
        check_folder(Path(split_dir))
    if preview_opacity not in PREVIEW_OPACITY:
        raise ExportError(
            f"preview opacity {preview_opacity!r}: use {' or '.join(PREVIEW_OPACITY)}",
            where=str(out),
        )
    if not (meters_per_unit > 0.0 and math.isfinite(meters_per_unit)):
        raise ExportError(
            f"metersPerUnit {meters_per_unit!r}: give a positive finite number", where=str(out)
        )
    if mtlx_surface not in MTLX_SURFACES:
        raise ExportError(
            f"mtlx surface {mtlx_surface!r}: use {' or '.join(MTLX_SURFACES)}", where=str(out)
        )
    specs = [
        material_spec(s, contexts, preview_opacity, meters_per_unit, mtlx_surface) for s in sources
    ]
    _check_names(specs, out)
    if package:
        publish.collect(specs, Path(workdir or out.parent) / f"{out.stem}_textures")
        publish.for_package(specs)
    elif collect:
        publish.collect(specs, out.parent / f"{out.stem}_textures")
    images = images_of(specs)
    check_images(images)
    layout = {"name": out.name, "geometry": preview_geometry, "meters_per_unit": meters_per_unit}
    with Staging() as staging:  # commits on success; removes every temporary otherwise
        for path in (out, mtlx_path):
            if path is not None:
                staging.folder(Path(path).parent)  # made as `mkdir -p`; removed on failure
        if package:
            written = _write_package(
                specs, images, out, Path(workdir or out.parent), staging, layout
            )
        else:
            written = _write_all(specs, images, out, split_dir, staging, layout)
        if mtlx_path is not None:
            mtlx.write_document(specs, staging.temp_for(Path(mtlx_path)), where=mtlx_path)
            written.append(Path(mtlx_path))
    return ExportResult(
        written, [s.name for s in specs], [i.path for i in images], losses_of(specs)
    )


def _check_names(specs: list[MaterialSpec], out: Path) -> None:
    seen: dict[str, str] = {}
    for spec in specs:
        key = prim_name(spec.name)
        if key in seen:
            raise ExportError(
                f"materials {seen[key]!r} and {spec.name!r} both become prim {key!r}",
                where=str(out),
            )
        seen[key] = spec.name
    if not specs:
        raise ExportError("no materials to export", where=str(out))


def _write_all(specs, images, out, split_dir, staging, layout) -> list[Path]:
    files = [out]
    for image in images:
        if image.write:
            staging.folder(image.path.parent)
            files += publish.write_image(image, staging.temp_for, image.path)
    if split_dir is not None:
        staging.folder(Path(split_dir))
        return files + _write_split(specs, out, Path(split_dir), staging, layout)
    layer = _one_layer(specs, out.parent, layout)
    _export_layer(layer, staging.temp_for(out), out)
    return files


def _write_package(specs, images, out: Path, workdir: Path, staging: Staging, layout):
    """A ``.usdz`` holding the stage and every texture it references."""
    from pxr import UsdUtils

    for image in images:
        if image.write:
            files.make_folder(image.path.parent)
            publish.write_image(image, lambda p: p, image.path)
    root = workdir / f"{out.stem}.usdc"  # the package's root layer keeps the output's name
    if root.exists():  # not a private folder: never overwrite what is there
        fd, name = tempfile.mkstemp(prefix=f".{out.stem}.", suffix=".usdc", dir=workdir)
        os.close(fd)
        root = Path(name)
    try:
        _export_layer(_one_layer(specs, workdir, layout), root)
        if not UsdUtils.CreateNewUsdzPackage(str(root), str(staging.temp_for(out))):
            raise ExportError("USD could not write the package", where=str(out))
    finally:
        root.unlink(missing_ok=True)
    return [out]


def _one_layer(specs: list[MaterialSpec], base: Path, layout: dict[str, Any]):
    """Every material in one layer, with the ``Look`` switch when there are several, the
    asset's metadata and, if asked, preview geometry."""
    layer = new_layer(meters_per_unit=layout["meters_per_unit"])
    paths = author(layer, specs, base)
    if len(specs) > 1:
        add_switch(layer, {prim_name(s.name): ("", p) for s, p in zip(specs, paths, strict=True)})
    _finish(layer, paths, layout)
    return layer


def _finish(layer, paths: list[str], layout: dict[str, Any]) -> None:
    publish.asset_metadata(layer, ROOT, layout["name"], len(paths))
    if layout["geometry"]:
        publish.add_preview_geometry(layer, ROOT, paths)


def _write_split(specs, out: Path, folder: Path, staging: Staging, layout) -> list[Path]:
    files, targets = [], {}
    library = new_layer(meters_per_unit=layout["meters_per_unit"])
    scope = Sdf.CreatePrimInLayer(library, "/Materials")
    scope.specifier, scope.typeName = Sdf.SpecifierDef, "Scope"
    for spec in specs:
        name = prim_name(spec.name)
        path = folder / f"{name}.usda"
        layer = new_layer(meters_per_unit=layout["meters_per_unit"])
        (prim_path,) = author(layer, [spec], folder)
        publish.asset_metadata(layer, ROOT, path.name, 1)
        _export_layer(layer, staging.temp_for(path), path)
        asset = relative_asset(path, out.parent)
        ref = Sdf.PrimSpec(scope, name, Sdf.SpecifierDef, "Material")
        ref.referenceList.prependedItems.append(Sdf.Reference(asset, Sdf.Path(prim_path)))
        targets[name] = (asset, prim_path)
        files.append(path)
    add_switch(library, targets)
    _finish(library, [f"/{ROOT}/{name}" for name in targets], layout)
    _export_layer(library, staging.temp_for(out), out)
    return files


def _export_layer(layer, path: Path, shown: Path | None = None) -> None:
    from pxr import Tf

    try:
        ok, message = layer.Export(str(path)), ""
    except Tf.ErrorException as exc:  # a full disk, a vanished folder
        ok, message = False, str(exc)
    if not ok:
        reason = files.failure_reason(path, message)
        raise ExportError(f"USD could not write the layer: {reason}", where=str(shown or path))
