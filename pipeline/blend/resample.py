"""Resampling textures with a filter, not a point.

Files are read by the one reader, :mod:`lookdev.library.images` (re-exported here:
:class:`TextureFile`, :func:`read_channels`, :func:`as_float`), in UV order, row 0 at
v = 0 (the bottom of the image as a viewer shows it, the USD and OpenGL convention).

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

import numpy as np

from lookdev.library.images import TextureFile, as_float, channel_index, read_channels

__all__ = ["TextureFile", "as_float", "channel_index", "read_channels", "resample", "taps"]


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
