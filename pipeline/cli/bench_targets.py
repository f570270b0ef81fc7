"""``lookdev bench targets`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.targets`)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from lookdev.pipeline.bench import targets

from .common import JsonOut, console, print_json, table

__all__ = ["targets_"]


def targets_(
    target: Annotated[
        list[float] | None,
        typer.Option("--target", "-t", help="A per-pixel target to price (repeatable)."),
    ] = None,
    output: Annotated[
        Path | None,
        typer.Option(
            "--output",
            "-o",
            file_okay=False,
            help="Keep every setting's proofs here, and targets.png: the shown frames of "
            "glass × sky, gold × studio and skin × sky, a column per setting.",
        ),
    ] = None,
    quick: Annotated[bool, typer.Option("--quick", help="One tiny proof (CI, tests).")] = False,
    as_json: JsonOut = False,
) -> None:
    """The main job's noise target against its cost: how many frames meet it, at what CPU.

    Runs the main job's proofs (every preset under every built-in IBL, one pose a
    turntable) as fresh `lookdev proof` processes: the uniform default, then per-pixel
    sampling at each --target (default 0.04, 0.03, 0.02 display RMS). Each run's CPU and
    wall seconds, frames that met their target, and the frames that stopped at the cap
    (with their residual and share of pixels met). Took 6 minutes on 2 idle cores.

    Example:

      lookdev bench targets --target 0.04 --target 0.02 --json
    """
    s = targets.TargetSettings.quick() if quick else targets.TargetSettings()
    if target:
        s = targets.TargetSettings(s.presets, s.ibls, tuple(target), s.resolution, s.max_spp)
    with console.status("running the main job's proofs per setting", spinner="dots"):
        report = targets.run(s, output)
    if as_json:
        print_json(report)
        return
    cols = ["setting", "frames", "met target", "mean spp", "CPU s", "wall s"]
    rows = [
        [r["setting"], r["frames"], r["met"], r["mean_spp"], r["cpu_s"], r["wall_s"]]
        for r in report["rows"]
    ]
    console.print(table("the main job, one pose a turntable", cols, rows))
    console.print(f"load average {report['load_average']}", highlight=False)
