"""``lookdev export usd``, ``lookdev import usd`` and ``lookdev validate usd``."""

from __future__ import annotations

from contextlib import contextmanager
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json, table

__all__ = [
    "Context",
    "ImportOpenPBR",
    "MtlxSurface",
    "PARTLY_IMPORTED",
    "PreviewOpacity",
    "export_usd",
    "import_app",
    "import_usd",
    "validate_app",
    "validate_usd",
]

import_app = typer.Typer(
    help="Read materials written by other tools back into presets.", no_args_is_help=True
)
validate_app = typer.Typer(
    help="Check exported files the way the tools that read them will.", no_args_is_help=True
)


class Context(StrEnum):
    universal = "universal"
    mtlx = "mtlx"
    ri = "ri"


class PreviewOpacity(StrEnum):
    keep = "keep"
    transmission = "transmission"


class ImportOpenPBR(StrEnum):
    disney = "disney"
    itself = "itself"


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


@import_app.command("usd")
def import_usd(
    file: Annotated[Path, typer.Argument(help="USD file with UsdShade materials.")],
    output: Annotated[
        Path | None,
        typer.Option(
            "--output",
            "-o",
            help="Preset .toml to write (a folder when the file holds several materials; "
            "made if missing); default: print the TOML.",
        ),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Replace preset files of the same name in -o.")
    ] = False,
    rename: Annotated[
        bool,
        typer.Option(
            "--rename",
            help="Import a material whose name another material of the file, a preset in "
            "-o, or (when -o is a library folder) a library preset has as NAME_imported "
            "(default: refuse; --force replaces a preset in -o instead).",
        ),
    ] = False,
    openpbr: Annotated[
        ImportOpenPBR,
        typer.Option(
            "--openpbr",
            help="OpenPBR Surface materials from other tools: 'disney' (translated to "
            "Burley's parameters, losses named) or 'itself' (an openpbr preset holding "
            "its inputs as they are, proofed by lookdev's OpenPBR model; a Standard "
            "Surface becomes one by MaterialX's own translation to OpenPBR).",
        ),
    ] = ImportOpenPBR.disney,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Read materials from a USD file back into presets.

    Reads UsdPreviewSurface, OpenPBR, Standard Surface and glTF PBR networks from any tool
    (values followed through the Material's interface inputs), and gives a lookdev
    export back exactly (its preset travels in the Material's customData). A parameter
    fed by a texture becomes the preset's texture table for it (file, channel, colour
    space, scale/offset, wrap; under "maps" with --json); what a preset cannot hold (alpha and
    cut-outs, normal, emission, occlusion, a specular-workflow conversion) is printed
    and listed as "# loss:" lines. A name another material of the file has, or (when
    -o is a folder of the library) a library preset elsewhere has, is refused unless
    --rename.

    Examples:

      lookdev import usd gold.usda

      lookdev import usd library.usda -o imported/

    Foreign files import as far as they can: a material that cannot become a preset (a
    layered Pixar material, a surface lookdev does not read) is skipped and a value a
    preset would reject (out of range, NaN, infinity; never clamped) refuses its
    material, each in one line on stderr naming the prim, the field and the value, and
    the others are written. An input on a lobe whose weight is 0 is not read. An existing
    preset file is replaced only with --force.

    Exit status: 0 every material imported; 3 partly imported (some written, some
    skipped or refused: the lines say which); 2 bad input (nothing importable, a file
    that is not USD, a name clash, an unwritable -o).
    """
    from lookdev.pipeline.export.usd.presets import import_names, screen, write_presets
    from lookdev.pipeline.export.usd.reader import import_usd as read

    skipped: list[str] = []
    refused: list[str] = []
    found = read(file.expanduser(), skipped, refused)
    if openpbr is ImportOpenPBR.itself:
        from lookdev.pipeline.export.usd.reader import import_as_openpbr

        not_openpbr: list[str] = []
        itself = import_as_openpbr(file.expanduser(), not_openpbr)
        for m in found:  # OpenPBR's ranges refuse it: it stays Burley's, and says why
            why = [line for line in not_openpbr if line.startswith(f"{m.prim}:")]
            if m.name not in itself and why:
                m.loss.append(f"mtlx: read as Burley's, not as OpenPBR ({why[0]})")
        found = [itself.get(m.name, m) for m in found]
    found = screen(found, refused)
    if not found:
        from lookdev.pipeline.export.usd.network import ExportError

        raise ExportError("no material to import: refused " + "; ".join(refused), where=str(file))
    names = import_names(found, _taken_names(output, rename), rename=rename)
    written = write_presets(found, output, force=force, names=names)
    if as_json:
        print_json(
            {
                "file": str(file),
                "materials": [
                    {
                        "name": m.name,
                        "prim": m.prim,
                        "preset": name,
                        "model": m.model,
                        "params": m.params,
                        "maps": {
                            k: v.model_dump(mode="json", exclude_defaults=True)
                            | {"texture": v.texture}
                            for k, v in m.maps.items()
                        },
                        "contexts": m.contexts,
                        "loss": m.loss,
                    }
                    for m, name in zip(found, names, strict=True)
                ],
                "written": [str(p) for p in written],
                "skipped": skipped,
                "refused": refused,
            }
        )
    elif output is None:
        from lookdev.pipeline.export.usd.presets import preset_toml

        for m, name in zip(found, names, strict=True):
            typer.echo(preset_toml(m, name))
    else:
        for path, m in zip(written, found, strict=True):
            console.print(f"wrote [bold]{path}[/]")
            for line in m.loss:
                console.print(f"  loss: {line}", markup=False, highlight=False)
    if skipped or refused:
        for line in skipped:  # one line each, never wrapped
            typer.echo(f"lookdev: skipped {line}", err=True)
        for line in refused:
            typer.echo(f"lookdev: refused {line}", err=True)
        total = len(found) + len(skipped) + len(refused)
        typer.echo(f"lookdev: partly imported: {len(found)} of {total} materials", err=True)
        raise typer.Exit(PARTLY_IMPORTED)


PARTLY_IMPORTED = 3
"""``lookdev import usd``'s exit status when some materials were written and some not."""


def _taken_names(output: Path | None, rename: bool) -> set[str]:
    """Preset names an import into ``output`` must not take.

    When ``output`` is a folder of the library's search path, a preset of the same name
    elsewhere in the library would shadow it or be shadowed: refused (or renamed). With
    ``rename``, the presets already in ``output`` are avoided too (without it, replacing
    one is ``--force``'s business).
    """
    if output is None:
        return set()
    from lookdev.library import Library

    target = output.expanduser()
    folder = (target.parent if target.suffix == ".toml" else target).resolve()
    taken: set[str] = set()
    if rename and folder.is_dir():
        taken |= {p.stem for p in folder.glob("*.toml")}
    library = Library()
    if any(folder == f.resolve() for f in library.folders if f.is_dir()):
        for name in library.names():
            if library.find(name).resolve().parent != folder:
                taken.add(name)
    return taken


@validate_app.command("usd")
def validate_usd(
    file: Annotated[Path, typer.Argument(help="USD file to check.")],
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Run every validator usd-core registers, and MaterialX's own check on mtlx networks.

    usd-core cannot know MaterialX (ND_*) or RenderMan (Pxr*) shader ids, so their
    MissingShaderIdInRegistry errors are expected and listed apart; every other error
    fails. Every authored shader input is also checked against its node's definition
    (renderers ignore an unknown input silently): Pxr* against RenderMan's input names
    kept with lookdev, ND_* against MaterialX's node definitions, UsdPreviewSurface and
    UsdUVTexture against usd-core's Sdr registry. Exit code 0 when valid, 1 when not.
    """
    from lookdev.pipeline.export.usd.validate import validate_usd as check

    report = check(file.expanduser())
    if as_json:
        print_json(
            {
                "file": report.path,
                "ok": report.ok,
                "validators": report.validators,
                "errors": report.errors,
                "warnings": report.warnings,
                "allowed": report.allowed,
                "mtlx_networks": report.mtlx_networks,
                "inputs_checked": report.inputs_checked,
            }
        )
    else:
        rows = [
            ["errors", len(report.errors)],
            ["warnings", len(report.warnings)],
            ["expected (MaterialX/RenderMan ids)", len(report.allowed)],
            ["MaterialX networks checked", report.mtlx_networks],
            ["shader inputs checked against their node's definition", report.inputs_checked],
        ]
        console.print(table(f"{file} — {report.validators} validators", ["check", "count"], rows))
        for line in report.errors + report.warnings:
            console.print(f"  {line}", markup=False, highlight=False)
        console.print("[green]valid[/]" if report.ok else "[red]not valid[/]")
    if not report.ok:
        raise typer.Exit(1)
