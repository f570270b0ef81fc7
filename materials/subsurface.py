"""The interior of a solid Disney material: (colour, scatter distance) ↔ (σt, albedo).

One home for the mapping that every consumer uses (the Mitsuba interior medium, the
exporters' scatter distances, the presets converted from measurements). Burley 2015's
BSDF with integrated subsurface scattering lets the diffuse entry and the specular
transmission of a solid lead into an isotropic homogeneous medium whose coefficients
follow from the surface colour A and the scatter distance d (Schutte seed,
``CalculateExtinction``; :func:`lookdev.materials.disney.medium_coefficients`):

* single-scattering albedo α = 1 − exp(−5.09406 A + 2.61188 A² − 4.31805 A³),
  Chiang, Kutz & Burley 2016 ("Practical and Controllable Subsurface Scattering for
  Production Path Tracing", eq. 4): the albedo inversion fitted so that a thick slab of
  the medium reflects A — the property this mapping must have;
* σt = 1 / (s·d), s = 1.9 − A + 3.5 (A − 0.8)² (Christensen & Burley 2015's fit of the
  profile's shape, as Chiang et al. use it): d is the distance the light spreads, not the
  mean free path.

Both are per channel; ``scatter_distance · scatter_distance_scale`` gives d per channel
(OpenPBR's radius and radius scale). Lengths are scene units (metres at
``metersPerUnit = 1``). How well a rendered thick slab reflects A with our boundary is
measured by :func:`lookdev.pipeline.bench.subsurface.slab_error` (``lookdev bench
subsurface``) and stated in the README.

Measured media convert the other way (:func:`from_measured`): Jensen et al. 2001's
reduced coefficients σs′, σa (Table 2, mm⁻¹) give the reduced albedo α′ = σs′/σt′ and
σt′ = σs′ + σa; the fit is inverted for A (bisection: α(A) increases on [0, 1]) and
d = 1/(s(A)·σt′). The similarity relation (σs′ with an isotropic phase in place of σs
with Jensen's forward-scattering g) keeps the diffuse look, which is what a preset shows.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .arrays import NumpyOps
from .disney import medium_coefficients

__all__ = [
    "JENSEN_2001",
    "MM",
    "albedo_of",
    "colour_for_albedo",
    "from_measured",
    "has_interior",
    "interior",
    "scatter_distances",
    "split_distances",
]

MM = 1e-3
"""A millimetre in metres: Jensen's coefficients are per millimetre."""

JENSEN_2001: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    # name: (σs′ RGB, σa RGB) in mm⁻¹; Jensen, Marschner, Levoy & Hanrahan 2001,
    # "A Practical Model for Subsurface Light Transport", Table 2 (η = 1.3 for all).
    "apple": ((2.29, 2.39, 1.97), (0.0030, 0.0034, 0.046)),
    "chicken1": ((0.15, 0.21, 0.38), (0.015, 0.077, 0.19)),
    "chicken2": ((0.19, 0.25, 0.32), (0.018, 0.088, 0.20)),
    "cream": ((7.38, 5.47, 3.15), (0.0002, 0.0028, 0.0163)),
    "ketchup": ((0.18, 0.07, 0.03), (0.061, 0.97, 1.45)),
    "marble": ((2.19, 2.62, 3.00), (0.0021, 0.0041, 0.0071)),
    "potato": ((0.68, 0.70, 0.55), (0.0024, 0.0090, 0.12)),
    "skimmilk": ((0.70, 1.22, 1.90), (0.0014, 0.0025, 0.0142)),
    "skin1": ((0.74, 0.88, 1.01), (0.032, 0.17, 0.48)),
    "skin2": ((1.09, 1.59, 1.79), (0.013, 0.070, 0.145)),
    "spectralon": ((11.6, 20.4, 14.9), (0.00, 0.00, 0.00)),
    "wholemilk": ((2.55, 3.21, 3.77), (0.0011, 0.0024, 0.014)),
}


def has_interior(params: Any) -> bool:
    """True when a Disney material's diffuse and transmission lead into a medium: solid
    (not ``thin``) with a scatter distance (Burley 2015; thin sheets keep Hanrahan-Krueger)."""
    return (not params.thin) and params.scatter_distance > 0.0


def scatter_distances(params: Any) -> np.ndarray:
    """d per channel (scene units): ``scatter_distance · scatter_distance_scale``."""
    return params.scatter_distance * np.asarray(params.scatter_distance_scale, dtype=np.float64)


def split_distances(rgb: Any) -> tuple[float, tuple[float, float, float]]:
    """(``scatter_distance``, ``scatter_distance_scale``) of a per-channel distance: the
    inverse of :func:`scatter_distances` (the largest channel, and each over it), as a DCC's
    RGB radius is read back. All-zero is no distance, scale white.

    >>> split_distances((0.002, 0.001, 0.0005))
    (0.002, (1.0, 0.5, 0.25))
    """
    d = np.broadcast_to(np.asarray(rgb, dtype=np.float64), (3,))
    top = float(d.max())
    if not top > 0.0:
        return 0.0, (1.0, 1.0, 1.0)
    return top, tuple(float(x) for x in np.clip(d / top, 0.0, 1.0))


def interior(params: Any, meters_per_unit: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(σt per scene unit, single-scattering albedo), RGB, of a solid material's medium.

    ``meters_per_unit`` converts a scene whose unit is not the preset's: a preset's
    distances are metres, so in a scene of 5 cm units σt per unit is σt per metre × 0.05.
    """
    sigma_t, albedo = medium_coefficients(
        NumpyOps(), params.base_color, scatter_distances(params)[:, None]
    )
    return np.asarray(sigma_t)[:, 0] * meters_per_unit, np.asarray(albedo)[:, 0]


def albedo_of(colour: Any) -> np.ndarray:
    """Chiang et al. 2016's single-scattering albedo α(A) of apparent colour A."""
    a = np.asarray(colour, dtype=np.float64)
    return 1.0 - np.exp(a * (-5.09406 + a * (2.61188 - 4.31805 * a)))


def colour_for_albedo(alpha: Any, iterations: int = 60) -> np.ndarray:
    """A with α(A) = ``alpha``: the fit inverted by bisection on [0, 1] (α increases there;
    α ≥ α(1) ≈ 0.9989 gives A = 1)."""
    target = np.asarray(alpha, dtype=np.float64)
    lo, hi = np.zeros_like(target), np.ones_like(target)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        below = albedo_of(mid) < target
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return 0.5 * (lo + hi)


def from_measured(
    sigma_s_reduced: Any, sigma_a: Any, unit: float = MM
) -> tuple[tuple[float, ...], float, tuple[float, ...]]:
    """(base colour, scatter_distance, scatter_distance_scale) of a measured medium.

    ``sigma_s_reduced``, ``sigma_a``: RGB per ``unit`` (metres; Jensen's mm by default).
    The distance is in metres; the scale is d per channel over its largest.

    >>> colour, d, scale = from_measured(*JENSEN_2001["marble"])
    >>> [round(c, 3) for c in colour], round(d * 1000, 3), [round(s, 3) for s in scale]
    ([1.0, 0.973, 0.938], 0.439, [1.0, 0.842, 0.737])
    """
    ss, sa = np.asarray(sigma_s_reduced, float), np.asarray(sigma_a, float)
    st = (ss + sa) / unit  # per metre
    colour = colour_for_albedo(ss / (ss + sa))
    s = 1.9 - colour + 3.5 * (colour - 0.8) ** 2
    d = 1.0 / (s * st)
    top = float(d.max())
    return tuple(float(c) for c in colour), top, tuple(float(x) for x in d / top)
