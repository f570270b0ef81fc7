"""The options and the run shared by the benchmarks that render presets (``lookdev bench
depth``, ``lookdev bench glass``)."""

from __future__ import annotations

from typing import Annotated, Any

import typer

from .common import console

__all__ = ["MIN_RESOLUTION", "Ibl", "Resolution", "Spp", "check_resolution", "rendered"]

Ibl = Annotated[str, typer.Option("--ibl", help="Built-in IBL name or an .exr/.hdr.")]
Spp = Annotated[int, typer.Option("--spp", min=1, help="Samples per pixel.")]
Resolution = Annotated[
    tuple[int, int], typer.Option("--resolution", help="Width and height in pixels (≥ 8).")
]
MIN_RESOLUTION = 8
"""Smallest frame side a rendering benchmark takes."""


def check_resolution(resolution: tuple[int, int], error: type[Exception]) -> None:
    """Refuse a frame side below :data:`MIN_RESOLUTION` with the benchmark's ``error``."""
    if min(resolution) < MIN_RESOLUTION:
        raise error(
            f"{resolution[0]} {resolution[1]}: at least {MIN_RESOLUTION}", field="--resolution"
        )


def rendered(run: Any, settings: Any, as_json: bool) -> Any:
    """``run(settings, progress=…)`` under a progress bar of one step per preset (none for
    ``--json``), as the rendering benchmarks report."""
    from rich.progress import Progress

    with Progress(console=console, transient=True, disable=as_json) as bar:
        task = bar.add_task("rendering", total=len(settings.presets))
        return run(settings, progress=lambda: bar.advance(task))
