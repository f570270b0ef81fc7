"""``lookdev bench library`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.library`)."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.progress import Progress

from lookdev.pipeline.bench import library

from .common import JsonOut, console, print_json, table

__all__ = ["library_"]


def library_(
    n: Annotated[int, typer.Option("--n", min=1, help="Presets in the generated library.")] = 10000,
    repeat: Annotated[int, typer.Option("--repeat", min=1, help="Runs per timing (best).")] = 5,
    as_json: JsonOut = False,
) -> None:
    """Time `presets list` over N generated presets against reading their bytes (target ≤ 2x).

    Example: lookdev bench library --n 10000
    """
    with Progress(console=console, transient=True, disable=as_json) as bar:
        task = bar.add_task(f"writing {n} presets", total=n)

        def step(what: str, done: int) -> None:
            bar.update(task, description=what, completed=done)

        result = library.run(n, repeat=repeat, progress=step)
    if as_json:
        print_json(result)
        return
    rows = [
        ["read bytes (baseline)", result["read_s"], 1.0],
        ["presets list", result["list_s"], result["ratio_list_to_read"]],
        ["presets list --json", result["list_json_s"], result["ratio_list_json_to_read"]],
        ["Library.entries()", result["entries_s"], result["ratio_entries_to_read"]],
        ["first listing (no index)", result["cold_s"], result["ratio_cold_to_read"]],
    ]
    console.print(table(f"library of {n} presets", ["what", "seconds", "× read"], rows))
    verdict = "meets" if result["meets_target"] else "MISSES"
    console.print(
        f"presets list {verdict} the target of ≤ {library.TARGET_RATIO:g}× reading the bytes"
    )
