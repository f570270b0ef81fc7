"""``lookdev bench depth`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.depth`)."""

from __future__ import annotations

from typing import Annotated

import typer

from lookdev.pipeline.bench import depth

from .common import JsonOut, console, print_json, table
from .render_options import Ibl, Resolution, Spp, check_resolution, rendered

__all__ = ["depth_"]


def depth_(
    presets: Annotated[
        list[str] | None,
        typer.Argument(help="Presets to measure (default: one per depth class)."),
    ] = None,
    ibl: Ibl = "studio",
    spp: Spp = 64,
    resolution: Resolution = (160, 80),
    reference_depth: Annotated[
        int, typer.Option("--reference-depth", min=2, help="Depth of the reference renders.")
    ] = 32,
    repeat: Annotated[int, typer.Option("--repeat", min=1, help="Timed rounds.")] = 3,
    as_json: JsonOut = False,
) -> None:
    """Time the proof scene at each material's chosen path depth against a deep reference.

    Example:

      lookdev bench depth gold glass_clear --spp 32 --json
    """
    check_resolution(resolution, depth.BenchDepthError)
    settings = depth.Settings(
        presets=tuple(presets or depth.DEFAULT_PRESETS),
        ibl=ibl,
        spp=spp,
        resolution=resolution,
        reference_depth=reference_depth,
        repeat=repeat,
    )
    result = rendered(depth.run, settings, as_json)
    if as_json:
        print_json(result)
        return
    columns = [
        "preset",
        "depth",
        "s",
        "ref depth",
        "ref s",
        "speed-up",
        "mean loss %",
        "p99 loss %",
    ]
    rows = [
        [
            r["preset"],
            r["depth"],
            r["seconds"],
            r["reference_depth"],
            r["reference_seconds"],
            r["speedup"],
            100 * r["mean_loss"],
            100 * r["p99_pixel_loss"],
        ]
        for r in result["presets"]
    ]
    console.print(table(f"path depth per material ({spp} spp, {ibl})", columns, rows))
