"""The Conty–Kulla microfacet sheen :cite:p:`Conty2017`.

A microfacet lobe for cloth, written once over the array shim (:mod:`.arrays`):

    f(ωi, ωo) = F · G · D(h) / (4 |ωo·n| |ωi·n|)                       (eq. 1)

with F the sheen colour, the exponentiated-sine fibre distribution D (eq. 2), the fitted
Smith Λ (eq. 3, Table 1) in the correlated form G = 1 / (1 + Λ(ωo) + Λ(ωi)) (§3), and,
on by default, the terminator softening Λ'(θi) = Λ(θi)^(1 + 2(1 − cos θi)^8) (eq. 4) on
the *light* side only. The softening is the paper's one non-physical step: with it the
BRDF is **not reciprocal**, f(ωi, ωo) ≠ f(ωo, ωi); switch it off
(``terminator_softening = false``) for a reciprocal lobe.

Sampling is uniform over the upper hemisphere (§2: it beats inverting D's CDF, whose
weights divide by cos θm near grazing), pdf 1/2π.

Layering (§5) scales the base by an albedo-derived factor; see :func:`base_scale` for
the reading taken. The directional albedo E(μ, r) is the table in :mod:`.sheen_albedo`,
with and without softening, at 64 μ × 32 r nodes. The size was chosen by measuring the
bilinear read against direct quadrature at off-node points
(``sheen_fit.albedo_table_error``); worst absolute error over μ ∈ [0, 1], r ∈ [R_MIN, 1]:
16×16: 7.9e-3, 32×32: 4.1e-3, 64×16: 3.3e-3, **64×32: 1.5e-3**, 64×64: 1.6e-3,
128×32: 6.8e-4. 1.5e-3 is the most the layering can gain (tests/materials/test_sheen.py).

Roughness: the paper's r lies in (0, 1] and, with the fitted Λ (``sheen_lambda = "fit"``),
r is clamped to :data:`R_MIN` = 0.08.
Table 1's "r = 0" row cannot be a fit at r → 0, where D tends to a delta at θm = 90°
and Λ to infinity; measured against the integrated Λ (``lookdev.pipeline.analysis.
sheen_fit``), the fit is under half the true Λ below r ≈ 0.03 and the lobe then reflects
more than it receives (albedo 1.04 at r = 0.01, cos θ = 0.01; without the softening
already 1.10 at r = 0.05). From r = 0.08 up the albedo stays below 0.96 either way.
Over r ∈ [0.08, 1], cos θ ∈ [0.01, 1] the fit's worst relative error is 0.21 (at r = 0.08,
cos θ = 0.97, counting Λ ≥ 0.01 only); the r = 1 row is within 6% (tests/materials/test_sheen.py
prints the figures, ``sheen_fit.lambda_fit_error`` computes them).

``sheen_lambda = "exact"`` replaces the fit by the integrated Λ, read from a table
(:mod:`.sheen_exact`, see :func:`lambda_exact`: 64 θ × 24 log r, worst relative error
1.6e-3), and lowers the floor to :data:`R_MIN_EXACT` = 0.01; its own albedo tables
(64 μ × 24 r on the same r nodes, worst error 1.25e-3, at most 7e-5 low) keep the
layering consistent. Measured over r ∈ [0.01, 1] (tests/materials/test_sheen.py): the lobe's albedo
stays ≤ 0.99992, ≤ 1.0001 over a white base. The default stays ``"fit"``: the paper's
model, which MaterialX's ``sheen_bsdf`` (``mode = "conty_kulla"``) implements, so a DCC
shows what the proofs show (the two modes' albedos differ by up to 0.07 at r = 0.3).

>>> import numpy as np
>>> round(float(D(np.float64(0.0), 1.0)), 6)  # (2 + 1)/2π · sin^1 90°
0.477465
>>> round(float(lambda_fit(np.float64(0.5), 1.0)), 5)  # e^L(0.5), Table 1 row r = 1
0.71003
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from pydantic import Field

from .arrays import NumpyOps
from .bsdf import Lobe, Model, Prepared, density, draw, evaluate
from .params import Color, Params, SheenLambda, register_schema
from .sheen_albedo import N_MU as _N_MU
from .sheen_albedo import N_R as _N_R
from .sheen_albedo import VALUES as _TABLE_VALUES
from .sheen_exact import ALBEDO as _EXACT_ALBEDO
from .sheen_exact import N_MU as _EXACT_N_MU
from .sheen_exact import N_R as _EXACT_N_R
from .sheen_tables import _AREA_TABLE as _AREA_TABLE
from .sheen_tables import (
    COS_MIN,
    R_MIN,
    bilinear,
    clamp_roughness,
    exact_roughness_nodes,
    lambda_exact,
    log_r_index,
    roughness_floor,
)
from .sheen_tables import R_MIN_EXACT as R_MIN_EXACT  # re-exported for callers of sheen
from .sheen_tables import area_nodes as area_nodes
from .sheen_tables import projected_area as projected_area

__all__ = [
    "D",
    "SheenPrepared",
    "INV_TWO_PI",
    "MODEL",
    "SHEEN_LOBES",
    "SheenParams",
    "albedo",
    "albedo_lookup",
    "base_scale",
    "distribution",
    "eval",
    "fit_coefficients",
    "interpolate",
    "lambda_fit",
    "lambda_table",
    "lobe",
    "log_lambda",
    "log_lambda_light",
    "pdf",
    "sample",
    "shadowing",
    "softening_exponent",
    "table_nodes",
]

INV_TWO_PI = 1.0 / (2.0 * math.pi)

# Table 1: (a, b, c, d, e) of L(x) = a / (1 + b x^c) + d x + e at r = 0 and r = 1.
_FIT_R0 = (25.3245, 3.32435, 0.16801, -1.27393, -4.85967)
_FIT_R1 = (21.5473, 3.82987, 0.19823, -1.97760, -4.32054)


@register_schema
class SheenParams(Params):
    """The sheen lobe on its own (Disney uses the same maths via ``sheen_roughness``)."""

    color: Color = Field((1.0, 1.0, 1.0), description="Sheen colour F (eq. 1), linear RGB.")
    roughness: float = Field(
        0.3,
        ge=0.0,
        le=1.0,
        description="Fibre spread r (eq. 2); clamped to 0.08 with the fitted Λ, 0.01 exact.",
    )
    terminator_softening: bool = Field(
        True, description="Eq. 4's softer light terminator (non-reciprocal)."
    )
    sheen_lambda: SheenLambda = Field(
        "fit",
        description="Smith Λ: 'fit' is the paper's Table 1 (r ≥ 0.08, what MaterialX's "
        "sheen_bsdf renders), 'exact' the integrated Λ from a table (r ≥ 0.01).",
    )


# -- the distribution, eq. 2 ---------------------------------------------------------------
def distribution(xp: Any, sin2_theta: Any, r: Any, r_min: float = R_MIN) -> Any:
    """D(m) = (2 + 1/r) sin^(1/r) θm / 2π (eq. 2), from sin²θm.

    Written as exp(log(sin²θ) / 2r) so that r → 0 and sin θ = 0 give 0, not NaN.
    Normalised: ∫ D cos θm dωm = (2 + 1/r) ∫₀¹ s^(1/r + 1) ds = 1 for every r.
    """
    r = clamp_roughness(xp, r, r_min)
    return (2.0 + 1.0 / r) * INV_TWO_PI * xp.exp(xp.log(sin2_theta) * (0.5 / r))


# -- shadowing, eq. 3 and eq. 4 ------------------------------------------------------------
def fit_coefficients(xp: Any, r: Any) -> tuple[Any, ...]:
    """Table 1 interpolated: P = (1 − r)² P₀ + (1 − (1 − r)²) P₁ (caption of Table 1)."""
    t = (1.0 - r) * (1.0 - r)
    return tuple(t * p0 + (1.0 - t) * p1 for p0, p1 in zip(_FIT_R0, _FIT_R1, strict=True))


def _curve(xp: Any, x: Any, coeffs: tuple[Any, ...]) -> Any:
    """L(x) = a / (1 + b x^c) + d x + e (eq. 3)."""
    a, b, c, d, e = coeffs
    return a / (1.0 + b * xp.power(x, c)) + d * x + e


def log_lambda(xp: Any, cos_theta: Any, coeffs: tuple[Any, ...]) -> Any:
    """log Λ(θ): L(cos θ) below cos θ = 0.5, 2 L(0.5) − L(1 − cos θ) above (eq. 3).

    The two branches meet continuously at 0.5 by construction; both are evaluated on
    clamped arguments so neither produces NaN where it is not selected.
    """
    mu = xp.clip(cos_theta, 0.0, 1.0)
    low = _curve(xp, mu, coeffs)
    high = 2.0 * _curve(xp, 0.5, coeffs) - _curve(xp, 1.0 - mu, coeffs)
    return xp.select(mu < 0.5, low, high)


def log_lambda_light(xp: Any, cos_theta: Any, coeffs: tuple[Any, ...], soften: bool) -> Any:
    """log Λ'(θi) = (1 + 2(1 − cos θi)^8) log Λ(θi) (eq. 4), or log Λ when not softened."""
    log_l = log_lambda(xp, cos_theta, coeffs)
    if not soften:
        return log_l
    return log_l * softening_exponent(xp, cos_theta)


def softening_exponent(xp: Any, cos_theta: Any) -> Any:
    """1 + 2(1 − cos θi)^8, the exponent of eq. 4's Λ'(θi) = Λ(θi)^(…)."""
    return 1.0 + 2.0 * xp.power(1.0 - xp.clip(cos_theta, 0.0, 1.0), 8.0)


def shadowing(xp: Any, cos_i: Any, cos_o: Any, r: Any, soften: bool, exact: bool = False) -> Any:
    """Correlated G = 1 / (1 + Λ(ωo) + Λ'(ωi)) (§3, §4), Λ fitted or ``exact``."""
    if exact:
        lam_o = lambda_exact(xp, cos_o, r)
        lam_i = lambda_exact(xp, cos_i, r)
        if soften:
            lam_i = xp.power(lam_i, softening_exponent(xp, cos_i))
        return 1.0 / (1.0 + lam_o + lam_i)
    coeffs = fit_coefficients(xp, clamp_roughness(xp, r))
    lam_o = xp.exp(log_lambda(xp, cos_o, coeffs))
    lam_i = xp.exp(log_lambda_light(xp, cos_i, coeffs, soften))
    return 1.0 / (1.0 + lam_o + lam_i)


def lobe(xp: Any, wi: Any, wo: Any, r: Any, soften: bool, exact: bool = False) -> Any:
    """Uncoloured sheen f(ωi, ωo) (eq. 1 with F = 1); 0 unless both lie above the surface.

    The cosines in 1/(4 cos θi cos θo) are floored at :data:`COS_MIN` (θ ≤ 89.9994°):
    the fitted Λ stays finite at 90° where the integrated one grows like 1/cos θ, so
    without the floor the albedo would diverge in that last 10⁻⁵ of cos θ (E = 1.5 at
    cos θo = 10⁻⁶, r = 1). The floor also keeps float32 from underflowing to 0/0.
    """
    cos_i, cos_o = wi[2], wo[2]
    upper = (cos_i > 0.0) & (cos_o > 0.0)
    h = wi + wo
    # sin²θh from the half vector's components: exact near the normal, unlike 1 − cos².
    sin2_h = (h[0] * h[0] + h[1] * h[1]) / xp.maximum(xp.dot(h, h), xp.tiny)
    g = shadowing(xp, cos_i, cos_o, r, soften, exact)
    denom = 4.0 * xp.maximum(cos_i, COS_MIN) * xp.maximum(cos_o, COS_MIN)
    f = distribution(xp, sin2_h, r, roughness_floor(exact)) * g / denom
    return xp.select(upper, f, 0.0)


# -- albedo and layering, §5 ---------------------------------------------------------------
# The table (:mod:`.sheen_albedo`) holds E at nodes uniform in t = μ^(1/8) from
# t(COS_MIN) to 1 (E changes fastest near grazing) and uniform in r. μ below COS_MIN
# reads the COS_MIN node: an upper bound there (E falls towards 0 as the fitted Λ takes
# over from the floored cosines), so it errs towards a darker base, never a gain.
_EXP = 0.125
_T0 = COS_MIN**_EXP


def table_nodes(n_mu: int, n_r: int, exact: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(μ, r) at which an albedo table is sampled.

    The exact mode's r nodes are the projected-area table's (:func:`area_nodes`, log r):
    its lobe is bilinear in log r between those nodes, with a kink at each, and an albedo
    table whose cells straddle a kink underestimated E by 1e-3 (a gain) at 64 × 32 sqrt-r
    nodes, against 8e-5 at 64 × 24 aligned ones (measured at the cells' midpoints).
    """
    t = np.linspace(_T0, 1.0, n_mu)
    if exact:
        return t ** (1.0 / _EXP), exact_roughness_nodes(n_r)
    return t ** (1.0 / _EXP), R_MIN + (1.0 - R_MIN) * np.linspace(0.0, 1.0, n_r) ** 2


def interpolate(xp: Any, table: np.ndarray, cos_theta: Any, r: Any, exact: bool = False) -> Any:
    """Bilinear read of ``table`` (shape (n_r, n_mu), nodes :func:`table_nodes`)."""
    n_r, n_mu = table.shape
    mu = xp.clip(cos_theta, COS_MIN, 1.0)
    x = (xp.power(mu, _EXP) - _T0) * ((n_mu - 1) / (1.0 - _T0))
    if exact:
        return bilinear(xp, table, x, log_r_index(xp, r, n_r) + 0.0 * x)
    y = xp.sqrt((clamp_roughness(xp, r) - R_MIN) / (1.0 - R_MIN)) * (n_r - 1) + 0.0 * x
    return bilinear(xp, table, x, y)


def albedo_lookup(xp: Any, cos_theta: Any, r: Any, soften: bool = True, exact: bool = False) -> Any:
    """E(μ, r) = ∫ f(ωi, ωo) cos θi dωi for a view at cos θo = μ (F = 1), from the table
    of the Λ mode in use (each tabulates its own lobe, from its own roughness floor)."""
    if exact:
        return interpolate(xp, _EXACT_TABLES[int(soften)], cos_theta, r, exact=True)
    return interpolate(xp, _TABLES[int(soften)], cos_theta, r)


def base_scale(
    xp: Any,
    cos_i: Any,
    cos_o: Any,
    r: Any,
    color: Any = 1.0,
    soften: bool = True,
    exact: bool = False,
) -> Any:
    """Factor on the layer under the sheen: 1 − F · max(E(ωi), E(ωo)).

    §5 says the nested lobe is scaled by "min(αi, αo)" of the albedos. Read literally
    (scale by the smaller albedo) a dark sheen would black out its base, so we read αi,
    αo as Kelemen & Szirmay-Kalos' albedo-scaling factors 1 − E: the minimum of
    1 − E(ωi) and 1 − E(ωo) is 1 − max(E(ωi), E(ωo)). Per channel with the sheen colour
    F ≤ 1 this is ≤ 1 − F·E(ωo), so sheen + scaled base never reflects more than the
    base alone could: no energy gain, whichever way the light travels.
    """
    e_i = albedo_lookup(xp, cos_i, r, soften, exact)
    e = xp.maximum(e_i, albedo_lookup(xp, cos_o, r, soften, exact))
    return 1.0 - color * e


# -- the Model -----------------------------------------------------------------------------
@dataclass(frozen=True, kw_only=True)
class SheenPrepared(Prepared):
    """What Conty–Kulla's sheen lobe reads (no IOR, no delta)."""

    color: Any
    """The sheen colour, channel-first."""
    r: Any
    """Sheen roughness r (the distribution's exponent 1/r, Conty–Kulla 2017 §2)."""
    soften: bool
    """The terminator softening of Λ on the light side (§3)."""
    exact: bool
    """Λ from the exact table, not the fit."""


def _prepare(xp: Any, params: SheenParams, **maps: Any) -> SheenPrepared:
    color = xp.color(maps.get("color", params.color))
    r = xp.scalar(maps.get("roughness", params.roughness))
    lobes = () if xp.known_zero(color) else (SHEEN_LOBES[0].name,)
    return SheenPrepared(
        lobes=lobes,
        color=color,
        r=r,
        soften=params.terminator_softening,
        exact=params.sheen_lambda == "exact",
    )


def _eval(xp: Any, prepared: SheenPrepared, wi: Any, wo: Any) -> Any:
    if not prepared.lobes:
        return xp.zeros(wi[2]) * prepared.color
    r, soften, exact = prepared.r, prepared.soften, prepared.exact
    return prepared.color * lobe(xp, wi, wo, r, soften, exact)


def _pdf(xp: Any, prepared: SheenPrepared, wi: Any, wo: Any) -> Any:
    if not prepared.lobes:
        return xp.zeros(wi[2])
    return xp.select((wi[2] > 0.0) & (wo[2] > 0.0), INV_TWO_PI, 0.0)


def _sample(xp: Any, prepared: SheenPrepared, wo: Any, u: Any) -> tuple[Any, Any, Any, bool]:
    # Uniform hemisphere (§2): cos θi = u1, φ = 2π u2; pdf 1/2π.
    z = u[1]
    s = xp.safe_sqrt(1.0 - z * z)
    phi = 2.0 * math.pi * u[2]
    wi = xp.vec3(s * xp.cos(phi), s * xp.sin(phi), z)
    pdf = _pdf(xp, prepared, wi, wo)
    f = _eval(xp, prepared, wi, wo)
    weight = f * xp.select(pdf > 0.0, z * (2.0 * math.pi), 0.0)
    return wi, weight, pdf, False  # no delta lobe


# [without, with] terminator softening, each (n_r, n_mu).
_TABLES = np.asarray(_TABLE_VALUES, dtype=np.float64).reshape(2, _N_R, _N_MU)
_EXACT_TABLES = np.asarray(_EXACT_ALBEDO, dtype=np.float64).reshape(2, _EXACT_N_R, _EXACT_N_MU)
SHEEN_LOBES = (
    Lobe(
        "sheen",
        "glossy",
        params=("color", "roughness", "terminator_softening", "sheen_lambda"),
        reciprocal=False,  # with terminator_softening (eq. 4, the default)
    ),
)


def _guide(xp: Any, prepared: SheenPrepared, wo: Any) -> Any:
    """A denoiser's albedo guide (:mod:`.guides`): the cloth's colour times the lobe's
    directional albedo E(θo) from the table (OIDN: the surface's approximate colour)."""
    if not prepared.lobes:
        return None
    e = albedo_lookup(xp, xp.abs(wo[2]), prepared.r, prepared.soften, prepared.exact)
    return prepared.color * e


MODEL = Model("sheen", SheenParams, _prepare, _eval, _pdf, _sample, lobes=SHEEN_LOBES, guide=_guide)


# -- public numpy API ----------------------------------------------------------------------
def D(cos_theta: Any, r: Any, r_min: float = R_MIN) -> np.ndarray:
    """Eq. 2 at micro-normal angle θ, float64, broadcast over both arguments."""
    c = np.asarray(cos_theta, dtype=np.float64)
    with np.errstate(divide="ignore"):
        s2 = np.maximum(1.0 - c * c, 0.0)
        return distribution(NumpyOps(), s2, np.asarray(r, float), r_min)


def lambda_fit(cos_theta: Any, r: Any) -> np.ndarray:
    """Λ(θ) from the fit (eq. 3, Table 1), broadcast over both arguments."""
    xp = NumpyOps()
    c, rr = np.broadcast_arrays(np.asarray(cos_theta, float), np.asarray(r, float))
    return np.exp(log_lambda(xp, c, fit_coefficients(xp, clamp_roughness(xp, rr))))


def lambda_table(cos_theta: Any, r: Any) -> np.ndarray:
    """Λ(θ) from the integrated table (``sheen_lambda = "exact"``), broadcast."""
    c, rr = np.broadcast_arrays(np.asarray(cos_theta, float), np.asarray(r, float))
    return lambda_exact(NumpyOps(), c, rr)


def albedo(
    cos_theta: Any, r: Any, terminator_softening: bool = True, sheen_lambda: str = "fit"
) -> np.ndarray:
    """Tabulated directional albedo E(μ, r) of the lobe with F = 1."""
    xp = NumpyOps()
    c, rr = np.broadcast_arrays(np.asarray(cos_theta, float), np.asarray(r, float))
    return albedo_lookup(xp, c, rr, terminator_softening, sheen_lambda == "exact")


def eval(params: SheenParams, wi: Any, wo: Any, **kw: Any) -> np.ndarray:  # noqa: A001
    """f(ωi, ωo) without the cosine, (..., 3); see :func:`lookdev.materials.bsdf.evaluate`."""
    return evaluate(MODEL, params, wi, wo, **kw)


def pdf(params: SheenParams, wi: Any, wo: Any, **kw: Any) -> np.ndarray:
    """Density of :func:`sample` producing ωi given ωo (solid angle)."""
    return density(MODEL, params, wi, wo, **kw)


def sample(params: SheenParams, wo: Any, u: Any, **kw: Any) -> tuple[np.ndarray, ...]:
    """(ωi, f·cos θi/pdf, pdf) from uniforms u of shape (..., 3)."""
    return draw(MODEL, params, wo, u, **kw)
