"""Bilinear reads of the look-up tables the models ship, on both array backends.

A table is a numpy array of shape (rows, columns) held in a data module of
:mod:`lookdev.materials` (materials does no file I/O). :func:`bilinear` reads it at
continuous grid coordinates with the array shim's operations, so the numpy backend
(analysis, tests) and the Dr.Jit backend (the Mitsuba plugins) read the same numbers;
each model maps its own parameters to grid coordinates (:mod:`.sheen`, :mod:`.energy`).
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = ["bilinear", "device_tables", "gather", "on_device"]

_DEVICE_TABLES: dict[tuple[type, int], Any] = {}


def on_device(float_type: type, flat: np.ndarray) -> Any:
    """``flat`` as a Dr.Jit array, copied once per array type and table.

    Copying in the render (4 copies a lookup) cost a host-to-device transfer per call and
    made renders impossible to freeze (``dr.freeze`` cannot record a host copy).
    """
    key = (float_type, hash(flat.tobytes()))
    if key not in _DEVICE_TABLES:
        _DEVICE_TABLES[key] = float_type(flat)
    return _DEVICE_TABLES[key]


def device_tables() -> list[Any]:
    """Every table copied so far (:func:`on_device`): what a frozen function that runs a
    model must take among its inputs (``dr.freeze`` refuses a variable made before its
    recording that it was not given)."""
    return list(_DEVICE_TABLES.values())


def gather(xp: Any, flat: np.ndarray, index: Any) -> Any:
    """``flat[index]`` for an index of any backend (integral values held as floats)."""
    if xp.name == "numpy":
        return flat[np.asarray(index, dtype=np.int64)]
    if isinstance(index, int | float):  # Mitsuba's scalar_rgb: its Float is Python's float
        return float(flat[int(index)])
    dr = xp.dr
    return dr.gather(xp.Float, on_device(xp.Float, flat), dr.uint32_array_t(xp.Float)(index))


def bilinear(xp: Any, table: np.ndarray, x: Any, y: Any) -> Any:
    """``table`` (shape (rows, columns)) read bilinearly at column ``x``, row ``y``.

    Coordinates are in nodes (0 … columns − 1, 0 … rows − 1); outside they extrapolate
    linearly from the edge cells, so callers clamp what must not extrapolate.
    """
    n_y, n_x = table.shape
    y = y + 0.0 * x  # one shape for both
    i = xp.clip(xp.floor(x), 0.0, n_x - 2.0)
    j = xp.clip(xp.floor(y), 0.0, n_y - 2.0)
    fx, fy = x - i, y - j
    flat = np.ascontiguousarray(table, dtype=np.float64).reshape(-1)
    k = j * n_x + i
    e0 = xp.lerp(gather(xp, flat, k), gather(xp, flat, k + 1.0), fx)
    e1 = xp.lerp(gather(xp, flat, k + n_x), gather(xp, flat, k + n_x + 1.0), fx)
    return xp.lerp(e0, e1, fy)
