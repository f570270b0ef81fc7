"""``lookdev blend``: blend a layered preset and bake the maps that vary to EXR."""

from __future__ import annotations

import time
from contextlib import contextmanager
from pathlib import Path
from typing import Annotated

import typer

from .common import console, err_console, print_json, table

__all__ = ["LARGE", "blend"]

LARGE = 1024 * 1024
"""Texels from which a bake shows a progress bar."""


def blend(
    preset: Annotated[str, typer.Argument(help="Preset name, or a path to a .toml file.")],
    output: Annotated[
        Path,
        typer.Option("--output", "-o", help="Folder for NAME.json and NAME_<param>.exr files."),
    ],
    resolution: Annotated[
        int, typer.Option("--resolution", "-r", min=1, max=16384, help="Texels per side.")
    ] = 1024,
    library: Annotated[
        list[Path] | None,
        typer.Option("--library", "-L", help="Extra preset folders searched before the built-ins."),
    ] = None,
    layering: Annotated[
        str,
        typer.Option(
            "--layering",
            help="Pixar stacks: full (light through a layer meets the ones below, Smits' "
            "table) or simple (A over B).",
        ),
    ] = "full",
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Blend PRESET's layers; write the maps that vary as EXR and the rest as JSON.

    Disney layers blend parameters under their masks (Burley §5.7), Pixar layers composite
    lobe weights (Smits); layers hidden or with zero coverage are skipped.

    Files are written top row = v 1: UV (0, 0) is the bottom-left texel.

    Examples:

      lookdev blend rusty_iron -o maps/

      lookdev blend looks/old_door.toml -o maps/ --resolution 4096 --json
    """
    from lookdev.pipeline import api

    material = api.load(preset, library)
    t0 = time.perf_counter()
    with _progress(resolution * resolution >= LARGE) as (blend_cb, bake_cb):
        blended = api.blend(material, resolution, progress=blend_cb, layering=layering)
        files = api.bake(blended, output, progress=bake_cb)
    seconds = time.perf_counter() - t0
    if as_json:
        print_json(_summary(blended, files, seconds))
        return
    _print(blended, files, seconds)


@contextmanager
def _progress(show: bool):
    """Progress callbacks for blending (rows) and baking (files); no-ops when small."""
    if not show:
        yield None, None
        return
    from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

    columns = (TextColumn("{task.description}"), BarColumn(), TimeRemainingColumn())
    with Progress(*columns, console=err_console, transient=True) as bar:
        rows = bar.add_task("blending", total=None)
        files = bar.add_task("writing EXR", total=None, visible=False)

        def on_rows(done: int, total: int) -> None:
            bar.update(rows, completed=done, total=total)

        def on_files(done: int, total: int) -> None:
            bar.update(files, completed=done, total=total, visible=True)

        yield on_rows, on_files


def _summary(blended, files: dict[str, Path], seconds: float) -> dict:
    return {
        "name": blended.name,
        "model": blended.model,
        "representation": blended.representation,
        "resolution": list(blended.resolution),
        "sidecar": str(files["sidecar"]),
        "maps": {
            name: {"file": str(files[name]), "min": float(a.min()), "max": float(a.max())}
            for name, a in blended.arrays.items()
        },
        "constants": blended.constants,
        "layers": [vars(d) for d in blended.decisions],
        "seconds": round(seconds, 4),
    }


def _print(blended, files: dict[str, Path], seconds: float) -> None:
    width, height = blended.resolution
    rows = [[d.layer, "kept" if d.kept else "skipped", d.reason] for d in blended.decisions]
    console.print(table(f"{blended.name}: layers", ["layer", "", "why"], rows))
    maps = [
        [name, f"{a.min():.4g} .. {a.max():.4g}", files[name].name]
        for name, a in blended.arrays.items()
    ]
    console.print(table(f"maps ({width}×{height})", ["parameter", "range", "file"], maps))
    console.print(
        f"{len(blended.constants)} constants and {len(maps)} maps written to "
        f"{files['sidecar'].parent} in {seconds:.2f} s (sidecar {files['sidecar'].name})",
        highlight=False,
    )
