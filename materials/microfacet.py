"""Microfacet building blocks: GTR distributions, anisotropic Smith masking, sampling.

Written once over the array shim (:mod:`.arrays`); directions are channel-first vectors in
the shading frame (normal +z, tangent +x). References:

* :cite:t:`Burley2012`, Appendix B: the Generalized-Trowbridge-Reitz distribution (eqs. 1–9) and
  its anisotropic γ = 2 form (eqs. 10–15); the 2014 addendum's α_x, α_y.
* :cite:t:`Heitz2014`, eq. 86 (anisotropic
  GGX Λ), as the 2014 addendum adopts it.
* :cite:t:`Heitz2018`, listing 1.

**Minimum α, and below it a delta.** ``ALPHA_MIN`` = 10⁻³, the value of the Disney BRDF
Explorer (and Schutte's and Mitsuba's ``principled``), is the smallest α a *glossy* GGX
lobe takes: at it the peak D(n) = 1/(π α²) ≈ 3·10⁵ is still finite in float32, and
``sample``, ``pdf`` and ``eval`` all see the same α. Roughness used to be clamped up to it,
so every roughness below √10⁻³ ≈ 0.0316 already rendered alike, as a lobe 0.06° wide that
a renderer had to treat as glossy (sample lights at every vertex for nothing).
The rule now (:func:`is_delta`): a GGX lobe whose larger α (roughness²/aspect, computed
from the float32 roughness and anisotropy every consumer stores) is below ``ALPHA_MIN``
is the α → 0 limit itself, a Dirac delta (mirror reflection, Snell refraction), sampled
exactly and left out of ``eval``/``pdf`` (:mod:`.disney_interface`). Only constants
decide: a roughness that varies per element (a texture) stays glossy with the clamp,
since the kernel's lobe kinds are fixed when it is traced. An anisotropic lobe with one
α above the minimum stays glossy and its other α is clamped.

**Stability of the GTR normalisation** (eq. 1) at γ → 1 and α → 1: with L = log α² and
t = (1 − γ) L the constant is

    c = (γ − 1)(α² − 1) / (π (1 − (α²)^(1−γ)))  =  exprel(L) / (π exprel(t)),

where exprel(x) = (eˣ − 1)/x → 1 as x → 0 is computed with ``expm1`` and a first-order
series within 10⁻⁶ of 0: eq. 4 (γ = 1) and 1/π (α = 1) are its limits, and there is no
0/0 anywhere near them.

>>> import numpy as np
>>> from .arrays import NumpyOps
>>> xp = NumpyOps()
>>> round(float(gtr_norm(xp, 2.0, 0.25)), 6) == round(0.25 / np.pi, 6)   # eq. 8
True
>>> round(float(gtr_norm(xp, 1.0, 1.0) * np.pi), 12)                      # α = 1
1.0
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from . import fresnel as fr

__all__ = [
    "ALPHA_MIN",
    "CLEARCOAT_G_ALPHA",
    "anisotropic_alphas",
    "dielectric_btdf",
    "exprel",
    "g1_over_cos",
    "g1_pair_denominator",
    "g1_pair_over_cos",
    "ggx_d",
    "ggx_d_denominator",
    "ggx_dg_over_cos",
    "ggx_roughness_like_gtr",
    "gtr_d",
    "gtr_half_max_sin2",
    "gtr_norm",
    "gtr_sample_cos2",
    "gtr_sample_sin2",
    "is_delta",
    "log_exprel",
    "projected_roughness",
    "reflect",
    "refract",
    "sample_ggx",
    "sample_gtr",
    "sample_visible_ggx",
    "smith_g1",
    "transmission_half",
    "visible_ggx_pdf",
]

ALPHA_MIN = 1e-3
CLEARCOAT_G_ALPHA = 0.25  # Burley 2012 §5.6: the clearcoat's fixed GGX G roughness
_SERIES = 1e-6  # |x| below which exprel and the sampling ratio use their series


# -- GTR, any γ > 0 (Burley App. B.2) --------------------------------------------------------
def exprel(xp: Any, x: Any) -> Any:
    """(eˣ − 1)/x, exact to rounding everywhere including x = 0 (limit 1)."""
    small = xp.abs(x) < _SERIES
    safe = xp.select(small, 1.0, x)
    return xp.select(small, 1.0 + 0.5 * x, xp.expm1(safe) / safe)


def gtr_norm(xp: Any, gamma: float, a2: Any) -> Any:
    """The constant c of eq. 1 (eq. 4 at γ = 1, 1/π at α = 1), as exprel(L)/(π exprel(t))."""
    log_a2 = xp.log(a2)
    return exprel(xp, log_a2) / (math.pi * exprel(xp, (1.0 - gamma) * log_a2))


def log_exprel(xp: Any, x: Any) -> Any:
    """log((eˣ − 1)/x) without overflow: max(x, 0) + log exprel(−|x|) (exprel(−|x|) ∈ (0, 1]).

    exprel(x) = eˣ exprel(−x), so for x > 0 the large factor eˣ is taken as its exponent:
    at γ = 10, α = 10⁻³ the normalisation's t = (1 − γ) log α² = 124 and e¹²⁴ overflows
    float32 (its largest exponent is 88.7), while D itself, ≈ (γ − 1)/(π α²), is 3·10⁶.
    """
    pos = xp.maximum(x, 0.0)
    return pos + xp.log(exprel(xp, x - 2.0 * pos))


def gtr_d(xp: Any, gamma: Any, a2: Any, cos2_h: Any, sin2_h: Any) -> Any:
    """D_GTR(θh) of eq. 1 from cos²θh and sin²θh (α² cos² + sin² = 1 + (α² − 1) cos²).

    Taking sin²θh separately (from the half vector's x, y) keeps the peak accurate: at
    α = 10⁻³ the denominator is 10⁻⁶ and 1 − cos² would lose it in float32.
    γ = 1 (the clearcoat) is c/(α² cos² + sin²) directly (one division, no exp or log in
    the kernel: the denominator is ≥ α² ≥ 10⁻⁶ wherever h ≠ 0); any other γ forms
    D = exp(log c − γ log(α² cos² + sin²)) (:func:`log_exprel`), because at large γ the
    normalisation c → 0 and the power → ∞ overflow separately in float32 (γ = 10, α = 10⁻³:
    c ≈ 10⁻⁵³, power 10⁶⁰) while their product is finite.
    """
    base = a2 * cos2_h + sin2_h
    if isinstance(gamma, float) and gamma == 1.0:
        c = gtr_norm(xp, gamma, a2)
        c = float(c) if isinstance(a2, float) else c  # a constant must not promote float32
        return c / base
    if isinstance(a2, float) and isinstance(gamma, float):
        log_c = _log_gtr_norm(gamma, a2)  # a Python float: must not promote float32 arrays
    else:
        log_a2 = xp.log(a2)
        log_c = log_exprel(xp, log_a2) - log_exprel(xp, (1.0 - gamma) * log_a2)
        log_c = log_c - math.log(math.pi)
    return xp.exp(log_c - gamma * xp.log(base))


def _log_gtr_norm(gamma: float, a2: float) -> float:
    """log c of eq. 1 for constants, in double precision (see :func:`log_exprel`)."""

    def log_exprel_f(x: float) -> float:
        if abs(x) < _SERIES:
            return math.log1p(0.5 * x)
        return max(x, 0.0) + math.log(-math.expm1(-abs(x)) / abs(x))

    log_a2 = math.log(a2)
    return log_exprel_f(log_a2) - log_exprel_f((1.0 - gamma) * log_a2) - math.log(math.pi)


def gtr_sample_cos2(xp: Any, gamma: Any, a2: Any, xi: Any) -> Any:
    """cos²θh from a uniform ξ (eq. 3; eq. 5 at γ = 1, eq. 9 at γ = 2), stably.

    With u = 1 − ξ, eq. 3's bracket is 1 + u·expm1(t) and its power 1/(1 − γ) = L/t, so
    cos²θh = r·exprel(L r)/exprel(L) with r = log1p(u·expm1(t))/t, whose t → 0 limit is
    u(1 + ξt/2) (eq. 5 is r = u). For t > 1 (γ > 1 on a sharp lobe) expm1(t) overflows
    float32 near γ = 10 (t = 124 at α = 10⁻³), and r = 1 − s with the s of
    :func:`gtr_sample_sin2`, which only takes e^{−t}, is used instead.
    """
    log_a2 = xp.log(a2)
    t = (1.0 - gamma) * log_a2
    u = 1.0 - xi
    small = xp.abs(t) < _SERIES
    large = t > 1.0
    safe = xp.select(small | large, -1.0, t)  # the first form only where it cannot overflow
    r = xp.select(small, u * (1.0 + 0.5 * xi * t), xp.log1p(u * xp.expm1(safe)) / safe)
    r = xp.select(large, 1.0 - _sin_split(xp, t, xi, u), r)
    return xp.clip(r * exprel(xp, log_a2 * r) / exprel(xp, log_a2), 0.0, 1.0)


def _sin_split(xp: Any, t: Any, xi: Any, u: Any) -> Any:
    """s = 1 − r of eq. 3 (see :func:`gtr_sample_sin2`), stable for t > 0 of any size."""
    small = xp.abs(t) < _SERIES
    safe = xp.select(small, 1.0, t)
    x = xi * xp.expm1(-safe)
    log_a = xp.select(x >= -0.5, xp.log1p(x), xp.log(u + xi * xp.exp(-safe)))
    s = xp.select(small, xi * (1.0 - 0.5 * u * t), -log_a / safe)
    return xp.clip(s, 0.0, 1.0)  # float32 at γ > 1, α → 0: log1p(−1) = −∞ where s → 1


def gtr_sample_sin2(xp: Any, gamma: float, a2: Any, xi: Any) -> Any:
    """sin²θh = 1 − cos²θh of :func:`gtr_sample_cos2`, without the cancellation.

    cos²θh = expm1(L r)/expm1(L) (L = log α²), so sin²θh = e^{L r}·expm1(L s)/expm1(L)
    with s = 1 − r = −log(a)/t, a = 1 + ξ·expm1(−t) = u + ξ·e^{−t} (series ξ(1 − u t/2)).
    Near the peak of a sharp lobe (α = 10⁻³, ξ → 0) 1 − cos² loses every digit in float32;
    this keeps them. log a is taken as log1p(ξ·expm1(−t)) where a ≥ ½ and as log(u + ξ·e^{−t})
    where a < ½ (only at γ > 1, t > 0: a sum of two positive terms, no cancellation): near
    ξ = 1, 1 + ξ·expm1(−t) would cancel to e^{−t} and lose the digits of s → 1 instead.
    """
    log_a2 = xp.log(a2)
    s = _sin_split(xp, (1.0 - gamma) * log_a2, xi, 1.0 - xi)
    sin2 = xp.exp(log_a2 * (1.0 - s)) * s * exprel(xp, log_a2 * s) / exprel(xp, log_a2)
    return xp.clip(sin2, 0.0, 1.0)


def sample_gtr(xp: Any, gamma: float, a2: Any, u1: Any, u2: Any) -> Any:
    """A micro-normal with density D_GTR(h) cos θh (eqs. 2–3)."""
    cos2 = gtr_sample_cos2(xp, gamma, a2, u2)
    sin_t = xp.sqrt(gtr_sample_sin2(xp, gamma, a2, u2))
    phi = 2.0 * math.pi * u1
    return xp.vec3(sin_t * xp.cos(phi), sin_t * xp.sin(phi), xp.sqrt(cos2))


def gtr_half_max_sin2(gamma: float, alpha: float) -> float:
    """sin²θh where D_GTR(θh) falls to half its peak: the highlight's half width.

    From eq. 1, D(θh)/D(0) = (α²/(α² + (1 − α²) sin²θh))^γ = ½ at
    sin²θh = α² (2^{1/γ} − 1)/(1 − α²); infinite at α = 1 (D is flat there).
    """
    a2 = max(alpha, ALPHA_MIN) ** 2
    return math.inf if a2 >= 1.0 else a2 * math.expm1(math.log(2.0) / gamma) / (1.0 - a2)


def ggx_roughness_like_gtr(gamma: float, roughness: float) -> float:
    """The roughness whose GGX (γ = 2) highlight is as wide as GTR γ's at ``roughness``.

    Width = the half-maximum of D in θh (:func:`gtr_half_max_sin2`), the angular size
    of the highlight seen at normal incidence (tests/materials/test_microfacet.py measures
    it on the model's own BRDF slice). Solving GGX's half width x = α²(√2 − 1)/(1 − α²)
    for α² gives α² = x/(√2 − 1 + x); roughness = √α. Identity at γ = 2.

    >>> round(ggx_roughness_like_gtr(2.0, 0.5), 12), round(ggx_roughness_like_gtr(1.0, 0.5), 4)
    (0.5, 0.6102)
    """
    if gamma == 2.0:
        return roughness
    x = gtr_half_max_sin2(gamma, roughness * roughness)
    a2 = 1.0 if math.isinf(x) else x / (math.sqrt(2.0) - 1.0 + x)
    return min(a2**0.25, 1.0)


# -- anisotropic GTR2 = GGX (Burley App. B, eqs. 10–15; 2014 addendum) ------------------
def anisotropic_alphas(xp: Any, roughness: Any, anisotropic: Any) -> tuple[Any, Any]:
    """α_x = r²/aspect, α_y = r²·aspect, aspect = √(1 − 0.9·anisotropic) (2014 addendum).

    Both are clamped below at :data:`ALPHA_MIN` (as the BRDF Explorer does).
    """
    a = roughness * roughness
    if isinstance(a, float) and isinstance(anisotropic, float):
        # Constants stay Python floats, so they fold into float32 arrays without promoting.
        aspect = math.sqrt(1.0 - 0.9 * anisotropic)
        return max(a / aspect, ALPHA_MIN), max(a * aspect, ALPHA_MIN)
    if xp.known_zero(anisotropic):
        a = xp.maximum(a, ALPHA_MIN)
        return a, a
    aspect = xp.sqrt(1.0 - 0.9 * anisotropic)
    return xp.maximum(a / aspect, ALPHA_MIN), xp.maximum(a * aspect, ALPHA_MIN)


def is_delta(roughness: Any, anisotropic: Any = 0.0) -> bool:
    """True when a GGX lobe of this roughness is a delta (see the module docstring).

    Decided on constants only (Python floats, rounded to float32 as stored in a scene),
    so the numpy backend and the Mitsuba plugin agree; per-element values give False.

    >>> is_delta(0.0), is_delta(0.02), is_delta(0.05), is_delta(0.03, 1.0)
    (True, True, False, False)
    """
    if not (isinstance(roughness, float) and isinstance(anisotropic, float)):
        return False
    r = float(np.float32(roughness))
    aspect = math.sqrt(1.0 - 0.9 * float(np.float32(anisotropic)))
    return r * r / aspect < ALPHA_MIN


def ggx_d(xp: Any, h: Any, ax: Any, ay: Any, n2: Any = None) -> Any:
    """D_GTR2aniso(h) = 1/(π αx αy ((h·x)²/αx² + (h·y)²/αy² + (h·n)²)²) (eq. 13).

    ``h`` need not be normalised: D is evaluated at h/|h| (the ratio is homogeneous);
    ``n2`` = |h|² when the caller knows it (1 for a unit h).
    """
    if n2 is None:
        n2 = h[0] * h[0] + h[1] * h[1] + h[2] * h[2]
    return (n2 * n2) / ggx_d_denominator(xp, h, ax, ay)  # h = 0 gives 0


def ggx_d_denominator(xp: Any, h: Any, ax: Any, ay: Any) -> Any:
    """‖h‖⁴/D of :func:`ggx_d` (1/D at a unit ``h``), π αx αy (…)², for a caller that
    divides by D's denominator and its own at once (one division instead of two)."""
    hx, hy, hz = h[0] / ax, h[1] / ay, h[2]
    s = hx * hx + hy * hy + hz * hz
    return (math.pi * ax * ay) * xp.maximum(s * s, xp.tiny)


def sample_ggx(xp: Any, ax: Any, ay: Any, u1: Any, u2: Any) -> Any:
    """A micro-normal with density D(h) cos θh via the projected half vector (eqs. 14–15)."""
    phi = 2.0 * math.pi * u1
    t = xp.sqrt(u2 / xp.maximum(1.0 - u2, 1e-30))
    return xp.normalize(xp.vec3(t * ax * xp.cos(phi), t * ay * xp.sin(phi), 1.0 + 0.0 * t))


# -- Smith masking (Heitz 2014) -------------------------------------------------------------
def smith_g1(xp: Any, w: Any, ax: Any, ay: Any) -> Any:
    """G1(w) = 1/(1 + Λ(w)), Λ = (−1 + √(1 + (αx²wx² + αy²wy²)/wz²))/2 (Heitz 2014 eq. 86).

    Written as 2|wz| / (|wz| + √(wz² + αx²wx² + αy²wy²)): no tan θ, so grazing w (wz → 0)
    gives 0 instead of ∞/∞, and w = n gives exactly 1.
    """
    z = xp.abs(w[2])
    return z * g1_over_cos(xp, z, projected_roughness(w, ax, ay))


def projected_roughness(w: Any, ax: Any, ay: Any) -> Any:
    """q = αx² wx² + αy² wy², the roughness Smith's Λ sees along w (Heitz 2014 eq. 86)."""
    return (ax * w[0]) * (ax * w[0]) + (ay * w[1]) * (ay * w[1])


def g1_over_cos(xp: Any, z: Any, q: Any, z2: Any = None) -> Any:
    """G1(w)/cos θ = 2/(z + √(z² + q)), q = αx²wx² + αy²wy², for z = cos θ ≥ 0.

    The form a microfacet BRDF needs (G1(wi) G1(wo) / (4 cos θi cos θo)): finite as
    z → 0, where G1 and cos θ both vanish.
    """
    return 2.0 / _g1_denominator(xp, z, q, z2)


def _g1_denominator(xp: Any, z: Any, q: Any, z2: Any = None) -> Any:
    z2 = z * z if z2 is None else z2
    # For z ≥ 0 and α ≥ ALPHA_MIN the denominator is ≥ 10⁻³ or ≥ 2z; the floor 10⁻⁶ only
    # keeps masked-out directions (z = 0, q = 0) finite.
    return xp.maximum(z + xp.sqrt(z2 + q), 1e-6)


def g1_pair_denominator(xp: Any, zi: Any, qi: Any, zo: Any, qo: Any, zi2=None, zo2=None):
    """dᵢ dₒ with G1(wi) G1(wo)/(cos θi cos θo) = 4/(dᵢ dₒ) (:func:`g1_over_cos`)."""
    return _g1_denominator(xp, zi, qi, zi2) * _g1_denominator(xp, zo, qo, zo2)


def g1_pair_over_cos(xp: Any, zi: Any, qi: Any, zo: Any, qo: Any, zi2=None, zo2=None) -> Any:
    """G1(wi) G1(wo)/(cos θi cos θo) = :func:`g1_over_cos` of both directions, as
    4/(dᵢ dₒ): one division instead of two (each d ≥ 10⁻⁶, so the product stays normal)."""
    return 4.0 / g1_pair_denominator(xp, zi, qi, zo, qo, zi2, zo2)


_SCALE = 2.0**64  # a power of two: scaling by it rounds nothing


def ggx_dg_over_cos(xp: Any, h: Any, n2: Any, ax: Any, ay: Any, g_den: Any) -> Any:
    """D(h) G1(wi) G1(wo)/(cos θi cos θo) of :func:`ggx_d` (h unnormalised, |h|² = ``n2``)
    and ``g_den`` (:func:`g1_pair_denominator`), with one division instead of two.

    For a reflection pair (h_z > 0) D's denominator is ≥ π αx αy (0.1 n2)², which at a
    grazing pair with α = 10⁻³ is 10⁻³⁶, and d_i d_o ≥ 10⁻⁶: their product would fall
    below float32's normal range, so numerator and denominator are both scaled by 2⁶⁴
    (the largest product, ≈ 10⁹, stays far from overflow)."""
    return ((4.0 * _SCALE) * (n2 * n2)) / ((ggx_d_denominator(xp, h, ax, ay) * _SCALE) * g_den)


# -- visible normals (Heitz 2018) ------------------------------------------------------------
def sample_visible_ggx(xp: Any, wo: Any, ax: Any, ay: Any, u1: Any, u2: Any) -> Any:
    """A micro-normal h with density D_wo(h) = G1(wo) max(0, wo·h) D(h) / wo.z.

    ``wo`` must lie in the upper hemisphere (callers flip it). Heitz 2018, listing 1.
    """
    vh = xp.normalize(xp.vec3(ax * wo[0], ay * wo[1], wo[2]))
    lensq = vh[0] * vh[0] + vh[1] * vh[1]
    inv = 1.0 / xp.sqrt(xp.select(lensq > 0.0, lensq, 1.0))
    t1 = xp.vec3(
        xp.select(lensq > 0.0, -vh[1] * inv, 1.0), xp.select(lensq > 0.0, vh[0] * inv, 0.0), 0.0
    )
    t2 = xp.cross(vh, t1)
    r = xp.sqrt(u1)
    phi = 2.0 * math.pi * u2
    p1 = r * xp.cos(phi)
    p2 = r * xp.sin(phi)
    s = 0.5 * (1.0 + vh[2])
    p2 = (1.0 - s) * xp.safe_sqrt(1.0 - p1 * p1) + s * p2
    nh = t1 * p1 + t2 * p2 + vh * xp.safe_sqrt(1.0 - p1 * p1 - p2 * p2)
    return xp.normalize(xp.vec3(ax * nh[0], ay * nh[1], xp.maximum(nh[2], 0.0)))


def visible_ggx_pdf(xp: Any, wo: Any, h: Any, ax: Any, ay: Any) -> Any:
    """D_wo(h) of :func:`sample_visible_ggx` (``wo`` upper, ``h`` unit)."""
    cos_o = xp.maximum(wo[2], xp.tiny)
    return smith_g1(xp, wo, ax, ay) * xp.maximum(xp.dot(wo, h), 0.0) * ggx_d(xp, h, ax, ay) / cos_o


def transmission_half(xp: Any, wi: Any, wo: Any, eta: Any) -> Any:
    """Walter et al. 2007's generalised half vector ∝ wi·η + wo, turned to the upper side.

    ``wo`` is on the side of relative IOR 1, ``wi`` across the interface (η = η_wi/η_wo).
    """
    h = xp.normalize(wi * eta + wo)
    one = xp.full(h[2], 1.0)  # keeps the dtype of h
    return h * xp.select(h[2] < 0.0, -one, one)


def dielectric_btdf(
    xp: Any,
    wi: Any,
    wo: Any,
    eta: Any,
    ax: Any,
    ay: Any,
    pdf: bool,
    h: Any = None,
    inv_eta: Any = None,
    g: Any = None,
    fresnel: Any = None,
    g_den: Any = None,
) -> Any:
    """Rough dielectric transmission (Walter et al. 2007 eq. 21; pbrt-v4 DielectricBxDF).

    f = (1 − F) D G1(wi) G1(wo) |wi·h| |wo·h| / (|cos θi| cos θo (wi·h + wo·h/η)² η²),
    the last 1/η² for radiance transport. ``wo`` is up (relative IOR 1), ``wi`` below,
    ``eta`` = η_wi/η_wo. With ``pdf``: the density of refracting ``wo`` about a visible
    normal, D_wo(h) |wi·h| / (wi·h + wo·h/η)². Zero where no microfacet connects them.
    ``h``: :func:`transmission_half` of (wi, wo), when the caller has it already;
    ``inv_eta``: 1/η, when the caller has it without a division (:func:`.fresnel.dielectric`);
    ``g``: G1(wi) G1(wo)/(|cos θi| cos θo) (:func:`g1_pair_over_cos`), when the caller
    shares its terms with a reflection lobe, or ``g_den``, its denominator dᵢ dₒ
    (:func:`g1_pair_denominator`), which then joins the one division; ``fresnel``:
    F(wo·h, η) (:func:`.fresnel.dielectric`), when the caller has it (wherever ``ok``).
    """
    inv_eta = 1.0 / eta if inv_eta is None else inv_eta
    h = transmission_half(xp, wi, wo, eta) if h is None else h
    ih, oh = xp.dot(wi, h), xp.dot(wo, h)
    ok = (ih < 0.0) & (oh > 0.0)
    denom = ih + oh * inv_eta
    denom2 = xp.maximum(denom * denom, xp.tiny)
    if pdf:
        return xp.select(ok, visible_ggx_pdf(xp, wo, h, ax, ay) * xp.abs(ih) / denom2, 0.0)
    if g is None and g_den is None:
        qi, qo = projected_roughness(wi, ax, ay), projected_roughness(wo, ax, ay)
        g = g1_pair_over_cos(xp, -wi[2], qi, wo[2], qo)
    if fresnel is None:
        fresnel = fr.dielectric(xp, oh, eta, inv_eta)
    f = (1.0 - fresnel) * (4.0 if g_den is not None else g) * xp.abs(ih * oh) * (inv_eta * inv_eta)
    # h is a unit vector, so D = 1/denominator, and that denominator is ≥ 0.01·π αx αy
    # (α ≤ 3.2): where ``ok``, h ≠ 0 and denom² = |wi η + wo|²/η² > 0, so one division
    # by the product serves both (and G's, each of its d ≥ 10⁻⁶: the product stays normal).
    den = denom2 * ggx_d_denominator(xp, h, ax, ay)
    return xp.select(ok, f / (den if g_den is None else den * g_den), 0.0)


def reflect(xp: Any, w: Any, h: Any) -> Any:
    """Mirror ``w`` about the unit normal ``h``: 2(w·h)h − w (Burley App. B.1)."""
    return h * (2.0 * xp.dot(w, h)) - w


def refract(xp: Any, w: Any, h: Any, eta: Any) -> tuple[Any, Any]:
    """Refract ``w`` (pointing away, on h's side) through ``h``; ``eta`` = η_t/η_i.

    Returns (direction, valid): ``valid`` is False under total internal reflection.
    """
    c = xp.dot(w, h)
    sin2_t = (1.0 - c * c) / (eta * eta)
    cos_t = xp.safe_sqrt(1.0 - sin2_t)
    d = h * (c / eta - cos_t) - w * (1.0 / eta)
    return d, sin2_t < 1.0
