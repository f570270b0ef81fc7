"""OpenPBR Surface's parameters (specification v1.1) and the closed forms its lobes share.

The schema names every input of ``ND_open_pbr_surface_surfaceshader`` that shapes the
BSDF, with the specification's defaults and ranges (:cite:`OpenPBR2024`). Inputs the model
of :mod:`.openpbr` does not evaluate (thin film, dispersion, volume depth and scatter,
emission) are accepted, so an imported material keeps them, and named by
:data:`NOT_MODELLED` wherever a figure depends on them.

The closed forms here are the specification's own:

- :func:`modulated_ior` — ``specular_weight`` scales the dielectric F0 by changing the IOR
  ratio (its equations "unmodulated_fresnel" and "modulated_ior"), the ratio itself
  blended towards ``specular_ior/coat_ior`` under a coat ("specular_ior_ratio");
- :func:`f82_tint` — the metal's Fresnel, Kutz et al.'s F82-tint :cite:`Kutz2021`;
- :func:`eon_table` — the energy-preserving Oren–Nayar diffuse (Fujii's form plus the
  compensation term, :cite:`Portsmouth2024`), its albedo integrated here numerically;
- :func:`darkening` — the coat's internal-reflection darkening Δ = (1 − K)/(1 − E_b K).

>>> round(modulated_ior(1.5, 1.0, 0.0, 1.6), 6)
1.5
>>> round(modulated_ior(1.5, 0.0, 0.0, 1.6), 6)
1.0
"""

from __future__ import annotations

import math
from functools import cache
from typing import TYPE_CHECKING, Annotated, Any

from pydantic import BeforeValidator, Field

from .params import Params, parse_color

if TYPE_CHECKING:
    import numpy as np

__all__ = [
    "NOT_MODELLED",
    "OpenPBRParams",
    "darkening",
    "eon",
    "eon_albedo",
    "eon_table",
    "f82_tint",
    "fresnel_average",
    "modulated_ior",
    "schlick_split",
    "schlick_split_table",
]

MU_BAR = 1.0 / 7.0
"""The F82-tint model's edge cosine (≈ 82°)."""


OpenChannel = Annotated[float, Field(ge=0.0, le=1e3)]
Color = Annotated[tuple[OpenChannel, OpenChannel, OpenChannel], BeforeValidator(parse_color)]
"""A colour input: non-negative; the specification's [0, 1] is a normal range, not a
bound (its own example materials, in ACEScg, reach 1.013)."""


def _u(default: float, description: str, le: float | None = 1.0) -> Any:
    return Field(default, ge=0.0, le=le, description=description)


class OpenPBRParams(Params):
    """OpenPBR Surface v1.1 inputs (the specification's names, defaults and ranges)."""

    base_weight: float = _u(1.0, "multiplier of the base albedo")
    base_color: Color = Field((0.8, 0.8, 0.8), description="albedo of the base (diffuse and metal)")
    base_metalness: float = _u(0.0, "mix towards the F82-tint conductor")
    base_diffuse_roughness: float = _u(0.0, "Oren–Nayar σ of the diffuse")
    specular_weight: float = _u(1.0, "dielectric F0 multiplier (via the IOR); metal scale", 1e3)
    specular_color: Color = Field(
        (1.0, 1.0, 1.0), description="tint of the specular (metal: F82 edge tint)"
    )
    specular_roughness: float = _u(0.3, "GGX roughness r, α = r²")
    specular_roughness_anisotropy: float = _u(0.0, "anisotropy of the specular lobe")
    specular_ior: float = Field(1.5, gt=0.0, le=1e3, description="IOR of the dielectric base")
    transmission_weight: float = _u(0.0, "mix towards the translucent base")
    transmission_color: Color = Field(
        (1.0, 1.0, 1.0), description="colour of the glass, reached at transmission_depth"
    )
    transmission_depth: float = _u(0.0, "distance at which transmission_color is reached", 1e9)
    transmission_scatter: Color = Field(
        (0.0, 0.0, 0.0), description="scattering coefficient of the interior"
    )
    transmission_scatter_anisotropy: float = Field(
        0.0, ge=-1.0, le=1.0, description="phase function g of the interior"
    )
    transmission_dispersion_scale: float = _u(0.0, "dispersion amount")
    transmission_dispersion_abbe_number: float = Field(
        20.0, gt=0.0, le=1e6, description="Abbe number of the dispersion"
    )
    subsurface_weight: float = _u(0.0, "mix towards the subsurface slab")
    subsurface_color: Color = Field((0.8, 0.8, 0.8), description="albedo of the subsurface")
    subsurface_radius: float = _u(1.0, "mean free path scale", 1e9)
    subsurface_radius_scale: Color = Field(
        (1.0, 0.5, 0.25), description="per-channel scale of the mean free path"
    )
    subsurface_scatter_anisotropy: float = Field(
        0.0, ge=-1.0, le=1.0, description="phase function g of the subsurface"
    )
    coat_weight: float = _u(0.0, "coverage of the coat")
    coat_color: Color = Field((1.0, 1.0, 1.0), description="absorption tint of the coat")
    coat_roughness: float = _u(0.0, "GGX roughness of the coat")
    coat_roughness_anisotropy: float = _u(0.0, "anisotropy of the coat")
    coat_ior: float = Field(1.6, gt=0.0, le=1e3, description="IOR of the coat")
    coat_darkening: float = _u(1.0, "1: the physical darkening under the coat; 0: none")
    fuzz_weight: float = _u(0.0, "coverage of the fuzz")
    fuzz_color: Color = Field((1.0, 1.0, 1.0), description="colour of the fuzz")
    fuzz_roughness: float = _u(0.5, "fibre-likeness of the fuzz")
    thin_film_weight: float = _u(0.0, "coverage of the thin film")
    thin_film_thickness: float = _u(0.5, "thickness in µm", 1e3)
    thin_film_ior: float = Field(1.4, gt=0.0, le=1e3, description="IOR of the thin film")
    emission_luminance: float = _u(0.0, "emitted luminance in nits", 1e12)
    emission_color: Color = Field((1.0, 1.0, 1.0), description="colour of the emission")
    geometry_opacity: float = _u(1.0, "coverage of the surface")
    geometry_thin_walled: bool = Field(False, description="a thin shell, not a solid")


NOT_MODELLED: dict[str, str] = {
    "thin_film_weight": "thin-film iridescence is not evaluated",
    "transmission_depth": "the volume under the surface is not traced: transmission_color "
    "tints the refraction at the surface (depth 0)",
    "transmission_scatter": "no volume scattering under the surface",
    "transmission_dispersion_scale": "no dispersion (one IOR for all wavelengths)",
    "subsurface_radius": "subsurface is its reflectance limit, a Lambertian of "
    "subsurface_color (no transport distance)",
    "geometry_thin_walled": "thin walls refract as the solid's surface (no slab offset); "
    "their subsurface is not transmitted",
    "emission_luminance": "emission is not part of the BSDF",
    "geometry_opacity": "the uncovered part is a pass-through, not scattered",
}
"""Input → what :mod:`.openpbr` leaves out when it is away from its default."""


def modulated_ior(
    specular_ior: float, specular_weight: float, coat_weight: float, coat_ior: float
) -> float:
    """The dielectric base's IOR ratio η′ after the coat blend and ``specular_weight``."""
    eta = (1.0 - coat_weight) * specular_ior + coat_weight * specular_ior / coat_ior
    f_s = ((1.0 - eta) / (1.0 + eta)) ** 2
    if f_s <= 0.0:
        return 1.0
    xi = min(max(specular_weight, 0.0), 1.0 / f_s)
    eps = math.copysign(math.sqrt(xi * f_s), eta - 1.0)
    return (1.0 + eps) / max(1.0 - eps, 1e-9)


def f82_tint(xp: Any, f0: Any, tint: Any, mu: Any) -> Any:
    """F82-tint: Schlick less a μ(1 − μ)⁶ term meeting ``tint``·Schlick at μ̄ = 1/7."""
    m = xp.maximum(1.0 - mu, 0.0)
    m5 = m * m * m * m * m
    schlick = f0 + (1.0 - f0) * m5
    bar5 = (1.0 - MU_BAR) ** 5
    s_bar = f0 + (1.0 - f0) * bar5
    denom = MU_BAR * (1.0 - MU_BAR) ** 6
    return schlick - (mu * m5 * m / denom) * (s_bar * (1.0 - tint))


def _fon(sigma: float, wi: np.ndarray, wo: np.ndarray) -> np.ndarray:
    """Fujii's Oren–Nayar f·π/ρ (without the compensation) for unit upper directions."""
    import numpy as np  # tables only: a preset's check imports no numpy

    a = 1.0 / (1.0 + (math.pi / 2.0 - 2.0 / 3.0) * sigma)
    b = sigma * a
    mu_i, mu_o = wi[..., 2], wo[..., 2]
    s = (wi * wo).sum(-1) - mu_i * mu_o
    t = np.where(s > 0.0, np.maximum(np.maximum(mu_i, mu_o), 1e-12), 1.0)
    return a + b * s / t


EON_MU = 33
EON_SIGMA = 17


@cache
def eon_table() -> np.ndarray:
    """Ê_ON(μ, σ) = ∫ f_ON cos θi dωi /ρ on μ nodes ``linspace(0, 1, EON_MU)`` (columns) and
    σ nodes ``linspace(0, 1, EON_SIGMA)`` (rows), by Gauss–Legendre quadrature."""
    import numpy as np

    x, w = np.polynomial.legendre.leggauss(48)
    mu_i = 0.5 * (x + 1.0)
    phi = math.pi * (x + 1.0)
    wm, wp = 0.5 * w, math.pi * w
    sin_i = np.sqrt(1.0 - mu_i * mu_i)
    wi = np.stack(
        [
            sin_i[:, None] * np.cos(phi)[None, :],
            sin_i[:, None] * np.sin(phi)[None, :],
            np.broadcast_to(mu_i[:, None], (48, 48)),
        ],
        -1,
    )
    weight = (wm[:, None] * wp[None, :]) * mu_i[:, None] / math.pi
    out = np.zeros((EON_SIGMA, EON_MU))
    for j, sigma in enumerate(np.linspace(0.0, 1.0, EON_SIGMA)):
        for k, mu in enumerate(np.linspace(0.0, 1.0, EON_MU)):
            wo = np.array([math.sqrt(max(1.0 - mu * mu, 0.0)), 0.0, mu])
            out[j, k] = float((_fon(sigma, wi, wo) * weight).sum())
    return out


def eon_albedo(xp: Any, mu: Any, sigma: float) -> Any:
    """Ê_ON(μ) at roughness σ, read bilinearly from :func:`eon_table`."""
    from .tables import bilinear

    x = xp.clip(mu, 0.0, 1.0) * (EON_MU - 1.0)
    return bilinear(xp, eon_table(), x, sigma * (EON_SIGMA - 1.0) + 0.0 * x)


def _eon_average(sigma: float) -> float:
    """⟨Ê_ON⟩ = 2 ∫ Ê_ON(μ) μ dμ (trapezoid on the table's μ nodes)."""
    import numpy as np

    row = np.array([np.interp(sigma, np.linspace(0.0, 1.0, EON_SIGMA), c) for c in eon_table().T])
    mu = np.linspace(0.0, 1.0, EON_MU)
    return float(np.trapezoid(2.0 * row * mu, mu))


def eon(xp: Any, rho: Any, sigma: float, wi: Any, wo: Any) -> Any:
    """The EON diffuse f(ωi, ωo) (no cosine), upper directions assumed."""
    if sigma <= 0.0:
        return rho * (1.0 / math.pi)
    a = 1.0 / (1.0 + (math.pi / 2.0 - 2.0 / 3.0) * sigma)
    s = xp.dot(wi, wo) - wi[2] * wo[2]
    t = xp.select(s > 0.0, xp.maximum(xp.maximum(wi[2], wo[2]), 1e-12), 1.0 + 0.0 * s)
    f_on = a + sigma * a * s / t
    e_avg = _eon_average(sigma)
    # ρ_ms as the white furnace requires (ρ = 1 → ∫ f cos = 1 at every view)
    rho_ms = (rho * rho) * (e_avg / (1.0 - e_avg)) / (1.0 - rho * (1.0 - e_avg))
    e_i, e_o = eon_albedo(xp, wi[2], sigma), eon_albedo(xp, wo[2], sigma)
    return (rho * f_on + rho_ms * ((1.0 - e_i) * (1.0 - e_o))) * (1.0 / math.pi)


@cache
def fresnel_average(eta: float) -> float:
    """E_F(η) = 2 ∫ F(μ, η) μ dμ of a smooth dielectric seen from outside."""
    import numpy as np

    from . import fresnel
    from .arrays import NumpyOps

    x, w = np.polynomial.legendre.leggauss(64)
    mu = 0.5 * (x + 1.0)
    f = fresnel.dielectric(NumpyOps(), mu, eta)
    return float((w * f * mu).sum())


def darkening(k: Any, e_base: Any) -> Any:
    """Δ = (1 − K)/(1 − E_b K): the interfaced-Lambertian darkening under a coat."""
    return (1.0 - k) / (1.0 - e_base * k)


SPLIT_MU = 32
SPLIT_R = 32


@cache
def schlick_split_table() -> np.ndarray:
    """B(μ, r) = ∫ f_ss(ωi, ωo) (1 − ωo·h)⁵ cos θi dωi of a white GGX lobe (F = 1), the
    Schlick-weighted part of its albedo E(μ, r), so that a lobe with Fresnel
    F0 + (1 − F0)(1 − ωo·h)⁵ reflects F0 (E − B) + B. Rows r = linspace(√ALPHA_MIN, 1),
    columns μ = linspace(0, 1)² (fixed-seed stratified visible-normal sampling, 256 per
    node)."""
    import numpy as np

    from .arrays import NumpyOps
    from .microfacet import ALPHA_MIN, sample_visible_ggx, smith_g1

    xp = NumpyOps()
    rng = np.random.default_rng(11)
    n = 256
    u = (np.arange(n)[:, None] + rng.random((n, 2))) / n  # stratified in u1
    mu = np.maximum(np.linspace(0.0, 1.0, SPLIT_MU) ** 2, 1e-4)
    wo = np.repeat(np.stack([np.sqrt(1.0 - mu * mu), 0.0 * mu, mu]), n, axis=1)
    u1, u2 = np.tile(u[:, 0], SPLIT_MU), np.tile(u[:, 1], SPLIT_MU)
    out = np.zeros((SPLIT_R, SPLIT_MU))
    for j, r in enumerate(np.linspace(math.sqrt(ALPHA_MIN), 1.0, SPLIT_R)):
        a = max(r * r, ALPHA_MIN)
        h = sample_visible_ggx(xp, wo, a, a, u1, u2)
        oh = np.clip((wo * h).sum(0), 0.0, 1.0)
        wi = 2.0 * oh * h - wo
        # the visible-normal estimator of ∫ f cos is G1(wi) per sample
        weight = np.where(wi[2] > 0.0, smith_g1(xp, wi, a, a), 0.0)
        out[j] = (weight * (1.0 - oh) ** 5).reshape(SPLIT_MU, n).mean(axis=1)
    return out


def schlick_split(xp: Any, mu: Any, r: Any) -> Any:
    """B(μ, r) of :func:`schlick_split_table`, read bilinearly."""
    from .microfacet import ALPHA_MIN
    from .tables import bilinear

    r0 = math.sqrt(ALPHA_MIN)
    x = xp.sqrt(xp.clip(mu, 0.0, 1.0)) * (SPLIT_MU - 1.0)
    y = (xp.clip(r, r0, 1.0) - r0) * ((SPLIT_R - 1.0) / (1.0 - r0))
    return bilinear(xp, schlick_split_table(), x, y + 0.0 * x)
