"""Pieces every command shares: consoles, JSON output, ``key=value`` parsing."""

from __future__ import annotations

import json
import sys
from typing import Annotated, Any

import typer
from rich.console import Console
from rich.table import Table

__all__ = ["JsonOut", "Repeat", "console", "err_console", "print_json", "table"]

console = Console()
err_console = Console(stderr=True)

JsonOut = Annotated[bool, typer.Option("--json", help="Print one JSON object.")]
"""The ``--json`` flag of every command that prints figures."""
Repeat = Annotated[int, typer.Option(min=1, max=20, help="Timed runs; the best counts.")]


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
