"""Rendering a frame to a noise level: passes of half-sample pairs until a target or a cap.

Every pass renders the frame as two independent half-sample images A and B in one launch
of the paired sensor (:meth:`.turntable.Turntable.render_halves`), with a new seed and the
same compiled (frozen) kernels. The passes' A images are averaged into one A, their B
images into one B; the frame is (A + B) / 2.

Noise estimate of that combined image (what the manifest calls ``noise``): for two
independent estimates of a pixel with equal variance σ², Var((A + B)/2) = σ²/2 and
E[(A − B)²] = 2σ², so the combined image's per-pixel error variance is E[(A − B)²]/4.
On luminance, averaged over the frame, square-rooted and divided by the frame's mean
luminance: the relative RMS noise. Because A and B are *accumulated* halves, the estimate
is that of everything rendered so far, not of one pass.

Fireflies are reported, not hidden: ``firefly_share`` is the share of that estimated
squared error carried by the frame's hottest 0.1 % of pixels (the largest (A − B)²); a
frame of plain grain gives ≈ 0.01, a frame whose error is sun caustics 0.5 – 1.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal

import numpy as np

from lookdev.materials.colour import luminance

from .turntable import Frame, Turntable

__all__ = [
    "FIREFLY_FRACTION",
    "PASS_SPP",
    "Estimate",
    "RenderedFrame",
    "Stop",
    "estimate",
    "firefly_share",
    "render_frame",
    "seed_for",
]

Stop = Literal["target", "max_spp", "time_budget", "spp"]
"""Why a frame stopped adding samples: it met its noise target, reached ``max_spp``,
would have overrun its ``time_budget``, or was asked for a fixed ``spp``."""

PASS_SPP = 8
"""Samples per pixel a pass adds (half to each of A and B) when rendering to a target.
One size for every pass (but a last one shortened to fit ``max_spp``), so the passes
replay one frozen recording. A pass has a fixed cost beyond its samples (at 480×240,
four passes of 4 spp took 1.19× the CPU time of one pass of 16: ``lookdev bench noise``),
so passes are not smaller than the main job's cap: its frames render in one pass."""

FIREFLY_FRACTION = 0.001
"""The hottest 0.1 % of a frame's pixels are its fireflies."""


@dataclass(frozen=True)
class Estimate:
    """The error of the combined image (A + B)/2, estimated from A − B on luminance."""

    rmse: float
    relative: float | None  # rmse / mean luminance; None for a black frame
    firefly_share: float | None  # None when the estimated error is exactly 0


def firefly_share(squared_error: np.ndarray, fraction: float = FIREFLY_FRACTION) -> float | None:
    """Share of ``squared_error``'s sum held by its largest ``fraction`` of pixels
    (at least one pixel); None when the sum is 0.

    >>> firefly_share(np.array([1.0] * 999 + [999.0]))
    0.5
    """
    flat = np.asarray(squared_error, dtype=np.float64).ravel()
    total = float(flat.sum())
    if total <= 0.0:
        return None
    k = max(1, math.ceil(fraction * flat.size))
    hottest = np.partition(flat, flat.size - k)[flat.size - k :]
    return float(hottest.sum() / total)


def estimate(a: np.ndarray, b: np.ndarray) -> Estimate:
    """The noise of (a + b)/2 from two independent images of equal sample counts
    (module docstring: per-pixel error variance E[(A − B)²]/4).

    >>> e = estimate(np.ones((2, 2, 3)), np.full((2, 2, 3), 3.0))
    >>> e.rmse, e.relative
    (1.0, 0.5)
    """
    diff = luminance(np.asarray(a, np.float64) - np.asarray(b, np.float64))
    squared = diff * diff / 4.0
    rmse = math.sqrt(float(np.mean(squared)))
    mean = float(np.mean(luminance(0.5 * (np.asarray(a, np.float64) + b))))
    relative = rmse / mean if mean > 0 else None
    return Estimate(rmse, relative, firefly_share(squared))


@dataclass(frozen=True)
class RenderedFrame:
    """A frame's image and what the manifest records about it."""

    frame: Frame
    image: np.ndarray
    seconds: float  # rendering, all passes
    spp: int  # samples per pixel of the image (both halves)
    passes: int
    noise_rmse: float
    noise: float | None  # relative; None for a black frame
    firefly_share: float | None
    stop: Stop


def seed_for(frame: Frame, pass_index: int) -> int:
    """A distinct 32-bit seed for every (frame, pass): frames < 2¹⁶, passes < 2¹⁶."""
    return ((frame.index & 0xFFFF) << 16) | (pass_index & 0xFFFF)


def render_frame(
    table: Turntable,
    frame: Frame,
    *,
    spp: int | None = None,
    noise: float | None = None,
    max_spp: int = 1024,
    time_budget: float | None = None,
    pass_spp: int = PASS_SPP,
    clock: Callable[[], float] = time.perf_counter,
    on_pass: Callable[[int, Estimate, float], None] | None = None,
) -> RenderedFrame:
    """Render ``frame``: ``spp`` samples in one pass, or passes of ``pass_spp`` until the
    estimated relative noise is at most ``noise``.

    With a target, a pass is added while the estimate is above it, the samples stay
    within ``max_spp`` (the last pass is shortened to fit) and, with a ``time_budget``
    (seconds of this frame's rendering), the next pass is not expected to end past it —
    expected from the mean duration of the passes so far. The first pass always runs.
    ``clock`` is injectable so that tests need no timing; ``on_pass(spp, estimate,
    seconds)`` is called after every pass (progress, benchmarks). An odd spp is rounded
    down to even (the halves share it), and never below 2.
    """
    if (spp is None) == (noise is None):
        raise ValueError("give exactly one of spp (a fixed count) and noise (a target)")
    first = _even(spp if spp is not None else min(pass_spp, max_spp))
    cap = first if spp is not None else _even(max_spp)
    t0 = clock()
    table.set_frame(frame)
    sum_a = sum_b = None
    done = passes = 0
    size = first
    while True:
        a, b = table.render_halves(size // 2, seed=seed_for(frame, passes))
        weight = size / 2.0  # samples per pixel of each half: a shortened pass weighs less
        a, b = a.astype(np.float64) * weight, b.astype(np.float64) * weight
        sum_a = a if sum_a is None else sum_a + a
        sum_b = b if sum_b is None else sum_b + b
        done += size
        passes += 1
        est = estimate(sum_a / (done / 2.0), sum_b / (done / 2.0))
        elapsed = clock() - t0
        if on_pass is not None:
            on_pass(done, est, elapsed)
        stop = _stop(spp, noise, est, done, cap, time_budget, elapsed, elapsed / passes)
        if stop is not None:
            break
        size = min(_even(pass_spp), cap - done)
    image = (0.5 * (sum_a + sum_b) / (done / 2.0)).astype(np.float32)
    return RenderedFrame(
        frame, image, elapsed, done, passes, est.rmse, est.relative, est.firefly_share, stop
    )


def _even(n: int) -> int:
    return max(2, int(n) // 2 * 2)


def _stop(
    spp: int | None,
    target: float | None,
    est: Estimate,
    done: int,
    cap: int,
    budget: float | None,
    elapsed: float,
    per_pass: float,
) -> Stop | None:
    """Why to stop after this pass, or None to render another."""
    if spp is not None:
        return "spp"
    if est.relative is None or est.relative <= target:  # a black frame has nothing to refine
        return "target"
    if done + 2 > cap:
        return "max_spp"
    if budget is not None and elapsed + per_pass > budget:
        return "time_budget"
    return None
