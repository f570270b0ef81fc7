"""What ``lookdev presets list`` writes: the presets of a library as rows or JSON.

The command and ``lookdev bench library`` both call these, so the benchmark times the
listing users get, not a copy of it.

>>> from lookdev.library import Library
>>> shown = [h for h in Library(use_env=False).entries() if h.name == "gold"]
>>> listing_text(shown, Library(use_env=False)).splitlines()[1].split()[:3]
['gold', 'disney', 'metal,']
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from typing import Any

from .index import Header
from .library import Library

__all__ = ["COLUMNS", "listing_json", "listing_text", "matching", "origin", "plain_columns", "row"]

COLUMNS = ["name", "model", "tags", "library", "description"]


def matching(headers: Sequence[Header], tags: Sequence[str], model: str | None) -> list[Header]:
    """The headers that parsed and carry every tag in ``tags`` (and ``model``, if given)."""
    return [
        h
        for h in headers
        if not h.error and all(t in h.tags for t in tags) and (model is None or h.model == model)
    ]


def origin(h: Header, lib: Library) -> str:
    """Where a preset was found: ``built-in``, or its library folder."""
    return "built-in" if h.library == lib.builtin_str else h.library


def row(h: Header, lib: Library) -> list[str]:
    """One preset's cells under :data:`COLUMNS` (``?``: a model only ``extends`` gives)."""
    return [h.name, h.model or "?", ", ".join(h.tags), origin(h, lib), h.description]


def plain_columns(columns: list[str], rows: list[list[str]]) -> str:
    """Rows as left-aligned text columns, the last one unpadded (like ``ls -l``)."""
    widths = [max(map(len, col)) for col in list(zip(columns, *rows, strict=True))[:-1]]
    line = "  ".join([*(f"{{{i}:<{w}}}" for i, w in enumerate(widths)), f"{{{len(widths)}}}"])
    return "\n".join(line.format(*r).rstrip() for r in [columns, *rows])


def listing_text(shown: Sequence[Header], lib: Library) -> str:
    """The plain listing: a header line, a row per preset, then the count."""
    rows = [row(h, lib) for h in shown]
    return plain_columns(COLUMNS, rows) + f"\n({len(rows)} presets)\n"


def listing_json(shown: Sequence[Header], lib: Library) -> str:
    """A JSON array, one preset per line: json's C encoder, as ``indent=2`` is 5x slower
    at 10^4 presets."""
    docs: list[dict[str, Any]] = [h.to_json(origin(h, lib)) for h in shown]
    lines = ",\n".join("  " + json.dumps(d) for d in docs)
    return f"[\n{lines}\n]\n" if docs else "[]\n"
