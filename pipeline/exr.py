"""The one EXR writer: every float image lookdev writes names its colour space.

Proof frames, cached IBLs, baked blend maps, Mitsuba scene bitmaps and the maps a USD
export writes all go through :func:`write_exr`. A colour image (RGB in a colour space of
the OCIO config, by default the working space) carries

* ``chromaticities``: the space's primaries and white (x, y) — the standard EXR attribute
  (OpenEXR ``ImfStandardAttributes``) that nuke, OIIO and RV read to know the primaries;
* ``colorSpace`` and ``oiio:ColorSpace``: the OCIO config's name of the space (OpenImageIO
  also records its interop ID, ``colorInteropID``: ``lin_rec709_scene``, ``lin_ap1_scene``).

A data image (roughness, masks, normals, heights: :data:`~lookdev.materials.colour.RAW`)
has no primaries, so no ``chromaticities``; its ``colorSpace`` says ``Raw`` so that no
reader colour-converts it. Pixels are float32, ZIP-compressed, row 0 at the top.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from lookdev.library import files
from lookdev.materials import colour

__all__ = ["write_exr", "colour_space_of", "name_colour_space"]


def colour_space_of(pixels: np.ndarray, *, data: bool = False) -> str:
    """The colour space a written map is in: the working space for RGB colour, else
    :data:`~lookdev.materials.colour.RAW` (one channel, or ``data`` such as normals)."""
    channels = 1 if np.ndim(pixels) == 2 else np.shape(pixels)[-1]
    return colour.RAW if data or channels not in (3, 4) else colour.working_space()


def name_colour_space(spec, space: str | None = None) -> None:
    """Set the colour-space attributes of an OpenImageIO ``spec`` about to be written:
    ``colorSpace`` and ``oiio:ColorSpace`` (the config's name of ``space``, default the
    working space) and, for a colour space, its ``chromaticities``. Every EXR lookdev
    writes gets them here (:func:`write_exr`; the USD export's tiled, mip-mapped maps)."""
    import OpenImageIO as oiio

    name = colour.canonical(space) if space else colour.working_space()
    spec.attribute("oiio:ColorSpace", name)
    spec.attribute("colorSpace", name)
    if not colour.is_data(name):
        spec.attribute("chromaticities", oiio.TypeDesc("float[8]"), colour.chromaticities(name))


def write_exr(
    path: str | os.PathLike,
    pixels: np.ndarray,
    space: str | None = None,
    *,
    shown: str | os.PathLike | None = None,
    compression: str = "zip",
) -> Path:
    """Write ``pixels`` ((H, W) or (H, W, C)) to exactly ``path`` as a float EXR in ``space``.

    ``space``: a colour space of the config (default: the working space; data spaces
    mark the file as data). ``compression``: OpenImageIO's name of a lossless OpenEXR
    compression, with a level after a colon (``"zip:1"``). Callers that want an atomic
    file pass a temporary path (``files.atomic_path``); ``shown`` is the name the error
    line gives instead.
    A failure is one :class:`lookdev.library.files.WriteError` line.
    """
    import OpenImageIO as oiio

    path = Path(path)
    px = np.asarray(pixels, dtype=np.float32)
    if px.ndim == 2:
        px = px[..., None]  # OpenImageIO reads a 2-D array as the wrong shape
    px = np.ascontiguousarray(px)
    height, width, channels = px.shape
    spec = oiio.ImageSpec(width, height, channels, oiio.FLOAT)
    spec.channelnames = {1: ("Y",), 3: ("R", "G", "B"), 4: ("R", "G", "B", "A")}.get(
        channels, tuple(f"C{i}" for i in range(channels))
    )
    spec.attribute("compression", compression)
    name_colour_space(spec, space)
    out = oiio.ImageOutput.create(str(path))
    ok = out is not None and out.open(str(path), spec)
    message = "" if ok else (out.geterror() if out is not None else oiio.geterror())
    if ok:
        try:
            ok = out.write_image(px)
            message = "" if ok else out.geterror()
        finally:
            ok = out.close() and ok
    if not ok:
        reason = files.failure_reason(path, message or "unknown error")
        raise files.WriteError(f"cannot write {shown or path}: {reason}")
    return path
