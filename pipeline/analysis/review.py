"""What the review page shows, as data: every proof's frames and numbers, every material's
description; and the page's static assets.

The page (``index.html``, written by :mod:`.report`) is static: it holds this data as one
JSON block and ``review.js`` (shipped with the package beside this module, copied into
``report/``) builds the players and the comparison from it in the browser. No network,
no framework; all text enters the page through ``textContent`` (names are user input).

Per proof: the turntable's frames in order (element turn, then light turn), each with its
view-transformed PNG (``raw``) and, where the proof denoised it, the denoised PNG, and the
numbers a reviewer checks: samples per pixel, the noise estimate reached and its target,
render time, why sampling stopped, the share of the error in the hottest pixels, any
clamp. Fields a manifest does not carry are left out (null) and the page says so; older
manifests' names (``seconds``, ``noise_relative``, ``png``/``exr`` file entries) are read
too. Per material: ``material.json`` (:mod:`lookdev.pipeline.proof.material_info`).
"""

from __future__ import annotations

import json
import math
import os
import urllib.parse
from pathlib import Path
from typing import Any

from lookdev.library import files

__all__ = ["ASSETS", "FRAME_FIELDS", "copy_assets", "data_script", "page_data"]

ASSETS = ("review.js", "review.css")
"""The page's static files, shipped beside this module."""
FRAME_FIELDS = ("spp", "noise", "noise_target", "time_s", "stop", "firefly_share", "clamp")
"""Per-frame numbers the page shows (the proof manifest's fields)."""
_OLD_NAMES = {"noise": "noise_relative", "time_s": "seconds"}
CHECK_FIELDS = ("noise_raw", "converged", "residual")
"""Per-pixel sampling's numbers (``residual``: the checked denoiser's, under ``denoise``)."""


def copy_assets(out_dir: Path) -> list[Path]:
    """Copy :data:`ASSETS` into ``out_dir`` (the batch's ``report/``); their paths."""
    here = Path(__file__).parent
    return [
        files.atomic_write(out_dir / name, (here / name).read_text(encoding="utf-8"))
        for name in ASSETS
    ]


def url(path: Path, base: Path) -> str:
    """``path`` relative to ``base`` as a URL path (quoted: ``#``, ``?`` and spaces)."""
    return urllib.parse.quote(Path(os.path.relpath(path, base)).as_posix())


def _name(value: Any) -> str | None:
    """A file name from a manifest value: a string, or a file entry ``{"file": …}``."""
    value = value.get("file") if isinstance(value, dict) else value
    return value if isinstance(value, str) else None


def _image(folder: Path, info: dict[str, Any], roles: tuple[str, ...]) -> Path | None:
    """The first of ``roles`` that names a file on disk, under ``images`` or at the top."""
    images = info.get("images") if isinstance(info.get("images"), dict) else {}
    for role in roles:
        for source in (images, info):
            name = _name(source.get(role))
            if name is not None:
                path = Path(name) if Path(name).is_absolute() else folder / name
                if path.is_file():
                    return path
    return None


def _frame(
    folder: Path, info: dict[str, Any], proof: dict[str, Any], web: Any, base: Path
) -> dict[str, Any] | None:
    raw = _image(folder, info, ("png", "path", "file", "raw", "exr"))
    if raw is None:
        return None
    denoised = _image(folder, info, ("denoised_png", "denoised"))
    settings = proof.get("settings") if isinstance(proof.get("settings"), dict) else {}
    record: dict[str, Any] = {
        "index": info.get("index"),
        "kind": info.get("kind"),
        "angle": info.get("angle"),
        "label": _label(info, raw),
        "raw": url(web(raw), base),
        "denoised": None if denoised is None else url(web(denoised), base),
    }
    for key in FRAME_FIELDS:
        value = info.get(key, info.get(_OLD_NAMES.get(key, ""), None))
        if value is None and key in ("spp", "clamp"):
            value = proof.get(key, settings.get(key))
        if value is None and key == "noise_target":
            value = settings.get("noise")
        if isinstance(value, float) and not math.isfinite(value):
            value = None  # JSON has no NaN or infinity
        record[key] = value if isinstance(value, int | float | str) else None
    _checks(folder, info, record, web, base)
    return record


def _checks(folder: Path, info: dict, record: dict, web: Any, base: Path) -> None:
    """:data:`CHECK_FIELDS` and the difference view (denoised − raw) into ``record``."""
    checked = info.get("denoise") if isinstance(info.get("denoise"), dict) else {}
    for key in CHECK_FIELDS:
        value = info.get(key, checked.get(key))
        ok = isinstance(value, int | float) and math.isfinite(value)
        record[key] = value if ok else None
    difference = _image(folder, info, ("difference_png",))
    record["difference"] = None if difference is None else url(web(difference), base)


def _label(info: dict[str, Any], path: Path) -> str:
    if "label" in info:
        return str(info["label"])
    if "kind" in info and "angle" in info:
        try:
            return f"{info['kind']} {float(info['angle']):.0f}°"
        except (TypeError, ValueError):
            pass
    return path.stem


def proof_data(entry: Any, web: Any, base: Path) -> dict[str, Any]:
    """One proof (a :class:`.report.Entry`) as the page's record."""
    data, folder = entry.data, entry.path.parent
    listed = next((v for k, v in data.items() if "frame" in k and isinstance(v, list)), [])
    frames = [
        _frame(folder, item if isinstance(item, dict) else {"path": item}, data, web, base)
        for item in listed
    ]
    frames = [f for f in frames if f is not None]
    if not frames:  # no manifest frames: the images beside it (report._frames' fallback)
        frames = [
            _frame(folder, {"path": str(p), "label": c}, data, web, base) for p, c in entry.frames
        ]
    settings = data.get("settings") if isinstance(data.get("settings"), dict) else {}
    return {
        "id": f"{entry.material}/{entry.ibl}",
        "material": entry.material,
        "ibl": entry.ibl,
        "filter": data.get("filter", settings.get("pixel_filter")),
        "rig": (data.get("rig") or {}).get("rig") if isinstance(data.get("rig"), dict) else None,
        "variant": data.get("variant"),
        "orientation": data.get("ibl_orientation"),
        "size": _size(settings.get("resolution")),
        "frames": frames,
    }


def _size(value: Any) -> list[int] | None:
    """A frame's [width, height] from the proof's settings (the page reserves the space
    before the frame is fetched), or None."""
    if isinstance(value, list | tuple) and len(value) == 2:
        if all(isinstance(v, int) and v > 0 for v in value):
            return [int(v) for v in value]
    return None


def page_data(
    batch_dir: Path,
    entries: list[Any],
    web: Any,
    plots: dict[str, dict[str, Path]],
    hubs: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Everything the page's script shows; image paths as URLs relative to ``batch_dir``.

    ``web(path)`` turns a frame file into a browser-viewable image (EXR → PNG thumbnail).
    A material's description is its ``material.json``, else that of its blended material
    in ``hubs`` when given, else None (the page says it was not recorded).
    """
    from lookdev.pipeline.proof.material_info import describe, read_material_info

    proofs = [proof_data(e, web, batch_dir) for e in entries]
    materials: dict[str, Any] = {}
    for e in entries:
        if e.material not in materials:
            info = read_material_info(e.path.parent.parent)
            if info is None and e.material in (hubs or {}):
                info = describe(hubs[e.material])
            materials[e.material] = info
    return {
        "batch": batch_dir.name,
        "proofs": proofs,
        "materials": materials,
        "ibls": list(dict.fromkeys(e.ibl for e in entries)),
        "plots": {
            m: {v: url(p, batch_dir) for v, p in views.items()} for m, views in plots.items()
        },
    }


def data_script(data: dict[str, Any]) -> str:
    """The data as a ``<script type="application/json">`` element, safe in HTML: ``<``,
    ``>`` and ``&`` are JSON escapes, so no name can close the element."""
    text = json.dumps(data, ensure_ascii=False, allow_nan=False)
    for ch, esc in (("<", "\\u003c"), (">", "\\u003e"), ("&", "\\u0026")):
        text = text.replace(ch, esc)
    text = text.replace("\u2028", "\\u2028").replace("\u2029", "\\u2029")
    return f'<script type="application/json" id="lookdev-data">{text}</script>'
