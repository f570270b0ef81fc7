"""The Disney BSDF: Burley 2012 (+ 2014 addenda) and its 2015 BSDF extension (Schutte seed).

One implementation over the array shim (:mod:`.arrays`), published as :data:`MODEL`
(the :mod:`.bsdf` contract) and as the numpy functions :func:`eval`, :func:`pdf` and
:func:`sample`. Lobes, with w_d = (1 − metallic)(1 − spec_trans) and
w_g = (1 − metallic)·spec_trans:

``diffuse``     w_d (1 − diff_trans) · base/π · [Burley §5.3 with retro-reflection, split as
                Schutte's f_lambert(1 − F_L/2)(1 − F_V/2) + f_retro; ``flatness`` (thin only)
                blends f_lambert towards Hanrahan-Krueger; ``subsurface`` (2012) blends the
                whole shape towards it as the BRDF Explorer does]
``diff_trans``  w_d · diff_trans · T/π, Lambertian through the surface (T = base, or √base thin);
                a solid with ``scatter_distance`` > 0 (Burley 2015) sends the whole w_d through
                it, white and shaped (1 − F_L/2)(1 − F_V/2), into the interior medium of
                :mod:`.subsurface`, keeping only the retro-reflection on the surface
``sheen``       w_d · sheen · mix(1, tint, sheen_tint) · (1 − cos θd)⁵ (2014 addendum), or the
                Conty-Kulla lobe of :mod:`.sheen` with ``sheen_model = "conty_kulla"``
``specular``    F · D · G / (4 cos θl cos θv), anisotropic GGX (App. B eq. 13) with the
                un-remapped anisotropic Smith G (2014 addendum); F blends metal, dielectric
                and the glass's reflection (see :func:`_fresnel_terms`); the expert
                ``specular_gamma`` ≠ 2 makes D the isotropic GTR of App. B eq. 1, sampled
                by eqs. 2–3 (Chichi 2018's ``d_gamma``)

``clearcoat``   0.25 · clearcoat · D_GTR1 · F(0.04) · G(α = 0.25) / (4 cos θl cos θv)

``spec_trans``  w_g · T · Walter et al. 2007 rough dielectric BTDF (solid), or the
                mirrored-reflection thin sheet with Burley 2015's roughness scale (thin)

Sources disagree in places; the choices (each said once in the code): the tint's luminance
is (0.3, 0.6, 0.1) (Burley; Schutte's 1.0 is a typo), the clearcoat keeps its
1/(4 cos cos) (Burley; Schutte and Mitsuba drop it), HK's F_ss90 uses roughness, not
roughness² (BRDF Explorer; Schutte squares it). Transmission uses the radiance-mode
1/η² (pbrt-v4, Mitsuba; Schutte omits it for his VCM).

Thin surfaces look the same from both sides; a solid one shows only its glass from inside.
Sampling picks a lobe with probability proportional to its estimated albedo; the
specular reflection and the glass transmission are one choice, split by the Fresnel term,
and below the glossy minimum α they are delta lobes (:mod:`.disney_interface`). A lobe
whose weight is a known zero is neither evaluated nor sampled.

>>> import numpy as np
>>> from .params import DisneyParams
>>> wi = wo = np.array([0.0, 0.0, 1.0])
>>> f = eval(DisneyParams(base_color=(1, 1, 1), specular=0, roughness=1), wi, wo)
>>> bool(np.all(f > 0))
True
"""

from __future__ import annotations

import dataclasses
import importlib
import math
from typing import Any

from . import energy
from . import fresnel as fr
from . import microfacet as mf
from .arrays import NumpyOps
from .bsdf import Model, density, draw, evaluate
from .disney_interface import (
    INTERFACE,
    etap,
    interface_pdf,
    inv_etap,
    pick,
    projected,
    sample_interface,
    specular_d,
    times,
    transmission,
    v_cavity_over_cos,
)
from .disney_prepare import (
    CLEARCOAT_F0,
    DISNEY_LOBES,
    INV_PI,
    LOBES,
    DisneyPrepared,
    mix,
    prepare,
    with_odds,
)
from .params import DisneyParams

__all__ = [
    "MODEL",
    "eval",
    "eval_core",
    "guide_core",
    "keep_every_lobe",
    "lobe_model",
    "pdf",
    "pdf_core",
    "restrict",
    "sample",
    "sample_core",
]


# -- the frame: thin sheets are two-sided, a solid is seen from inside only through glass --
def _orient(xp: Any, wi: Any, wo: Any) -> tuple[Any, Any, Any]:
    """(wi, wo) mirrored so that wo is in the upper hemisphere, and the mirror sign ±1."""
    s = xp.copysign(1.0, wo[2])  # of the directions' dtype: float32 stays float32
    return xp.vec3(wi[0], wi[1], wi[2] * s), xp.vec3(wo[0], wo[1], wo[2] * s), s


def _front(pr: DisneyPrepared, s: Any) -> Any:
    """1 where the outside's lobes exist, 0 inside a solid; None on a (two-sided) thin sheet."""
    return None if pr.thin else 0.5 + 0.5 * s


# -- lobes, in the oriented frame (wo.z ≥ 0) -------------------------------------------------
def _diffuse_shape(xp: Any, pr: DisneyPrepared, ci: Any, co: Any, cos2_d: Any) -> Any:
    """Burley §5.3 diffuse (without base/π), retro-reflection, flatness and subsurface."""
    fl, fv = fr.schlick_weight(xp, ci), fr.schlick_weight(xp, co)
    rr = 2.0 * pr.roughness * cos2_d
    retro = rr * (fl + fv + fl * fv * (rr - 1.0))  # Schutte's split of (1 + (F_D90 − 1)F)²
    if pr.volume:
        return retro  # Burley 2015: the Lambertian part enters the medium (diff_trans)
    lambert = (1.0 - 0.5 * fl) * (1.0 - 0.5 * fv)
    flat, sss = pr.flatness, pr.subsurface
    if xp.known_zero(flat) and xp.known_zero(sss):
        return retro + lambert
    # Hanrahan-Krueger; F_ss90 = cos²θd·roughness as the BRDF Explorer (Schutte: roughness²).
    fss90 = cos2_d * pr.roughness
    fss = mix(1.0, fss90, fl) * mix(1.0, fss90, fv)
    # 1e-20 keeps HK's integrable 1/(cos θl + cos θv) finite at ci = co = 0 (float32 too).
    hk = 1.25 * (fss * (1.0 / xp.maximum(ci + co, 1e-20) - 0.5) + 0.5)
    shape = retro + lambert * mix(1.0, hk, flat)  # 2015 flatness (Schutte)
    return mix(shape, hk, sss)  # 2012 subsurface (BRDF Explorer)


def _conty_kulla() -> Any:
    return importlib.import_module(".sheen", __package__)


def _conty_kulla_color(xp: Any, pr: DisneyPrepared) -> Any:
    """The microfacet sheen's reflectance F, per channel at most 1.

    Burley's tint (base over its luminance) exceeds 1 in saturated channels; a lobe
    reflecting more than all of the light would make the albedo scaling 1 − F·E negative
    and the material gain energy, so the Conty-Kulla colour is clamped to 1.
    """
    return xp.minimum(pr.sheen * pr.sheen_color, 1.0)


def _base_scale(xp: Any, pr: DisneyPrepared, ci: Any, co: Any) -> Any:
    """Conty-Kulla §5 albedo scaling of what lies under their sheen (1 elsewhere)."""
    if "sheen" not in pr.lobes or pr.sheen_model != "conty_kulla":
        return 1.0
    color = _conty_kulla_color(xp, pr)
    r = xp.asarray(pr.sheen_r)  # an array of the model's dtype: float32 stays float32
    scale = _conty_kulla().base_scale(xp, ci, co, r, color, exact=pr.sheen_exact)
    return xp.maximum(scale, 0.0)


def _energy_factor(xp: Any, pr: DisneyPrepared, co: Any, front: Any) -> Any:
    """1 + F0 (1 − E(μo))/E(μo) outside, 1 inside a solid (the glass's own reflection)."""
    extra = energy.factor(xp, pr.energy_f0, co, pr.energy_r) - 1.0
    return 1.0 + times(extra, front)


def _masked(xp: Any, cond: Any, x: Any) -> Any:
    """x where cond, else 0, for an ``x`` that is finite everywhere.

    With numpy a product with the boolean mask: ``np.where`` costs 20 times as much on
    the random masks of a BSDF (measured: 0.5 ms against 0.023 ms for 125k float32).
    """
    return x * cond if isinstance(xp, NumpyOps) else xp.select(cond, x, 0.0)


def _reflection_terms(
    xp: Any, pr: DisneyPrepared, wi: Any, wo: Any, front: Any, t_cos: Any = None
) -> tuple[list, Any]:
    """(colour or None, scalar) pairs summing to the reflection lobes, masked to wi, wo up,
    and the exact Fresnel term of the glass's reflection (None without one).

    Scalars carry every per-direction factor and colours are constants (or per-element
    maps), so each lobe costs one colour product. The half vector is h = wi + wo,
    unnormalised: |h|² = 4 cos²θd and D is homogeneous in h. ``t_cos``: wo·h of the
    glass's transmission, where wi is below; the exact Fresnel is then taken there
    instead of at θd, so that one call serves the lanes of both lobes (a pair either
    reflects or transmits).
    """
    lobes = pr.lobes
    up = (wi[2] > 0.0) & (wo[2] > 0.0)
    # Clamped cosines keep every term finite where ``up`` is false, so masking is a product.
    ci, co = xp.maximum(wi[2], 0.0), xp.maximum(wo[2], 0.0)
    h = wi + wo
    # |wi + wo|² = 4 cos²θd, taken from h itself: (1 + wi·wo)/2 cancels to 0 in float32
    # for a grazing mirror pair (cos θ = 1e-4), losing the whole highlight.
    h2 = xp.dot(h, h)
    cos2_d = 0.25 * h2
    cos_d = xp.sqrt(cos2_d)
    w = fr.schlick_weight(xp, cos_d)
    # z² of the directions themselves (= the clamped cosines' squares wherever a lobe is
    # kept): the glass's BTDF takes the same Smith terms
    # (:func:`.disney_interface.smith_denominator`), so the kernel computes their square
    # roots once for both sides.
    zi2, zo2 = wi[2] * wi[2], wo[2] * wo[2]
    scale = _base_scale(xp, pr, ci, co)
    terms = []
    f_exact = None
    if "specular" in lobes and "specular" not in pr.delta:
        if pr.ggx:
            qi, qo = projected(pr, wi, zi2), projected(pr, wo, zo2)
            # With glass, |cos θi| (= ci where the lobe is kept): its BTDF shares G's roots.
            zi = xp.abs(wi[2]) if "spec_trans" in lobes else ci
            g_den = mf.g1_pair_denominator(xp, zi, qi, co, qo, zi2, zo2)
            # specular_d's GGX and G over one division.
            dg = _masked(xp, up, 0.25 * mf.ggx_dg_over_cos(xp, h, h2, pr.ax, pr.ay, g_den))
        else:
            g = v_cavity_over_cos(xp, h, h2, ci, co)
            dg = xp.select(up, 0.25 * specular_d(xp, pr, h, h2) * g, 0.0)
        a, b, c = pr.spec_a, pr.spec_b, pr.spec_c
        dg_out = times(dg, front)
        spec_scale = scale
        if pr.energy:
            # Turquin 2019, seen from outside only (:mod:`.energy`): a colour factor
            # on this lobe alone (the layers under it keep ``scale``).
            ms = _energy_factor(xp, pr, co, front)
            spec_scale = ms if isinstance(scale, float) else scale * ms
        if not (xp.known_zero(a) and xp.known_zero(b)):  # no Schlick part: white glass
            terms += [(a * spec_scale, dg_out), ((b - a) * spec_scale, dg_out * w)]
        if not xp.known_zero(c):
            # The glass reflects the exact Fresnel on either side; inside, nothing else does.
            # wo·h > 0 too: h is 0/0 at wi = −wo with η = 1, and no NaN may reach the
            # reflection's masked product (the BTDF is 0 there: it needs wo·h > 0 itself).
            below = None if t_cos is None else (wi[2] < 0.0) & (t_cos > 0.0)
            cos = cos_d if below is None else xp.select(below, t_cos, cos_d)
            f_exact = fr.dielectric(xp, cos, etap(xp, pr, front), inv_etap(xp, pr, front))
            k = f_exact * dg * pick(xp, front, c, pr.glass)
            terms.append((None if isinstance(spec_scale, float) else spec_scale, k))
    if "diffuse" in lobes:
        shape = _diffuse_shape(xp, pr, ci, co, cos2_d)
        k = times(pr.diffuse * INV_PI * shape, front)
        terms.append((pr.base * scale, _masked(xp, up, k)))
    if "sheen" in lobes:
        if pr.sheen_model == "conty_kulla":
            r = xp.asarray(pr.sheen_r)
            lobe = _conty_kulla().lobe(xp, wi, wo, r, True, pr.sheen_exact)
            color = _conty_kulla_color(xp, pr)
        else:
            lobe = w * pr.sheen  # 2014 addendum: sheen · (1 − cos θd)⁵, no 1/π (Explorer)
            color = pr.sheen_color
        terms.append((color, _masked(xp, up, times(lobe, front))))
    if "clearcoat" in lobes:
        inv_h2 = 1.0 / xp.maximum(h2, xp.tiny)
        sin2_h = (h[0] * h[0] + h[1] * h[1]) * inv_h2  # not 1 − cos²: the α = 10⁻³ peak
        d = mf.gtr_d(xp, 1.0, pr.clearcoat_a2, h[2] * h[2] * inv_h2, sin2_h)
        a2 = mf.CLEARCOAT_G_ALPHA * mf.CLEARCOAT_G_ALPHA
        g = mf.g1_pair_over_cos(xp, ci, a2 * (1.0 - zi2), co, a2 * (1.0 - zo2), zi2, zo2)
        f = fr.schlick(xp, CLEARCOAT_F0, cos_d)
        # Burley's clearcoat keeps the 1/(4 cos cos) that Schutte and Mitsuba leave out.
        k = times((0.25 * pr.clearcoat) * f * d * g, front)
        terms.append((None, xp.select(up, k, 0.0)))  # D is 0/0 at wi = −wo: a true select
    return terms, f_exact


# -- the model's four core functions -------------------------------------------------------
def _eval_oriented(xp: Any, pr: DisneyPrepared, wi: Any, wo: Any, front: Any) -> Any:
    lobes = pr.lobes
    glossy_t = "spec_trans" in lobes and "spec_trans" not in pr.delta
    # A solid glass reflects and transmits with the exact Fresnel at the same η, at θd or
    # at its refracted microfacet: one call for both (see _reflection_terms).
    ht = t_cos = None
    if glossy_t and not pr.thin and "specular" in lobes and "specular" not in pr.delta:
        ht = mf.transmission_half(xp, wi, wo, etap(xp, pr, front))
        t_cos = xp.dot(wo, ht)
    terms, f_exact = _reflection_terms(xp, pr, wi, wo, front, t_cos)
    if "diff_trans" in lobes or glossy_t:
        down = (wi[2] < 0.0) & (wo[2] > 0.0)
        t = pr.diff_trans * INV_PI if "diff_trans" in lobes else 0.0
        if pr.volume and "diff_trans" in lobes:
            # The entry into (and exit from) the medium is the diffuse's Lambertian part,
            # Schutte's f_lambert (1 − F_L/2)(1 − F_V/2): symmetric, and with no internal
            # reflection it keeps the boundary's albedo below 1 from either side.
            t = t * (1.0 - 0.5 * fr.schlick_weight(xp, -wi[2]))
            t = t * (1.0 - 0.5 * fr.schlick_weight(xp, wo[2]))
        if glossy_t:
            f_t = None if t_cos is None else f_exact  # None: no exact reflection to share
            t = t + pr.glass * transmission(xp, pr, wi, wo, front, False, ht, f_t)
        terms.append((pr.trans_color, xp.select(down, t, 0.0)))
    grey = [s for c, s in terms if c is None]
    f = xp.zeros(wi[2]) * pr.base if not grey else None
    for color, scalar in terms:
        f = _add(f, color * scalar if color is not None else None)
    return _add(f, sum(grey[1:], grey[0]) if grey else None)


def _add(total: Any, term: Any) -> Any:
    if term is None:
        return total
    return term if total is None else total + term


def _odds(xp: Any, pr: DisneyPrepared, front: Any) -> dict[str, Any]:
    return {k: pick(xp, front, v, pr.odds_inside[k]) for k, v in pr.odds.items()}


def _pdf_oriented(xp: Any, pr: DisneyPrepared, wi: Any, wo: Any, front: Any) -> Any:
    odds = _odds(xp, pr, front)
    ci, co = wi[2], wo[2]
    up = (ci > 0.0) & (co > 0.0)
    down = (ci < 0.0) & (co > 0.0)
    h = wi + wo
    h2 = xp.maximum(xp.dot(h, h), xp.tiny)  # 4 cos²θd, from h for float32 (see above)
    p_up = xp.zeros(ci)
    if "diffuse" in odds or "sheen" in odds:
        p_up = (odds.get("diffuse", 0.0) + odds.get("sheen", 0.0)) * INV_PI * ci
    if "clearcoat" in odds:
        # D(h) cos θh / (4 wo·h) with cos θh = h_z/|h| and wo·h = |h|/2.
        d = mf.gtr_d(xp, 1.0, pr.clearcoat_a2, h[2] * h[2] / h2, (h[0] * h[0] + h[1] * h[1]) / h2)
        p_up = p_up + odds["clearcoat"] * d * h[2] / (2.0 * h2)
    p = xp.select(up, p_up, 0.0)
    if "diff_trans" in odds:
        p = p + xp.select(down, odds["diff_trans"] * -ci * INV_PI, 0.0)
    glossy = [k for k in INTERFACE if k in odds and k not in pr.delta]
    if glossy:
        o_d = sum(odds[k] for k in INTERFACE if k in odds)
        p = p + o_d * interface_pdf(xp, pr, wi, wo, front, h2, up, down)
    return p


def _oriented(xp: Any, pr: DisneyPrepared, wi: Any, wo: Any) -> tuple[Any, Any, Any, Any]:
    """(wi, wo, front, s) in the frame where wo is up; untouched when nothing needs it.

    Only a thin sheet (two-sided) or transmission looks at a viewer below the surface:
    without them every lobe is masked to wo.z > 0 anyway, and the flip is skipped.
    """
    if not (pr.thin or "spec_trans" in pr.lobes or "diff_trans" in pr.lobes):
        return wi, wo, None, None
    wi_, wo_, s = _orient(xp, wi, wo)
    return wi_, wo_, _front(pr, s), s


def eval_core(xp: Any, pr: DisneyPrepared, wi: Any, wo: Any) -> Any:
    """f(wi, wo) without the cosine (the :class:`~.bsdf.Model` contract)."""
    wi_, wo_, front, _ = _oriented(xp, pr, wi, wo)
    return _eval_oriented(xp, pr, wi_, wo_, front)


def pdf_core(xp: Any, pr: DisneyPrepared, wi: Any, wo: Any) -> Any:
    """Solid-angle density of :func:`sample_core` producing wi: the lobe mixture."""
    wi_, wo_, front, _ = _oriented(xp, pr, wi, wo)
    return _pdf_oriented(xp, pr, wi_, wo_, front)


def _candidates(xp: Any, pr: DisneyPrepared, wo: Any, u1: Any, u2: Any) -> dict:
    """One direction per present lobe outside the interface, and whether it is valid."""
    lobes = pr.lobes
    out = {}
    if {"diffuse", "sheen", "diff_trans"} & set(lobes):
        r, phi = xp.sqrt(u1), 2.0 * math.pi * u2  # Malley's method
        x, y, z = r * xp.cos(phi), r * xp.sin(phi), xp.safe_sqrt(1.0 - u1)
        out["diffuse"] = out["sheen"] = (xp.vec3(x, y, z), z > 0.0)
        out["diff_trans"] = (xp.vec3(x, y, -z), z > 0.0)
    if "clearcoat" in lobes:
        wi = mf.reflect(xp, wo, mf.sample_gtr(xp, 1.0, pr.clearcoat_a2, u1, u2))
        out["clearcoat"] = (wi, wi[2] > 0.0)
    return out


def sample_core(xp: Any, pr: DisneyPrepared, wo: Any, u: Any) -> tuple[Any, Any, Any, Any]:
    """(wi, f·|cos θi|/pdf, pdf, delta): u[0] picks a lobe by its odds, u[1], u[2] its
    direction. The specular interface (reflection and glass) is one choice, taking the
    last share of u[0], and splits by the Fresnel term (:mod:`.disney_interface`); a delta
    lobe's sample has the probability of its choice as ``pdf`` and ``delta`` True."""
    _, wo_, front, s = _oriented(xp, pr, wo, wo)
    odds = _odds(xp, pr, front)
    zero = xp.zeros(wo_[2])
    if not odds:  # nothing to sample (an opaque solid seen from inside)
        return xp.vec3(zero, zero, zero), zero * pr.base, zero, False
    interface = [k for k in INTERFACE if k in odds]
    others = [k for k in LOBES if k in odds and k not in INTERFACE]
    cands = _candidates(xp, pr, wo_, u[1], u[2])
    delta, value, o_d, p_choice, start = False, None, 0.0, 1.0, 0.0
    if interface:
        o_d = sum(odds[k] for k in interface)
        start = sum((odds[k] for k in others), 0.0)
        v = (u[0] - start) / xp.select(o_d > 0.0, o_d, 1.0) if others else u[0]
        scale = _base_scale(xp, pr, wo_[2], wo_[2])
        wi, valid, delta, value, p_choice = sample_interface(
            xp, pr, wo_, xp.clip(v, 0.0, 1.0), u[1], u[2], front, scale
        )
        if others and delta is not False:
            is_interface = u[0] >= start
            delta = is_interface if delta is True else is_interface & delta
        listed = others
    else:
        wi, valid = cands[others[-1]]
        listed = others[:-1]
    cum = 0.0
    chosen = []
    for k in listed:
        cum = cum + odds[k]
        chosen.append((u[0] < cum, k))
    for cond, k in reversed(chosen):
        wi = xp.vec3(*(xp.select(cond, cands[k][0][i], wi[i]) for i in range(3)))
        valid = xp.select(cond, cands[k][1], valid)
    valid = valid & (wo_[2] > 0.0)
    # A failed candidate may be NaN; evaluate at a harmless finite direction instead.
    wi = xp.vec3(*(xp.select(valid, wi[k], wo_[k]) for k in range(3)))
    if any(k not in pr.delta for k in odds):
        pdf = xp.select(valid, _pdf_oriented(xp, pr, wi, wo_, front), 0.0)
        f = _eval_oriented(xp, pr, wi, wo_, front)
        ok = pdf > 0.0
        weight = f * xp.select(ok, xp.abs(wi[2]) / xp.select(ok, pdf, 1.0), 0.0)
    else:  # only delta lobes: nothing has a density
        pdf, weight = zero, zero * pr.base
    if delta is not False:
        p_delta = o_d * p_choice
        ok_d = valid & (p_delta > 0.0)
        w_delta = value * xp.select(ok_d, 1.0 / xp.select(ok_d, p_delta, 1.0), 0.0)
        weight = xp.select(delta, w_delta, weight)
        pdf = xp.select(delta, xp.select(ok_d, p_delta, 0.0), pdf)
    ok = pdf > 0.0
    z = wi[2] if s is None else wi[2] * s
    # A failed sample is the zero vector with pdf 0 and weight 0, never NaN.
    wi = xp.vec3(xp.select(ok, wi[0], 0.0), xp.select(ok, wi[1], 0.0), xp.select(ok, z, 0.0))
    if delta is not False:
        delta = ok if delta is True else delta & ok
    return wi, weight, pdf, delta


def restrict(xp: Any, prepared: DisneyPrepared, names: Any) -> DisneyPrepared:
    """``prepared`` with only the lobes in ``names``, their sampling odds renormalised."""
    return with_odds(xp, prepared, tuple(k for k in prepared.lobes if k in names))


def guide_core(xp: Any, pr: DisneyPrepared, wo: Any) -> Any:
    """The glossy lobes' share of a denoiser's albedo guide (:mod:`.guides`), by OIDN's
    rules: a metal its colour at normal incidence (metallic·base, the F0 of the Schlick
    blend in ``spec_a``); glass the Fresnel blend of its reflection (1) and its
    transmission colour at the view, F(θo, η) + (1 − F)·T, with 1/η from inside a solid;
    the dielectric specular of a plastic and the clearcoat (non-absorbing coats) nothing.
    Seen from inside an opaque solid, nothing at all. None when no glossy lobe adds.
    """
    lobes = pr.lobes
    _, wo_, front, _ = _oriented(xp, pr, wo, wo)
    if front is None and not pr.thin:
        front = xp.select(wo[2] > 0.0, 1.0, 0.0)  # one-sided: nothing from below, as eval
    out = None
    if "specular" in lobes:
        # 1 − w_d − w_g = metallic (disney_prepare: w_d + w_g = 1 − metallic).
        metallic = 1.0 - pr.diffuse - pr.diff_trans - pr.glass
        if not xp.known_zero(metallic):
            out = times(metallic * pr.base, front)
    if "spec_trans" in lobes:
        f = fr.dielectric(xp, wo_[2], etap(xp, pr, front), inv_etap(xp, pr, front))
        out = _add(out, pr.glass * (f + (1.0 - f) * pr.trans_color))
    return out


MODEL = Model(
    "disney",
    DisneyParams,
    prepare,
    eval_core,
    pdf_core,
    sample_core,
    restrict,
    DISNEY_LOBES,
    guide_core,
)


def keep_every_lobe(xp: Any, prepared: DisneyPrepared) -> DisneyPrepared:
    """A prepared material with pruning undone: every lobe evaluated, zero weights and all.

    The same values at a higher cost; the baseline that measures what pruning saves.
    """
    return with_odds(xp, prepared, LOBES)


def lobe_model(*names: str) -> Model:
    """The Disney model restricted to some lobes (their odds renormalised), for tests and
    per-lobe analysis. ``lobe_model("clearcoat")`` evaluates and samples only the clearcoat.
    """
    unknown = set(names) - set(LOBES)
    if unknown:
        raise ValueError(f"unknown lobe(s) {sorted(unknown)}; known: {', '.join(LOBES)}")

    def prepare_only(xp: Any, params: DisneyParams, **maps: Any) -> DisneyPrepared:
        return restrict(xp, prepare(xp, params, **maps), names)

    return dataclasses.replace(MODEL, name="disney[" + ",".join(names) + "]", prepare=prepare_only)


# -- public numpy API --------------------------------------------------------------------
def eval(params: DisneyParams, wi: Any, wo: Any, **kw: Any) -> Any:  # noqa: A001
    """f(wi, wo) without the cosine, shape (..., 3); wi towards the light, wo the viewer."""
    return evaluate(MODEL, params, wi, wo, **kw)


def pdf(params: DisneyParams, wi: Any, wo: Any, **kw: Any) -> Any:
    """Solid-angle density with which :func:`sample` produces wi given wo, shape (...)."""
    return density(MODEL, params, wi, wo, **kw)


def sample(params: DisneyParams, wo: Any, u: Any, **kw: Any) -> tuple[Any, ...]:
    """(wi, weight = f·|cos θi|/pdf, pdf) from uniforms u of shape (..., 3); with
    ``delta=True`` a fourth array marks delta-lobe samples (their pdf is a probability)."""
    return draw(MODEL, params, wo, u, **kw)
