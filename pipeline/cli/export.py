"""``lookdev export …``: presets out to other tools, one sub-command per target."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json
from .lazy import Lazy, lazy_group

__all__ = ["app", "mitsuba"]

app = typer.Typer(
    cls=lazy_group(
        {"usd": Lazy(".export_usd:export_usd", "Write presets as UsdShade materials for DCCs.")}
    ),
    help="Write presets for other tools: Mitsuba scenes, USD shading networks.",
    no_args_is_help=True,
)


@app.command("mitsuba")
def mitsuba(
    preset: Annotated[str, typer.Argument(help="Preset name or .toml file.")],
    output: Annotated[
        Path,
        typer.Option("--output", "-o", help="Scene XML to write.", dir_okay=False),
    ],
    resolution: Annotated[
        tuple[int, int],
        typer.Option("--resolution", help="Film width and height in pixels, each 1 .. 16384."),
    ] = (512, 512),
    spp: Annotated[int, typer.Option("--spp", min=1, max=2**20, help="Samples per pixel.")] = 128,
    environment: Annotated[
        str | None,
        typer.Option(
            "--ibl",
            help="Environment light: a built-in IBL name or an .exr/.hdr file "
            "(default: a constant white sky, the white-furnace set-up).",
        ),
    ] = None,
    ibl_rotation: Annotated[
        float,
        typer.Option(
            "--ibl-rotation",
            min=-360.0,
            max=360.0,
            help="Turn the IBL by this many degrees about +y, as a proof's lighting frame "
            "does (positive: a front light moves to the camera's right).",
        ),
    ] = 0.0,
    map_resolution: Annotated[
        int,
        typer.Option(
            "--map-resolution", min=1, max=16384, help="Texels a side of layered presets' maps."
        ),
    ] = 512,
    force_all_lobes: Annotated[
        bool,
        typer.Option(
            "--force-all-lobes",
            help="Trace every lobe, zero weights included (a baseline for measuring pruning).",
        ),
    ] = False,
    library: Annotated[
        list[Path] | None,
        typer.Option("--library", "-L", help="Extra preset folders searched before the built-ins."),
    ] = None,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Write PRESET as a Mitsuba 3 scene: the material on a sphere under an environment.

    The material renders through lookdev's own BSDF plugins (the same model code as the
    plots and tests); the first line of the XML says how to load them. Untextured metals
    use Mitsuba's built-in principled BSDF, measured equal. Layered presets are blended
    and their varying parameters written as EXR maps beside the scene.

    Examples:

      lookdev export mitsuba gold -o gold.xml

      lookdev export mitsuba rusty_iron -o rust/scene.xml --ibl studio --spp 64

      lookdev --working-space acescg export mitsuba gold -o gold.xml --ibl sky

    The scene is in the working space (global --working-space): its maps carry its
    chromaticities, and an IBL in another space is converted beside it (NAME_env.exr).
    """
    from lookdev.pipeline import api

    with console.status(f"exporting {preset}…", spinner="dots"):
        result = api.export_mitsuba(
            preset,
            output,
            ibl=environment,
            ibl_rotation=ibl_rotation,
            resolution=resolution,
            spp=spp,
            map_resolution=map_resolution,
            force_all_lobes=force_all_lobes,
            library=library,
        )
    summary = result.to_json()
    if as_json:
        print_json(summary)
        return
    console.print(
        f"wrote [bold]{output}[/]: {summary['bsdf']}, {len(summary['textures'])} maps, "
        f"max_depth {summary['max_depth']}"
    )
    if summary["plugins"]:
        console.print(
            "load it after: import lookdev.pipeline.export.mitsuba as m; m.register_plugins()",
            highlight=False,
        )
