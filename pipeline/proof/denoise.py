"""Denoising proof frames on the CPU: Intel Open Image Denoise, guided by albedo and normals.

OIDN's ``RT`` filter (through ``pyoidn``, its Python binding on PyPI) runs in HDR mode on
the scene-linear frame, guided by two images rendered with it by Mitsuba's ``aov``
integrator from the same sensor:

* ``albedo`` — :meth:`BSDF.eval_diffuse_reflectance` at the first hit, which our plugins
  implement by OIDN's rules (:mod:`lookdev.materials.guides`: no highlight baked in,
  glass the Fresnel blend of 1 and its transmission colour, metals their F0);
* ``sh_normal`` — the world-space shading normal (normal maps included), in [−1, 1] as
  OIDN wants; 0 where a ray leaves the scene.

They share the frame's pixel filter, as OIDN requires. OIDN also requires that filter to
be a *box*: a splatting filter (Mitsuba's default Gaussian) spreads each sample over
neighbouring pixels, the noise is no longer independent per pixel and the denoiser
removes almost none of it (measured: plastic at 32 spp, 0.023 → 0.018 relative MSE with
the Gaussian against 0.0023 with a box).

The guides are rendered with as many samples as the frame, at most :data:`GUIDE_SPP`
(anti-aliased, nearly noise-free: they are first-hit quantities), and ``cleanAux`` stays
off (a few samples leave some noise in them at edges and in textures). A guide sample costs
≈ 1/5 of a path-traced one, so guides of the frame's count add ≈ 20 % to it; fewer
guide samples trade error for time about evenly (README, "Denoised proofs"). Their cost and the
denoiser's are returned with every frame (:class:`Denoised`), so a manifest can state
them; ``lookdev bench error`` weighs them against the samples they replace.

Where denoising misleads (README, "Denoised proofs"): it smooths texture detail finer than
the noise (a fine weave, brushed-metal streaks) when the albedo guide is itself noisy or
the texture lives only in a glossy lobe; it turns sparse fireflies (sun caustics through
glass) into soft blotches that look like real light; and its error is not the noise
estimate the manifest reports for the raw frame. Judge fine texture on the raw EXR, which
is always kept beside the denoised one.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials.errors import LookdevError

__all__ = [
    "AOVS",
    "GUIDE_SPP",
    "DenoiseError",
    "Denoised",
    "GuideRenderer",
    "Guides",
    "NEGATIVE_MARGIN",
    "denoise",
    "denoise_timed",
    "guide_renderer",
    "oidn",
    "write_denoised",
    "write_guided",
]

GUIDE_SPP = 16
"""Most samples per pixel of the albedo and normal guides; a frame of fewer samples gets
guides of its own count (first-hit only: ≈ 1/5 of a path sample; their share of a
denoised frame's time is measured by ``lookdev bench error --item denoise``)."""
NEGATIVE_MARGIN = 8
"""Pixels around negative light that its own denoising sees (:func:`denoise`)."""
AOVS = "albedo:albedo,normal:sh_normal"
"""Mitsuba ``aov`` integrator channels: RGB albedo, then the XYZ shading normal."""


class DenoiseError(LookdevError):
    """Denoising cannot run here (the denoiser is not installed, or failed)."""


def oidn() -> Any:
    """The ``pyoidn`` module; a one-line :class:`DenoiseError` when it is missing."""
    try:
        import pyoidn
    except ImportError:
        raise DenoiseError("denoising needs Intel Open Image Denoise: pip install pyoidn") from None
    return pyoidn


@dataclass(frozen=True)
class Guides:
    """A frame's albedo (H, W, 3) in [0, 1] and shading normal (H, W, 3) in [−1, 1]."""

    albedo: np.ndarray
    normal: np.ndarray
    seconds: float  # wall time of their render
    cpu_seconds: float = 0.0  # process time (all threads) of their render
    spp: int = GUIDE_SPP


@dataclass(frozen=True)
class Denoised:
    """A denoised frame and what it cost: the guides' render and the denoiser itself."""

    image: np.ndarray
    aov_seconds: float
    denoise_seconds: float
    aov_cpu_seconds: float = 0.0  # process time (all threads): less hurt by a shared machine
    denoise_cpu_seconds: float = 0.0
    guide_spp: int = GUIDE_SPP

    def timings(self) -> dict[str, float]:
        """The manifest's ``denoise`` entry: ``{"aov_s", "denoise_s", "guide_spp"}``."""
        return {
            "aov_s": round(self.aov_seconds, 4),
            "denoise_s": round(self.denoise_seconds, 4),
            "guide_spp": self.guide_spp,
        }


class GuideRenderer:
    """Renders the guides of a loaded scene's current pose with the ``aov`` integrator.

    With ``freeze`` the launch is frozen (``dr.freeze``) like the turntable's own renders,
    so after the first frames a pose costs the kernels, not the tracing again. Mitsuba
    3.9's orthographic camera cannot be frozen, and a failed recording leaves Dr.Jit
    unable to record other frozen functions in the process: pass ``freeze=False`` there.
    """

    def __init__(self, scene: Any, sensor: int = 0, spp: int = GUIDE_SPP, freeze: bool = True):
        """``spp``: the guides' samples per pixel, and the most a frame's own count
        (:meth:`render`'s ``spp``) may raise them to."""
        import drjit as dr
        import mitsuba as mi

        oidn()  # fail before anything renders
        self.scene = scene
        self.sensor = sensor
        self.spp = int(spp)
        self.integrator = mi.load_dict({"type": "aov", "aovs": AOVS})

        # The integrator is an argument, not a closure: a frozen function must see every
        # Dr.Jit value it reads among its inputs (a new spp is a new recording).
        def launch(scene: Any, integrator: Any, spp: int, seed: Any) -> Any:
            return mi.render(scene, sensor=sensor, integrator=integrator, spp=spp, seed=seed)

        self._launch = dr.freeze(launch) if freeze and dr.is_jit_v(mi.Float) else launch

    def render(self, seed: int = 0, spp: int | None = None) -> Guides:
        """The guides at the scene's current pose (the same seed gives the same images),
        with ``min(spp, self.spp)`` samples (``self.spp`` when ``spp`` is None)."""
        import mitsuba as mi

        n = self.spp if spp is None else max(1, min(int(spp), self.spp))
        t0, c0 = time.perf_counter(), time.process_time()
        image = self._launch(self.scene, self.integrator, n, mi.UInt32(seed))
        out = np.array(image, dtype=np.float32)
        albedo = np.clip(out[..., 0:3], 0.0, 1.0)
        normal = np.clip(np.nan_to_num(out[..., 3:6]), -1.0, 1.0)
        return Guides(albedo, normal, time.perf_counter() - t0, time.process_time() - c0, n)

    def denoise(self, image: np.ndarray, seed: int = 0, spp: int | None = None) -> Denoised:
        """``image`` (rendered at the current pose with ``spp`` samples) denoised with
        freshly rendered guides of as many samples, at most ``self.spp``."""
        return denoise_timed(image, self.render(seed, spp))


def denoise_timed(image: np.ndarray, guides: Guides) -> Denoised:
    """``image`` denoised with ``guides`` (:func:`denoise`), with what both cost."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = denoise(image, guides)
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    return Denoised(out, guides.seconds, wall, guides.cpu_seconds, cpu, guides.spp)


def denoise(image: np.ndarray, guides: Guides | None = None) -> np.ndarray:
    """``image`` (H, W, 3) scene-linear, denoised by OIDN's ``RT`` filter in HDR mode.

    With ``guides`` the filter also sees the albedo and normal images; without, only the
    colour (worse on texture and edges). Non-finite pixels are set to 0 first. OIDN's HDR
    input is [0, ∞), so light below 0 — a chart patch outside the working space's gamut,
    such as the ColorChecker's cyan in Rec.709 — is denoised apart, as the positive image
    of its magnitude over the box that holds it, and subtracted: OIDN is applied to each
    sign as to light, and the patch keeps its value instead of being clamped to 0.
    """
    pyoidn = oidn()
    image = np.nan_to_num(np.asarray(image, np.float32), nan=0.0, posinf=0.0, neginf=0.0)
    out = _oidn(pyoidn, np.maximum(image, 0.0), guides)
    below = (image < 0).any(axis=-1)
    if below.any():
        rows, cols = np.nonzero(below)
        box = (
            slice(max(rows.min() - NEGATIVE_MARGIN, 0), rows.max() + NEGATIVE_MARGIN + 1),
            slice(max(cols.min() - NEGATIVE_MARGIN, 0), cols.max() + NEGATIVE_MARGIN + 1),
        )
        part = None if guides is None else replace(guides, albedo=guides.albedo[box],
                                                   normal=guides.normal[box])  # fmt: skip
        out[box] -= _oidn(pyoidn, np.maximum(-image[box], 0.0), part)
    return out


def _oidn(pyoidn: Any, color: np.ndarray, guides: Guides | None) -> np.ndarray:
    kwargs = {}
    if guides is not None:
        kwargs = {
            "albedo": np.ascontiguousarray(guides.albedo, np.float32),
            "normal": np.ascontiguousarray(guides.normal, np.float32),
        }
    try:
        color = np.ascontiguousarray(color, np.float32)
        out = pyoidn.denoise(color, hdr=True, quality="high", **kwargs)
    except (RuntimeError, ValueError, TypeError) as exc:
        raise DenoiseError(f"Open Image Denoise failed: {exc}") from None
    return np.array(out, np.float32)


# -- proofs ------------------------------------------------------------------------------
def guide_renderer(table: Any) -> GuideRenderer:
    """The guides of a :class:`~.turntable.Turntable` (its single-frame camera), rendered
    per frame with the frame's own samples, at most GUIDE_SPP (:func:`write_denoised`):
    an 8-spp frame under a noise target does not pay for 16-spp guides, and the proofs
    run what ``lookdev bench error`` measures."""
    # Not frozen: tracing the aov integrator is cheap (≈ 0.03-0.1 s a frame, measured on
    # 32×16 proofs), and a second frozen launch over the turntable's scene is one more
    # recording that can fail (see GuideRenderer); lookdev bench error times frozen guides.
    return GuideRenderer(table.scene, table.camera_index, GUIDE_SPP, freeze=False)


def write_denoised(
    guides: GuideRenderer,
    image: np.ndarray,
    stem: Path,
    exposure: float,
    seed: int,
    spp: int | None = None,
) -> tuple[dict[str, Path], dict[str, float]]:
    """Denoise a frame (of ``spp`` samples) at the pose it was just rendered in, with
    guides rendered now (:func:`write_guided`)."""
    return write_guided(guides.render(seed, spp), image, stem, exposure)


def write_guided(
    aov: Guides, image: np.ndarray, stem: Path, exposure: float
) -> tuple[dict[str, Path], dict[str, float]]:
    """Denoise a frame with its guides ``aov`` (rendered at its pose); write
    ``<stem>_denoised.exr`` and ``.png`` beside the raw ``<stem>.exr``. Returns the
    written files by manifest role (``denoised``, ``denoised_png``) and the manifest's
    ``denoise`` entry (:meth:`Denoised.timings`)."""
    from . import contact, tonemap

    d = denoise_timed(image, aov)
    exr = contact.write_exr(d.image, stem.with_name(stem.name + "_denoised.exr"))
    display = tonemap.view(d.image, exposure)
    png = contact.write_png(display, stem.with_name(stem.name + "_denoised.png"))
    return {"denoised": exr, "denoised_png": png}, d.timings()
