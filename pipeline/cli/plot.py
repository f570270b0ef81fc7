"""``lookdev plot``: BRDF-explorer views of presets, side by side (Burley 2012 §3.2)."""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json

__all__ = ["View", "plot"]


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
            "point light (and under --ibl). (The OCIO display view is the global option: "
            "`lookdev --view Un-tone-mapped plot …`.)",
        ),
    ] = View.slice,
    exposure: Annotated[
        float,
        typer.Option(
            "--exposure",
            "-e",
            min=-32.0,
            max=32.0,
            help="Stops applied before display (slice, sphere); -32 .. 32.",
        ),
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
    vary: Annotated[
        str | None,
        typer.Option(
            "--vary",
            metavar="PARAM=V1,V2,…",
            help="Draw each preset once per value of one parameter, e.g. "
            "specular_gamma=1,1.5,2,3 or energy_compensation=off,on (uniform presets).",
        ),
    ] = None,
    uv: Annotated[
        tuple[float, float] | None,
        typer.Option(
            "--uv", help="Plot a texture-driven material as it is at this UV (default: centre)."
        ),
    ] = None,
    overlay: Annotated[
        bool,
        typer.Option(
            "--overlay",
            help="albedo, polar: every material on one axes (a measurement and its fit).",
        ),
    ] = False,
    as_json: Annotated[
        bool, typer.Option("--json", help="Print one JSON object for scripts.")
    ] = False,
) -> None:
    """Draw PRESET… as one BRDF-explorer view and write it to an image.

    A PRESET may be a measured BRDF file (.mbsdf, MERL .binary).

    Examples:

      lookdev plot gold copper --view albedo -o metals.png

      lookdev plot velvet --view sphere --ibl studio -o velvet.png --exposure -1

      lookdev plot gold --vary specular_gamma=1,1.5,2,3 -o gamma.png --exposure -3

      lookdev plot gold --view albedo --vary energy_compensation=off,on -o ms.png

      lookdev plot carpaint_red.mbsdf red_fit.toml --view polar --overlay -o fit.png
      lookdev --view Un-tone-mapped plot gold -o gold.png    # another OCIO view (global)
    """
    from lookdev.pipeline import api

    with console.status(f"plotting {view.value} of {len(presets)} material(s)"):
        result = api.plot(
            presets,
            output,
            view=view.value,
            exposure=exposure,
            ibl=ibl,
            resolution=resolution,
            library=library,
            vary=_vary(vary),
            uv=uv,
            overlay=overlay,
        )
    if as_json:
        print_json(result.to_json())
    else:
        console.print(f"wrote {output}")


def _vary(text: str | None) -> tuple[str, list[float]] | None:
    """``PARAM=V1,V2,…`` → (PARAM, [V1, V2, …]); a malformed one is one error line."""
    if text is None:
        return None
    from lookdev.pipeline.analysis.plots import PlotError

    name, _, values = text.partition("=")
    switch = {"off": 0.0, "false": 0.0, "on": 1.0, "true": 1.0}  # a switch's two values
    words = [v.strip().lower() for v in values.split(",") if v.strip()]
    try:
        numbers = [switch[w] if w in switch else float(w) for w in words]
    except ValueError:
        numbers = []
    if not name.strip() or not numbers:
        raise PlotError(
            f"--vary {text!r}: expected PARAM=V1,V2,… with numbers (or off,on)", field="--vary"
        )
    return name.strip(), numbers
