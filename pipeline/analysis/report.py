"""The review page of a proof batch: ``index.html``, static, opens from disk, no network.

:func:`write_report` reads every ``manifest.json`` under a batch folder (one per material
× IBL, written by :mod:`lookdev.pipeline.proof`) and writes ``index.html`` beside them:
a raw/denoised toggle, a comparison (all materials under one IBL, or one material under
every IBL, side by side and synchronised), then per material its resolved parameters,
source and USD loss notes, its BRDF-explorer plots (slice, albedo, polar, lit sphere) and
a turntable player per IBL (play, pause, scrub through the element and the light turn,
each frame's spp, noise, time); then the time/noise table and the contact sheets. The
players are ``review.js`` (package data, copied into ``report/``) reading the page's JSON
(:mod:`.review`).

Everything the page shows lives under the batch folder and is linked relatively, so the
folder can be moved, zipped or served as it is. Browsers cannot show EXR, so EXR frames
get PNG thumbnails in ``report/`` through the OCIO view (:mod:`lookdev.pipeline.proof.
tonemap`); plots go there too. Images are only linked once
they exist on disk: the page has no broken images by construction, and the test opens it
in headless Chromium, plays, scrubs, toggles and compares to make sure.
"""

from __future__ import annotations

import html
import json
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library import files
from lookdev.materials.errors import LookdevError

from . import review

__all__ = [
    "Entry",
    "NOT_IN_TABLE",
    "PLOT_VIEWS",
    "REPORT_DIR",
    "ReportError",
    "WEB_IMAGES",
    "contact_sheets",
    "material_plots",
    "read_manifests",
    "render_page",
    "summary",
    "table_rows",
    "web_image",
    "write_report",
]

REPORT_DIR = "report"
WEB_IMAGES = (".png", ".jpg", ".jpeg", ".gif", ".webp", ".svg")
PLOT_VIEWS = ("slice", "albedo", "polar", "sphere")
# Manifest fields that identify files rather than describe the proof.
NOT_IN_TABLE = frozenset(
    {"key", "sha256", "size", "file", "version", "contact_sheet", "rig", "ibl_orientation"}
)


class ReportError(LookdevError):
    """A batch folder cannot be turned into a review page."""


@dataclass
class Entry:
    """One manifest: a material under one IBL."""

    path: Path
    data: dict[str, Any]
    material: str
    ibl: str
    frames: list[tuple[Path, str]] = field(default_factory=list)  # (file, caption)


# -- reading a batch -----------------------------------------------------------------
def read_manifests(batch_dir: Path) -> list[Entry]:
    """Every ``manifest.json`` under ``batch_dir`` (recursively), sorted by material, IBL."""
    entries = []
    for path in sorted(batch_dir.rglob("manifest.json")):
        try:
            data = json.loads(path.read_text())
        except (OSError, json.JSONDecodeError) as exc:
            raise ReportError(f"unreadable manifest: {exc}", where=str(path)) from None
        if not isinstance(data, dict):
            raise ReportError("a manifest must be a JSON object", where=str(path))
        if "proofs" in data:  # the batch's own manifest: its jobs have their own
            continue
        material = str(data.get("material") or data.get("name") or path.parent.parent.name)
        ibl = str(data.get("ibl") or path.parent.name)
        entries.append(Entry(path, data, material, ibl, _frames(path.parent, data)))
    return sorted(entries, key=lambda e: (e.material, e.ibl))


def _frame_lists(data: dict[str, Any]) -> list[list[Any]]:
    """Lists under keys naming frames (``frames``, ``element_frames`` …)."""
    return [v for k, v in data.items() if "frame" in k and isinstance(v, list)]


def _frames(folder: Path, data: dict[str, Any]) -> list[tuple[Path, str]]:
    """(file, caption) of the frames a manifest lists, else of the images beside it.

    A listed frame is a path, or an object naming its file in ``images`` (``png`` or
    ``raw``, as :mod:`lookdev.pipeline.proof.batch` writes them; the PNG is preferred, it
    went through the proof's view transform), as ``path``, ``file``, or a file entry
    ``png``/``exr`` (``{"file": …}``); for
    the caption, ``label`` or ``kind`` and ``angle``.
    """
    listed = []
    for frames in _frame_lists(data):
        for item in frames:
            info = item if isinstance(item, dict) else {}
            p = _frame_file(info) if info else item
            if isinstance(p, str):
                path = Path(p) if Path(p).is_absolute() else folder / p
                listed.append((path, _caption(info, path)))
    if not listed:
        images = (p for p in folder.iterdir() if p.suffix.lower() in (*WEB_IMAGES, ".exr"))
        listed = [(p, p.stem) for p in sorted(images)]
    return [(p, c) for p, c in listed if p.is_file() and "contact" not in p.name]


def _frame_file(info: dict[str, Any]) -> str | None:
    images = info.get("images")
    if isinstance(images, dict):  # a proof frame: its view-transformed PNG, else its EXR
        for role in ("png", "raw"):
            if isinstance(images.get(role), str):
                return images[role]
    for key in ("path", "file", "png", "exr"):
        value = info.get(key)
        value = value.get("file") if isinstance(value, dict) else value
        if isinstance(value, str):
            return value
    return None


def _caption(info: dict[str, Any], path: Path) -> str:
    if "label" in info:
        return str(info["label"])
    if "kind" in info and "angle" in info:
        return f"{info['kind']} {float(info['angle']):.0f}°"
    return path.stem


def contact_sheets(batch_dir: Path) -> list[Path]:
    """Images named ``*contact*`` anywhere in the batch, outside ``report/``."""
    return sorted(
        p
        for p in batch_dir.rglob("*contact*")
        if p.suffix.lower() in (*WEB_IMAGES, ".exr")
        and REPORT_DIR not in p.relative_to(batch_dir).parts
    )


# -- the time/noise table ------------------------------------------------------------
def table_rows(entries: Iterable[Entry]) -> tuple[list[str], list[list[str]]]:
    """Columns and rows: material, IBL, then every scalar field the manifests carry."""
    entries = list(entries)
    keys: dict[str, None] = {}
    for e in entries:
        for k in _scalars(e.data):
            if k not in ("material", "name", "ibl"):
                keys.setdefault(k)
    columns = ["material", "ibl", *keys]
    rows = []
    for e in entries:
        flat = _scalars(e.data)
        rows.append([e.material, e.ibl, *(_fmt(flat.get(k)) for k in keys)])
    return columns, rows


def _scalars(data: dict[str, Any], prefix: str = "") -> dict[str, Any]:
    """Numbers, strings and booleans of a manifest, nested keys joined with dots.

    Per-frame numbers are summarised: times (keys with ``seconds`` or ``time``) summed,
    everything else (noise …) averaged, e.g. ``frames.time_s (sum)``.
    """
    out: dict[str, Any] = {}
    for k, v in data.items():
        name = f"{prefix}{k}"
        if k in NOT_IN_TABLE:
            continue
        if isinstance(v, dict):
            out.update(_scalars(v, f"{name}."))
        elif "frame" in k and isinstance(v, list):
            out.update(_frame_summary(v, name))
        elif isinstance(v, bool | int | float) or (isinstance(v, str) and len(v) < 60):
            out[name] = v
    return out


def _frame_summary(frames: list[Any], name: str) -> dict[str, float]:
    numbers: dict[str, list[float]] = {}
    for item in frames:
        for k, v in item.items() if isinstance(item, dict) else ():
            if (
                isinstance(v, int | float)
                and not isinstance(v, bool)
                and k not in ("index", "angle")
            ):
                numbers.setdefault(k, []).append(float(v))
    out: dict[str, Any] = {f"{name}": len(frames)} if frames else {}
    for k, vs in numbers.items():
        timed = "seconds" in k or "time" in k
        out[f"{name}.{k} ({'sum' if timed else 'mean'})"] = sum(vs) if timed else sum(vs) / len(vs)
    return out


def _fmt(v: Any) -> str:
    if v is None:
        return ""
    if isinstance(v, float):
        return f"{v:.4g}"
    return str(v)


# -- images ---------------------------------------------------------------------------
def web_image(src: Path, out_dir: Path, exposure: float = 0.0) -> Path:
    """A browser-viewable version of ``src``: itself, or a PNG of an EXR through the view."""
    if src.suffix.lower() in WEB_IMAGES:
        return src
    import OpenImageIO as oiio

    from lookdev.pipeline.proof.tonemap import to_8bit, view

    try:  # named after its place in the batch, so material/ibl/frame_000 stay apart
        parts = src.relative_to(out_dir.parent).with_suffix("").parts
    except ValueError:
        parts = src.with_suffix("").parts[-3:]
    dst = out_dir / "frames" / ("_".join(parts) + ".png")
    if dst.exists() and dst.stat().st_mtime >= src.stat().st_mtime:
        return dst
    from lookdev.pipeline.proof.contact import ProofImageError, read_rgb

    try:
        rgb = read_rgb(src)
    except ProofImageError as exc:
        raise ReportError(f"cannot read frame: {exc.message}", where=str(src)) from None
    img = to_8bit(view(rgb, exposure))
    files.make_folder(dst.parent)
    out = oiio.ImageBuf(oiio.ImageSpec(img.shape[1], img.shape[0], 3, oiio.UINT8))
    out.set_pixels(oiio.ROI(), img)
    with files.atomic_path(dst) as tmp:
        if not out.write(str(tmp)):
            raise ReportError(f"cannot write thumbnail: {out.geterror()}", where=str(dst))
    return dst


def material_plots(
    names: Iterable[str], hubs: Mapping[str, Any], out_dir: Path, ibl: str | None = None
) -> dict:
    """``{material: {view: png}}``; the sphere also under ``ibl`` (one of the batch's).

    ``hubs`` are the blended materials by name; a material of the batch not among them
    (proofed in an earlier run) keeps the plots that run drew, if they are still there;
    its frames and numbers are shown either way.
    """
    from .plots import figure, load_environment, save_figure

    environment = _environment(ibl, load_environment)
    result: dict[str, dict[str, Path]] = {}
    for name in names:
        if name not in hubs:
            # Proofed in an earlier run into this folder: keep the plots it drew.
            kept = {v: out_dir / "plots" / f"{_slug(name)}_{v}.png" for v in PLOT_VIEWS}
            if all(p.is_file() for p in kept.values()):
                result[name] = kept
            continue
        result[name] = {
            view: save_figure(
                figure(
                    [hubs[name]],
                    view,
                    resolution=64,
                    environment=environment if view == "sphere" else None,
                    ibl_name=ibl or "",
                ),
                out_dir / "plots" / f"{_slug(name)}_{view}.png",
            )
            for view in PLOT_VIEWS
        }
    return result


def _slug(name: str) -> str:
    """A file-name-safe form of a material name.

    >>> _slug("rusty iron/v2")
    'rusty_iron_v2'
    """
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "unnamed"


def _environment(ibl: str | None, load: Any) -> np.ndarray | None:
    if ibl is None:
        return None
    try:
        return load(ibl, 128)
    except LookdevError:
        return None


# -- the page -------------------------------------------------------------------------
def _img(src: Path, base: Path, alt: str, cls: str = "") -> str:
    c = f' class="{cls}"' if cls else ""
    return f'<img{c} src="{html.escape(review.url(src, base))}" alt="{html.escape(alt)}">'


def render_page(
    batch_dir: Path,
    entries: list[Entry],
    sheets: list[Path],
    plots: dict,
    hubs: Mapping[str, Any] | None = None,
) -> str:
    """The HTML text of the review page: a sticky raw/denoised toggle, the comparison
    and a turntable player per proof (built by ``report/review.js`` from the page's JSON,
    :mod:`.review`), then the time/noise table and the contact sheets."""
    out = batch_dir / REPORT_DIR
    esc = html.escape
    materials = list(dict.fromkeys(e.material for e in entries))
    data = review.page_data(
        batch_dir, entries, lambda p: web_image(p, out), plots, dict(hubs or {})
    )
    parts = [
        "<!doctype html><html lang=en><head><meta charset=utf-8>",
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>lookdev proof: {esc(batch_dir.name)}</title>",
        f'<link rel="stylesheet" href="{REPORT_DIR}/review.css"></head><body>',
        f"<h1>lookdev proof — {esc(batch_dir.name)}</h1>",
        f"<p>{esc(summary(materials, data['ibls'], len(entries)))}</p>",
        "<noscript><p>The players and the comparison need JavaScript; the table and the "
        "contact sheets below do not.</p></noscript>",
        '<main id="review"></main>',
    ]
    columns, rows = table_rows(entries)
    parts.append("<h2>Time and noise</h2><table><thead><tr>")
    parts += [f"<th>{esc(c)}</th>" for c in columns]
    parts.append("</tr></thead><tbody>")
    for row in rows:
        parts.append("<tr>" + "".join(f"<td>{esc(v)}</td>" for v in row) + "</tr>")
    parts.append("</tbody></table>")
    if sheets:
        parts.append("<h2>Contact sheets</h2>")
        for s in sheets:
            parts.append(
                f"<figure>{_img(web_image(s, out), batch_dir, s.stem, 'sheet')}"
                f"<figcaption>{esc(s.relative_to(batch_dir).as_posix())}</figcaption></figure>"
            )
    parts.append(review.data_script(data))
    parts.append(f'<script src="{REPORT_DIR}/review.js"></script>')
    parts.append("</body></html>")
    return "\n".join(parts)


def _count(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if n == 1 else "s")


def summary(materials: list[str], ibls: list[str], proofs: int) -> str:
    """The page's first line: what was proofed under what, by name.

    >>> summary(["gold", "jade"], ["studio", "sky"], 4)
    '2 materials, each under 2 IBLs (4 proofs). Materials: gold, jade. IBLs: studio, sky.'
    >>> summary(["gold"], ["studio", "sky"], 1)
    '1 proof of 1 material under 2 IBLs. Materials: gold. IBLs: studio, sky.'
    """
    if proofs == len(materials) * len(ibls):
        head = f"{_count(len(materials), 'material')}, each under {_count(len(ibls), 'IBL')}"
        head += f" ({_count(proofs, 'proof')})"
    else:  # a batch re-proofed in part: not every material under every IBL
        head = f"{_count(proofs, 'proof')} of {_count(len(materials), 'material')} under "
        head += _count(len(ibls), "IBL")
    return f"{head}. Materials: {', '.join(materials)}. IBLs: {', '.join(ibls)}."


def write_report(
    batch_dir: str | Path, *, materials: Mapping[str, Any] | None = None, plots: bool = True
) -> Path:
    """Write ``batch_dir/index.html`` (and its thumbnails and plots); return its path.

    ``materials`` are blended materials by name, plotted where the batch holds them.
    """
    batch_dir = Path(batch_dir).resolve()
    if not batch_dir.is_dir():
        raise ReportError("no such batch folder", where=str(batch_dir))
    entries = read_manifests(batch_dir)
    if not entries:
        raise ReportError("no manifest.json found: is this a proof batch?", where=str(batch_dir))
    out = batch_dir / REPORT_DIR
    out.mkdir(exist_ok=True)
    names = dict.fromkeys(e.material for e in entries)
    made = material_plots(names, materials or {}, out, entries[0].ibl) if plots else {}
    review.copy_assets(out)
    page = render_page(batch_dir, entries, contact_sheets(batch_dir), made, materials)
    index = batch_dir / "index.html"
    return files.atomic_write(index, page)
