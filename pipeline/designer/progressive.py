"""Progressive accumulation shared by both viewport modes: two halves and a stopping rule.

Passes alternate between two accumulators A and B, so the noise of the mean image is
estimated from A − B exactly as the proofs estimate a frame's
(:func:`lookdev.pipeline.proof.passes.estimate`); refinement stops when that relative
noise reaches :data:`NOISE_TARGET` or the samples reach ``max_spp``.

Designer mode accumulates each sub-pixel position of its g-buffer on its own
(:class:`Part`), and the material's pixels apart from the rest, so an edit restarts the
material alone while the ground, the rig and the background keep what they reached.
"""

from __future__ import annotations

import numpy as np

from lookdev.pipeline.proof.passes import estimate

__all__ = ["MAX_SPP", "NOISE_TARGET", "Part"]

NOISE_TARGET = 0.005
"""Relative RMS noise (luminance, over the part's pixels) at which refinement stops."""
MAX_SPP = 1024
"""Samples per pixel at which refinement stops whatever the noise."""


class Part:
    """Accumulated passes of one set of pixels over ``layers`` sub-pixel positions.

    :meth:`add` takes a pass's mean of ``spp`` samples per pixel at one position;
    passes at a position alternate between its halves. The noise is estimated again
    once per round of positions (each estimate reads every position's halves).
    """

    def __init__(
        self,
        pixels: int,
        layers: int = 1,
        noise_target: float = NOISE_TARGET,
        max_spp: int = MAX_SPP,
    ):
        self.pixels, self.layers = pixels, layers
        self.noise_target, self.max_spp = noise_target, max_spp
        self.reset()

    def reset(self) -> None:
        self.sums = np.zeros((self.layers, 2, self.pixels, 3), np.float32)
        self.counts = np.zeros((self.layers, 2), np.int64)
        self.spp = 0
        self.mask = np.zeros(self.pixels, bool)
        self.passes = 0
        self._noise: tuple[int, float | None] = (-self.layers, None)

    def add(self, rgb: np.ndarray, layer: int, spp: int, pixels: np.ndarray | None = None) -> None:
        """Add a pass of ``spp`` samples per pixel at sub-pixel position ``layer``:
        ``rgb`` (N, 3), the mean of its samples at ``pixels`` (N distinct flat indices;
        None: every pixel in order, added in place without an index)."""
        half = int(self.counts[layer, 0] > self.counts[layer, 1])
        # A slice adds in place; an index array gathers, adds and scatters (≈ 5× slower).
        where = slice(None) if pixels is None else pixels
        self.sums[layer, half, where] += np.asarray(rgb, np.float32) * np.float32(spp)
        self.counts[layer, half] += spp
        self.mask[where] = True
        self.spp += spp
        self.passes += 1

    @property
    def noise(self) -> float | None:
        """The relative noise of the mean (None until both halves have passes)."""
        if self.passes - self._noise[0] >= self.layers:
            halves = self.halves()
            value = None
            if halves is not None:
                a, b = halves
                value = estimate(a[self.mask], b[self.mask]).relative
            self._noise = (self.passes, value)
        return self._noise[1]

    def done(self) -> np.ndarray:
        """The sub-pixel positions that have at least one pass."""
        return np.flatnonzero(self.counts.sum(axis=1) > 0)

    def mean(self, layers: np.ndarray | None = None) -> np.ndarray:
        """(H·W, 3): each position's mean, averaged over ``layers`` (default: done ones)."""
        layers = self.done() if layers is None else layers
        out = np.zeros((self.pixels, 3), np.float32)
        for layer in layers:
            total = self.counts[layer].sum()
            if total:
                out += (self.sums[layer, 0] + self.sums[layer, 1]) * np.float32(1.0 / total)
        return out / max(len(layers), 1)

    def halves(self) -> tuple[np.ndarray, np.ndarray] | None:
        """(A, B) averaged over the positions that have both, or None."""
        both = np.flatnonzero(np.all(self.counts > 0, axis=1))
        if not both.size:
            return None
        a = sum(self.sums[k, 0] / self.counts[k, 0] for k in both) / both.size
        b = sum(self.sums[k, 1] / self.counts[k, 1] for k in both) / both.size
        return a, b

    @property
    def converged(self) -> bool:
        if self.spp >= self.max_spp:
            return True
        noise = self.noise
        return noise is not None and noise <= self.noise_target
