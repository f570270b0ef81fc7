"""What makes an exported file an asset a pipeline can publish.

- Maps the exporter writes are half-float, tiled, mip-mapped EXRs made by OpenImageIO's
  ``make_texture`` (what renderers page from), with a fixed ``DateTime`` so the same
  input gives byte-identical files; inside a ``.usdz`` they are PNG instead (the only
  formats ARKit reads with EXR excluded): 8-bit sRGB-encoded for colour maps, 16-bit for
  data, values outside 0..1 brought into range with the texture node's scale and bias.
- ``--collect`` copies the preset's own texture files (UDIM tiles included) beside the
  exported file, so paths are relative and the folder moves as one
  (:func:`collect`); a package always collects.
- The root prim carries ``kind = "component"`` and ``assetInfo``, the layer a ``doc``
  naming lookdev and its version (:func:`asset_metadata`), and ``--preview-geometry``
  adds a sphere mesh per material bound with ``MaterialBindingAPI``, in a grid, so a DCC's
  default import shows the library (:func:`add_preview_geometry`).
"""

from __future__ import annotations

import dataclasses
import shutil
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library import files
from lookdev.materials import colour
from lookdev.pipeline.exr import colour_space_of, name_colour_space

from .network import ExportError, Image, MaterialSpec

__all__ = [
    "FIXED_DATETIME",
    "add_preview_geometry",
    "asset_metadata",
    "collect",
    "for_package",
    "write_texture",
]

FIXED_DATETIME = "2000:01:01 00:00:00"
"""The EXR ``DateTime`` of every map written: OpenImageIO's make_texture stamps the
time of writing otherwise, and re-exports would differ byte for byte."""
TILE = 64


@cache
def lookdev_version() -> str:
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("lookdev")
    except PackageNotFoundError:
        return "0+unknown"


def tile_files(path: Path) -> list[Path]:
    """The files a texture path stands for: itself, or a ``<UDIM>`` set's tiles."""
    from lookdev.pipeline.blend.errors import TextureError
    from lookdev.pipeline.blend.surface_maps import udim_tiles

    try:
        return sorted(udim_tiles(path).values())
    except TextureError:
        return []


def write_image(image: Image, temp_for, shown: Path) -> list[Path]:
    """Write ``image`` through ``temp_for(final path)``; returns the final paths."""
    if image.reference:  # a preset's own file (each tile of a set), copied as it is
        finals = targets_of(image, image.path)
        for final in finals:
            copy_texture(
                dataclasses.replace(image, path=final, origin=tile_of(image, final)),
                temp_for(final),
            )
        return finals
    if image.path.suffix.lower() == ".png":
        write_png(temp_for(image.path), image, shown)
    else:
        write_texture(temp_for(image.path), image, shown)
    return [image.path]


def tile_of(image: Image, final: Path) -> Path:
    """The source tile of a collected file ``final`` (the file itself when not UDIM)."""
    if not image.udim:
        return image.origin
    head, tail = image.path.name.split("<UDIM>", 1)
    number = final.name[len(head) : len(final.name) - len(tail)]
    return image.origin.with_name(image.origin.name.replace("<UDIM>", number))


def write_texture(target: Path, image: Image, shown: Path | None = None) -> None:
    """``image`` as a half-float, tiled, mip-mapped EXR at ``target`` (deterministic).

    Pixels come from the bake it was copied from (``origin``, already encoded: normals
    as (n + 1)/2), else from ``image.pixels`` (row 0 = top)."""
    import OpenImageIO as oiio

    if image.origin is not None:
        buf = oiio.ImageBuf(str(image.origin))
        buf.read(force=True)
    else:
        px = np.ascontiguousarray(image.pixels, dtype=np.float32)
        px = px[..., None] if px.ndim == 2 else px
        buf = oiio.ImageBuf(oiio.ImageSpec(px.shape[1], px.shape[0], px.shape[2], oiio.FLOAT))
        buf.set_pixels(oiio.ROI(), px)
    if buf.has_error:
        raise ExportError(f"cannot read {image.origin}: {buf.geterror()}", where=str(shown))
    spec = buf.specmod()
    spec.attribute("DateTime", FIXED_DATETIME)
    # the one place EXR colour attributes are set (pipeline/exr.py): chromaticities too
    # (no colour space given: written by lookdev, RGB colour in the working space, else data)
    space = image.colorspace
    if space is None or spec.nchannels not in (3, 4):
        space = colour_space_of(np.zeros((1, 1, spec.nchannels)))
    name_colour_space(spec, space)
    config = oiio.ImageSpec()
    config.format = oiio.HALF
    config.tile_width = config.tile_height = TILE
    config.attribute("compression", "zip")
    config.attribute("maketx:fileformatname", "exr")
    if not oiio.ImageBufAlgo.make_texture(oiio.MakeTxTexture, buf, str(target), config):
        reason = files.failure_reason(target, oiio.geterror())
        raise ExportError(f"cannot write {shown or target}: {reason}")


def write_png(target: Path, image: Image, shown: Path | None = None) -> None:
    """``image.pixels`` as PNG (inside a ``.usdz``): sRGB-encoded 8-bit when the image
    says so (:func:`for_package` decided), else 16-bit data, already in 0..1."""
    import OpenImageIO as oiio

    px = np.asarray(image.pixels, dtype=np.float32)
    px = px[..., None] if px.ndim == 2 else px
    srgb = image.colorspace is not None and colour.canonical(image.colorspace) == (
        colour.canonical(colour.SRGB_TEXTURE)
    )
    if srgb:
        px = colour.convert(px, colour.working_space(), colour.SRGB_TEXTURE)
    fmt = oiio.UINT8 if srgb else oiio.UINT16
    spec = oiio.ImageSpec(px.shape[1], px.shape[0], px.shape[2], fmt)
    out = oiio.ImageOutput.create(str(target))
    ok = out is not None and out.open(str(target), spec)
    ok = ok and out.write_image(np.ascontiguousarray(np.clip(px, 0.0, 1.0)))
    if out is not None:
        out.close()
    if not ok:
        reason = files.failure_reason(target, oiio.geterror())
        raise ExportError(f"cannot write {shown or target}: {reason}")


def copy_texture(image: Image, target: Path) -> None:
    """Copy a referenced file (``origin``, one tile) to ``target``, byte for byte."""
    shutil.copyfile(image.origin, target)


def targets_of(image: Image, target: Path) -> list[Path]:
    """The files writing ``image`` to ``target`` makes (a UDIM set: one per tile)."""
    if not (image.reference and image.udim):
        return [target]
    head, tail = image.origin.name.split("<UDIM>", 1)
    return [
        target.with_name(target.name.replace("<UDIM>", t.name[len(head) : len(t.name) - len(tail)]))
        for t in tile_files(image.origin)
    ]


def _retarget(specs: list[MaterialSpec], change) -> None:
    """Replace every Image input of every node by ``change(image, node, input)``."""
    for spec in specs:
        for net in spec.networks:
            for node in net.nodes:
                for name, (kind, value) in list(node.inputs.items()):
                    if kind == "asset" and isinstance(value, Image):
                        node.inputs[name] = (kind, change(value, node, name))


def collect(specs: list[MaterialSpec], folder: Path) -> None:
    """Point every referenced texture at a copy in ``folder`` (made when written).

    Two different files of one name get the name of their folder in front."""
    chosen: dict[Path, Path] = {}
    taken: dict[str, Path] = {}

    def change(image: Image, node: Any, name: str) -> Image:
        if not image.reference:
            return image
        if image.path not in chosen:
            file_name = image.path.name
            if taken.get(file_name, image.path) != image.path:
                file_name = f"{image.path.parent.name}_{file_name}"
            taken[file_name] = image.path
            chosen[image.path] = folder / file_name
        return dataclasses.replace(image, path=chosen[image.path], origin=image.path, write=True)

    _retarget(specs, change)


def for_package(specs: list[MaterialSpec]) -> None:
    """Maps the exporter writes become PNGs (ARKit reads no EXR): colour maps 8-bit
    sRGB (``sourceColorSpace = sRGB``), data 16-bit with values brought into 0..1 by
    the UsdUVTexture's scale and bias. A preset's own file must already be PNG or JPEG."""
    done: dict[Path, tuple[Image, float, float]] = {}

    def change(image: Image, node: Any, name: str) -> Image:
        if image.path.suffix.lower() in (".png", ".jpg", ".jpeg"):
            return image
        if image.path not in done:
            done[image.path] = _png_of(_with_file_pixels(image) if image.reference else image)
        png, lo, span = done[image.path]
        if node.id == "UsdUVTexture":
            _fold_range(node, lo, span)
            node.inputs["sourceColorSpace"] = ("token", "sRGB" if span == 0 else "raw")
            node.color_spaces.pop("file", None)
        elif node.id == "PxrTexture":
            if span == 0:
                node.inputs["linearize"] = ("int", 1)
            elif (lo, span) != (0.0, 1.0):
                node.inputs["colorScale"] = ("color3f", (span,) * 3)
                node.inputs["colorOffset"] = ("color3f", (lo,) * 3)
        elif span == 0:
            node.color_spaces["file"] = "srgb_texture"
        elif (lo, span) != (0.0, 1.0):
            node.custom["loss"] = (
                f"in the package {png.path.name} holds (value − {lo:g})/{span:g} (PNG is "
                "0..1); this MaterialX image node reads it as it is"
            )
        return png

    _retarget(specs, change)


def _with_file_pixels(image: Image) -> Image:
    """A preset's own file (not PNG or JPEG) with its stored pixels, row 0 = top, colour
    converted to the working space; the texture node's scale and bias still apply."""
    import OpenImageIO as oiio

    source = image.origin or image.path
    if image.udim:
        raise ExportError(
            f"the UDIM set {source.name} cannot go into a .usdz as it is (ARKit reads PNG "
            "and JPEG); convert its tiles to PNG, or export .usda with --collect",
            where=str(source),
        )
    buf = oiio.ImageBuf(str(source))
    px = buf.get_pixels(oiio.FLOAT)
    if buf.has_error or px is None:
        raise ExportError(f"cannot read {source}: {buf.geterror()}", where=str(source))
    px = np.asarray(px, dtype=np.float32)
    if image.colorspace is not None and not colour.is_data(image.colorspace) and px.ndim == 3:
        px = colour.convert(px[..., :3], image.colorspace, colour.working_space())
        return dataclasses.replace(image, pixels=px, colorspace=colour.working_space())
    return dataclasses.replace(image, pixels=px)


def _png_of(image: Image) -> tuple[Image, float, float]:
    """(PNG image, lo, span): a colour map in 0..1 as sRGB (span 0 marks it), else the
    data remapped ``(x − lo)/span``."""
    px = np.asarray(image.pixels, dtype=np.float32)
    if image.origin is not None and image.path.name.endswith("_normal_map.exr"):
        px = 0.5 * px + 0.5  # baked normals are unit vectors in memory, (n + 1)/2 on disk
    colour_map = (
        px.ndim == 3 and image.colorspace is not None and not colour.is_data(image.colorspace)
    )
    path = image.path.with_suffix(".png")
    if colour_map and float(px.min()) >= 0.0 and float(px.max()) <= 1.0:
        return Image(path, px, write=True, colorspace=colour.SRGB_TEXTURE), 0.0, 0.0
    lo, hi = float(px.min()), float(px.max())
    span = hi - lo if hi > lo else 1.0
    if 0.0 <= lo and hi <= 1.0:
        lo, span = 0.0, 1.0
    return Image(path, (px - lo) / span, write=True, colorspace=colour.RAW), lo, span


def _fold_range(node: Any, lo: float, span: float) -> None:
    """value = (png · span + lo) · scale + bias: fold the remap into the node's own."""
    if span in (0.0, 1.0) and lo == 0.0:
        return
    scale = node.inputs.get("scale", ("float4", (1.0, 1.0, 1.0, 1.0)))[1]
    bias = node.inputs.get("bias", ("float4", (0.0, 0.0, 0.0, 0.0)))[1]
    node.inputs["scale"] = ("float4", (*(s * span for s in scale[:3]), scale[3]))
    new_bias = tuple(s * lo + b for s, b in zip(scale[:3], bias[:3], strict=True))
    node.inputs["bias"] = ("float4", (*new_bias, bias[3]))
    fallback = node.inputs.get("fallback")
    if fallback is not None:
        f = fallback[1]
        node.inputs["fallback"] = ("float4", (*((x - lo) / span for x in f[:3]), f[3]))


def asset_metadata(layer, root: str, name: str, count: int) -> None:
    """``kind = "component"`` and ``assetInfo`` on the root prim, a layer ``doc``."""
    from pxr import Kind, Sdf

    prim = layer.GetPrimAtPath(f"/{root}")
    prim.SetInfo("kind", Kind.Tokens.component)
    prim.assetInfo = {
        "name": name,
        "identifier": Sdf.AssetPath(f"./{name}"),
        "version": lookdev_version(),
    }
    layer.documentation = (
        f"Written by lookdev {lookdev_version()}: {count} material(s) under /{root}, "
        "each with UsdPreviewSurface, MaterialX and RenderMan networks; what a context "
        "cannot express is in each Material's doc."
    )


def add_preview_geometry(layer, root: str, material_paths: list[str]) -> None:
    """A unit sphere mesh per material under ``/ROOT/Geometry``, bound to it with
    ``MaterialBindingAPI``, in a square grid (2.5 units apart, y up, on the ground).

    Each sphere references one mesh (:func:`.geometry.uv_sphere`, a ``class`` prim
    under ``Geometry``), so the file holds its arrays once."""
    from pxr import Sdf, Vt

    from .geometry import uv_sphere

    types = Sdf.ValueTypeNames
    geometry = Sdf.CreatePrimInLayer(layer, f"/{root}/Geometry")
    geometry.specifier, geometry.typeName = Sdf.SpecifierDef, "Xform"
    mesh = uv_sphere()
    proto = Sdf.PrimSpec(geometry, "preview_sphere", Sdf.SpecifierClass, "Mesh")
    for name, kind, value in (
        ("points", types.Point3fArray, Vt.Vec3fArray.FromNumpy(mesh.points.astype(np.float32))),
        ("normals", types.Normal3fArray, Vt.Vec3fArray.FromNumpy(mesh.normals.astype(np.float32))),
        ("faceVertexCounts", types.IntArray, Vt.IntArray.FromNumpy(mesh.counts)),
        ("faceVertexIndices", types.IntArray, Vt.IntArray.FromNumpy(mesh.indices)),
        ("primvars:st", types.TexCoord2fArray, Vt.Vec2fArray.FromNumpy(mesh.st.astype(np.float32))),
        ("extent", types.Float3Array, Vt.Vec3fArray([(-1.0, -1.0, -1.0), (1.0, 1.0, 1.0)])),
    ):
        Sdf.AttributeSpec(proto, name, kind).default = value
    proto.attributes["normals"].SetInfo("interpolation", "vertex")
    proto.attributes["primvars:st"].SetInfo("interpolation", "vertex")
    # Vertex normals, not a subdivision surface: shaded smooth as the proof's sphere.
    scheme = Sdf.AttributeSpec(proto, "subdivisionScheme", types.Token, Sdf.VariabilityUniform)
    scheme.default = "none"
    columns = max(1, int(np.ceil(np.sqrt(len(material_paths)))))
    for i, material in enumerate(material_paths):
        name = Sdf.Path(material).name
        sphere = Sdf.PrimSpec(geometry, f"{name}_sphere", Sdf.SpecifierDef, "Mesh")
        sphere.referenceList.prependedItems = [Sdf.Reference(primPath=proto.path)]
        sphere.SetInfo("apiSchemas", Sdf.TokenListOp.Create(prependedItems=["MaterialBindingAPI"]))
        translate = Sdf.AttributeSpec(sphere, "xformOp:translate", types.Double3)
        translate.default = (2.5 * (i % columns), 1.0, -2.5 * (i // columns))
        order = Sdf.AttributeSpec(
            sphere, "xformOpOrder", types.TokenArray, variability=Sdf.VariabilityUniform
        )
        order.default = ["xformOp:translate"]
        binding = Sdf.RelationshipSpec(sphere, "material:binding", custom=False)
        binding.targetPathList.explicitItems = [Sdf.Path(material)]
