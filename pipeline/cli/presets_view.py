"""How ``lookdev presets`` shows presets: tables, plain columns, JSON and layer stacks."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from .common import console, table

if TYPE_CHECKING:  # listing presets reads headers only: no materials imported for it
    from rich.table import Table

    from lookdev.library import Material

__all__ = ["material_json", "print_resolved", "text_table"]


def text_table(title: str, columns: list[str], rows: list[list[str]]) -> Table:
    """A Rich table of text columns: left-aligned, names never wrapped."""
    from rich.table import Table

    t = Table(title=title, title_justify="left")
    for c in columns:
        t.add_column(c, no_wrap=c in ("name", "model"), ratio={"tags": 1, "description": 2}.get(c))
    for r in rows:
        t.add_row(*r, style="dim" if r[1] == "?" else None)
    return t


def material_json(m: Material) -> dict[str, Any]:
    doc = m.model_dump(mode="json", exclude={"layers", "params"})
    doc["params"] = m.params.model_dump(mode="json") if m.params is not None else None
    doc["layers"] = [
        {
            **layer.model_dump(mode="json", exclude={"material"}),
            "material": material_json(layer.material),
        }
        for layer in m.layers
    ]
    return doc


def print_resolved(m: Material) -> None:
    from lookdev.library.display import layer_rows, parameter_rows

    if m.params is not None:
        rows = [list(r) for r in parameter_rows(m)]
        console.print(
            table(f"{m.name} ({m.model}, resolved)", ["parameter", "value", "set by"], rows)
        )
        return
    console.print(
        table(
            f"{m.name} (layered, bottom to top)",
            ["#", "layer", "material", "model", "mask", "presence"],
            [list(r) for r in layer_rows(m)],
        )
    )
