"""The lobe shapes of Smits' Wall-E/Up model, over the array shim (:mod:`.arrays`).

Smits writes every lobe as π × BRDF ("a traditional diffuse BRDF is a constant [1]";
his energy plots divide by π). Here every function is the BRDF itself, so a white
traditional diffuse is 1/π and the hemispherical integrals are the plain ones.

Transcription traps in the seed (:doc:`/design`): ``(1 - cos)5`` is (1 − cos)⁵; ``FrnBlend``
and ``FrnlBlend`` are one function; ``PSpecular``'s trailing ``4`` divides.

>>> from lookdev.materials.arrays import NumpyOps
>>> xp = NumpyOps()
>>> float(frn_blend(xp, 0.04, 1.0, 1.0)), float(frn_blend(xp, 0.04, 1.0, 0.0))
(0.04, 1.0)
>>> round(float(power_specular(xp, 1.0, 1.0)), 4)  # ln 10 / sin²35°
6.999
"""

from __future__ import annotations

import math
from typing import Any

__all__ = [
    "CONE_MIN_DEG",
    "DEG",
    "INV_PI",
    "LN_10",
    "back_view",
    "cone_power",
    "cosine_hemisphere",
    "distribution",
    "frn_blend",
    "half_vector_pdf",
    "p_diffuse",
    "p_specular",
    "power_reflection",
    "power_specular",
    "reflect",
    "reflection_cone",
    "sample_half_vector",
    "schlick_weight",
    "sin2_of",
    "specular_cone",
    "to_back",
    "weight",
]

INV_PI = 1.0 / math.pi
LN_10 = math.log(10.0)
DEG = math.pi / 180.0
CONE_MIN_DEG = 0.5
"""The tightest highlight cone (degrees): Smits' powerR is infinite at roughness 0, and he
takes "0 (or epsilon in practice)". 0.5° is about the sun's disc: a mirror for any proof
resolution, and its power (3.0e4) keeps exp(−p sin²θ) and p itself well inside float32."""


def schlick_weight(xp: Any, cos_theta: Any) -> Any:
    """s = (1 − cos θ)⁵, with cos θ clipped to 0..1: 0 at normal incidence, 1 at grazing."""
    c = xp.clip(cos_theta, 0.0, 1.0)
    t = (1.0 - c) * (1.0 - c)
    return t * t * (1.0 - c)


def frn_blend(xp: Any, normal: Any, grazing: Any, cos_theta: Any) -> Any:
    """Smits' generalised Schlick: Mix[normal, grazing, (1 − cos θ)⁵]."""
    return xp.lerp(normal, grazing, schlick_weight(xp, cos_theta))


def p_diffuse(xp: Any, cos_u: Any, cos_v: Any, norm_refl: Any, grazing_refl: Any) -> Any:
    """``PDiffuse`` / π: FrnBlend[1 − nRefl, 1 − gRefl, u·n] FrnBlend[…, v·n] / π."""
    a, b = 1.0 - norm_refl, 1.0 - grazing_refl
    return frn_blend(xp, a, b, cos_u) * frn_blend(xp, a, b, cos_v) * INV_PI


def specular_cone(r: Any, scale: Any = 1.0) -> Any:
    """Smits' specular cone angle in degrees, (30 r + 5)° × ``specular_cone_scale``.

    His powerS falls to 10 % at ``Sin[(30 r + 5) Degree]``: "cone angle … goes from 5
    degrees to 35 degrees based on roughness" (seed, PSpecular). Arithmetic only, so
    floats and either backend's arrays.

    >>> specular_cone(0.0), specular_cone(1.0), specular_cone(0.5, 2.0)
    (5.0, 35.0, 40.0)
    """
    return (30.0 * r + 5.0) * scale


def reflection_cone(r: Any, scale: Any = 1.0) -> Any:
    """Smits' reflection cone angle in degrees, 10 r° × ``reflection_cone_scale``.

    "The reflection cone angle goes between 0 (or epsilon in practice) and 10 degrees"
    (seed, powerR). 0 at roughness 0 here; :func:`cone_power` floors it at
    :data:`CONE_MIN_DEG` where a lobe is evaluated.

    >>> reflection_cone(0.0), reflection_cone(1.0), reflection_cone(0.5, 2.0)
    (0.0, 10.0, 10.0)
    """
    return (10.0 * r) * scale


def cone_power(xp: Any, falloff_log: Any, cone_deg: Any) -> Any:
    """−log(falloff)/sin²(cone): the exponent at which the lobe falls to ``falloff``."""
    s = xp.sin(xp.maximum(cone_deg, CONE_MIN_DEG) * DEG)
    return falloff_log / (s * s)


def power_specular(xp: Any, r: Any, cone_scale: Any = 1.0) -> Any:
    """powerS[r] = −Log[0.1^r] / Sin[(30 r + 5)°]² (0 at r = 0: a flat, unused lobe)."""
    return cone_power(xp, r * LN_10, specular_cone(r, cone_scale))


def power_reflection(xp: Any, r: Any, cone_scale: Any = 1.0) -> Any:
    """powerR[r] = −Log[0.1] / Sin[(10 r)°]², with the cone floored at CONE_MIN_DEG."""
    return cone_power(xp, LN_10, reflection_cone(r, cone_scale))


def _floored(xp: Any, p: Any) -> Any:
    """powerS is exactly 0 at roughness 0, where weightS = p/(1 − e^(−p)) is 0/0 (limit 1).
    At the dtype's smallest normal number expm1(−p) = −p exactly, so the ratio is exactly
    its limit there and the floor changes nothing else."""
    return xp.maximum(p, xp.tiny)


def _expm1(xp: Any, x: Any) -> Any:
    """e^x − 1; a constant (a Python float, known when the kernel is traced) folds here.

    Dr.Jit's select evaluates both branches on Python floats, so the shim's Kahan expm1
    divides by log(1) = 0 for a constant near 0 (Smits' weightS at roughness 0).
    """
    return math.expm1(x) if isinstance(x, float) else xp.expm1(x)


def weight(xp: Any, p: Any) -> Any:
    """weightS = p / (1 − e^(−p)) through expm1, continuous into its limit 1 at p = 0."""
    q = _floored(xp, p)
    return q / -_expm1(xp, -q)


def distribution(xp: Any, sin2_h: Any, p: Any) -> Any:
    """PSpecDist / π = weight · e^(−p sin²θh) / π, normalised: ∫ D cos θh dωh = 1."""
    q = _floored(xp, p)
    return weight(xp, q) * INV_PI * xp.exp(-q * sin2_h)


def sin2_of(xp: Any, h: Any) -> Any:
    """sin²θ of an unnormalised vector from its components (exact near the normal)."""
    return (h[0] * h[0] + h[1] * h[1]) / xp.maximum(xp.dot(h, h), xp.tiny)


def p_specular(xp: Any, wi: Any, wo: Any, p: Any, fn: Any, fg: Any, fresnel_cos: Any = None) -> Any:
    """``PSpecular`` / π: D(h) FrnBlend[N, G, u·h] / (4 ((n·u)² + (n·v)² − (n·u)(n·v))).

    Both directions above the surface; the caller masks. Colour weights broadcast.
    ``fresnel_cos`` replaces u·h in the Fresnel blend (the transmitted lobes blend by
    the front-side incidence). ``(n·u)² + (n·v)² − (n·u)(n·v)`` ≥ ((n·u)² + (n·v)²)/2
    vanishes only when both directions graze; it is floored at ε² (both within ε of the
    tangent plane), which keeps f finite in float32 and changes nothing elsewhere.
    """
    h = xp.normalize(wi + wo)
    ci, co = wi[2], wo[2]
    denom = 4.0 * xp.maximum(ci * ci + co * co - ci * co, xp.epsilon * xp.epsilon)
    d = distribution(xp, sin2_of(xp, h), p)
    cos_f = xp.dot(wi, h) if fresnel_cos is None else fresnel_cos
    return frn_blend(xp, fn, fg, cos_f) * (d / denom)


# -- sampling the Gaussian-of-sin distribution --------------------------------------------
def sample_half_vector(xp: Any, p: Any, u1: Any, u2: Any) -> Any:
    """h with density D(h) cos θh: sin²θh = −log(1 − u (1 − e^(−p))) / p, φ = 2πu2.

    The density of s = sin²θ is p e^(−ps)/(1 − e^(−p)) on [0, 1]; its inverse CDF goes
    through log1p/expm1 so it stays exact as p → 0, where s → u (the flat lobe); that
    limit is taken outright where u (1 − e^(−p)) underflows.
    """
    q = _floored(xp, p)
    x = u1 * _expm1(xp, -q)
    s = xp.clip(xp.select(x == 0.0, u1, -xp.log1p(x) / q), 0.0, 1.0)
    sin_t = xp.sqrt(s)
    phi = 2.0 * math.pi * u2
    return xp.vec3(sin_t * xp.cos(phi), sin_t * xp.sin(phi), xp.safe_sqrt(1.0 - s))


def half_vector_pdf(xp: Any, wi: Any, wo: Any, p: Any) -> Any:
    """Solid-angle density of wi = reflect(wo, h) with h ~ D cos θh: D cos θh / 4|wo·h|.

    The Jacobian 1/4|wo·h| is singular at wi = −wo, reachable only with both directions
    in the tangent plane; the density is taken as 0 where |wo·h| ≤ ε (as pbrt-v4 does at
    exactly grazing), so it cannot overflow float32 or meet a zero odds as 0 · ∞.
    """
    h = xp.normalize(wi + wo)
    d = distribution(xp, sin2_of(xp, h), p)
    cos_oh = xp.abs(xp.dot(wo, h))
    ok = cos_oh > xp.epsilon
    return xp.select(ok, d * xp.abs(h[2]) / (4.0 * xp.select(ok, cos_oh, 1.0)), 0.0)


def reflect(xp: Any, w: Any, h: Any) -> Any:
    """Mirror w about h (both unit): 2 (w·h) h − w."""
    return h * (2.0 * xp.dot(w, h)) - w


def cosine_hemisphere(xp: Any, u1: Any, u2: Any) -> Any:
    """Malley's method: a uniform disk point lifted onto the upper hemisphere."""
    r = xp.sqrt(u1)
    phi = 2.0 * math.pi * u2
    return xp.vec3(r * xp.cos(phi), r * xp.sin(phi), xp.safe_sqrt(1.0 - u1))


# -- transmission geometry ----------------------------------------------------------------
def back_view(xp: Any, wo: Any, eta: Any) -> Any:
    """Smits' transmitted-lobe view, in the back side's own frame (its normal is +z).

    The view is refracted into the surface by the IOR (total internal reflection cannot
    happen from outside), wt = −wo/η + n (cos θo/η − cos θt); reflecting wt off the
    surface gives the back-side view whose mirror direction is wt. Seen from the back
    (z ↦ −z) that view is simply −wt, and a lobe evaluated there with the back-side
    light (wi.x, wi.y, −wi.z) is centred on the refracted direction.
    """
    co = wo[2]
    cos_t = xp.safe_sqrt(1.0 - (1.0 - co * co) / (eta * eta))
    return xp.vec3(wo[0] / eta, wo[1] / eta, cos_t)


def to_back(xp: Any, w: Any) -> Any:
    """The same direction expressed in the back side's frame (z ↦ −z)."""
    return xp.vec3(w[0], w[1], -w[2])
