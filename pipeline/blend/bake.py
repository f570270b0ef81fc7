"""Write a :class:`~.engine.BlendedMaterial` to disk: one EXR per map, one JSON sidecar.

Layout for a material ``NAME`` in ``out_dir``::

    NAME.json              constants, map files, resolution, decisions (the sidecar), and
                           the colour space of each (the working space; Raw for data)
    NAME_roughness.exr     one file per varying parameter (float32, ZIP), "Y" or "R,G,B"
    NAME_normal_map.exr    unit normals encoded (n + 1)/2, the usual normal-map encoding

Files are written the way images are viewed, top row first: the top row of each file is
v = 1 (the UsdUVTexture and OpenImageIO convention), so UV (0, 0) is the bottom-left.
Reading one back with :func:`.resample.read_channels` gives the map in UV order again.

Nothing is half-written: every file goes to a temporary beside its destination first
(:class:`lookdev.library.files.Transaction`, the one write path) and is renamed into place
only when all were written; the sidecar is renamed last, so a
sidecar on disk always describes files that are complete. Map files listed by an older
sidecar of the same material and not written now are removed (they no longer vary).
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library import files
from lookdev.materials import colour
from lookdev.pipeline.exr import colour_space_of, write_exr

from .errors import BlendError
from .result import BlendedMaterial

__all__ = ["SCHEMA", "bake", "sidecar_dict"]

SCHEMA = "lookdev.blend/1"


def bake(
    blended: BlendedMaterial,
    out_dir: str | Path,
    *,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Path]:
    """Write the maps and the sidecar; returns ``{map name: path, "sidecar": path}``."""
    out_dir = Path(out_dir)
    created: list[Path] = []
    files.make_folder(out_dir, created)
    arrays = blended.arrays
    names = {name: f"{blended.name}_{name}.exr" for name in arrays}
    sidecar = out_dir / f"{blended.name}.json"
    stale = _listed_files(sidecar) - set(names.values())
    with files.Transaction() as staged:  # renamed into place together, the sidecar last
        staged.created += created  # a failed first bake leaves no empty folder
        for i, (name, array) in enumerate(arrays.items()):
            final = out_dir / names[name]
            space = colour_space_of(array, data=name.endswith("normal_map"))
            _write_exr(staged.temp_for(final), _encode(name, array), blended.name, final, space)
            if progress is not None:
                progress(i + 1, len(arrays) + 1)
        text = json.dumps(sidecar_dict(blended, names), indent=2)
        staged.temp_for(sidecar).write_text(text, encoding="utf-8")
    for name in stale:
        files.remove_quietly(out_dir / name)
    if progress is not None:
        progress(len(arrays) + 1, len(arrays) + 1)
    return {**{name: out_dir / f for name, f in names.items()}, "sidecar": sidecar}


def sidecar_dict(blended: BlendedMaterial, files: dict[str, str]) -> dict[str, Any]:
    """The JSON sidecar: everything a reader needs besides the pixels."""
    width, height = blended.resolution
    return {
        "schema": SCHEMA,
        "name": blended.name,
        "model": blended.model,
        "representation": blended.representation,
        "resolution": [width, height],
        "orientation": "top row of each file is v = 1; UV (0, 0) is the bottom-left texel",
        # the OCIO name of the space colour constants and RGB colour maps are in
        "colour_space": colour.working_space(),
        "uv_extent": list(blended.uv_extent),
        "udim_tiles": list(blended.tiles),
        "textures": {k: t.model_dump(mode="json") for k, t in blended.textures.items()},
        "constants": {k: _plain(v) for k, v in blended.constants.items()},
        "maps": {
            name: {
                "file": files[name],
                "colour_space": colour_space_of(array, data=name.endswith("normal_map")),
                "channels": ["R", "G", "B"] if array.ndim == 3 else ["Y"],
                "encoding": "(n + 1) / 2" if name.endswith("normal_map") else "linear",
            }
            for name, array in blended.arrays.items()
        },
        "layers": [
            {"layer": d.layer, "kept": d.kept, "reason": d.reason} for d in blended.decisions
        ],
    }


def _encode(name: str, array: np.ndarray) -> np.ndarray:
    """(H, W, C) in file order (top row v = 1); normals in the (n + 1)/2 encoding."""
    if name.endswith("normal_map"):
        array = 0.5 * array + 0.5
    if array.ndim == 2:
        array = array[..., None]  # OpenImageIO reads a 2-D array as the wrong shape
    return np.ascontiguousarray(array[::-1], dtype=np.float32)


def _write_exr(path: Path, pixels: np.ndarray, where: str, final: Path, space: str) -> None:
    try:
        write_exr(path, pixels, space, shown=final)
    except files.WriteError as exc:
        raise BlendError(exc.message, where=where) from None


def _listed_files(sidecar: Path) -> set[str]:
    """Map files named by an existing sidecar (empty if there is none or it is not ours)."""
    try:
        data = json.loads(sidecar.read_text())
        return {m["file"] for m in data["maps"].values() if "/" not in m["file"]}
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return set()


def _plain(value: Any) -> Any:
    if isinstance(value, tuple | list | np.ndarray):
        return [float(x) for x in np.asarray(value).ravel()]
    return value.item() if isinstance(value, np.generic) else value
