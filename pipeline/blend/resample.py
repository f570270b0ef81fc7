"""Reading mask textures with OpenImageIO and resampling them with a filter, not a point.

Images are read as linear data: OpenImageIO normalises integer formats to 0..1, no
colour transform is applied and alpha is not multiplied in (a mask or a normal map is
data, not colour). Arrays here are
in UV order, row 0 at v = 0 (the bottom of the image as a viewer shows it, the USD and
OpenGL convention), so a file's rows are flipped once, on read.

The UV mapping of a :class:`~lookdev.materials.layers.TextureMask` is axis-aligned
(scale and offset per axis), so a lookup is separable: each output row and column takes a
weighted sum of a few source rows and columns (its *taps*). The weights are a tent whose
radius is one source texel when magnifying (bilinear interpolation) and the footprint of
an output texel when minifying (an area-like filter, so a 4096² mask seen at 64² is an
average, not 64² samples of noise).

>>> idx, w = taps(2, 4, 1.0, 0.0, "periodic")  # 2:1: a tent two source texels wide
>>> idx.tolist(), w.tolist()
([[3, 0, 1, 2], [1, 2, 3, 0]], [[0.125, 0.375, 0.375, 0.125], [0.125, 0.375, 0.375, 0.125]])
>>> taps(4, 4, 1.0, 0.0, "clamp")[1].tolist()  # 1:1 is an exact copy
[[1.0], [1.0], [1.0], [1.0]]
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import OpenImageIO as oiio

from lookdev.materials.layers import TextureMask

from .errors import TextureError

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

_ALIASES = {"r": 0, "g": 1, "b": 2, "a": 3, "x": 0, "y": 1, "z": 2}
"""Channel letters understood when a file does not name its channels that way."""


def read_channels(tex: TextureMask, count: int = 1, *, where: str | None = None) -> np.ndarray:
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

    def __init__(self, tex: TextureMask, count: int = 1, *, where: str | None = None):
        self.path, self.where, self.count = Path(tex.path), where, count
        if not self.path.is_file():
            what = "is a folder, not an image file" if self.path.is_dir() else "does not exist"
            raise TextureError(f"texture file {self.path} {what}", where=where)
        image = self._open()
        spec = image.spec()
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
        self.nbytes = spec.height * spec.width * count * np.dtype(self.dtype).itemsize

    def _open(self) -> oiio.ImageInput:
        image = oiio.ImageInput.open(str(self.path), _AS_DATA)
        if image is None or image.spec().nchannels == 0:
            raise TextureError(f"cannot decode {self.path}: {_oiio_error()}", where=self.where)
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
            pixels = image.read_scanlines(0, 0, y, y + rows, 0, c0, c0 + count, self.format)
            if pixels is None or np.size(pixels) == 0:
                raise TextureError(
                    f"cannot read pixels of {self.path}: {_oiio_error(image)}", where=self.where
                )
            pixels = np.asarray(pixels, dtype=self.dtype).reshape(rows, w, count)
            if pixels.dtype.kind == "f" and not np.isfinite(pixels).all():
                raise TextureError(
                    f"{self.path} has non-finite pixels (NaN or infinity)", where=self.where
                )
            out[n - top - rows : n - top] = pixels[::-1]

    def chunks(self, rows: int = 256):
        """(first UV row, its rows as stored) in runs of ``rows``, bottom to top."""
        for lo in range(0, self.shape[0], rows):
            yield lo, self[np.arange(lo, min(lo + rows, self.shape[0]))]


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


def _oiio_error(image: oiio.ImageInput | None = None) -> str:
    own = image.geterror() if image is not None else ""
    message = " ".join(own.split()) or " ".join(oiio.geterror().split()) or "unknown format"
    return message[:200]


def taps(
    n_out: int, n_src: int, scale: float, offset: float, wrap: str, rows: slice | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Source indices and tent weights of output texels ``rows`` along one axis.

    Output texel ``i`` has its centre at ``t = (i + ½) / n_out`` and looks up the source at
    ``s = t · scale + offset``, i.e. at continuous texel coordinate ``x = s · n_src − ½``.
    The tent's radius is ``max(1, |scale| · n_src / n_out)`` source texels, capped at the
    source size (wider than that is the mean anyway). Returns (n, K) int32 indices into
    the source (wrapped) and float32 weights summing to 1 per row (less than 1 where
    ``wrap="black"`` reads outside the image).
    """
    i = np.arange(n_out, dtype=np.float64)[rows if rows is not None else slice(None)]
    x = ((i + 0.5) / n_out * scale + offset) * n_src - 0.5
    x = np.where(np.abs(x - np.round(x)) < 1e-9, np.round(x), x)  # exact 1:1 stays exact
    radius = min(max(1.0, abs(scale) * n_src / n_out), float(n_src))
    k = np.floor(x - radius)[:, None] + 1 + np.arange(int(np.floor(2 * radius)) + 1)
    w = np.maximum(0.0, 1.0 - np.abs(k - x[:, None]) / radius)
    w /= w.sum(axis=1, keepdims=True)
    idx, inside = _wrap(k.astype(np.int64), n_src, wrap)
    w = np.where(inside, w, 0.0)
    used = (w > 0).any(axis=0)
    return idx[:, used].astype(np.int32), w[:, used].astype(np.float32)


def _wrap(k: np.ndarray, n: int, wrap: str) -> tuple[np.ndarray, np.ndarray]:
    """Indices ``k`` brought into 0..n-1 by the wrap mode, and where they were inside."""
    inside = (k >= 0) & (k < n)
    if wrap == "periodic":
        return k % n, np.ones_like(inside)
    if wrap == "mirror":
        m = k % (2 * n)
        return np.where(m >= n, 2 * n - 1 - m, m), np.ones_like(inside)
    return np.clip(k, 0, n - 1), (inside if wrap == "black" else np.ones_like(inside))


def resample(
    src: np.ndarray, v_taps: tuple[np.ndarray, np.ndarray], u_taps: tuple[np.ndarray, np.ndarray]
) -> np.ndarray:
    """Separable filtered lookup: (h, w[, c]) source → (len(v_taps), len(u_taps)[, c]).

    Only the source rows some output row needs are filtered along u, so a tile of output
    rows costs a tile of source rows.
    """
    v_idx, v_w = v_taps
    needed, v_local = np.unique(v_idx, return_inverse=True)
    v_local = v_local.reshape(v_idx.shape)
    rows = _apply_axis(as_float(src[needed]), *u_taps, axis=1)
    return _apply_axis(rows, v_local, v_w, axis=0)


def _apply_axis(a: np.ndarray, idx: np.ndarray, w: np.ndarray, axis: int) -> np.ndarray:
    """Σ_k w[:, k] · a[idx[:, k]] along ``axis`` (0 rows, 1 columns)."""
    if idx.shape[1] == 1 and (w == 1).all() and _is_run(idx[:, 0], a.shape[axis]):
        return a
    shape = [1] * a.ndim
    shape[axis] = -1
    out = None
    for k in range(idx.shape[1]):
        term = np.take(a, idx[:, k], axis=axis) * w[:, k].reshape(shape)
        out = term if out is None else np.add(out, term, out=out)
    return out


def _is_run(idx: np.ndarray, n: int) -> bool:
    """True when ``idx`` is exactly 0, 1, …, n-1 (a 1:1 copy needs no arithmetic)."""
    return idx.shape[0] == n and bool((idx == np.arange(n)).all())
