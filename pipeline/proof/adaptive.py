"""Per-pixel adaptive sampling: each pass renders only the pixels not yet converged.

**The estimate.** Every pixel p keeps two independent half images A and B (each lane of a
pass goes to one of them), so ``(A + B)/2`` is the pixel and ``(A − B)/2`` has the
variance of its error (E[(A − B)²]/4 = Var((A + B)/2), :mod:`.passes`). The error is
measured *on the image a person sees*: through the proof's view transform
(:func:`.tonemap.view`, the OCIO display view at the frame's exposure), in display code
values 0–1, where one 8-bit step is 1/255. Linearised, view(A) − view(B) ≈ view′(I)·(A − B),
so ``|view(A) − view(B)|/2`` is the display-space error of the pixel; the view's compressive
curve plays the part of Cycles' ``|I − A| / √I`` normalisation (more tolerance in the
highlights, less in the shadows) without a hand-chosen floor, and a highlight the view
rolls off to white costs nothing. One pixel's (A − B)² over three channels is a noisy
estimate of its variance (≈ χ²₃), so it is averaged over a (2·:data:`WINDOW` + 1)² window
before the test, as Cycles filters its error over neighbours; but a pixel whose error
stands out from its neighbours (a glint, a firefly, a caustic's speck) is then diluted by
them, so the estimate is the larger of the window's mean and :data:`OWN` times the pixel's
own (:func:`local_mean`). Measured against 1024-spp references (plastic_glossy, 16 and
64 spp), the window alone read 0.43–0.68 of the hottest 1 % of pixels' error; with half
the pixel's own as a floor 0.58–0.80, smooth pixels 1.05–1.11
(docs/measurements/adaptive.md).

**The stop rule.** A pixel is converged when its estimate is at most the target; every
pixel first gets :data:`MIN_SPP` samples (fewer leave rare paths — a sun caustic — unseen
by both halves). Unconverged pixels keep their neighbours within :data:`DILATE` pixels
open, so a converged island does not starve its edges. The frame meets its target when
at least :data:`CONVERGED_SHARE` of its pixels do (``stop: "target"``; the last 0.1 % are
the hottest pixels, which had the most samples); else it stops when the open pixels have
all reached ``max_spp`` (``"max_spp"``) or the next pass is expected to overrun
``time_budget`` (``"time_budget"``). ``converged`` records the share either way.

**The passes.** Each open pixel gets the samples its own estimate predicts it needs
(variance ∝ 1/n: n·(e/target)² in all), at most doubling what it has (the estimate is
noisy and a doubling bounds the overshoot), within ``max_spp``. The wavefront of a pass is
compacted — lane i renders pixel ``pixels[i]``, nothing is launched for a converged pixel
— and its radiance is summed per (pixel, half) with one scatter-add; the film is not used
(a box pixel filter: a sample lands in its own pixel, which is what the proofs use).
Pixels with the largest estimates — fireflies among them — are the ones that stay open,
so they get more samples first.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = [
    "CONVERGED_SHARE",
    "DILATE",
    "MAX_LANES",
    "MIN_SPP",
    "OWN",
    "WINDOW",
    "AdaptiveFrame",
    "PixelRenderer",
    "box_mean",
    "dilate",
    "local_mean",
    "pass_samples",
    "pixel_error",
    "render_adaptive",
]

MIN_SPP = 16
"""Samples a pixel has before it may stop (both halves): the first pass gives every pixel
this many."""
WINDOW = 1
"""Radius of the window the per-pixel squared error is averaged over (3×3)."""
OWN = 0.5
"""Share of a pixel's own squared estimate that its windowed one may not fall below. Not
1: one pixel's estimate has three degrees of freedom (its 99.9th percentile is 5.4× its
mean), and at 1 the stop rule's last 0.1 % of pixels chase that noise (measured on the
tests' noise picture: the cap reached with 99.7 % met; at 0.5 the target with 100 %, in
no more samples)."""
DILATE = 1
"""An open pixel keeps its neighbours within this radius open (Cycles does the same)."""
MAX_LANES = 1 << 21
"""Most samples one launch of a pass takes (≈ 480×240 at 16 spp, what ``mi.render`` of a
proof's first pass holds anyway)."""
CONVERGED_SHARE = 0.999
"""A frame meets its target when this share of its pixels do (module docstring)."""


def box_mean(x: np.ndarray, radius: int) -> np.ndarray:
    """Mean of ``x`` (H, W) over a (2r + 1)² window, the window clipped at the borders.

    >>> box_mean(np.array([[0.0, 3.0], [0.0, 3.0]]), 1).tolist()
    [[1.5, 1.5], [1.5, 1.5]]
    """
    x = np.asarray(x, np.float64)
    if radius <= 0:
        return x
    out = x
    for axis in (0, 1):
        n = x.shape[axis]
        pad = [(1, 0) if a == axis else (0, 0) for a in (0, 1)]
        c = np.cumsum(np.pad(out, pad), axis=axis)
        lo = np.clip(np.arange(n) - radius, 0, n)
        hi = np.clip(np.arange(n) + radius + 1, 0, n)
        shape = [1, 1]
        shape[axis] = n
        count = (hi - lo).reshape(shape)
        out = (np.take(c, hi, axis=axis) - np.take(c, lo, axis=axis)) / count
    return out


def local_mean(x: np.ndarray, radius: int) -> np.ndarray:
    """The larger of :func:`box_mean` and :data:`OWN` × ``x``: a windowed estimate that an
    outstanding pixel is not averaged away in (module docstring).

    >>> local_mean(np.array([[0.0, 12.0, 0.0]]), 1).tolist()
    [[6.0, 6.0, 6.0]]
    >>> local_mean(np.array([[0.0, 0.0, 0.0, 30.0]]), 1).tolist()
    [[0.0, 0.0, 10.0, 15.0]]
    """
    return np.maximum(box_mean(x, radius), OWN * np.asarray(x, np.float64))


def dilate(mask: np.ndarray, radius: int) -> np.ndarray:
    """``mask`` (H, W) grown by ``radius`` pixels (a square neighbourhood)."""
    return box_mean(mask.astype(np.float64), radius) > 0 if radius > 0 else mask.astype(bool)


def pixel_error(a: np.ndarray, b: np.ndarray, exposure: float = 0.0) -> np.ndarray:
    """The estimated RMS error (H, W) of view((a + b)/2) in display code values, averaged
    over the :data:`WINDOW`, never below the pixel's own (module docstring)."""
    from .tonemap import view

    d = view(a, exposure, exact=True) - view(b, exposure, exact=True)
    squared = np.mean(d * d, axis=-1) / 4.0
    return np.sqrt(local_mean(squared, WINDOW))


def pass_samples(spp: np.ndarray, error: np.ndarray, target: float, max_spp: int) -> np.ndarray:
    """Samples to add to each pixel (even): n·((e/target)² − 1), at least n/2 (fewer passes
    of a few samples would cost more in fixed costs than they save) and at most n, within
    ``max_spp``; 0 where that leaves none.

    >>> pass_samples(np.array([16, 16, 16, 60]), np.array([0.02, 0.011, 0.5, 1]), 0.01, 64).tolist()
    [16, 8, 16, 4]
    """
    n = spp.astype(np.float64)
    ratio = np.square(np.asarray(error, np.float64) / target)
    want = np.ceil(np.clip(n * (ratio - 1.0), np.maximum(n / 2, 2.0), n) / 2.0) * 2.0
    room = np.maximum(max_spp - spp, 0) // 2 * 2
    return np.minimum(want, room).astype(np.int64)


class PixelRenderer:
    """Renders chosen pixels of a loaded scene's sensor with the scene's integrator.

    :meth:`render` launches one wavefront whose lanes are the samples of the listed
    pixels only, and returns their radiance summed per pixel and half.
    """

    def __init__(self, scene: Any, sensor: int = 0, freeze: bool = True):
        import drjit as dr
        import mitsuba as mi

        self.scene = scene
        self.sensor = scene.sensors()[sensor]
        film = self.sensor.film()
        if not film.rfilter().is_box_filter():
            raise ValueError("adaptive sampling needs the box pixel filter")
        self.width, self.height = (int(v) for v in film.crop_size())
        self.integrator = scene.integrator()
        self._mi = mi
        size = (self.width, self.height)

        # Sizes and the seed enter as JIT values, so one recording replays every pass
        # whatever its wavefront's width (a Python int would key a recording per pass).
        def launch(scene, sensor, integrator, lane_pixel, row, scale, seed):  # noqa: ANN001
            return _trace(mi, dr, scene, sensor, integrator, lane_pixel, row, scale, seed, size)

        self._launch = dr.freeze(launch) if freeze and dr.is_jit_v(mi.Float) else launch

    def render(
        self, pixels: np.ndarray, samples: np.ndarray, seed: int
    ) -> tuple[np.ndarray, np.ndarray]:
        """Sums (N, 3) of radiance over the A and B halves of ``samples[i]`` (even) new
        samples of pixel ``pixels[i]`` (a flat index y·W + x); half of each to A.

        A pass of more than :data:`MAX_LANES` samples is launched in pieces (a path's
        state is a few hundred bytes a lane), each with its own seed offset."""
        pixels = np.asarray(pixels, np.int64)
        samples = np.asarray(samples, np.int64)
        out_a, out_b = np.zeros((len(pixels), 3)), np.zeros((len(pixels), 3))
        ends = np.cumsum(samples)
        lo, piece = 0, 0
        while lo < len(pixels):
            base = ends[lo - 1] if lo else 0
            hi = max(lo + 1, int(np.searchsorted(ends, base + MAX_LANES, side="right")))
            a, b = self._piece(
                pixels[lo:hi], samples[lo:hi], (int(seed) + piece * 0x9E3779B1) & 0xFFFFFFFF
            )
            out_a[lo:hi], out_b[lo:hi] = a, b
            lo, piece = hi, piece + 1
        return out_a, out_b

    def _piece(
        self, pixels: np.ndarray, samples: np.ndarray, seed: int
    ) -> tuple[np.ndarray, np.ndarray]:
        mi = self._mi
        n = len(pixels)
        slot = np.repeat(np.arange(n, dtype=np.uint32), samples)
        start = np.repeat(np.cumsum(samples) - samples, samples)
        rank = np.arange(len(slot)) - start
        half = (rank >= np.repeat(samples // 2, samples)).astype(np.uint32)
        sums = self._launch(
            self.scene,
            self.sensor,
            self.integrator,
            mi.UInt32(pixels[slot].astype(np.uint32)),
            mi.UInt32((2 * pixels[slot] + half).astype(np.uint32)),
            mi.Float(1.0 / math.sqrt(max(1.0, len(slot) / n))),
            mi.UInt32(seed),
        )
        sums = np.asarray(sums, np.float64).reshape(self.height * self.width, 2, 3)[pixels]
        return sums[:, 0], sums[:, 1]


def _trace(mi, dr, scene, sensor, integrator, lane_pixel, row, scale, seed, size):  # noqa: ANN001, PLR0913
    """One wavefront, a sample per lane: radiance scatter-added into a (H·W·2, 3) buffer of
    (pixel, half) sums at ``row``; ray differentials scaled by ``scale`` (1/√spp, as the
    film's renders do)."""
    w, h = size
    sampler = sensor.sampler().clone()
    sampler.seed(seed, dr.width(lane_pixel))
    pos = mi.Point2f(mi.Float(lane_pixel % w), mi.Float(lane_pixel // w)) + sampler.next_2d()
    aperture = sampler.next_2d() if sensor.needs_aperture_sample() else mi.Point2f(0.5)
    ray, weight = sensor.sample_ray_differential(
        time=sensor.shutter_open(),
        sample1=0.0,
        sample2=mi.Point2f(pos.x / w, pos.y / h),
        sample3=aperture,
    )
    ray.scale_differential(scale)
    spec, valid, _ = integrator.sample(scene, sampler, ray, None, True)
    rgb = mi.Color3f(spec * weight)
    out = dr.zeros(mi.Float, 3 * 2 * w * h)
    for c in range(3):
        value = dr.select(valid & dr.isfinite(rgb[c]), rgb[c], 0.0)
        dr.scatter_reduce(dr.ReduceOp.Add, out, value, 3 * row + c)
    return out


@dataclass(frozen=True)
class AdaptiveFrame:
    """What the pass loop reached: the frame, per-pixel counts and estimates, and why it
    stopped."""

    image: np.ndarray  # (H, W, 3) float32, (A + B)/2
    a: np.ndarray  # (H, W, 3) float64 half means (kept for the denoiser's check)
    b: np.ndarray
    spp: np.ndarray  # (H, W) samples per pixel, both halves
    error: np.ndarray  # (H, W) estimated display RMS error of the shown pixel (windowed)
    raw_error: np.ndarray  # (H, W) the same of the raw pixel
    passes: int
    seconds: float
    stop: str
    converged: float  # share of pixels at or below the target
    checked: Any = None  # the last .checked.Checked when denoising was checked
    check_seconds: float = 0.0  # of ``seconds``, spent denoising and checking

    @property
    def mean_spp(self) -> float:
        return float(self.spp.mean())

    @property
    def noise(self) -> float:
        """The frame's display RMS error (all pixels), estimated."""
        return math.sqrt(float(np.mean(np.square(self.error))))


def render_adaptive(
    renderer: PixelRenderer,
    *,
    target: float,
    max_spp: int,
    seed: Callable[[int], int],
    exposure: float = 0.0,
    min_spp: int = MIN_SPP,
    time_budget: float | None = None,
    check: Callable[[np.ndarray, np.ndarray, np.ndarray], Any] | None = None,
    clock: Callable[[], float] = time.perf_counter,
) -> AdaptiveFrame:
    """Render the renderer's current pose to ``target`` (display RMS per pixel).

    ``seed(pass_index)`` gives each pass its seed. ``check(a, b, raw_error)``, when given
    (the checked denoiser, :func:`.checked.check`), returns an object whose ``residual``
    (H, W) replaces the raw estimate in the stop rule: the target then applies to the
    frame that is shown; the last one is returned as ``checked``. Denoising three images
    costs about a pass, so between checks a pixel's residual is predicted from the last
    check (∝ 1/√n, never above the raw estimate) and the check runs again only when the
    prediction says the frame is done, and on the frame returned.
    """
    h, w = renderer.height, renderer.width
    first = max(2, min(int(min_spp), int(max_spp)) // 2 * 2)
    sum_a = np.zeros((h * w, 3))
    sum_b = np.zeros((h * w, 3))
    spp = np.zeros(h * w, np.int64)
    pixels = np.arange(h * w)
    samples = np.full(h * w, first, np.int64)
    t0 = clock()
    passes = 0
    checked, checked_spp = None, spp
    checking = 0.0
    while True:
        sa, sb = renderer.render(pixels, samples, seed(passes))
        sum_a[pixels] += sa
        sum_b[pixels] += sb
        spp[pixels] += samples
        passes += 1
        half = np.maximum(spp, 2)[:, None] / 2.0
        a, b = (sum_a / half).reshape(h, w, 3), (sum_b / half).reshape(h, w, 3)
        raw_error = pixel_error(a, b, exposure)
        error = raw_error
        if check is not None:
            error, fresh = None, True
            if checked is not None:  # predicted: residual ∝ 1/√n since the last check
                scale = np.sqrt(checked_spp / np.maximum(spp, 1)).reshape(h, w)
                error = np.minimum(raw_error, checked.residual * scale)
                fresh = np.mean(error > target) <= 1.0 - CONVERGED_SHARE
            if fresh:
                c0 = clock()
                checked, checked_spp = check(a, b, raw_error), spp.copy()
                checking += clock() - c0
                error = checked.residual
        flat_err = error.ravel()
        over = error > target
        converged = 1.0 - float(np.mean(over))
        open_ = dilate(over, DILATE).ravel() & (spp < max_spp)
        samples = np.where(open_, pass_samples(spp, flat_err, target, max_spp), 0)
        pixels = np.flatnonzero(samples)
        samples = samples[pixels]
        elapsed = clock() - t0
        if converged >= CONVERGED_SHARE:
            stop = "target"
        elif len(pixels) == 0:
            stop = "max_spp"
        elif time_budget is not None and elapsed + elapsed / passes > time_budget:
            stop = "time_budget"
        else:
            continue
        if check is not None and not fresh:  # the shown frame is checked at its samples
            c0 = clock()
            checked = check(a, b, raw_error)
            checking += clock() - c0
            error = checked.residual
            converged = 1.0 - float(np.mean(error > target))
        image = (0.5 * (a + b)).astype(np.float32)
        return AdaptiveFrame(
            image,
            a,
            b,
            spp.reshape(h, w),
            error,
            raw_error,
            passes,
            elapsed,
            stop,
            converged,
            checked,
            checking,
        )
