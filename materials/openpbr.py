"""OpenPBR Surface as its specification reduces it to a mixture of lobes: what an OpenPBR
renderer shows.

The specification (v1.1, section "Reduction to a mixture of lobes", :cite:`OpenPBR2024`)
derives, with the non-reciprocal albedo-scaling of layers, ::

    f_dielectric = f_spec + (1 − E[f_spec]) · lerp(lerp(f_diffuse, f_sss, S), f_trans, T)
    f_substrate  = lerp(f_dielectric, f_conductor, M)
    f_coated     = C f_coat + lerp(1, coat_color (1 − E[f_coat]), C) · lerp(1, Δ, C δ) · f_substrate
    f_surface    = F f_fuzz + (1 − F E[f_fuzz]) · f_coated

with M, T, S, C, F the metalness, transmission, subsurface, coat and fuzz weights and
δ = ``coat_darkening``. The lobes:

- ``specular``: GGX reflection (α = r², the specification's anisotropy
  α_x = α √(2/(1 + (1 − a)²)), α_y = (1 − a) α_x) with the exact dielectric Fresnel of
  the modulated IOR ratio (:func:`.openpbr_params.modulated_ior`) tinted by
  ``specular_color``;
- ``metal``: the same GGX lobe with the F82-tint Fresnel (:func:`.openpbr_params.f82_tint`)
  times ``specular_weight``;
- ``transmission``: Walter's rough dielectric BTDF at the same IOR, tinted by
  ``transmission_color``, its own Fresnel factor left out as the specification allows
  (on a thin wall without the radiance factor 1/η², the slab's two faces cancelling);
- ``diffuse``: the energy-preserving Oren–Nayar (EON) of ``base_weight · base_color``;
- ``subsurface``: the slab's reflectance limit, a Lambertian of ``subsurface_color``;
- ``coat``: GGX reflection with the dielectric Fresnel of ``coat_ior``;
- ``fuzz``: a fibre-like sheen of ``fuzz_color``.

Where the specification leaves the implementation free, this model chooses, and each
choice is a difference from other OpenPBR implementations, measured in
``docs/measurements/contexts.md``: the GGX lobes carry Turquin's multiple-scattering
factor (:mod:`.energy`), and E[f] of a dielectric GGX lobe is the compensated lobe's
albedo with Schlick's Fresnel from the exact F0, F0 (E − B) + B
(:func:`.openpbr_params.schlick_split`); the fuzz is Conty and Kulla's sheen
(:mod:`.sheen`, r = ``fuzz_roughness``), not Zeltner's LTC fit; the darkening Δ follows
the specification's suggested K = lerp(K_s, K_r, r_b); under a coat denser than the base
(η′ < 1) the base's reflection takes the Fresnel of 1/η′ (same F0, no total internal
reflection: light refracted into the coat never reaches the base at grazing). Inputs
outside the BSDF are listed in :data:`.openpbr_params.NOT_MODELLED`.

>>> import numpy as np
>>> from .bsdf import evaluate
>>> n = np.array([0.0, 0.0, 1.0])
>>> round(float(evaluate(MODEL, OpenPBRParams(specular_weight=0.0), n, n)[0]), 4)  # 0.8/π
0.2546
>>> bool(0.6 < evaluate(MODEL, OpenPBRParams(), n, n)[0] < 0.7)  # and the r = 0.3 peak
True
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from . import energy, fresnel, sheen
from .bsdf import Lobe, Model, Prepared
from .microfacet import (
    ALPHA_MIN,
    dielectric_btdf,
    ggx_d,
    reflect,
    refract,
    sample_visible_ggx,
    smith_g1,
    visible_ggx_pdf,
)
from .openpbr_params import (
    OpenPBRParams,
    darkening,
    eon,
    f82_tint,
    fresnel_average,
    modulated_ior,
    schlick_split,
)

__all__ = ["MODEL", "OpenPBRParams", "OpenPBRPrepared"]

MAPPED = ("base_color", "base_weight", "base_metalness", "specular_roughness")
"""Inputs that may vary per element (the rest are constants of a material)."""


def _alphas(xp: Any, r: Any, aniso: float) -> tuple[Any, Any]:
    """The specification's (α_x, α_y) of roughness r and anisotropy, floored at ALPHA_MIN."""
    stretch = math.sqrt(2.0 / (1.0 + (1.0 - aniso) ** 2))
    if isinstance(r, float):
        a = r * r * stretch
        return max(a, ALPHA_MIN), max((1.0 - aniso) * a, ALPHA_MIN)
    a = r * r * stretch
    return xp.maximum(a, ALPHA_MIN), xp.maximum((1.0 - aniso) * a, ALPHA_MIN)


def _positive(value: Any) -> bool:
    return not isinstance(value, float) or value > 0.0


@dataclass(frozen=True, kw_only=True)
class OpenPBRPrepared(Prepared):
    """What the OpenPBR lobes read (OpenPBR 1.1 names in brackets); ``eta`` is the
    specular IOR as modulated by the coat above it."""

    m: Any
    """Metalness (``base_metalness``)."""
    t: float
    """``transmission_weight``."""
    s: float
    """``subsurface_weight``."""
    c: float
    """``coat_weight``."""
    fuzz_w: float
    """``fuzz_weight``."""
    base: Any
    """``base_color`` × ``base_weight``."""
    sss: Any
    """``subsurface_color``."""
    sigma: float
    """Oren–Nayar roughness of the diffuse (``base_diffuse_roughness``)."""
    spec_color: Any
    """``specular_color``."""
    spec_weight: float
    """``specular_weight``."""
    trans_color: Any
    """``transmission_color``."""
    coat_color: Any
    """``coat_color``."""
    coat_ior: float
    """``coat_ior``."""
    darken: float
    """``coat_darkening``."""
    fuzz_color: Any
    """``fuzz_color``."""
    fuzz_r: float
    """``fuzz_roughness``."""
    opacity: float
    """``geometry_opacity``."""
    thin: bool
    """``geometry_thin_walled``."""
    eta_r: Any
    """The IOR the reflection is read with: max(η, 1/η) (no total internal reflection)."""
    ax: Any
    """Specular GGX αx."""
    ay: Any
    """Specular GGX αy."""
    r: Any
    """The specular roughness (αx αy)^¼ the energy tables are read at."""
    cax: Any
    """Coat GGX αx."""
    cay: Any
    """Coat GGX αy."""
    cr: float
    """The coat's (αx αy)^¼."""
    e_base: Any
    """Normal-incidence albedo of the base under the coat (the darkening's E_b)."""
    r_b: Any
    """The base's roughness for the darkening."""
    k_r: float
    """The coat's internal reflectance 1 − (1 − F̄)/n² (the darkening)."""
    p_cos: float
    """Probability of a cosine-weighted sample (diffuse, subsurface, fuzz)."""
    p_spec: float
    """Probability of a specular (metal or dielectric) sample."""
    p_coat: float
    """Probability of a coat sample."""
    p_trans: float
    """Probability of a transmission sample."""


def prepare(xp: Any, params: OpenPBRParams, **maps: Any) -> OpenPBRPrepared:
    """Weights, alphas, IORs and the view-independent parts of the darkening."""
    p = params
    m = maps.get("base_metalness", p.base_metalness)
    weight = maps.get("base_weight", p.base_weight)
    base = xp.color(maps.get("base_color", p.base_color)) * weight
    r = maps.get("specular_roughness", p.specular_roughness)
    ax, ay = _alphas(xp, r, p.specular_roughness_anisotropy)
    cax, cay = _alphas(xp, p.coat_roughness, p.coat_roughness_anisotropy)
    eta = modulated_ior(p.specular_ior, p.specular_weight, p.coat_weight, p.coat_ior)
    f0_d = ((1.0 - eta) / (1.0 + eta)) ** 2
    t, s, c, fz = p.transmission_weight, p.subsurface_weight, p.coat_weight, p.fuzz_weight
    dielectric = not isinstance(m, float) or m < 1.0
    lobes = []
    if _positive(m):
        lobes.append("metal")
    if dielectric and f0_d > 0.0 and max(p.specular_color) > 0.0:
        lobes.append("specular")
    if dielectric and t > 0.0:
        lobes.append("transmission")
    if dielectric and t < 1.0 and s > 0.0:
        lobes.append("subsurface")
    if dielectric and t < 1.0 and s < 1.0 and _positive(weight) and max(p.base_color) > 0.0:
        lobes.append("diffuse")
    if c > 0.0:
        lobes.append("coat")
    if fz > 0.0:
        lobes.append("fuzz")
    spec_color = xp.color(p.specular_color)
    # normal-incidence albedo of the base under the coat (the darkening's E_b)
    r_spec = (
        xp.sqrt(xp.sqrt(ax * ay)) if not isinstance(ax, float) else math.sqrt(math.sqrt(ax * ay))
    )
    e_spec0 = spec_color * f0_d if "specular" in lobes else 0.0 * spec_color
    under = (1.0 - t) * (s * xp.color(p.subsurface_color) + (1.0 - s) * base)
    e_diel = e_spec0 + (1.0 - e_spec0) * under
    e_base = e_diel + (p.specular_weight * base - e_diel) * m
    r_d = 1.0 + (r - 1.0) * min(max(f0_d, 0.0), 1.0)
    r_b = r_d + (r - r_d) * m
    k_r = 1.0 - (1.0 - fresnel_average(p.coat_ior)) / (p.coat_ior * p.coat_ior)
    live = {
        "cos": (1.0 - t) * 0.8 + 0.5 * fz
        if ({"diffuse", "subsurface", "fuzz"} & set(lobes))
        else 0.0,
        "spec": 1.0 if ({"metal", "specular"} & set(lobes)) else 0.0,
        "coat": 0.5 * c,
        "trans": t if "transmission" in lobes else 0.0,
    }
    total = sum(live.values()) or 1.0
    return OpenPBRPrepared(
        lobes=tuple(lobes),
        m=m,
        t=t,
        s=s,
        c=c,
        fuzz_w=fz,
        base=base,
        sss=xp.color(p.subsurface_color),
        sigma=p.base_diffuse_roughness,
        spec_color=spec_color,
        spec_weight=p.specular_weight,
        trans_color=xp.color(p.transmission_color),
        coat_color=xp.color(p.coat_color),
        coat_ior=p.coat_ior,
        darken=p.coat_darkening,
        fuzz_color=xp.color(p.fuzz_color),
        fuzz_r=p.fuzz_roughness,
        opacity=p.geometry_opacity,
        thin=p.geometry_thin_walled,
        eta=eta,
        # under a denser coat η′ < 1: the reflection is read with 1/η′ (same F0, no
        # total internal reflection, which the light refracted into the coat never meets)
        eta_r=max(eta, 1.0 / eta),
        ax=ax,
        ay=ay,
        r=r_spec,
        cax=cax,
        cay=cay,
        cr=math.sqrt(math.sqrt(cax * cay)),
        e_base=e_base,
        r_b=r_b,
        k_r=k_r,
        p_cos=live["cos"] / total,
        p_spec=live["spec"] / total,
        p_coat=live["coat"] / total,
        p_trans=live["trans"] / total,
    )


def _ggx(xp: Any, h: Any, wi: Any, wo: Any, ax: Any, ay: Any) -> Any:
    """D G1 G1 / (4 μi μo) of a GGX reflection (upper directions)."""
    g = smith_g1(xp, wi, ax, ay) * smith_g1(xp, wo, ax, ay)
    return ggx_d(xp, h, ax, ay) * g / (4.0 * xp.maximum(wi[2], 1e-9) * xp.maximum(wo[2], 1e-9))


def _lobe_albedo(xp: Any, f0: Any, mu: Any, r: Any) -> Any:
    """E(μ) of a GGX lobe with Schlick's Fresnel from ``f0``: F0 (E − B) + B."""
    e = energy.albedo_lookup(xp, mu, r)
    b = schlick_split(xp, mu, r)
    return f0 * (e - b) + b


def eval(xp: Any, p: OpenPBRPrepared, wi: Any, wo: Any) -> Any:
    """f(wi, wo) without the cosine, for a view above the surface."""
    lobes = p.lobes
    mu_o = xp.maximum(wo[2], 1e-9)
    up = (wi[2] > 0.0) & (wo[2] > 0.0)
    down = (wi[2] < 0.0) & (wo[2] > 0.0)
    h = xp.normalize(wi + wo)
    oh = xp.clip(xp.dot(wo, h), 0.0, 1.0)
    m = p.m
    zero = 0.0 * p.base * wi[2]
    reflected, transmitted = zero, zero
    term = _ggx(xp, h, wi, wo, p.ax, p.ay) if {"metal", "specular"} & set(lobes) else 0.0
    e_spec = zero
    if "specular" in lobes:
        f0 = fresnel.ior_to_f0(p.eta)
        comp = energy.factor(xp, f0, mu_o, p.r)
        spec = p.spec_color * fresnel.dielectric(xp, oh, p.eta_r) * (term * comp)
        reflected = reflected + (1.0 - m) * spec
        e_spec = p.spec_color * (_lobe_albedo(xp, f0, mu_o, p.r) * comp)
    under = zero
    t, s = p.t, p.s
    if "diffuse" in lobes:
        under = under + (1.0 - t) * (1.0 - s) * eon(xp, p.base, p.sigma, wi, wo)
    if "subsurface" in lobes:
        under = under + (1.0 - t) * s * p.sss * (1.0 / math.pi)
    reflected = reflected + (1.0 - m) * (1.0 - e_spec) * under
    if "transmission" in lobes:
        wi_t = xp.select(down, wi, -wi)  # keeps the masked-out lanes finite
        btdf = dielectric_btdf(xp, wi_t, wo, p.eta, p.ax, p.ay, False)
        h_t = xp.normalize(wi_t * p.eta + wo)
        keep = 1.0 - fresnel.dielectric(xp, xp.abs(xp.dot(wo, h_t)), p.eta)
        lobe = btdf / xp.maximum(keep, 1e-6)  # the specification omits this Fresnel factor
        if p.thin:
            # a thin wall's second interface undoes the first's radiance compression
            lobe = lobe * (p.eta * p.eta)
        transmitted = (1.0 - m) * t * (1.0 - e_spec) * p.trans_color * lobe
    if "metal" in lobes:
        f = f82_tint(xp, p.base, p.spec_color, oh) * p.spec_weight
        comp = energy.factor(xp, p.base, mu_o, p.r)
        reflected = reflected + m * f * (term * comp)
    if "coat" in lobes:
        c = p.c
        cterm = _ggx(xp, h, wi, wo, p.cax, p.cay)
        ccomp = energy.factor(xp, fresnel.ior_to_f0(p.coat_ior), mu_o, p.cr)
        f_view = fresnel.dielectric(xp, mu_o, p.coat_ior)
        e_coat = _lobe_albedo(xp, fresnel.ior_to_f0(p.coat_ior), mu_o, p.cr) * ccomp
        k = f_view + (p.k_r - f_view) * p.r_b
        dark = 1.0 + (darkening(k, p.e_base) - 1.0) * (c * p.darken)
        scale = (1.0 - c + c * p.coat_color * (1.0 - e_coat)) * dark
        coat = c * fresnel.dielectric(xp, oh, p.coat_ior) * cterm * ccomp
        reflected = reflected * scale + coat
        transmitted = transmitted * scale
    if "fuzz" in lobes:
        fz = p.fuzz_w
        fuzz = sheen.lobe(xp, wi, wo, p.fuzz_r, True)
        e_fuzz = sheen.albedo_lookup(xp, mu_o, p.fuzz_r)
        reflected = fz * p.fuzz_color * fuzz + (1.0 - fz * e_fuzz) * reflected
        transmitted = (1.0 - fz * e_fuzz) * transmitted
    out = xp.select(up, reflected, zero) + xp.select(down, transmitted, zero)
    return out * p.opacity


def pdf(xp: Any, p: OpenPBRPrepared, wi: Any, wo: Any) -> Any:
    """Density of :func:`sample`: cosine, visible-normal GGX reflection (base and coat),
    visible-normal refraction."""
    up = (wi[2] > 0.0) & (wo[2] > 0.0)
    down = (wi[2] < 0.0) & (wo[2] > 0.0)
    h = xp.normalize(wi + wo)
    jac = 1.0 / xp.maximum(4.0 * xp.abs(xp.dot(wo, h)), 1e-12)
    out = 0.0 * wi[2]
    if p.p_cos > 0.0:
        out = out + p.p_cos * xp.maximum(wi[2], 0.0) / math.pi
    if p.p_spec > 0.0:
        out = out + p.p_spec * visible_ggx_pdf(xp, wo, h, p.ax, p.ay) * jac
    if p.p_coat > 0.0:
        out = out + p.p_coat * visible_ggx_pdf(xp, wo, h, p.cax, p.cay) * jac
    nothing = 0.0 * wi[2]  # not 0·out: masked lanes may hold NaN (a view below)
    out = xp.select(up, out, nothing)
    if p.p_trans > 0.0:
        wi_t = xp.select(down, wi, -wi)
        pt = p.p_trans * dielectric_btdf(xp, wi_t, wo, p.eta, p.ax, p.ay, True)
        out = out + xp.select(down, pt, nothing)
    return out


def sample(xp: Any, p: OpenPBRPrepared, wo: Any, u: Any) -> Any:
    """Pick cosine, base reflection, coat reflection or refraction by ``u[0]``."""
    u0, u1, u2 = u[0], u[1], u[2]
    r = xp.sqrt(u1)
    phi = 2.0 * math.pi * u2
    cos_dir = xp.vec3(r * xp.cos(phi), r * xp.sin(phi), xp.safe_sqrt(1.0 - u1))
    wo_up = xp.vec3(wo[0], wo[1], xp.maximum(wo[2], 1e-6))
    h = sample_visible_ggx(xp, wo_up, p.ax + 0.0 * u1, p.ay + 0.0 * u1, u1, u2)
    hc = sample_visible_ggx(xp, wo_up, p.cax + 0.0 * u1, p.cay + 0.0 * u1, u1, u2)
    refr, _ = refract(xp, wo_up, h, p.eta)
    c1 = p.p_cos
    c2 = c1 + p.p_spec
    c3 = c2 + p.p_coat
    wi = xp.select(
        u0 < c1,
        cos_dir,
        xp.select(u0 < c2, reflect(xp, wo_up, h), xp.select(u0 < c3, reflect(xp, wo_up, hc), refr)),
    )
    density = pdf(xp, p, wi, wo)
    f = eval(xp, p, wi, wo)
    ok = (density > 0.0) & (wo[2] > 0.0)
    nothing = 0.0 * u0
    weight = xp.select(ok, f * xp.abs(wi[2]) / xp.maximum(density, 1e-30), nothing + 0.0 * p.base)
    return wi, weight, xp.select(ok, density, nothing), False


MODEL = Model(
    name="openpbr",
    params_type=OpenPBRParams,
    prepare=prepare,
    eval=eval,
    pdf=pdf,
    sample=sample,
    lobes=(
        Lobe("fuzz", "glossy", params=("fuzz_color", "fuzz_roughness"), switches=("fuzz_weight",)),
        Lobe("coat", "glossy", highlight=True, params=("coat_roughness",),
             switches=("coat_weight",)),
        Lobe("metal", "glossy", highlight=True, switches=("base_metalness",)),
        Lobe("specular", "glossy", highlight=True, params=("specular_ior",)),
        Lobe("transmission", "glossy", transmits=True, switches=("transmission_weight",),
             params=("transmission_color",)),
        Lobe("subsurface", "diffuse", params=("subsurface_color",),
             switches=("subsurface_weight",)),
        Lobe("diffuse", "diffuse", params=("base_diffuse_roughness",)),
    ),
)  # fmt: skip
"""OpenPBR Surface as a model (the ``mtlx`` context's surface; ``openpbr`` presets)."""
