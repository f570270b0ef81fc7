"""``lookdev bench dcc``: Blender Cycles from the exported USD beside lookdev's proofs."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

__all__ = ["dcc_"]


def dcc_(
    presets: Annotated[
        list[str] | None,
        typer.Argument(
            help="Presets (default: a metal, plastic, glass, velvet, skin, a "
            "layered textured one, a Pixar one and a car paint)."
        ),
    ] = None,
    output: Annotated[
        Path, typer.Option("--output", "-o", help="Folder for the USD, proofs and renders.")
    ] = Path("bench-dcc"),
    ibl: Annotated[str, typer.Option("--ibl", "-i", help="A built-in IBL or a lat-long file.")] = (
        "studio"
    ),
    resolution: Annotated[
        tuple[int, int], typer.Option("--resolution", "-r", help="Frame size W H.")
    ] = (200, 100),
    spp: Annotated[
        int, typer.Option("--spp", "-s", min=4, max=4096, help="Samples per pixel of each render.")
    ] = 128,
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Render presets in Blender Cycles (CPU, from `export usd`) and in lookdev's proof
    and `--context universal` proof, same camera, IBL and scene; compare on the ball.

    Reports per preset the mean colour's relative luminance difference and the per-pixel
    relative RMS difference, Cycles against the universal proof and against the preset's
    own proof, beside each side's noise (two renders each) and the loss note Blender shows
    (the material's custom property lookdev:loss), and whether they agree: Cycles
    against the proof within the note's stated albedo change (none where it says
    "fully") plus three standard errors. Needs Blender's bpy (scripts/setup.sh installs
    it into .venv-blender).

    Example: lookdev bench dcc --spp 256 --json > dcc.json
    """
    from rich.progress import Progress

    from lookdev.pipeline.bench import dcc

    from .common import console, print_json, table

    chosen = tuple(presets) if presets else dcc.PRESETS
    with Progress(console=console, transient=True, disable=as_json) as bar:
        task = bar.add_task("bench dcc", total=None)
        result = dcc.run(
            output,
            chosen,
            ibl=ibl,
            resolution=(resolution[0], resolution[1]),
            spp=spp,
            progress=lambda text: bar.update(task, description=text),
        )
    if as_json:
        print_json(result)
        return
    rows = [
        [
            r["preset"],
            f"{100 * r['mean_diff']['cycles-universal']:+.1f} %",
            f"{100 * r['mean_diff']['cycles-proof']:+.1f} %",
            f"{100 * r['pixel_rms']['cycles-proof']:.1f} %",
            f"{100 * r['noise']['cycles_pixel']:.1f} % / {100 * r['noise']['proof_pixel']:.1f} %",
            "fully" if r["fully"] else f"{100 * r['stated']:+.1f} %",
            f"{100 * r['bound']:.1f} %",
            "yes" if r["agree"] else "NO",
        ]
        for r in result["rows"]
    ]
    console.print(
        table(
            f"Blender {result['blender']} Cycles vs lookdev proofs ({result['ibl']}, "
            f"{result['resolution'][0]}×{result['resolution'][1]}, {result['spp']} spp, "
            f"{result['ball_pixels']} ball pixels)",
            [
                "preset",
                "mean vs universal",
                "mean vs proof",
                "pixel vs proof",
                "noise Cycles / proof (pixel)",
                "note says",
                "may be",
                "agree",
            ],
            rows,
        )
    )
    for r in result["rows"]:
        console.print(f"{r['preset']}: {r['loss']}", markup=False, highlight=False)
