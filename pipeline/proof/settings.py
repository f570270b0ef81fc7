"""What every turntable of a proof batch shares, its defaults and their allowed ranges.

The one home of the proof options: :class:`Settings` is what the batch hashes into each
proof's key (so changing any of them re-renders), what the manifests record, and what
``lookdev proof`` and :func:`lookdev.proof` fill in; :func:`check` holds every range.

Sampling is either a fixed count (``spp``: one pass, the manifests' ``stop`` reads
``"spp"``) or a noise target (``noise``). With a target and the box pixel filter, frames
are sampled per pixel (:mod:`.adaptive`): ``noise`` is then the RMS error each pixel may
have on the image a person sees (display code values 0–1, after the view transform) and
``max_spp`` a pixel's cap; with ``adaptive=False`` (or a Gaussian filter) whole-frame
passes run to a relative RMS on luminance (:mod:`.passes`), as before.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field
from typing import Any

from lookdev.materials import colour
from lookdev.materials.errors import LookdevError, argument, check_range

from . import shaderball
from .rig import DEFAULT_RIG, RIGS
from .turntable import Frame, frames

__all__ = [
    "DEFAULT_ADAPTIVE",
    "DEFAULT_DENOISE",
    "DEFAULT_PIXEL_MAX_SPP",
    "UNIFORM_NOISE",
    "DEFAULT_FRAMES",
    "DEFAULT_LIGHT_FRAMES",
    "DEFAULT_MAX_SPP",
    "DEFAULT_NOISE",
    "DEFAULT_RESOLUTION",
    "MAX_SAMPLES",
    "MAX_SIDE",
    "MIN_SIDE",
    "ProofError",
    "Settings",
    "check",
]

DEFAULT_NOISE = 0.02
"""A pixel's target when no ``spp`` is given: 0.02 RMS in display code values, ≈ 5 of 255
8-bit steps, on the frame shown (the checked denoised one when denoising). Chosen from
the wall time against target curve (docs/measurements/adaptive.md)."""
DEFAULT_PIXEL_MAX_SPP = 256
"""A pixel's sample cap under per-pixel sampling, unless ``max_spp`` is given."""
UNIFORM_NOISE = 0.05
"""The whole-frame relative-noise target of ``adaptive=False`` (5 % RMS on luminance)."""
DEFAULT_ADAPTIVE = False
"""Whether a target with the box filter samples per pixel (:mod:`.adaptive`); off until it
is shown to pay. Measured (docs/measurements/adaptive.md): the checked residual is now
within 2× of the error against references on smooth pixels and edges, but reads 0.2–0.5
of it on the sun's hot pixels (paths neither half has seen); over the main job's frames
(``lookdev bench targets``, one pose a turntable) a target of 0.04 was met by 21 of 28
at 5.4× the uniform default's CPU, 0.02 by 14 at 7.9×, and their frames show a speckle
the uniform default's do not. ``--adaptive`` (``adaptive=True``) turns it on."""
DEFAULT_MAX_SPP = 4
"""The sample cap of a frame rendered to a noise target, unless ``max_spp`` is given.
Chosen by measurement with the frames and denoising below (docs/measurements/mainjob.md;
``lookdev bench mainjob`` and ``lookdev bench error --item mainjob``):
denoised, a frame's relMSE × CPU time was lowest at 4 of caps 4, 8, 16 in all four
sampled cases, since the denoised error falls slowly with samples (8 bought 1.3× lower
error for 1.4× the time). No frame of the main job reaches 5 % within it (their
manifests say ``stop: "max_spp"``); ``--max-spp`` buys more."""
DEFAULT_FRAMES = 4
"""Element-rotation frames of a turntable (90° apart), unless ``--frames`` is given."""
DEFAULT_LIGHT_FRAMES = 4
"""Lighting-rotation frames (90° apart), unless ``--light-frames`` is given: with
:data:`DEFAULT_FRAMES`, both of Burley's rotations (2012, §6.1) at the fewest frames that
still show each quarter of the turn."""
DEFAULT_DENOISE = True
"""Also write every frame denoised (:mod:`.denoise`, the raw kept), unless
``--no-denoise``: at the main job's sample counts the denoised frame's relMSE against a
converged reference was 19–650× lower than a raw frame's at about the same time, and
6.6–30× lower than the old job's (192×96, 32 spp), where raw frames at
480×240 stay above it at any affordable cap (README)."""
DEFAULT_RESOLUTION = (480, 240)
"""Frame width and height of a proof: big enough to judge a texture."""
MIN_SIDE, MAX_SIDE = 8, 8192
"""Frame width and height of a proof, in pixels (``--resolution W H``)."""
MAX_SAMPLES = 2**32 - 1
"""Most samples one render may take, width × height × spp: Dr.Jit indexes a render's
wavefront with 32-bit integers (a noise-target pass is small; a fixed ``spp`` is one)."""
MAX_SPP = 65536
RANGES: dict[str, tuple[float, float]] = {
    "frames": (1, 360),
    "light_frames": (0, 360),
    "spp": (2, MAX_SPP),
    "noise": (1e-4, 10.0),
    "max_spp": (2, 2**20),
    "time_budget": (0.01, 86400.0),
    "clamp": (1e-3, 1e9),
}
"""Allowed ranges of the numeric proof arguments (:func:`lookdev.proof`'s names; the CLI
shows its options), inclusive (NaN and infinity never)."""


class ProofError(LookdevError):
    """A proof cannot run as asked (output folder, settings, scheduler)."""


@dataclass(frozen=True)
class Settings:
    """What every turntable of a batch shares.

    Give ``spp`` for a fixed count, or nothing / ``noise`` for a noise target (then
    ``max_spp`` defaults to :data:`DEFAULT_MAX_SPP`); :meth:`__post_init__` fills the
    defaults, so a manifest always spells out what ran.
    """

    element_frames: int = DEFAULT_FRAMES
    light_frames: int = DEFAULT_LIGHT_FRAMES
    spp: int | None = None
    resolution: tuple[int, int] = DEFAULT_RESOLUTION
    exposure: float = 0.0  # display only: applied by the view transform, not the render
    noise: float | None = None
    max_spp: int | None = None
    time_budget: float | None = None  # seconds of rendering per frame
    clamp: float | None = None  # None: unclamped (the default; see .clamp)
    pixel_filter: str = "box"
    geometry: str | None = None
    """A mesh in the cup's place (the cached PLY of :func:`.geometry.proof_mesh`: its
    name holds the hash of the user's file, so the proof key follows the mesh)."""
    rig: str = DEFAULT_RIG  # the calibrated rig beside the material (.rig)
    colour: colour.Settings = field(default_factory=colour.pinned)
    """The OCIO config, working space and view the batch was asked in (workers are other
    processes, perhaps on other machines: they enter these, not their own defaults)."""
    denoise: bool = DEFAULT_DENOISE  # also write each frame denoised (OIDN, .denoise), raw kept
    adaptive: bool = DEFAULT_ADAPTIVE  # per-pixel sampling to the target (.adaptive)

    def __post_init__(self) -> None:
        if self.spp is not None:
            extra = [
                name
                for name, value in (
                    (argument("noise"), self.noise),
                    (argument("max_spp"), self.max_spp),
                    (argument("time_budget"), self.time_budget),
                )
                if value is not None
            ]
            if extra:
                raise ProofError(
                    f"{argument('spp')} is a fixed count; {', '.join(extra)} go with a noise "
                    f"target (drop {argument('spp')})",
                    field=argument("spp"),
                )
            return
        pixel = self.per_pixel()
        if self.noise is None:
            object.__setattr__(self, "noise", DEFAULT_NOISE if pixel else UNIFORM_NOISE)
        if self.max_spp is None:
            object.__setattr__(self, "max_spp", DEFAULT_PIXEL_MAX_SPP if pixel else DEFAULT_MAX_SPP)

    def per_pixel(self) -> bool:
        """True when frames are sampled per pixel (:mod:`.adaptive`): a target, the box
        filter, ``adaptive`` on."""
        return self.spp is None and self.adaptive and self.pixel_filter == "box"

    def frames(self) -> list[Frame]:
        return frames(self.element_frames, self.light_frames)

    def sampling(self) -> dict[str, Any]:
        """The keyword arguments of :func:`.passes.render_frame` these settings ask for."""
        if self.spp is not None:
            return {"spp": self.spp}
        return {"noise": self.noise, "max_spp": self.max_spp, "time_budget": self.time_budget}

    def as_json(self) -> dict[str, Any]:
        """The settings as they read back from a manifest (lists, not tuples)."""
        return json.loads(json.dumps(asdict(self)))


def check(settings: Settings, jobs: int | None = None) -> Settings:
    """Every setting in its documented range, or one :class:`ProofError` line."""
    from . import tonemap

    s = settings
    if len(tuple(s.resolution)) != 2:
        raise ProofError(f"{tuple(s.resolution)} is not W H", field=argument("resolution"))
    for side in s.resolution:
        check_range(side, MIN_SIDE, MAX_SIDE, field=argument("resolution"), error=ProofError)
    values = {
        "frames": s.element_frames,
        "light_frames": s.light_frames,
        "spp": s.spp,
        "noise": s.noise,
        "max_spp": s.max_spp,
        "time_budget": s.time_budget,
        "clamp": s.clamp,
    }
    for name, value in values.items():
        if value is not None:
            check_range(value, *RANGES[name], field=argument(name), error=ProofError)
    if jobs is not None:
        check_range(jobs, 1, 1024, field=argument("jobs"), error=ProofError)
    check_range(
        s.exposure,
        -tonemap.EXPOSURE_MAX,
        tonemap.EXPOSURE_MAX,
        field=argument("exposure"),
        error=ProofError,
    )
    if s.rig not in RIGS:
        raise ProofError(f"unknown rig {s.rig!r}; use {', '.join(RIGS)}", field=argument("rig"))
    if s.pixel_filter not in shaderball.PIXEL_FILTERS:
        raise ProofError(
            f"{s.pixel_filter!r} is not one of {', '.join(shaderball.PIXEL_FILTERS)}",
            field=argument("pixel_filter"),
        )
    spp = s.spp if s.spp is not None else min(s.max_spp, _pass_spp())
    if s.per_pixel():  # a pass launches in pieces of at most adaptive.MAX_LANES samples
        spp = 1
    samples = s.resolution[0] * s.resolution[1] * spp
    if samples > MAX_SAMPLES:
        raise ProofError(
            f"{s.resolution[0]}×{s.resolution[1]} at {spp} spp is {samples:.3g} samples a "
            f"frame; allowed ≤ {MAX_SAMPLES:.3g} (lower {argument('spp')} or "
            f"{argument('resolution')})",
            field=argument("resolution"),
        )
    return s


def _pass_spp() -> int:
    from .passes import PASS_SPP

    return PASS_SPP
