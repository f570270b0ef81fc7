"""The interior of a solid Disney material: (colour, scatter distance) ↔ (σt, albedo).

One home for the mapping that every consumer uses (the Mitsuba interior medium, the
exporters' scatter distances, the presets converted from measurements). Burley 2015's
BSDF with integrated subsurface scattering lets the diffuse entry and the specular
transmission of a solid lead into an isotropic homogeneous medium whose coefficients
follow from the surface colour A and the scatter distance d (Schutte seed,
``CalculateExtinction``), per channel:

* single-scattering albedo α(A) from :data:`SLAB_TABLE`: our own thick slab's rendered
  reflectance as a function of α, inverted, so that a thick slab reflects A — the
  property this mapping must have. Chiang, Kutz & Burley 2016's fitted inversion
  (α = 1 − exp(−5.09406 A + 2.61188 A² − 4.31805 A³), their eq. 4) was made without
  our boundary and left the slab 4–14 % darker than A; the table is rendered with it.
  Linear interpolation in (A, √(1 − α)): diffusion theory makes 1 − R ∝ √(1 − α) near
  α = 1, so the last rows are nearly straight there.
* σt = 1 / (s·d), s = 1.9 − A + 3.5 (A − 0.8)² (Christensen & Burley 2015's fit of the
  profile's shape, as Chiang et al. use it): d is the distance the light spreads, not the
  mean free path.

The boundary caps what a slab can reflect: Schutte's entry and exit
(1 − F_L/2)(1 − F_V/2) have no internal reflection, so light meeting the surface from
inside loses ≥ 4.8 % each time and a slab of α = 1 reflects :data:`REFLECTANCE_MAX`
(≈ 0.84, at specular 0 and roughness 0; the surface's retro-reflection and specular add
to it). A colour above it gets α = 1 and renders at the cap.

``scatter_distance · scatter_distance_scale`` gives d per channel (OpenPBR's radius and
radius scale). Lengths are scene units (metres at ``metersPerUnit = 1``). How well a
rendered thick slab reflects A is measured by ``lookdev bench subsurface`` and stated in
the README.

Measured media convert the other way (:func:`from_measured`): Jensen et al. 2001's
reduced coefficients σs′, σa (Table 2, mm⁻¹) give the reduced albedo α′ = σs′/σt′ and
σt′ = σs′ + σa; A is the table's reflectance at α′ (what our slab of that medium
reflects) and d = 1/(s(A)·σt′). The similarity relation (σs′ with an isotropic phase in
place of σs with Jensen's forward-scattering g) keeps the diffuse look, which is what a
preset shows.
"""

from __future__ import annotations

from typing import Any

import numpy as np

__all__ = [
    "JENSEN_2001",
    "MM",
    "REFLECTANCE_MAX",
    "SLAB_TABLE",
    "albedo_of",
    "colour_for_albedo",
    "extinction_scale",
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


SLAB_TABLE: tuple[tuple[float, float], ...] = (
    # (A, α): the thick slab's rendered reflectance A at normal view (specular 0,
    # roughness 0, isotropic medium of single-scattering albedo α) and α; rendered by
    # lookdev.pipeline.bench.subsurface.albedo_table(spp=512, size=32) (32×32 px, 512 spp,
    # standard error ≤ 0.002), α = 1 − u² over the roots u listed there; (0, 0) exact.
    (0.0000, 0.000000),
    (0.0125, 0.065556),
    (0.0257, 0.128889),
    (0.0394, 0.190000),
    (0.0538, 0.248889),
    (0.0688, 0.305556),
    (0.0846, 0.360000),
    (0.1012, 0.412222),
    (0.1187, 0.462222),
    (0.1370, 0.510000),
    (0.1562, 0.555556),
    (0.1765, 0.598889),
    (0.1979, 0.640000),
    (0.2205, 0.678889),
    (0.2444, 0.715556),
    (0.2696, 0.750000),
    (0.2962, 0.782222),
    (0.3245, 0.812222),
    (0.3545, 0.840000),
    (0.3869, 0.865556),
    (0.4210, 0.888889),
    (0.4573, 0.910000),
    (0.4953, 0.928889),
    (0.5367, 0.945556),
    (0.5811, 0.960000),
    (0.6293, 0.972222),
    (0.6800, 0.982222),
    (0.7325, 0.990000),
    (0.7630, 0.993600),
    (0.7908, 0.996400),
    (0.8083, 0.997975),
    (0.8219, 0.999100),
    (0.8282, 0.999600),
    (0.8308, 0.999804),
    (0.8321, 0.999900),
    (0.8330, 0.999975),
    (0.8334, 1.000000),
)
"""Our own thick slab's reflectance against its albedo (see the module note)."""

REFLECTANCE_MAX = SLAB_TABLE[-1][0]
"""What a thick slab of albedo 1 reflects through our boundary: the brightest A."""

_A = np.array([row[0] for row in SLAB_TABLE])
_U = np.sqrt(1.0 - np.array([row[1] for row in SLAB_TABLE]))  # √(1 − α), decreasing


def extinction_scale(colour: Any) -> np.ndarray:
    """Christensen & Burley 2015's s(A) = 1.9 − A + 3.5 (A − 0.8)²: σt = 1/(s·d)."""
    a = np.asarray(colour, dtype=np.float64)
    return 1.9 - a + 3.5 * (a - 0.8) ** 2


def interior(params: Any, meters_per_unit: float = 1.0) -> tuple[np.ndarray, np.ndarray]:
    """(σt per scene unit, single-scattering albedo), RGB, of a solid material's medium.

    ``meters_per_unit`` converts a scene whose unit is not the preset's: a preset's
    distances are metres, so in a scene of 5 cm units σt per unit is σt per metre × 0.05.
    """
    colour = np.asarray(params.base_color, dtype=np.float64)
    sigma_t = 1.0 / (extinction_scale(colour) * scatter_distances(params))
    return sigma_t * meters_per_unit, albedo_of(colour)


def albedo_of(colour: Any) -> np.ndarray:
    """The single-scattering albedo α whose thick slab reflects ``colour`` A
    (:data:`SLAB_TABLE`, linear in √(1 − α)); α = 1 from :data:`REFLECTANCE_MAX` up."""
    a = np.asarray(colour, dtype=np.float64)
    u = np.interp(a, _A, _U)
    return 1.0 - u * u


def colour_for_albedo(alpha: Any) -> np.ndarray:
    """The A a thick slab of albedo ``alpha`` reflects: the inverse of :func:`albedo_of`."""
    u = np.sqrt(np.clip(1.0 - np.asarray(alpha, dtype=np.float64), 0.0, 1.0))
    return np.interp(u, _U[::-1], _A[::-1])


def from_measured(
    sigma_s_reduced: Any, sigma_a: Any, unit: float = MM
) -> tuple[tuple[float, ...], float, tuple[float, ...]]:
    """(base colour, scatter_distance, scatter_distance_scale) of a measured medium.

    ``sigma_s_reduced``, ``sigma_a``: RGB per ``unit`` (metres; Jensen's mm by default).
    The distance is in metres; the scale is d per channel over its largest.

    >>> colour, d, scale = from_measured(*JENSEN_2001["marble"])
    >>> [round(c, 3) for c in colour], round(d * 1000, 3), [round(s, 3) for s in scale]
    ([0.821, 0.813, 0.804], 0.422, [1.0, 0.83, 0.719])
    """
    ss, sa = np.asarray(sigma_s_reduced, float), np.asarray(sigma_a, float)
    st = (ss + sa) / unit  # per metre
    colour = colour_for_albedo(ss / (ss + sa))
    d = 1.0 / (extinction_scale(colour) * st)
    top = float(d.max())
    return tuple(float(c) for c in colour), top, tuple(float(x) for x in d / top)
