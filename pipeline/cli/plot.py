"""``lookdev plot``: BRDF-explorer views of presets, side by side (Burley 2012 §3.2)."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json

FORMATS = (".png", ".pdf", ".svg")


class View(StrEnum):
    slice = "slice"
    albedo = "albedo"
    polar = "polar"
    sphere = "sphere"


def plot(
    presets: Annotated[
        list[str],
        typer.Argument(
            metavar="PRESET…", help="Preset names or .toml files; each becomes one column."
        ),
    ],
    output: Annotated[
        Path,
        typer.Option("--output", "-o", help="Image to write: .png, .pdf or .svg.", dir_okay=False),
    ],
    view: Annotated[
        View,
        typer.Option(
            "--view",
            "-v",
            help="slice: f(θh, θd) at φd = 90° (left edge = specular peak, top = Fresnel "
            "peak). albedo: directional albedo per channel vs incidence angle. polar: f in "
            "the plane of incidence for θi = 0, 30, 60, 80°. sphere: a lit sphere under a "
            "point light (and under --ibl).",
        ),
    ] = View.slice,
    exposure: Annotated[
        float,
        typer.Option("--exposure", "-e", help="Stops applied before display (slice, sphere)."),
    ] = 0.0,
    ibl: Annotated[
        str | None,
        typer.Option(
            "--ibl", help="Also light the sphere with this IBL: a built-in name or an .exr/.hdr."
        ),
    ] = None,
    resolution: Annotated[
        int,
        typer.Option(
            "--resolution", min=8, max=1024, help="Pixels per side of slices and spheres."
        ),
    ] = 128,
    library: Annotated[
        list[Path] | None,
        typer.Option("--library", "-L", help="Extra preset folders searched before the built-ins."),
    ] = None,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object for scripts.")
    ] = False,
) -> None:
    """Draw PRESET… as one BRDF-explorer view and write it to an image.

    Examples:

      lookdev plot gold copper --view albedo -o metals.png

      lookdev plot velvet --view sphere --ibl studio -o velvet.png --exposure -1
    """
    # Imported here: matplotlib should not slow down every other command.
    from lookdev.pipeline.analysis import plots
    from lookdev.pipeline.analysis.plots import PlotError

    if output.suffix.lower() not in FORMATS:
        raise PlotError(
            f"cannot write {output.suffix or 'no extension'}; allowed {', '.join(FORMATS)}",
            where=str(output),
        )
    from lookdev.library import Library, load_material
    from lookdev.pipeline.blend import blend

    lib = Library(library)
    hubs = [blend(load_material(name, lib), plots.MAP_RESOLUTION) for name in presets]
    environment = None
    if ibl is not None:
        if view is not View.sphere:
            raise PlotError("--ibl only applies to --view sphere", field="--ibl")
        environment = plots.load_environment(ibl)
    with console.status(f"plotting {view.value} of {len(hubs)} material(s)"):
        fig = plots.figure(
            hubs,
            view.value,
            exposure=exposure,
            environment=environment,
            ibl_name=ibl or "",
            resolution=resolution,
        )
        plots.save_figure(fig, output)
    if as_json:
        print_json({"output": str(output), "view": view.value, "materials": [h.name for h in hubs]})
    else:
        console.print(f"wrote {output}")
