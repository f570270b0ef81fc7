"""A denoiser that is checked, not trusted: each denoised frame's own residual, per pixel.

The frame I = (A + B)/2 is denoised as D = den(I); the halves are denoised too, with the
same guides, as D_A = den(A) and D_B = den(B). Two parts of D's error are estimated, in
display code values like the raw estimate (:func:`.adaptive.pixel_error`):

* **what is left of the noise**: D_A and D_B are independent, and a denoiser of roughly
  linear response halves the variance when its input's halves are averaged, so
  v = E[(D_A − D_B)²]/4 estimates Var(D), as E[(A − B)²]/4 estimates Var(I);
* **what the denoiser invented or removed** (bias: a blurred texture, a darkened glint,
  a caustic turned to blobs), by *hold-out*, the dual-buffer idea of
  :cite:`Rousselle2012`: B is unbiased and independent of D_A (the guides are rendered
  apart from both halves), so E[(D_A − B)²] = MSE(D_A) + Var(B), and
  h = ((D_A − B)² + (D_B − A)²)/2 − (A − B)²/2 estimates MSE(D_A) = bias² + Var(D_A)
  without looking inside the denoiser. The squared bias is h − 2v, averaged over a
  (2·:data:`BIAS_WINDOW` + 1)² window (h is a difference of noisy squares).

Why not v alone, as before: D_A and D_B share the guides and the denoiser's structure, so
whatever they get wrong *alike* — the bias, and noise the shared guides turn into the same
blotch in both — cancels in D_A − D_B. Measured against 1024-spp references that made v
read 0.24–0.65 of the denoised frame's error (the worst on hot pixels); the hold-out sees
it, since B is not denoised. Any part of D_A − D_B that is correlated is counted as bias,
which is kept whole where the variance would halve: the estimate errs high, not low
(docs/measurements/adaptive.md).

The residual is √(v + bias²), v windowed as the raw estimate is
(:func:`.adaptive.local_mean`). The target applies to it when denoising is on: a pixel
whose residual misses gets more samples. What is shown blends the raw and denoised pixels
by the inverse of their estimated squared errors (:func:`blend`), so where samples have
made the raw pixel better than the denoiser's guess, the raw pixel wins: more samples
never make a shown frame worse (the denoiser's output alone can: OIDN's bias on glass
grew with samples). The shown pixel's residual is taken as the smaller of the two
estimates (the errors are correlated, so the blend's would be optimistic). Light below
zero — a chart patch outside the working space's gamut — is denoised, not clamped, by
:func:`.denoise.denoise`, so it needs no rule here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from .adaptive import WINDOW, box_mean, local_mean

__all__ = ["BIAS_WINDOW", "Checked", "blend", "check"]

BIAS_WINDOW = 2
"""Radius of the window the hold-out bias estimate is averaged over (5×5): it is a
difference of squares each as noisy as the raw frame, so it needs more pixels than the
raw estimate's 3×3; narrow enough to keep a glint."""


@dataclass(frozen=True)
class Checked:
    """A checked denoised frame: the image shown, its residual and its parts (H, W)."""

    image: np.ndarray  # (H, W, 3) float32: raw and denoised blended (blend)
    denoised: np.ndarray  # (H, W, 3) float32: den((A + B)/2) as OIDN gave it
    residual: np.ndarray  # estimated display RMS error of ``image``
    variance: np.ndarray  # of D: E[(D_A − D_B)²]/4
    bias: np.ndarray  # squared, by hold-out (h − 2v, windowed), ≥ 0
    raw_weight: float  # mean weight of the raw pixels in the blend

    @property
    def noise(self) -> float:
        return float(np.sqrt(np.mean(np.square(self.residual))))


def check(
    a: np.ndarray,
    b: np.ndarray,
    raw_error: np.ndarray,
    denoise: Any,
    exposure: float = 0.0,
) -> Checked:
    """Denoise (a + b)/2 and both halves with ``denoise(image) -> image`` (the same
    guides for all three), and estimate the result's residual (module docstring).

    ``raw_error`` is the raw frame's windowed estimate (:func:`.adaptive.pixel_error`).
    """
    from .tonemap import view

    image = (0.5 * (a + b)).astype(np.float32)
    d = np.asarray(denoise(image), np.float32)
    da = np.asarray(denoise(np.asarray(a, np.float32)), np.float32)
    db = np.asarray(denoise(np.asarray(b, np.float32)), np.float32)
    va, vb = view(a, exposure, exact=True), view(b, exposure, exact=True)
    vda, vdb = view(da, exposure, exact=True), view(db, exposure, exact=True)
    variance = np.mean(np.square(vda - vdb), axis=-1) / 4.0
    hold = (
        np.mean(np.square(vda - vb), axis=-1) + np.mean(np.square(vdb - va), axis=-1)
    ) / 2.0 - np.mean(np.square(va - vb), axis=-1) / 2.0
    bias = np.maximum(box_mean(hold - 2.0 * variance, BIAS_WINDOW), 0.0)
    residual = np.sqrt(local_mean(variance, WINDOW) + bias)
    shown, weight = blend(image, d, raw_error, residual)
    final = np.minimum(raw_error, residual)
    return Checked(shown, d, final, variance, bias, float(weight.mean()))


def blend(
    raw: np.ndarray, denoised: np.ndarray, raw_error: np.ndarray, residual: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Raw and denoised pixels weighted by the inverse of their estimated squared errors;
    the shown frame and the raw pixels' weights (H, W).

    >>> img, w = blend(np.zeros((1, 2, 3)), np.ones((1, 2, 3)),
    ...                np.array([[0.0, 0.3]]), np.array([[0.2, 0.1]]))
    >>> [round(float(v), 2) for v in img[0, :, 0]], np.round(w, 2).tolist()
    ([0.0, 0.9], [[1.0, 0.1]])
    """
    s2 = np.square(np.asarray(raw_error, np.float64))
    r2 = np.square(np.asarray(residual, np.float64))
    total = s2 + r2
    with np.errstate(invalid="ignore"):
        weight = np.where(total > 0, r2 / np.where(total > 0, total, 1.0), 0.0)
    weight = np.where(np.isinf(r2), 1.0, weight)  # no denoised estimate: raw
    out = weight[..., None] * raw + (1.0 - weight[..., None]) * denoised
    return out.astype(np.float32), weight
