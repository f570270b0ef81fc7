"""``lookdev export usd``: presets as UsdShade materials, with what each context lost."""

from __future__ import annotations

from contextlib import contextmanager
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json, table

__all__ = ["Context", "MtlxSurface", "PreviewOpacity", "export_usd"]


class Context(StrEnum):
    universal = "universal"
    mtlx = "mtlx"
    ri = "ri"


class PreviewOpacity(StrEnum):
    keep = "keep"
    transmission = "transmission"


class MtlxSurface(StrEnum):
    openpbr = "openpbr"
    disney = "disney"


def export_usd(
    presets: Annotated[
        list[str] | None,
        typer.Argument(
            help="Preset names or .toml files (several make a library).", show_default=False
        ),
    ] = None,
    output: Annotated[
        Path,
        typer.Option("--output", "-o", help="USD file: .usda, .usdc, .usd, or .usdz (packaged)."),
    ] = Path("materials.usda"),
    contexts: Annotated[
        list[Context] | None,
        typer.Option(
            "--context",
            "-c",
            help="Render context to write; repeat for several (default: all three).",
        ),
    ] = None,
    mtlx_file: Annotated[
        Path | None,
        typer.Option("--mtlx", help="Also write the MaterialX networks as a standalone .mtlx."),
    ] = None,
    bake_maps: Annotated[
        bool,
        typer.Option("--bake", help="Layered presets: bake blended parameter maps and read those."),
    ] = False,
    resolution: Annotated[
        int, typer.Option("--map-resolution", min=1, max=16384, help="Texels a side of baked maps.")
    ] = 1024,
    package: Annotated[
        bool, typer.Option("--package", help="Write a .usdz holding the stage and its textures.")
    ] = False,
    split: Annotated[
        Path | None,
        typer.Option(
            "--split",
            help="One file per material in this folder; -o becomes a library that references "
            "them, with a variant set 'preset' on /Materials/Look to switch between them.",
        ),
    ] = None,
    all_presets: Annotated[
        bool, typer.Option("--all", help="Export every preset of the library.")
    ] = False,
    library: Annotated[
        list[Path] | None,
        typer.Option("--library", "-L", help="Extra preset folders searched before the built-ins."),
    ] = None,
    preview_opacity: Annotated[
        PreviewOpacity,
        typer.Option(
            "--preview-opacity",
            help="Transmissive materials in UsdPreviewSurface: 'keep' opacity at 1 (DCCs read "
            "opacity as alpha; the loss is named) or 'transmission', the spec's reading "
            "opacity = 1 - spec_trans.",
        ),
    ] = PreviewOpacity.keep,
    meters_per_unit: Annotated[
        float,
        typer.Option(
            "--meters-per-unit",
            min=1e-9,
            max=1e9,
            help="The stage's metersPerUnit (0.01 for a centimetre scene); lookdev's lengths "
            "(scatter_distance, metres) are written in these units.",
        ),
    ] = 1.0,
    report: Annotated[
        bool,
        typer.Option(
            "--report",
            help="Measure every context of each material against the material (universal, "
            "mtlx as OpenPBR and as ND_disney_principled, ri where its model is known): "
            "directional albedo 0-85° (RMS, worst) and the highlight's energy and width.",
        ),
    ] = False,
    collect: Annotated[
        bool,
        typer.Option(
            "--collect",
            help="Copy the presets' texture files (UDIM tiles included) into NAME_textures "
            "beside the output and reference them by relative paths.",
        ),
    ] = False,
    preview_geometry: Annotated[
        bool,
        typer.Option(
            "--preview-geometry",
            help="Add a sphere per material, bound to it, so a DCC's default import shows it.",
        ),
    ] = False,
    mtlx_surface: Annotated[
        MtlxSurface,
        typer.Option(
            "--mtlx-surface",
            help="The mtlx surface of Disney presets: 'openpbr' (OpenPBR Surface, what "
            "current MaterialX renderers read; the mapping's losses are named) or 'disney' "
            "(ND_disney_principled, Burley's parameters as they are).",
        ),
    ] = MtlxSurface.openpbr,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Write presets as UsdShade materials that DCCs and their renderers read.

    Each preset becomes /Materials/NAME with up to three render contexts: **universal**
    (UsdPreviewSurface, read everywhere), **mtlx** (MaterialX OpenPBR Surface, or
    ND_disney_principled with --mtlx-surface disney) and **ri** (RenderMan
    PxrDisneyBsdf). What a context cannot express is printed as a table, written as
    the Material's doc string and kept in the surface's customData (under "losses"
    with --json). Glass keeps opacity 1 in UsdPreviewSurface unless
    --preview-opacity transmission. Only what a material needs is written: inputs at
    the target's default and lobes without weight are left out. Layered presets are
    blended and their
    varying parameters baked to EXR maps beside the file (UsdPreviewSurface has no mix
    node). With several presets, /Materials/Look carries a variant set that switches between
    them. A parameter read from one texture file references that file (its colour space
    named: sourceColorSpace, colorSpace, colorspace, linearize), or a copy with --collect;
    a preset's height map becomes displacement in scene units (metersPerUnit = 1).

    Clearcoat in UsdPreviewSurface: clearcoat = 0.25 x lookdev's clearcoat (Burley weights
    his GTR1 coat 0.25, the spec's coat is unweighted: the scale keeps the coat's reflected
    energy) and clearcoatRoughness = sqrt(mix(0.1, 0.001, clearcoat_gloss)) (Burley's coat
    alpha, squared back by the spec); import divides and inverts the same way. The
    subsurface radius is scatter_distance (metres) / --meters-per-unit, 1 mm where only
    Burley 2012's distance-less subsurface is live.

    Examples:

      lookdev export usd gold -o gold.usda

      lookdev export usd gold copper glass_clear -o metals.usda --context universal

      lookdev export usd --all -o library.usda --split materials/ --mtlx library.mtlx

      lookdev export usd rusty_iron -o rust.usdz --package

      lookdev --working-space acescg export usd gold -o gold.usda --mtlx gold.mtlx

    Values and maps are in the working space (global --working-space), named on each
    Material (ColorSpaceAPI colorSpace:name) and in the MaterialX document (colorspace).
    """
    from lookdev.pipeline import api

    with _progress("reading presets", quiet=as_json) as progress:
        result = api.export_usd(
            presets or [],
            output,
            tuple(c.value for c in contexts) if contexts else api.USD_CONTEXTS,
            mtlx=mtlx_file,
            bake=bake_maps,
            map_resolution=resolution,
            package=package,
            split=split,
            all_presets=all_presets,
            library=library,
            progress=progress,
            preview_opacity=preview_opacity.value,
            meters_per_unit=meters_per_unit,
            report=report,
            collect=collect,
            preview_geometry=preview_geometry,
            mtlx_surface=mtlx_surface.value,
        )
    if as_json:
        print_json(result.to_json())
        return
    console.print(
        f"wrote [bold]{result.output}[/]: {len(result.materials)} materials, "
        f"contexts {', '.join(result.contexts)}, {len(result.textures)} textures"
    )
    for extra in result.files[1:]:
        console.print(f"  {extra}", highlight=False)
    rows = result.loss_rows()
    if rows:
        losses = table(
            "What each render context could not express",
            ["material", "context", "cannot express"],
            [list(r) for r in rows],
        )
        losses.columns[1].justify = losses.columns[2].justify = "left"
        losses.columns[2].overflow = "fold"
        console.print(losses)
    else:
        console.print("every render context expresses every material fully")
    if result.contexts_fidelity:
        rows = [f for by in result.contexts_fidelity.values() for f in by]
        rows.sort(key=lambda f: (f.material, f.context))
        fid = table(
            "Each context vs the material (albedo over 0-85°, highlight at 30°)",
            ["material", "context", "albedo RMS", "worst", "highlight energy", "width"],
            [f.row() for f in rows],
        )
        console.print(fid)
        for note in sorted({n for f in rows for n in f.notes}):
            console.print(f"note: {note}", highlight=False)


@contextmanager
def _progress(label: str, quiet: bool):
    """A transient bar once there are 8 or more presets to read; None when quiet."""
    if quiet:
        yield None
        return
    from rich.progress import Progress

    with Progress(console=console, transient=True) as bar:
        task = None

        def advance(done: int, total: int, name: str) -> None:
            nonlocal task
            if total < 8:
                return
            if task is None:
                task = bar.add_task(label, total=total)
            bar.update(task, completed=done)

        yield advance
