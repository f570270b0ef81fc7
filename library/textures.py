"""Parameter textures: UDIM tiles, channels, colour spaces, and their checks at load.

A parameter written as a texture (:class:`~lookdev.materials.textures.TextureInput`) is
opened here as a :class:`ParamTexture`: its tiles found (``<UDIM>`` → ``1001 + u + 10 v``),
its channels chosen, its colour space named (:func:`lookdev.materials.colour.texture_space`),
and its values checked against the parameter's range. Pixels come from the one reader,
:mod:`.images`; the blending engine filters what a :class:`Decoded` tile returns.

**Channels.** ``channel`` names one channel (``"r"``, ``"a"``, ``"Y"``, ``"diffuse.R"``, an
index) or a run of them (``"rgb"``, ``"xyz"``, consecutive in the file). A colour takes
three channels: by default the file's first three, or one channel repeated as grey when
the file (or ``channel``) gives one; a file of two channels (grey and alpha, or two data
channels) must name the one it means. A scalar takes one: by default the first.

**Tiles.** A UDIM set is the files matching the pattern; every tile must agree on how its
pixels are stored (all integer or all float, one channel layout): a set mixing a 16-bit
tile with a float one would be read in two colour spaces by the file rule.

**The range rule.** Values after conversion, remap, scale and offset must lie in the
parameter's range. Within :data:`~lookdev.materials.textures.CLAMP_TOLERANCE` of it (1 %
of the span, at most 0.01) they are clamped, with a one-line warning; further out the
preset is refused, naming the file, the values found and the range allowed.

Statistics (per-channel min and max) read every texel once, streamed by rows, and are
remembered per file state (path, size, modification time), in the process and under
``$LOOKDEV_CACHE/textures/`` (safe to delete).
"""

from __future__ import annotations

import hashlib
import json
import os
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials import colour
from lookdev.materials.errors import LookdevError
from lookdev.materials.textures import (
    CLAMP_TOLERANCE,
    UDIM_TOKEN,
    TextureInput,
    field_range,
    texturable,
    tile_uv,
)

from . import files
from .errors import TextureError
from .images import TextureFile, as_float, channel_index
from .index import warn

__all__ = ["Decoded", "FileChannel", "ParamTexture", "Tiles", "udim_tiles"]

Tiles = dict[int | None, Path]
"""UDIM tile number → file; the key ``None`` for a plain (not UDIM) texture."""


@dataclass(frozen=True)
class FileChannel:
    """What :class:`.images.TextureFile` reads: a file and its first channel."""

    path: Path
    channel: int | str


def udim_tiles(pattern: str | Path) -> dict[int, Path]:
    """The tiles of a UDIM pattern that exist, by tile number (1001 and up), sorted.

    >>> udim_tiles("/nonexistent/a.<UDIM>.png")
    {}
    """
    pattern = str(pattern)
    folder, name = os.path.split(pattern)
    head, tail = name.split(UDIM_TOKEN, 1)
    regex = re.compile(re.escape(head) + r"(1\d{3}|[2-9]\d{3})" + re.escape(tail))
    try:
        names = os.listdir(folder or ".")
    except OSError:
        return {}
    found = {int(m.group(1)): Path(folder, n) for n in names if (m := regex.fullmatch(n))}
    return {t: found[t] for t in sorted(found) if t >= 1001}


class ParamTexture:
    """A texture that drives parameter ``field`` of a ``params_type`` model (module doc)."""

    def __init__(
        self,
        tex: TextureInput,
        field: str,
        params_type: type,
        *,
        where: str | None,
        label: str | None = None,
    ):
        """``where`` names the preset file in messages, ``label`` the field (default
        ``field``; the library passes ``params.roughness`` or ``layers[1].params.…``)."""
        self.tex, self.field, self.where, self.label = tex, field, where, label or field
        self.count = texturable(params_type)[field]
        self.bounds = field_range(params_type, field)
        self.tiles: Tiles = udim_tiles(tex.texture) if tex.udim else {None: Path(tex.texture)}
        if not self.tiles:
            raise self.error(
                f"no tile of the UDIM set {tex.texture} exists (tiles are named 1001, 1002, …)"
            )
        first_tile = next(iter(self.tiles))
        probe = TextureFile(FileChannel(self.tiles[first_tile], 0), 1, where=self._where())
        self.first, self.read_count = self._channels(probe)
        self.files = {
            t: TextureFile(FileChannel(p, self.first), self.read_count, where=self._where())
            for t, p in self.tiles.items()
        }
        self._same_storage()
        self.integer = np.dtype(next(iter(self.files.values())).dtype).kind == "u"
        try:
            self.space = colour.texture_space(
                self.integer, self.count == 3, tex.colorspace, str(self.tiles[first_tile])
            )
        except colour.ColourError as exc:
            raise self.error(exc.message) from None

    # -- what it is ------------------------------------------------------------------------
    def _where(self) -> str:
        return ": ".join(p for p in (self.where, self.label) if p)

    def error(self, message: str) -> TextureError:
        return TextureError(message, where=self.where, field=self.label)

    @property
    def extent(self) -> tuple[int, int, int, int]:
        """(0, 0, u1, v1): the UV squares from tile 1001 to the tiles' far corner ((0, 0, 1, 1)
        if plain); UDIM grids start at tile 1001, whatever tiles a set holds."""
        if None in self.tiles:
            return (0, 0, 1, 1)
        uvs = [tile_uv(t) for t in self.tiles]
        return (0, 0, max(u for u, _ in uvs) + 1, max(v for _, v in uvs) + 1)

    def _channels(self, probe: TextureFile) -> tuple[int, int]:
        """(first channel, how many to read) for ``tex.channel`` in ``probe``'s file."""
        names, channel = probe.channel_names, self.tex.channel
        if channel is None:
            if self.count == 3 and len(names) == 2:  # grey and alpha? two data channels?
                raise self.error(
                    f"{probe.path} has 2 channels ({', '.join(names)}); a colour takes 3, or 1 "
                    f"as grey: say which, e.g. channel = {names[0]!r}"
                )
            return 0, 3 if self.count == 3 and len(names) >= 3 else 1
        single = channel_index(channel, names)
        if single is not None:
            return single, 1
        letters = [channel_index(c, names) for c in channel] if isinstance(channel, str) else []
        if len(letters) > 1 and None not in letters:
            if letters != list(range(letters[0], letters[0] + len(letters))):
                raise self.error(
                    f"channels {channel!r} are not consecutive in {probe.path} "
                    f"({', '.join(names)}); name one channel or a consecutive run"
                )
            if len(letters) != self.count:
                what = "a colour takes 3 (or 1, as grey)" if self.count == 3 else "it takes one"
                raise self.error(f"channel {channel!r} names {len(letters)} channels; {what}")
            return letters[0], len(letters)
        raise self.error(f"{probe.path} has no channel {channel!r}; it has {', '.join(names)}")

    def _same_storage(self) -> None:
        """Every tile stored alike (integer or float; a float tile among integer ones would
        be read in another colour space by the file rule)."""
        files = list(self.files.values())
        kind = {f.path: np.dtype(f.dtype).kind == "u" for f in files}
        first = files[0]
        for f in files[1:]:
            if kind[f.path] != kind[first.path]:
                raise self.error(
                    f"UDIM tiles are stored differently: {first.path.name} is {first.stored}, "
                    f"{f.path.name} is {f.stored}; store every tile of a set alike "
                    "(all 8/16-bit integer or all float)"
                )

    # -- values ----------------------------------------------------------------------------
    def decode(self, stored: np.ndarray, clamp: bool = True) -> np.ndarray:
        """Stored texels (n, w, read_count) → the parameter's values (n, w, count), float32."""
        if stored.shape[-1] != self.count:  # one channel as grey
            stored = np.repeat(stored, self.count, axis=-1)
        bounds = self.bounds if clamp else None
        if self.count == 3 and stored.dtype.kind == "u" and not colour.is_data(self.space):
            linear = colour.convert_codes(stored, self.space)  # integer codes: by table
            return self.tex.values(linear, colour.RAW, bounds)
        return self.tex.values(as_float(stored), self.space, bounds)

    def stats(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-channel (min, max) of the values over every tile, before the clamp."""
        key = (
            tuple((str(p), _state(p)) for p in self.tiles.values()),
            self.first,
            self.read_count,
            self.count,
            self.space,
            self.tex.range,
            self.tex.scale,
            self.tex.offset,
            colour.settings().config_name,
            colour.working_space(),
        )
        if key not in _STATS:
            _STATS[key] = _stored_stats(key) or self._read_stats(key)
        return _STATS[key]

    def _read_stats(self, key: tuple) -> tuple[np.ndarray, np.ndarray]:
        """Every texel read once (streamed), then remembered on disk (:func:`_stored_stats`)."""
        lo = np.full(self.count, np.inf)
        hi = np.full(self.count, -np.inf)
        for f in self.files.values():
            for _, rows in f.chunks():
                v = self.decode(rows, clamp=False).reshape(-1, self.count)
                if v.size:  # per channel: numpy reduces a (N, 3) axis 0 slowly
                    lo = np.minimum(lo, [v[:, c].min() for c in range(self.count)])
                    hi = np.maximum(hi, [v[:, c].max() for c in range(self.count)])
        _store_stats(key, lo, hi)
        return lo, hi

    def bounds_after_clamp(self) -> tuple[np.ndarray, np.ndarray]:
        """Per-channel (min, max) of what blending sees (after the clamp)."""
        lo, hi = self.stats()
        return np.clip(lo, *self.bounds), np.clip(hi, *self.bounds)

    def uniform(self) -> Any:
        """The one value every texel has (a float or an RGB tuple), or None if they differ."""
        lo, hi = self.bounds_after_clamp()
        if not np.array_equal(lo, hi):
            return None
        return float(lo[0]) if self.count == 1 else tuple(float(x) for x in lo)

    def check(self) -> None:
        """Refuse values out of range beyond the tolerance; warn where they are clamped, and
        where an integer map with no colour space drives a colour (read as sRGB)."""
        lo, hi = self.stats()
        low, high = self.bounds
        tolerance = CLAMP_TOLERANCE * min(high - low, 1.0)
        found = f"{_fmt(lo)} .. {_fmt(hi)}"
        allowed = f"[{low:g}, {high:g}]"
        if (lo < low - tolerance).any() or (hi > high + tolerance).any():
            raise self.error(
                f"texture {self.tex.texture} gives values {found}, outside the allowed range "
                f"{allowed}; fix the map, or give range/scale/offset"
            )
        if (lo < low).any() or (hi > high).any():
            warn(
                f"{self._where()}: texture {self.tex.texture} gives {found}, slightly outside "
                f"{allowed}; clamped (within {CLAMP_TOLERANCE:.0%} of the range)"
            )
        if self.count == 3 and self.integer and self.tex.colorspace is None:
            warn(
                f"{self._where()}: integer map {self.tex.texture} has no colorspace; read as "
                f"{self.space!r} by the file rule (declare colorspace to say so)"
            )


class Decoded:
    """One tile's parameter values, indexed by UV rows like a :class:`.images.TextureFile`
    (``decoded[rows]`` → (n, w, count) float32), converted a run of rows at a time from
    ``file``: the :class:`.images.TextureFile`, or its texels as stored, already read."""

    def __init__(self, texture: ParamTexture, file: Any):
        self.texture, self.file = texture, file
        self.shape = (*file.shape[:2], texture.count)
        self.dtype = np.dtype(np.float32)
        self.nbytes = self.shape[0] * self.shape[1] * texture.count * 4

    def __getitem__(self, rows: np.ndarray) -> np.ndarray:
        return self.texture.decode(self.file[rows])

    def chunks(self, rows: int = 256):
        """(first UV row, its values) in runs of ``rows``, bottom to top."""
        for lo in range(0, self.shape[0], rows):
            yield lo, self[np.arange(lo, min(lo + rows, self.shape[0]))]


_STATS: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}
"""Statistics read in this process, by everything they depend on."""


def _stats_file(key: tuple) -> Path:
    """``$LOOKDEV_CACHE/textures/<sha256 of the key>.json``: the statistics of a texture
    survive the process, so loading a preset with a 4K UDIM set reads its texels once per
    change of its files (their sizes and modification times are in the key), not per run."""
    digest = hashlib.sha256(repr(key).encode()).hexdigest()
    return files.cache_root() / "textures" / f"{digest}.json"


def _stored_stats(key: tuple) -> tuple[np.ndarray, np.ndarray] | None:
    try:
        doc = json.loads(_stats_file(key).read_text())
        return np.array(doc["lo"], dtype=np.float64), np.array(doc["hi"], dtype=np.float64)
    except (OSError, ValueError, KeyError, TypeError):
        return None


def _store_stats(key: tuple, lo: np.ndarray, hi: np.ndarray) -> None:
    """Best effort: a cache that cannot be written is not used (the next run reads again)."""
    path = _stats_file(key)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        files.atomic_write(path, json.dumps({"lo": lo.tolist(), "hi": hi.tolist()}))
    except (OSError, LookdevError):
        pass


def _state(path: Path) -> tuple[int, int]:
    st = path.stat()
    return st.st_size, st.st_mtime_ns


def _fmt(a: np.ndarray) -> str:
    return f"{a[0]:.4g}" if a.size == 1 else "(" + ", ".join(f"{x:.4g}" for x in a) + ")"
