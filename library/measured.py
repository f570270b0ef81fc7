"""Readers and writers of measured isotropic BRDF files: NVIDIA MBSDF and MERL.

What each format stores, as checked by the tests rather than assumed:

* **MBSDF** :cite:`NVIDIA2025MDL` (Appendix B): an ASCII header (``NVIDIA ARC MBSDF V1``,
  then ``key="value"`` lines), then one or two blocks, ``MBSDF_DATA_REFLECTION=`` (or
  ``MBSDF_DATA=``) and ``MBSDF_DATA_TRANSMISSION=``, each a little-endian ``uint32`` type
  (0 scalar, 1 RGB), ``uint32`` n_θ, ``uint32`` n_φ and n_θ·n_θ·n_φ values (·3 for RGB),
  ``float32``, index ``(i_θi·n_θ + i_θo)·n_φ + i_φ``. The values are f, not f·cos: MDL's
  reference sampler multiplies them by the sampled cosine; the tests check that the
  directional albedo they imply stays ≤ 1 read as f, and the light/viewer symmetry.
* **MERL** :cite:`Matusik2003`: three ``int32`` dimensions (90, 90, 180) then
  3·90·90·180 ``float64``, all red, then all green, then all blue, index
  ``(i_θh·90 + i_θd)·180 + i_φd``, scaled on reading by 1/1500, 1.15/1500 and 1.66/1500;
  negative values mark directions that were not measured.

A reader returns a :class:`~lookdev.materials.measured.MeasuredTable`; bad files raise
one :class:`MeasuredFileError` line naming the file.
"""

from __future__ import annotations

import os
import struct
from pathlib import Path

import numpy as np

from lookdev.materials.errors import LookdevError
from lookdev.materials.measured import MeasuredTable, grid_directions

from .files import atomic_write

__all__ = [
    "MEASURED_SUFFIXES",
    "MERL_SCALE",
    "MERL_SHAPE",
    "MeasuredFileError",
    "builtin_measured",
    "read_mbsdf",
    "read_measured",
    "read_merl",
    "resolve_measured",
    "write_mbsdf",
    "write_merl",
]

MBSDF_MAGIC = b"NVIDIA ARC MBSDF V1\n"
_REFLECTION = (b"MBSDF_DATA_REFLECTION=\n", b"MBSDF_DATA=\n")
_TRANSMISSION = b"MBSDF_DATA_TRANSMISSION=\n"
MERL_SHAPE = (90, 90, 180)
MERL_SCALE = (1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0)
MEASURED_SUFFIXES = (".mbsdf", ".binary", ".merl")


class MeasuredFileError(LookdevError):
    """A measured BRDF file that cannot be read (format, size, values)."""


def builtin_measured() -> list[Path]:
    """The measured BRDF files shipped in the built-in library (``presets/measured``)."""
    from .library import builtin_folder

    folder = builtin_folder() / "measured"
    return sorted(p for p in folder.glob("*") if p.suffix.lower() in MEASURED_SUFFIXES)


def resolve_measured(path: str | os.PathLike) -> Path:
    """``path`` as given where it exists, else the shipped measurement of that file name
    (``carpaint_red.mbsdf``); a :class:`MeasuredFileError` naming both otherwise."""
    p = Path(path)
    if p.exists():
        return p
    for shipped in builtin_measured():
        if shipped.name == p.name or shipped.stem == p.name:
            return shipped
    known = ", ".join(q.name for q in builtin_measured())
    raise MeasuredFileError(
        f"no such file, nor a shipped measurement (shipped: {known})", where=str(p)
    )


def read_measured(path: str | os.PathLike) -> MeasuredTable:
    """The reflection table of an ``.mbsdf`` or MERL (``.binary``/``.merl``) file."""
    p = Path(path)
    if p.suffix.lower() == ".mbsdf":
        return read_mbsdf(p)
    if p.suffix.lower() in (".binary", ".merl"):
        return read_merl(p)
    raise MeasuredFileError(
        f"not a measured BRDF file (known: {', '.join(MEASURED_SUFFIXES)})", where=str(p)
    )


def _read_bytes(p: Path) -> bytes:
    try:
        return p.read_bytes()
    except OSError as exc:
        raise MeasuredFileError(exc.strerror or str(exc), where=str(p)) from None


def read_mbsdf(path: str | os.PathLike) -> MeasuredTable:
    """The BRDF block of an MBSDF file (a transmission block is read and checked, and
    reported in ``MeasuredTable.source``; lookdev's measured model reflects only)."""
    p = Path(path)
    data = _read_bytes(p)
    if not data.startswith(MBSDF_MAGIC):
        raise MeasuredFileError("not an MBSDF file (no 'NVIDIA ARC MBSDF V1' header)", where=str(p))
    offset = len(MBSDF_MAGIC)
    blocks: dict[str, np.ndarray] = {}
    while offset < len(data):
        end = data.find(b"\n", offset)
        if end < 0:
            raise MeasuredFileError("header line without an end", where=str(p))
        line = data[offset : end + 1]
        offset = end + 1
        if line in _REFLECTION or line == _TRANSMISSION:
            kind = "transmission" if line == _TRANSMISSION else "reflection"
            blocks[kind], offset = _mbsdf_block(data, offset, p)
        elif not line.rstrip(b"\n").endswith(b'"') and line.strip():
            raise MeasuredFileError(f"unexpected header line {line[:40]!r}", where=str(p))
    if "reflection" not in blocks:
        raise MeasuredFileError("no reflection (BRDF) block", where=str(p))
    values = blocks["reflection"]
    source = p.name + (" (its transmission block is not used)" if "transmission" in blocks else "")
    return _table("mbsdf", values, source, p)


def _mbsdf_block(data: bytes, offset: int, p: Path) -> tuple[np.ndarray, int]:
    if len(data) < offset + 12:
        raise MeasuredFileError("truncated block header", where=str(p))
    kind, n_theta, n_phi = struct.unpack_from("<III", data, offset)
    if kind not in (0, 1) or n_theta < 2 or n_phi < 2:
        raise MeasuredFileError(
            f"block of type {kind} with n_theta {n_theta}, n_phi {n_phi}; "
            "allowed: type 0 or 1, resolutions ≥ 2",
            where=str(p),
        )
    channels = 3 if kind == 1 else 1
    count = n_theta * n_theta * n_phi * channels
    start = offset + 12
    if len(data) < start + 4 * count:
        raise MeasuredFileError(
            f"truncated: {n_theta}×{n_theta}×{n_phi}×{channels} values need "
            f"{4 * count} bytes, {len(data) - start} remain",
            where=str(p),
        )
    values = np.frombuffer(data, "<f4", count, start).reshape(n_theta, n_theta, n_phi, channels)
    if channels == 1:
        values = np.repeat(values, 3, axis=-1)
    return values.astype(np.float32), start + 4 * count


def read_merl(path: str | os.PathLike) -> MeasuredTable:
    """A MERL binary file; unmeasured directions (negative values) read as zero."""
    p = Path(path)
    data = _read_bytes(p)
    if len(data) < 12:
        raise MeasuredFileError("not a MERL file (shorter than its header)", where=str(p))
    dims = struct.unpack_from("<iii", data, 0)
    n = int(np.prod(dims))
    if min(dims) < 2 or len(data) != 12 + 8 * 3 * n:
        raise MeasuredFileError(
            f"not a MERL file: dimensions {dims} need {12 + 24 * max(n, 0)} bytes, "
            f"the file has {len(data)}",
            where=str(p),
        )
    raw = np.frombuffer(data, "<f8", 3 * n, 12).reshape(3, *dims)
    values = np.moveaxis(raw, 0, -1) * np.asarray(MERL_SCALE)
    return _table("merl", values.astype(np.float32), p.name, p)


def _table(grid: str, values: np.ndarray, source: str, p: Path) -> MeasuredTable:
    if not np.all(np.isfinite(values)):
        bad = int(np.count_nonzero(~np.isfinite(values)))
        raise MeasuredFileError(f"{bad} values are NaN or infinite", where=str(p))
    negative = int(np.count_nonzero(values < 0))
    return MeasuredTable(grid, values, source=source, negative=negative)  # type: ignore[arg-type]


def _merl_bytes(values: np.ndarray) -> bytes:
    channel_first = np.moveaxis(np.asarray(values, dtype=np.float64), -1, 0)
    raw = channel_first / np.asarray(MERL_SCALE)[:, None, None, None]
    return struct.pack("<iii", *values.shape[:3]) + raw.astype("<f8").tobytes()


def write_merl(path: str | os.PathLike, values: np.ndarray) -> Path:
    """Write f on the MERL grid ((90, 90, 180, 3), see :func:`tabulate`) atomically."""
    return atomic_write(Path(path), _merl_bytes(values))


def write_mbsdf(
    path: str | os.PathLike, values: np.ndarray, *, meta: dict[str, str] | None = None
) -> Path:
    """Write an RGB reflection block ((n_θ, n_θ, n_φ, 3)) atomically."""
    header = MBSDF_MAGIC + b"".join(f'{k}="{v}"\n'.encode("ascii") for k, v in (meta or {}).items())
    n_t, _, n_p, _ = values.shape
    block = _REFLECTION[0] + struct.pack("<III", 1, n_t, n_p)
    body = np.asarray(values, dtype="<f4").tobytes()
    return atomic_write(Path(path), header + block + body)


def tabulate(evaluate, grid: str, shape: tuple[int, int, int]) -> np.ndarray:
    """``evaluate(wi, wo)`` (f, (..., 3)) at every sample of ``grid``: a table to write."""
    wi, wo = grid_directions(grid, shape)
    return np.asarray(evaluate(wi, wo), dtype=np.float64)
