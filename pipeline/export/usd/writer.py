"""Authoring networks into USD layers: one stage, a split library, a ``.usdz`` package.

The layers' specs are authored by :func:`.authoring.author`. Files are written to
temporary names beside their destination and renamed into place only when everything
succeeded, so a failure leaves no partial file (:class:`Staging`).
"""

from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pxr import Sdf

from lookdev.library import files

from . import mtlx, preview, publish, ri
from .authoring import author, network_notes, new_layer, relative_asset
from .mtlx_openpbr import MTLX_SURFACES
from .names import PREVIEW_OPACITY
from .network import (
    ExportError,
    Image,
    MaterialSpec,
    Source,
    prim_name,
)

__all__ = [
    "BUILDERS",
    "ExportResult",
    "ROOT",
    "SWITCH",
    "Staging",
    "USD_SUFFIXES",
    "add_switch",
    "check_folder",
    "check_images",
    "check_writable",
    "export_usd",
    "images_of",
    "losses_of",
    "material_spec",
]

BUILDERS = {"universal": preview.build, "mtlx": mtlx.build, "ri": ri.build}
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
