"""``lookdev bench fit``: a fit of the Disney (or Pixar) model to a measured BRDF."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import console, print_json

__all__ = ["fit_"]


def fit_(
    measured: Annotated[
        Path, typer.Argument(help="An .mbsdf or MERL file, or a shipped one's name.")
    ] = Path("carpaint_red.mbsdf"),
    model: Annotated[str, typer.Option("--model", "-m", help="disney or pixar.")] = "disney",
    starts: Annotated[int, typer.Option(min=1, max=64, help="Starting points.")] = 4,
    json_out: Annotated[bool, typer.Option("--json", help="Print one JSON object.")] = False,
) -> None:
    """Fit twice from one seed: CPU and wall seconds, the ratio to one model evaluation,
    whether both fits agree. Target: under a minute on 2 cores."""
    from lookdev.library.measured import read_measured, resolve_measured
    from lookdev.pipeline.bench.fit import fit_cost

    with console.status("fitting (twice)"):
        result = fit_cost(read_measured(resolve_measured(measured)), model, starts=starts)
    if json_out:
        print_json(result)
        return
    console.print(
        f"{result['model']} to {result['measurement']}: {result['cpu_s'][0]:.1f} CPU-s, "
        f"{result['wall_s'][0]:.1f} s wall ({result['fit_over_one_evaluation']:.0f}× one "
        f"evaluation), log RMS {result['error']:.4f}, reproducible: {result['reproducible']}"
    )
