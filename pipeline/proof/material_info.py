"""What a proof batch knows about each material, kept beside its proofs for the review page.

``OUT/<material>/material.json`` holds the blended material's resolved parameters
(constants, and a summary of each map), where it came from (the preset file, the files it
extends, its ``source`` citation) and the loss notes an export to USD would carry
(:func:`lookdev.pipeline.export.usd.loss_notes`, the exporter's own words). Written by
:func:`lookdev.pipeline.api.proof` after the batch, so a review page regenerated later
from the folder alone still shows them.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library import files
from lookdev.materials.errors import LookdevError

__all__ = ["FILE", "describe", "read_material_info", "write_material_info"]

FILE = "material.json"


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray | list | tuple):
        return [round(float(c), 6) for c in np.asarray(value, dtype=np.float64).ravel()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return round(value, 6)
    # a parameter that is not a number or a switch (a measured table) shows as its repr
    return value if isinstance(value, int | str | bool | None) else repr(value)


def describe(hub: Any) -> dict[str, Any]:
    """The description of a blended material the review page shows."""
    origin = getattr(hub, "origin", None)
    chain = [str(p) for p in getattr(origin, "chain", None) or []]
    maps = {}
    for name, array in sorted(hub.maps.items()):
        a = np.asarray(array, dtype=np.float64)
        maps[name] = {
            "size": [int(a.shape[1]), int(a.shape[0])],
            "min": _plain(a.reshape(-1, *a.shape[2:]).min(axis=0)),
            "max": _plain(a.reshape(-1, *a.shape[2:]).max(axis=0)),
        }
    try:
        from lookdev.pipeline.export.usd import loss_notes

        losses: dict[str, str] | None = loss_notes(hub)
        loss_error = None
    except LookdevError as exc:
        losses, loss_error = None, exc.one_line()
    source = getattr(origin, "source", None)
    return {
        "material": hub.name,
        "model": hub.preset_model,
        "description": hub.description,
        "parameters": {k: _plain(v) for k, v in sorted(hub.constants.items())},
        "maps": maps,
        "normal_map": hub.normal_map is not None,
        "live_lobes": list(hub.live_lobes),
        "source": {
            "file": None if source is None else str(source),
            "extends": chain[1:],
            "citation": getattr(origin, "citation", None),
        },
        "usd_losses": losses,
        "usd_losses_error": loss_error,
    }


def write_material_info(out: Path, hubs: list[Any]) -> list[Path]:
    """``OUT/<material>/material.json`` for each blended material; the paths written."""
    from .batch import _slug

    written = []
    for hub in hubs:
        path = Path(out) / _slug(hub.name) / FILE
        files.make_folder(path.parent)
        files.atomic_write(path, json.dumps(describe(hub), indent=2) + "\n")
        written.append(path)
    return written


def read_material_info(folder: Path) -> dict[str, Any] | None:
    """A material folder's ``material.json``; None when absent or unreadable."""
    try:
        doc = json.loads((Path(folder) / FILE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return doc if isinstance(doc, dict) else None
