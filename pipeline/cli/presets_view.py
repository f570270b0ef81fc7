"""How ``lookdev presets`` shows presets: tables, plain columns, JSON and layer stacks."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from rich.table import Table

from lookdev.library import Material
from lookdev.library.library import set_by
from lookdev.materials.layers import children

from .common import console, table


def text_table(title: str, columns: list[str], rows: list[list[str]]) -> Table:
    """A Rich table of text columns: left-aligned, names never wrapped."""
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
    if m.params is not None:
        origin = {k: p.name for k, p in set_by(m).items()}
        values = m.params.model_dump()
        if getattr(m.params, "uses_ior", False):  # Disney: one parameter, two spellings
            values["specular"], origin["specular"] = m.params.effective_specular, "(from ior)"
        values |= {k: f"texture {t.texture}" for k, t in m.textures.items()}
        rows = [[k, value_text(v), origin.get(k, "default")] for k, v in values.items()]
        console.print(
            table(f"{m.name} ({m.model}, resolved)", ["parameter", "value", "set by"], rows)
        )
        return
    rows = [
        [
            i,
            layer.name,
            layer.material.name,
            layer.material.model,
            mask_text(layer.mask),
            layer.presence,
        ]
        for i, layer in enumerate(m.layers)
    ]
    console.print(
        table(
            f"{m.name} (layered, bottom to top)",
            ["#", "layer", "material", "model", "mask", "presence"],
            rows,
        )
    )


def value_text(v: Any) -> str:
    if isinstance(v, tuple | list):
        return "[" + ", ".join(f"{x:.4g}" for x in v) + "]"
    return f"{v:.4g}" if isinstance(v, float) else str(v)


def mask_text(mask: Any) -> str:
    """A mask tree as a call expression: ``levels(noise(scale=6.0, seed=7), low=0.42)``."""
    fields = mask.model_dump(
        mode="json", exclude_defaults=True, exclude={"kind", "input", "inputs"}
    )
    if "path" in fields:
        fields["path"] = Path(fields["path"]).name
    args = [mask_text(c) for c in children(mask)] + [f"{k}={v}" for k, v in fields.items()]
    return f"{mask.kind}({', '.join(args)})"
