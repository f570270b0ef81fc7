"""UsdPreviewSurface's BRDF as its specification defines it: what a DCC's preview shows.

OpenUSD, *UsdPreviewSurface Specification* 2.5 (openusd.org/release/spec_usdpreviewsurface):

- ``roughness`` "is usually squared before use with a GGX or Beckmann lobe": a GGX lobe
  with α = roughness² (clamped at 0.001 as the reference implementation does);
- metallic workflow: "If metallic is 1, then both F0 … and edge F90 reflectivity will
  simply be the Albedo. If metallic is 0, then Albedo is ignored in the calculation of F0
  and F90; F0 is derived from ior via ((1 − ior)/(1 + ior))² and F90 is white. In between,
  we interpolate"; pure metals have no diffuse;
- specular workflow: ``specularColor`` is F0, "edge color is assumed white", blended
  "according to Schlick fresnel approximation";
- ``clearcoat``: "second specular lobe amount. The color is white", with F0 from ``ior``
  ("including the clearcoat if clearcoat > 0") and roughness ``clearcoatRoughness``.

Where the text leaves a choice, the reference implementation shipped with USD (Storm's
``previewSurface.glslfx``) decides, since that is the preview users see: the interpolation
is ``specColor = mix(1, diffuseColor, metallic)``, ``F0 = mix(R²·specColor, specColor,
metallic)``, ``F90 = specColor``; Schlick's weight is taken at θd (light to half vector);
Smith G is Schlick-GGX with k = α/2; the Lambert diffuse is scaled by ``1 − F`` (energy the
highlight took). Its shader constants (π ≈ 3.1415, ε added to D and to 4 cos θl cos θv)
are left out: they are numerical guards, not the model.

Written once over the array shim like the other models (numpy for analysis; a sampler
that mixes cosine-weighted diffuse and GGX micro-normal sampling, so it can be checked by
chi-square). Transmission, opacity, normal and displacement are not part of the BRDF.

>>> import numpy as np
>>> from .bsdf import evaluate
>>> p = PreviewParams(diffuse_color=(0.5, 0.5, 0.5), roughness=1.0)
>>> f = evaluate(MODEL, p, np.array([0.0, 0.0, 1.0]), np.array([0.0, 0.0, 1.0]))
>>> bool(0.15 < f[0] < 0.16)  # 0.5/π·(1 − 0.04) plus a broad lobe
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from pydantic import Field

from .bsdf import Lobe, Model, Prepared
from .fresnel import schlick_weight
from .microfacet import ggx_d, sample_ggx
from .params import Color, Params

__all__ = ["MODEL", "PreviewParams", "PreviewPrepared"]

ALPHA_MIN = 0.001 * 0.001
"""The reference clamps roughness at 0.001 before squaring."""


class PreviewParams(Params):
    """UsdPreviewSurface's inputs that shape its BRDF (spec names in snake_case)."""

    diffuse_color: Color = Field((0.18, 0.18, 0.18))
    use_specular_workflow: bool = False
    specular_color: Color = Field((0.0, 0.0, 0.0))
    metallic: float = Field(0.0, ge=0.0, le=1.0)
    roughness: float = Field(0.5, ge=0.0, le=1.0)
    clearcoat: float = Field(0.0, ge=0.0, le=10.0)
    clearcoat_roughness: float = Field(0.01, ge=0.0, le=1.0)
    ior: float = Field(1.5, ge=0.0, le=1e7)


def _alpha(xp: Any, r: Any) -> Any:
    if isinstance(r, float):
        return max(r * r, ALPHA_MIN)
    return xp.maximum(r * r, ALPHA_MIN)


@dataclass(frozen=True, kw_only=True)
class PreviewPrepared(Prepared):
    """What UsdPreviewSurface's lobes read (its reference implementation's terms)."""

    diffuse: Any
    """The Lambertian colour (``diffuseColor``, times 1 − metallic)."""
    f0: Any
    """Schlick's F0 of the specular."""
    f90: Any
    """Schlick's F90 of the specular."""
    alpha: Any
    """GGX α = roughness² of the specular (at least :data:`ALPHA_MIN`)."""
    cc: float
    """``clearcoat`` weight."""
    cc_alpha: float
    """GGX α of the clearcoat."""
    cc_f0: float
    """F0 of the clearcoat, from ``ior``."""
    p_diffuse: float
    """Probability of sampling the diffuse."""
    p_coat: float
    """Probability of sampling the clearcoat."""


def prepare(xp: Any, params: PreviewParams, **maps: Any) -> PreviewPrepared:
    """F0, F90, the diffuse colour and the lobe weights of the metallic or specular workflow.

    ``maps`` may vary ``diffuse_color``, ``metallic`` and ``roughness`` per element."""
    base = xp.color(maps.get("diffuse_color", params.diffuse_color))
    r = (1.0 - params.ior) / (1.0 + params.ior)
    r2 = r * r
    if params.use_specular_workflow:
        f0 = xp.color(params.specular_color)
        f90 = xp.color((1.0, 1.0, 1.0))
        diffuse = base
    else:
        m = maps.get("metallic", params.metallic)
        spec = 1.0 + (base - 1.0) * m  # mix(1, diffuseColor, metallic)
        f0 = r2 * spec + (spec - r2 * spec) * m
        f90 = spec
        diffuse = base * (1.0 - m)
    metal = "metallic" not in maps and params.metallic >= 1.0 and not params.use_specular_workflow
    lobes = ["specular"] if metal else ["diffuse", "specular"]  # a pure metal has no diffuse
    if params.clearcoat > 0.0:
        lobes.append("clearcoat")
    return PreviewPrepared(
        lobes=tuple(lobes),
        diffuse=diffuse,
        f0=f0,
        f90=f90,
        alpha=_alpha(xp, maps.get("roughness", params.roughness)),
        cc=params.clearcoat,
        cc_alpha=_alpha(xp, params.clearcoat_roughness),
        cc_f0=r2,
        p_diffuse=0.0 if metal else 0.5,
        p_coat=0.2 if params.clearcoat > 0.0 else 0.0,
    )


def _schlick_ggx_g(nl: Any, nv: Any, alpha: float) -> Any:
    """Smith G, Schlick-GGX form with k = α/2 (the reference's ``Geometric``)."""
    k = 0.5 * alpha
    return (nv / (nv * (1.0 - k) + k)) * (nl / (nl * (1.0 - k) + k))


def eval(xp: Any, p: PreviewPrepared, wi: Any, wo: Any) -> Any:
    """f(wi, wo) without the cosine; 0 below either horizon."""
    nl, nv = wi[2], wo[2]
    up = (nl > 0.0) & (nv > 0.0)
    nl_, nv_ = xp.maximum(nl, 1e-9), xp.maximum(nv, 1e-9)
    h = xp.normalize(wi + wo)
    w = schlick_weight(xp, xp.clip(xp.dot(wo, h), 0.0, 1.0))
    f = p.f0 + (p.f90 - p.f0) * w
    denom = 4.0 * nl_ * nv_
    a = p.alpha
    spec = f * (ggx_d(xp, h, a, a, 1.0) * _schlick_ggx_g(nl_, nv_, a) / denom)
    out = p.diffuse * (1.0 / math.pi) * (1.0 - f) + spec
    if "clearcoat" in p.lobes:
        ca = p.cc_alpha
        fc = p.cc_f0 + (1.0 - p.cc_f0) * w
        out = out + p.cc * fc * ggx_d(xp, h, ca, ca, 1.0) * _schlick_ggx_g(nl_, nv_, ca) / denom
    return xp.select(up, out, 0.0 * out)


def pdf(xp: Any, p: PreviewPrepared, wi: Any, wo: Any) -> Any:
    """Density of :func:`sample`: cosine diffuse, GGX micro-normals D(h)cosθh/(4|wo·h|)."""
    nl = wi[2]
    h = xp.normalize(wi + wo)
    jac = 1.0 / xp.maximum(4.0 * xp.abs(xp.dot(wo, h)), 1e-12)
    pd = p.p_diffuse
    pc = p.p_coat
    ps = 1.0 - pd - pc
    a = p.alpha
    out = pd * xp.maximum(nl, 0.0) / math.pi + ps * ggx_d(xp, h, a, a, 1.0) * h[2] * jac
    if pc > 0.0:
        ca = p.cc_alpha
        out = out + pc * ggx_d(xp, h, ca, ca, 1.0) * h[2] * jac
    return xp.select((nl > 0.0) & (wo[2] > 0.0), out, 0.0 * out)


def sample(xp: Any, p: PreviewPrepared, wo: Any, u: Any) -> Any:
    """Pick diffuse (cosine), specular or coat (GGX micro-normal, reflected) by ``u[0]``."""
    pd, pc = p.p_diffuse, p.p_coat
    u1, u2 = u[1], u[2]
    r = xp.sqrt(u1)
    phi = 2.0 * math.pi * u2
    cos_dir = xp.vec3(r * xp.cos(phi), r * xp.sin(phi), xp.safe_sqrt(1.0 - u1))
    a = p.alpha + 0.0 * u1  # arrays, so select works on either backend
    ca = (p.cc_alpha if pc > 0.0 else p.alpha) + 0.0 * u1
    use_coat = u[0] >= 1.0 - pc
    alpha = xp.select(use_coat, ca, a)
    h = sample_ggx(xp, alpha, alpha, u1, u2)
    refl = 2.0 * xp.dot(wo, h) * h - wo
    wi = xp.select(u[0] < pd, cos_dir, refl)
    density = pdf(xp, p, wi, wo)
    f = eval(xp, p, wi, wo)
    ok = (density > 0.0) & (wi[2] > 0.0)
    weight = xp.select(ok, f * wi[2] / xp.maximum(density, 1e-30), 0.0 * f)
    return wi, weight, xp.select(ok, density, 0.0 * density), False  # no delta lobes


MODEL = Model(
    name="usd_preview_surface",
    params_type=PreviewParams,
    prepare=prepare,
    eval=eval,
    pdf=pdf,
    sample=sample,
    lobes=(
        Lobe("diffuse", "diffuse", params=("diffuse_color",)),
        Lobe("specular", "glossy", highlight=True),
        Lobe("clearcoat", "glossy", highlight=True, params=("clearcoat",), switches=("clearcoat",)),
    ),
)
"""UsdPreviewSurface as a model (not in the preset registry: no preset is written in it)."""
