"""Pieces every command shares: consoles, JSON output, ``key=value`` parsing."""

from __future__ import annotations

import json
import sys
from typing import TYPE_CHECKING, Annotated, Any

import typer

if TYPE_CHECKING:
    from rich.console import Console
    from rich.table import Table

__all__ = ["JsonOut", "Repeat", "console", "err_console", "print_json", "table"]


class _OnFirstUse:
    """A Rich ``Console`` made when a command first prints through it: a command whose
    output is JSON or plain text (``presets show gold > mine.toml``) imports no Rich,
    which costs a command line ≈ 0.02 CPU s."""

    def __init__(self, **options: Any) -> None:
        self._options = options
        self._console: Console | None = None

    def made(self) -> Console:
        """The Console itself, made on the first call."""
        if self._console is None:
            from rich.console import Console

            self._console = Console(**self._options)
        return self._console

    def __getattr__(self, name: str) -> Any:
        return getattr(self.made(), name)

    # the dunders Console defines: Python looks them up on the type, not through __getattr__
    def __enter__(self) -> Console:
        return self.made().__enter__()

    def __exit__(self, *exc: Any) -> None:
        self.made().__exit__(*exc)

    def __repr__(self) -> str:
        return repr(self.made())


console: Console = _OnFirstUse()  # type: ignore[assignment]
err_console: Console = _OnFirstUse(stderr=True)  # type: ignore[assignment]

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
    from rich.table import Table

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
