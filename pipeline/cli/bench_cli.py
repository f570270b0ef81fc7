"""``lookdev bench cli`` (registered in :mod:`.bench`; the measuring is
:mod:`lookdev.pipeline.bench.cli`)."""

from __future__ import annotations

from typing import Annotated

import typer
from rich.progress import Progress

from .common import JsonOut, console, err_console, print_json, table

__all__ = ["cli_"]


def cli_(
    rounds: Annotated[
        int, typer.Option("--rounds", min=1, max=100, help="Interleaved rounds (median).")
    ] = 7,
    as_json: JsonOut = False,
) -> None:
    """CPU time of `lookdev --help`, `--version`, `presets list` and `presets show gold`
    against `python -c "import typer"` (target ≤ 3×).

    Each command runs as a fresh process and is charged the user + system CPU time of
    that process; the floor and the commands take turns in every round, and the median
    over rounds is reported with the spread of the ratios.

    Example:

      lookdev bench cli --rounds 9 --json
    """
    from lookdev.pipeline.bench import cli

    with Progress(console=err_console, transient=True, disable=as_json) as bar:
        task = bar.add_task("timing rounds", total=rounds)
        result = cli.run(rounds, progress=lambda done: bar.update(task, completed=done))
    if as_json:
        print_json(result)
        return
    rows = [["python -c 'import typer' (floor)", result["floor_cpu_s"], 1.0, "", ""]]
    for name, r in result["commands"].items():
        spread = f"{r['ratio_min']:.2f}–{r['ratio_max']:.2f}"
        rows.append([name, r["cpu_s"], r["ratio"], spread, "met" if r["met"] else "missed"])
    load = " → ".join(f"{v:g}" for v in result["load_average"])
    title = f"CPU s per command, median of {rounds} rounds (load average {load})"
    console.print(table(title, ["command", "CPU s", "× floor", "range", "≤ 3×"], rows))
