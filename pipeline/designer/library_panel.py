"""The library panel: every preset on the library path, with a cached thumbnail.

A thumbnail is the BRDF explorer's lit sphere under the studio IBL
(:func:`lookdev.pipeline.analysis.sphere.ibl_sphere`, the numpy backend of the model,
MIS of BSDF and environment samples) through the proofs' view transform. It is cached as
a PNG under the session's cache folder by a hash of every file the preset resolves
through (its ``extends`` chain and layers), so editing a preset, or its parent,
refreshes it; an unchanged library costs one ``stat`` and hash per preset.
"""

from __future__ import annotations

import hashlib
import threading
from pathlib import Path
from typing import Any

from lookdev.library import Library

__all__ = ["THUMB_PX", "entries", "thumbnail"]

THUMB_PX = 64
THUMB_SPP = 12
THUMB_IBL = "studio"
_lock = threading.Lock()
_env: dict[str, Any] = {}


def entries(library: Library) -> list[dict[str, Any]]:
    """Every preset name on the path with its model, tags, description and file."""
    return [
        {
            "name": h.name,
            "model": h.model,
            "tags": list(h.tags or []),
            "description": h.description or "",
            "file": h.file,
            "error": h.error,
            "builtin": library.builtin_str is not None and h.library == library.builtin_str,
        }
        for h in library.entries()
    ]


def _key(material: Any) -> str:
    digest = hashlib.sha256(material.model_dump_json().encode())
    for path in _files(material):
        try:
            digest.update(path.read_bytes())
        except OSError:
            digest.update(b"missing")
    return digest.hexdigest()[:24]


def _files(material: Any) -> list[Path]:
    out = list(material.chain)
    for layer in material.layers:
        out += _files(layer.material)
    return out


def thumbnail(library: Library, name: str, cache: Path) -> Path:
    """The PNG thumbnail of preset ``name``, made if missing or stale."""
    import lookdev

    material = library.load(name)
    path = cache / f"{name}-{_key(material)}.png"
    if path.is_file():
        return path
    with _lock:  # one at a time: numpy renders use every core already
        if path.is_file():
            return path
        image = _render(lookdev.hub(material, 64))
        cache.mkdir(parents=True, exist_ok=True)
        for stale in cache.glob(f"{name}-*.png"):
            stale.unlink(missing_ok=True)
        from lookdev.library import files

        from .render import encode

        files.atomic_write(path, encode(image, "PNG"))
    return path


def _render(hub: Any):
    from lookdev.pipeline.analysis import plots
    from lookdev.pipeline.analysis.sphere import ibl_sphere
    from lookdev.pipeline.proof import tonemap

    if "pixels" not in _env:
        _env["pixels"] = plots.load_environment(THUMB_IBL, 128)
    radiance = ibl_sphere(  # as the BRDF explorer's sphere view draws it
        hub.bsdf_model,
        hub.centre_params,
        _env["pixels"],
        resolution=THUMB_PX,
        spp=THUMB_SPP,
        maps=hub.maps or None,
    )
    return tonemap.to_8bit(tonemap.view(radiance))
