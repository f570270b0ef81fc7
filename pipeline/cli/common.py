"""Pieces every command shares: consoles, JSON output, ``key=value`` parsing."""

from __future__ import annotations

import json
import sys
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

console = Console()
err_console = Console(stderr=True)

JsonOut = Annotated[bool, typer.Option("--json", help="Print one JSON object.")]
"""The ``--json`` flag of every command that prints figures."""
Repeat = Annotated[int, typer.Option(min=1, max=20, help="Timed runs; the best counts.")]

# The options and the run of the benchmarks that render presets (bench depth, bench glass).
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


def print_json(obj: Any) -> None:
    """One JSON document on stdout, for scripts (no Rich markup, no wrapping)."""
    sys.stdout.write(json.dumps(obj, indent=2, default=_jsonable) + "\n")


def _jsonable(obj: Any) -> Any:
    if hasattr(obj, "tolist"):
        return obj.tolist()
    if hasattr(obj, "model_dump"):
        return obj.model_dump(mode="json")
    return str(obj)


def table(title: str, columns: list[str], rows: list[list[Any]]) -> Table:
    """A Rich table with the house style: numbers right-aligned."""
    t = Table(title=title, title_justify="left")
    for c in columns:
        t.add_column(c, justify="left" if c == columns[0] else "right")
    for r in rows:
        t.add_row(*(_cell(v) for v in r))
    return t


def _cell(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)
