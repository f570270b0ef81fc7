"""Reading texture files with OpenImageIO: the one reader of masks, normal maps and
parameter textures, a run of rows at a time.

Images are read as stored: OpenImageIO normalises nothing here, no colour transform is
applied and alpha is not multiplied in (a mask or a normal map is data; a colour map is
converted afterwards, by the texture's colour space, in :mod:`.textures`). Arrays are in
UV order, row 0 at v = 0 (the bottom of the image as a viewer shows it, the USD and
OpenGL convention), so a file's rows are flipped once, on read.

It lives in the library because the library validates texture files when it loads a
preset; the blending engine (:mod:`lookdev.pipeline.blend`) filters what it returns.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import OpenImageIO as oiio

from .errors import TextureError
from .files import quiet_c_stderr

__all__ = [
    "RANDOM_ACCESS",
    "TextureFile",
    "as_float",
    "channel_index",
    "oiio_error",
    "read_channels",
]

_AS_DATA = oiio.ImageSpec()
_AS_DATA.attribute("oiio:UnassociatedAlpha", 1)
"""Read hint: keep colour channels as stored. By default OpenImageIO premultiplies formats
with unassociated alpha (PNG, TGA, some TIFFs) on read, which would scale a mask channel
by alpha."""

_STORED = {
    "uint8": (oiio.UINT8, np.uint8),
    "uint16": (oiio.UINT16, np.uint16),
    "half": (oiio.HALF, np.float16),
}
"""File pixel formats kept as they are in memory (OpenImageIO type, numpy dtype)."""

_CHUNK_BYTES = 1 << 20
"""Bytes of scanlines decoded per OpenImageIO call (rounded to 32 rows, OpenEXR's largest
common block), the transient a read costs on top of the rows it returns."""

RANDOM_ACCESS = ("openexr", "tiff", "dpx", "cineon")
"""OpenImageIO formats whose scanlines can be read in any order at the cost of those rows.
Others (PNG, JPEG, Targa …) decode from the top each time a read goes backwards, and a
blend reads UV rows bottom to top, so streaming them costs the square of their rows."""

_ALIASES = {"r": 0, "g": 1, "b": 2, "a": 3, "x": 0, "y": 1, "z": 2}
"""Channel letters understood when a file does not name its channels that way."""


def read_channels(tex: Any, count: int = 1, *, where: str | None = None) -> np.ndarray:
    """``count`` channels of ``tex.path`` from ``tex.channel`` on, (h, w, count), UV order.

    Values are kept as stored, so a decoded mask costs no more memory than the file's
    pixels: uint8 and uint16 stay integers, half stays float16, anything else becomes
    float32; :func:`as_float` normalises them (integers to 0..1). Raises
    :class:`TextureError` (one line naming ``where`` and the file) when the file is
    missing, cannot be decoded, lacks the channel, or holds NaN or infinity.
    """
    source = TextureFile(tex, count, where=where)
    return source[np.arange(source.shape[0])]


class TextureFile:
    """A texture's channels read from its file a run of rows at a time, only those asked for.

    Indexing with UV row indices (``source[rows]``, as a numpy array would be indexed)
    decodes just those rows, in the file's pixel format (see :func:`read_channels`), so a
    tile of output needs only the source rows under it in memory. Opening reads the
    header alone; every read checks what it decoded for NaN and infinity.
    """

    def __init__(self, tex: Any, count: int = 1, *, where: str | None = None):
        """``tex`` is anything with a ``path`` and a ``channel`` (a
        :class:`~lookdev.materials.layers.TextureMask`, a :class:`.textures.FileChannel`):
        ``count`` channels are read from that one on."""
        self.path, self.where, self.count = Path(tex.path), where, count
        if not self.path.is_file():
            what = "is a folder, not an image file" if self.path.is_dir() else "does not exist"
            raise TextureError(f"texture file {self.path} {what}", where=where)
        image = self._open()
        spec = image.spec()
        self.random_access = image.format_name() in RANDOM_ACCESS
        """True when rows may be streamed (:data:`RANDOM_ACCESS`)."""
        image.close()
        self.first = channel_index(tex.channel, list(spec.channelnames))
        if self.first is None or self.first + count > spec.nchannels:
            wanted = tex.channel if count == 1 else f"{tex.channel} (+{count - 1} more)"
            raise TextureError(
                f"{self.path} has no channel {wanted!r}; it has {', '.join(spec.channelnames)}",
                where=where,
            )
        self.y0 = spec.y
        self.shape = (spec.height, spec.width, count)
        self.format, self.dtype = _STORED.get(str(spec.format), (oiio.FLOAT, np.float32))
        self.stored = str(spec.format)
        """The file's pixel format as OpenImageIO names it (``uint8``, ``half``, …)."""
        self.channel_names = list(spec.channelnames)
        self.nbytes = spec.height * spec.width * count * np.dtype(self.dtype).itemsize

    def _open(self) -> oiio.ImageInput:
        with quiet_c_stderr():  # libpng prints its own line beside ours: keep ours only
            image = oiio.ImageInput.open(str(self.path), _AS_DATA)
        if image is None or image.spec().nchannels == 0:
            raise TextureError(f"cannot decode {self.path}: {oiio_error()}", where=self.where)
        return image

    def __getitem__(self, rows: np.ndarray) -> np.ndarray:
        """UV rows ``rows`` (int array, any order, repeats allowed): (len, w, count)."""
        rows = np.asarray(rows, dtype=np.int64)
        if rows.size == 0:
            return np.zeros((0, *self.shape[1:]), dtype=self.dtype)
        wanted = np.unique(rows)
        runs = np.split(wanted, np.flatnonzero(np.diff(wanted) != 1) + 1)
        read = np.empty((wanted.size, *self.shape[1:]), dtype=self.dtype)
        image = self._open()
        try:
            start = 0
            for run in runs:
                self._run(image, int(run[0]), read[start : start + run.size])
                start += run.size
        finally:
            image.close()
        if len(rows) == len(wanted) and (rows == wanted).all():
            return read  # rows asked for in order, each once: no copy
        return read[np.searchsorted(wanted, rows)]

    def _run(self, image: oiio.ImageInput, lo: int, out: np.ndarray) -> None:
        """UV rows lo..lo+len(out)-1 into ``out``: file rows h-lo-n..h-lo-1, flipped (row 0
        is v = 0). Read a chunk of about :data:`_CHUNK_BYTES` at a time and flipped into
        place, so that a run costs its own bytes plus one chunk, not twice its bytes."""
        h, w, count = self.shape
        n, c0 = len(out), self.first
        step = max(32, _CHUNK_BYTES // (w * count * out.itemsize) // 32 * 32)
        for top in range(0, n, step):  # top: rows from the run's top edge, in file order
            rows = min(step, n - top)
            y = self.y0 + h - lo - n + top
            with quiet_c_stderr():
                pixels = image.read_scanlines(0, 0, y, y + rows, 0, c0, c0 + count, self.format)
            if pixels is None or np.size(pixels) == 0:
                raise TextureError(
                    f"cannot read pixels of {self.path}: {oiio_error(image)}", where=self.where
                )
            pixels = np.asarray(pixels, dtype=self.dtype).reshape(rows, w, count)
            if pixels.dtype.kind == "f" and not np.isfinite(pixels).all():
                raise TextureError(
                    f"{self.path} has non-finite pixels (NaN or infinity)", where=self.where
                )
            out[n - top - rows : n - top] = pixels[::-1]

    def chunks(self, rows: int = 256):
        """(first UV row, its rows as stored) in runs of ``rows``, in the file's order (top
        to bottom, so UV rows descending) through one open file: a sequential format (PNG)
        is decoded once, not once per run."""
        h = self.shape[0]
        image = self._open()
        try:
            for lo in reversed(range(0, h, rows)):
                out = np.empty((min(rows, h - lo), *self.shape[1:]), dtype=self.dtype)
                self._run(image, lo, out)
                yield lo, out
        finally:
            image.close()


def as_float(a: np.ndarray) -> np.ndarray:
    """Stored texels as float32: integers normalised to 0..1 (v / 255, v / 65535).

    >>> as_float(np.array([0, 51, 255], dtype=np.uint8)).tolist()
    [0.0, 0.20000000298023224, 1.0]
    """
    if a.dtype.kind == "u":
        return a.astype(np.float32) / np.float32(np.iinfo(a.dtype).max)
    return a.astype(np.float32, copy=False)


def channel_index(channel: int | str, names: list[str]) -> int | None:
    """Index of ``channel`` (an index, a name in ``names``, or R/G/B/A), or None.

    >>> channel_index("A", ["R", "G", "B", "A"]), channel_index("G", ["Y"]), channel_index(2, ["Y"])
    (3, None, None)
    """
    if isinstance(channel, int):
        return channel if channel < len(names) else None
    if channel in names:
        return names.index(channel)
    lowered = [n.lower() for n in names]
    if channel.lower() in lowered:
        return lowered.index(channel.lower())
    alias = _ALIASES.get(channel.lower())
    return alias if alias is not None and alias < len(names) else None


def oiio_error(image: oiio.ImageInput | None = None) -> str:
    own = image.geterror() if image is not None else ""
    message = " ".join(own.split()) or " ".join(oiio.geterror().split()) or "unknown format"
    return message[:200]
