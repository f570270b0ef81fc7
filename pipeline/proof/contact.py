"""Labelled contact sheets of proof frames (OpenImageIO).

A sheet is a title bar, then the frames in a grid, each with its label underneath.
Text is drawn with OpenImageIO's ``ImageBufAlgo.render_text`` (FreeType, the DroidSans
fonts OpenImageIO ships with); where no font can be found, a built-in 3×5 pixel font
still labels every frame, so a sheet is never unlabelled.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library import files
from lookdev.library.files import quiet_c_stderr
from lookdev.materials.errors import LookdevError

__all__ = [
    "BACKGROUND",
    "EXR_COMPRESSION",
    "GAP",
    "PNG_COMPRESSION",
    "ProofImageError",
    "TEXT",
    "bitmap_text",
    "contact_sheet",
    "draw_text",
    "file_entry",
    "fitting_size",
    "read_rgb",
    "write_exr",
    "write_png",
]

BACKGROUND = 0.08
TEXT = (0.92, 0.92, 0.92)
GAP = 4
EXR_COMPRESSION = "zip:1"
"""Proof frames' EXR compression: ZIP (lossless) at zlib level 1, not OpenEXR's default 4:
the same size within 0.1 % on rendered noise, ≈ 20 % less CPU a frame
(docs/measurements/proof-cost.md)."""
PNG_COMPRESSION = {"png:compressionLevel": 1, "png:filter": 8}
"""How proof PNGs (frames, sheets) are compressed: zlib level 1, rows unfiltered (libpng's
``PNG_FILTER_NONE`` = 8). Lossless at any setting: only the bytes change, not the pixels.
Measured on 480×240 proof frames and their sheets, against OpenImageIO's default (level 6,
every filter tried per row): ≈ 2.3× less CPU a frame and ≈ 2.4× a sheet, and files no
larger (rendered noise defeats the row filters) — docs/measurements/proof-cost.md."""

# 3×5 glyphs, rows top to bottom, '#' = ink. Lower case is drawn as upper case.
_GLYPHS = {
    "A": ".#.#.#####.##.#",
    "B": "##.#.###.#.###.",
    "C": ".###..#..#...##",
    "D": "##.#.##.##.###.",
    "E": "####..###..####",
    "F": "####..###..#...",
    "G": ".###..#.##.#.##",
    "H": "#.##.#####.##.#",
    "I": "###.#..#..#.###",
    "J": "..#..#..##.#.#.",
    "K": "#.##.###.#.##.#",
    "L": "#..#..#..#..###",
    "M": "#.#####.##.##.#",
    "N": "##.#.##.##.##.#",
    "O": ".#.#.##.##.#.#.",
    "P": "##.#.###.#..#..",
    "Q": ".#.#.##.##.#..#",
    "R": "##.#.###.#.##.#",
    "S": ".###...#...###.",
    "T": "###.#..#..#..#.",
    "U": "#.##.##.##.####",
    "V": "#.##.##.##.#.#.",
    "W": "#.##.##.#####.#",
    "X": "#.##.#.#.#.##.#",
    "Y": "#.##.#.#..#..#.",
    "Z": "###..#.#.#..###",
    "0": "####.##.##.####",
    "1": ".#.##..#..#.###",
    "2": "##...#.#.#..###",
    "3": "##...#.#...###.",
    "4": "#.##.####..#..#",
    "5": "####..##...###.",
    "6": ".###..####.####",
    "7": "###..#..#.#..#.",
    "8": "####.#####.####",
    "9": "####.####..###.",
    ".": "............#..",
    ",": "..........#.#..",
    "-": "......###......",
    "_": "............###",
    "/": "..#..#.#.#..#..",
    ":": "....#.....#....",
    "×": "...#.#.#.#.#...",
    "°": "###.#.###......",
    "(": ".#.#..#..#...#.",
    ")": ".#...#..#..#.#.",
    "+": "....#.###.#....",
    " ": "...............",
}


class ProofImageError(LookdevError):
    """A proof image (frame, sheet) cannot be assembled or written."""


def _glyph(ch: str) -> np.ndarray:
    rows = _GLYPHS.get(ch.upper(), _GLYPHS["-"])
    return np.array([c == "#" for c in rows], dtype=bool).reshape(5, 3)


def bitmap_text(text: str, scale: int) -> np.ndarray:
    """A boolean ink mask (5·scale, 4·scale·len) of ``text`` in the built-in 3×5 font.

    >>> bitmap_text("A1", 1).shape
    (5, 8)
    """
    cells = [np.pad(_glyph(ch), ((0, 0), (0, 1))) for ch in text] or [np.zeros((5, 4), bool)]
    ink = np.concatenate(cells, axis=1)
    return np.kron(ink, np.ones((scale, scale), dtype=bool))


def draw_text(canvas: np.ndarray, x: int, y: int, text: str, size: int) -> None:
    """Draw ``text`` with its baseline at (x, y) into a float (H, W, 3) canvas, in place.

    FreeType through OpenImageIO when a font is found, else the built-in bitmap font.
    """
    import OpenImageIO as oiio

    # only the box the text can touch goes through OIIO: the whole sheet per label cost a
    # second per proof, a strip of the sheet's width ≈ 13 ms a label, the box ≈ 1 ms
    top, bottom, left, right = _text_box(oiio, canvas.shape, x, y, text, size)
    box = canvas[top:bottom, left:right]
    buf = oiio.ImageBuf(np.ascontiguousarray(box, dtype=np.float32))
    if oiio.ImageBufAlgo.render_text(buf, x - left, y - top, text, size, "DroidSans", TEXT):
        box[...] = buf.get_pixels(oiio.FLOAT)
        return
    scale = max(1, size // 6)
    ink = bitmap_text(text, scale)
    top = max(0, y - ink.shape[0])
    region = canvas[top : top + ink.shape[0], x : x + ink.shape[1]]
    region[ink[: region.shape[0], : region.shape[1]]] = TEXT


def _text_box(oiio: Any, shape: tuple, x: int, y: int, text: str, size: int) -> tuple:
    """Rows and columns (top, bottom, left, right) of the canvas that ``text`` at (x, y)
    can touch: FreeType's box of it, a margin of ``size`` around (antialiasing, a glyph
    past its advance); without a font, the old strip (two sizes above the baseline, one
    below, the full width)."""
    roi = oiio.ImageBufAlgo.text_size(text, size, "DroidSans")
    h, w = shape[:2]
    if not roi.defined:
        return max(0, y - 2 * size), min(h, y + size), 0, w
    return (
        max(0, y + roi.ybegin - size),
        min(h, y + roi.yend + size),
        max(0, x + roi.xbegin - size),
        min(w, x + roi.xend + size),
    )


def fitting_size(text: str, size: int, width: int, smallest: int = 10) -> int:
    """The largest font size up to ``size`` at which ``text`` fits ``width`` pixels (a
    one-frame sheet is narrower than its title at the full size), at least ``smallest``."""
    import OpenImageIO as oiio

    while size > smallest:
        roi = oiio.ImageBufAlgo.text_size(text, size, "DroidSans")
        if not roi.defined or roi.width <= width:
            break
        size -= 1
    return size


def contact_sheet(
    images: list[np.ndarray], labels: list[str], title: str, columns: int
) -> np.ndarray:
    """Frames (H, W, 3) in [0, 1] on a grid with a label under each and a title on top."""
    if not images or len(images) != len(labels):
        raise ProofImageError("a contact sheet needs one label per frame and a frame")
    h, w = images[0].shape[:2]
    columns = max(1, min(columns, len(images)))
    rows = -(-len(images) // columns)
    label_h = max(12, h // 8)
    title_h = max(16, h // 5)
    cell_h, cell_w = h + label_h + GAP, w + GAP
    sheet = np.full((title_h + rows * cell_h + GAP, columns * cell_w + GAP, 3), BACKGROUND)
    for i, (img, label) in enumerate(zip(images, labels, strict=True)):
        r, c = divmod(i, columns)
        y, x = title_h + r * cell_h, GAP + c * cell_w
        sheet[y : y + h, x : x + w] = img[..., :3]
        draw_text(sheet, x + 2, y + h + label_h - 3, label, max(8, label_h - 3))
    size = fitting_size(title, max(10, title_h - 6), sheet.shape[1] - 2 * GAP - 2)
    draw_text(sheet, GAP + 2, title_h - 4, title, size)
    return sheet.astype(np.float32)


def _atomic_write(path: Path, suffix: str, write) -> Path:
    """Call ``write(tmp)`` on a hidden temporary beside ``path``, then rename it over.

    A frame is either complete under its name or absent: an interruption leaves only a
    hidden temporary, which nothing reads.
    """
    path = Path(path)
    try:
        files.make_folder(path.parent)
        with files.atomic_path(path) as tmp:  # the one write path: modes, signals, cleanup
            error = write(str(tmp))
            if error is not None:
                raise ProofImageError(f"cannot write: {_first_line(error)}", where=str(path))
    except OSError as exc:
        raise ProofImageError(f"cannot write ({exc.strerror})", where=str(path)) from None
    except files.WriteError as exc:
        raise ProofImageError(exc.message) from None
    return path


def _first_line(text: str) -> str:
    return next((line for line in str(text).splitlines() if line.strip()), "unknown error")


def write_exr(pixels: np.ndarray, path: Path, space: str | None = None) -> Path:
    """Write scene-linear (H, W, C) pixels in ``space`` (default: the working space) as a
    float EXR naming it (:func:`lookdev.pipeline.exr.write_exr`), atomically."""
    from lookdev.pipeline.exr import write_exr as write

    def write_to(tmp: str) -> None:
        write(tmp, pixels, space, shown=path, compression=EXR_COMPRESSION)

    return _atomic_write(path, ".exr", write_to)


def write_png(display: np.ndarray, path: Path) -> Path:
    """Write display-referred [0, 1] RGB as an 8-bit PNG, atomically."""
    import OpenImageIO as oiio

    from .tonemap import to_8bit

    buf = oiio.ImageBuf(np.ascontiguousarray(to_8bit(display)))
    for name, value in PNG_COMPRESSION.items():
        buf.specmod().attribute(name, value)
    return _atomic_write(path, ".png", lambda tmp: None if buf.write(tmp) else buf.geterror())


def read_rgb(path: Path) -> np.ndarray:
    """(H, W, 3) float32 RGB of an image file (a grey one repeated), or one
    :class:`ProofImageError` line when it does not decode; nothing reaches stderr."""
    import OpenImageIO as oiio

    with quiet_c_stderr():
        buf = oiio.ImageBuf(str(path))
        pixels = buf.get_pixels(oiio.FLOAT)
        error = buf.geterror() if buf.has_error else ""
        del buf  # its destructor prints any error left unread
    if error or pixels is None or np.ndim(pixels) != 3:
        first = (error or "no pixels").strip().splitlines()[0]
        raise ProofImageError(f"cannot decode the image ({first})", where=str(path))
    pixels = np.asarray(pixels, dtype=np.float32)
    return pixels[..., :3] if pixels.shape[-1] >= 3 else np.repeat(pixels[..., :1], 3, -1)


def file_entry(path: Path) -> dict[str, Any]:
    """``{"file", "size", "sha256"}`` of a written file: how a manifest records it."""
    data = path.read_bytes()
    return {"file": path.name, "size": len(data), "sha256": hashlib.sha256(data).hexdigest()}
