"""The Disney specular interface: ``specular`` and ``spec_trans`` as one dielectric surface.

The reflection of the specular lobe and the transmission of the glass meet at one surface
with one roughness, so they are sampled as one strategy, as Mitsuba's ``dielectric`` and
``roughdielectric`` do (Walter et al. 2007 §5.3; pbrt-v4 ``DielectricBxDF``):

* **Fresnel-weighted choice.** Reflection or transmission is chosen with probability
  proportional to what each lets through: P_R = F_R / (F_R + F_T), with F_R the
  (luminance of the) reflection Fresnel of the specular lobe and F_T = w_g (1 − F), F the
  exact dielectric Fresnel. For white glass that is P_R = F exactly, Mitsuba's rule.
  A solid rough surface takes F at the sampled microfacet (wo·h), so each micro-normal
  reflects or refracts as its own Fresnel says; a thin sheet, whose two lobes have
  different roughnesses, and a smooth surface take it at the macro normal (cos θo). A
  fixed choice costs 2.3–2.9× the per-pixel noise on glass (:doc:`/measurements/glass`).
* **Smooth lobes are deltas.** Where a lobe's α (roughness², stretched by
  ``anisotropic``) is below :data:`~.microfacet.ALPHA_MIN` — the value roughness 0 used
  to be clamped to — the lobe is a Dirac delta (:func:`~.microfacet.is_delta`): the
  mirror reflection and the Snell refraction (straight through a thin sheet). ``eval``
  and ``pdf`` leave it out (it has no density); ``sample`` returns it with the lobe's
  exact weight (:func:`delta_reflectance`, :func:`delta_transmittance`) over the
  probability it was chosen with, which is also the ``pdf`` it reports, and flags it
  ``delta``; the renderer then does not sample lights at that vertex. The limit is exact
  in energy: ∫ f cos dω of the glossy lobe tends to these weights as α → 0.

The clearcoat (GTR1, γ = 1) is not a delta at gloss 1: its α = 0.001 is Burley's, and
GTR1's long tails carry visible energy at any α. The diffuse, sheen and clearcoat lobes of
a material with a smooth interface are sampled as before, beside it (one-sample MIS over
the lobes that have a density).
"""

from __future__ import annotations

from typing import Any

from . import fresnel as fr
from . import microfacet as mf
from .disney_prepare import DisneyPrepared

__all__ = [
    "INTERFACE",
    "delta_reflectance",
    "delta_transmittance",
    "interface_pdf",
    "inv_etap",
    "pick",
    "projected",
    "sample_interface",
    "smith_denominator",
    "specular_d",
    "split",
    "transmission",
    "v_cavity_over_cos",
]

INTERFACE = ("specular", "spec_trans")
"""The Disney lobes this module samples together."""


def pick(xp: Any, front: Any, outside: Any, inside: Any) -> Any:
    """``outside`` where front is 1, ``inside`` where it is 0 (exactly: x·1 + y·0)."""
    same = isinstance(outside, float) and isinstance(inside, float) and outside == inside
    return outside if front is None or same else outside * front + inside * (1.0 - front)


def times(x: Any, front: Any) -> Any:
    return x if front is None else x * front


def projected(pr: DisneyPrepared, w: Any, z2: Any, transmitted: bool = False) -> Any:
    """αx² x² + αy² y², the projected roughness of Smith's Λ (Heitz 2014 eq. 86).

    Isotropic constants use x² + y² = 1 − z² (only its absolute error matters: q is
    added to z²), which saves two products per direction.
    """
    ax2, ay2 = (pr.tax2, pr.tay2) if transmitted else (pr.ax2, pr.ay2)
    if isinstance(ax2, float) and ax2 == ay2:
        return ax2 * (1.0 - z2)
    return ax2 * (w[0] * w[0]) + ay2 * (w[1] * w[1])


def _qt(pr: DisneyPrepared, w: Any) -> Any:
    return projected(pr, w, w[2] * w[2], transmitted=True)


def etap(xp: Any, pr: DisneyPrepared, front: Any) -> Any:
    """η of the far side over the viewer's side (a thin sheet: η on both sides)."""
    return pick(xp, front, pr.eta, 1.0 / pr.eta)


def inv_etap(xp: Any, pr: DisneyPrepared, front: Any) -> Any:
    """1/:func:`etap`, picked from the two constants: no per-element division."""
    return pick(xp, front, 1.0 / pr.eta, pr.eta)


def transmission(
    xp: Any,
    pr: DisneyPrepared,
    wi: Any,
    wo: Any,
    front: Any,
    pdf: bool,
    h: Any = None,
    fresnel: Any = None,
) -> Any:
    """f (without weight and colour) of the glossy transmission, or its lobe pdf; wi below.

    A solid's caller may pass its generalised half vector ``h``
    (:func:`~.microfacet.transmission_half` at :func:`etap`) and the Fresnel term at it
    (:func:`~.microfacet.dielectric_btdf`'s ``fresnel``)."""
    ax, ay = pr.tax, pr.tay
    if pr.thin:
        # Schutte: reflection about the rougher thin α, mirrored through the sheet.
        wm = xp.vec3(wi[0], wi[1], -wi[2])
        h = xp.normalize(wm + wo)
        oh = xp.dot(wo, h)
        if pdf:
            return mf.visible_ggx_pdf(xp, wo, h, ax, ay) / xp.maximum(4.0 * oh, xp.tiny)
        g = mf.g1_pair_over_cos(xp, wm[2], _qt(pr, wm), wo[2], _qt(pr, wo))
        return (1.0 - fr.dielectric(xp, oh, pr.eta)) * mf.ggx_d(xp, h, ax, ay) * g * 0.25
    e, inv = etap(xp, pr, front), inv_etap(xp, pr, front)
    g_den = None if pdf else smith_denominator(xp, pr, wi, wo)
    return mf.dielectric_btdf(
        xp, wi, wo, e, ax, ay, pdf, h=h, inv_eta=inv, fresnel=fresnel, g_den=g_den
    )


def smith_denominator(xp: Any, pr: DisneyPrepared, wi: Any, wo: Any) -> Any:
    """dᵢ dₒ of G1(wi) G1(wo)/(−cos θi cos θo) = 4/(dᵢ dₒ) of the solid glass (wi below,
    wo up; :func:`~.microfacet.g1_pair_denominator`), written as the specular reflection
    writes its own (:func:`.disney._reflection_terms`: the same z² and :func:`projected`,
    the absolute cos θi for wi): where the two α agree the kernel takes G's square roots
    once for both, and the BTDF divides by it in its own one division."""
    zi2, zo2 = wi[2] * wi[2], wo[2] * wo[2]
    qi, qo = projected(pr, wi, zi2, transmitted=True), projected(pr, wo, zo2, transmitted=True)
    return mf.g1_pair_denominator(xp, xp.abs(wi[2]), qi, xp.maximum(wo[2], 0.0), qo, zi2, zo2)


def specular_d(xp: Any, pr: DisneyPrepared, h: Any, h2: Any) -> Any:
    """D of the primary specular lobe at the unnormalised half vector h (|h|² = ``h2``):
    the anisotropic GGX (eq. 13) at γ = 2, else the isotropic GTR of eq. 1 with α² = αx αy
    (``specular_gamma``, Burley 2012 App. B).

    The GTR D is ∞ at h = 0 (wi = −wo, never a reflection pair): callers select, not mask.
    """
    if pr.ggx:
        return mf.ggx_d(xp, h, pr.ax, pr.ay, n2=h2)
    inv_h2 = 1.0 / xp.maximum(h2, xp.tiny)
    sin2_h = (h[0] * h[0] + h[1] * h[1]) * inv_h2  # not 1 − cos²: the α = 10⁻³ peak
    return mf.gtr_d(xp, pr.gamma, pr.a2, h[2] * h[2] * inv_h2, sin2_h)


def v_cavity_over_cos(xp: Any, h: Any, h2: Any, ci: Any, co: Any) -> Any:
    """G/(cos θi cos θo) with the Cook–Torrance V-cavity G = min(1, 2 cos θh cos θ/(wo·h))
    over both directions, written with the unnormalised h (2 cos θh/(wo·h) = 4 h_z/|h|²).

    The shadowing of GTR at γ ≠ 2: Smith's Λ has no closed form for it (App. B closes
    only GTR2), and GGX's Λ at the same α under GTR's heavier tail gains energy without
    bound (measured, white metal at cos θo = 10⁻⁴: albedo 1.92 at γ = 1, roughness 0.5;
    131 at roughness 0), while the V-cavity G is normalised for any D (Heitz 2014 §5.2:
    ∫ G1 ⟨wo, h⟩ D dh = cos θo), so the lobe never reflects more than the light.
    """
    k = 4.0 * xp.maximum(h[2], 0.0) / xp.maximum(h2, xp.tiny)
    inv = 1.0 / xp.maximum(ci * co, xp.tiny)
    return xp.minimum(inv, k / xp.maximum(xp.maximum(ci, co), xp.tiny))


def _has(pr: DisneyPrepared) -> tuple[bool, bool, bool, bool]:
    """(reflection present, transmission present, reflection delta, transmission delta)."""
    lobes, delta = pr.lobes, pr.delta
    r, t = "specular" in lobes, "spec_trans" in lobes
    return r, t, r and "specular" in delta, t and "spec_trans" in delta


def per_facet(pr: DisneyPrepared) -> bool:
    """Whether the choice takes F at the sampled microfacet (a solid, rough, both lobes)."""
    r, t, dr, _ = _has(pr)
    # A GTR reflection (γ ≠ 2) and the GGX glass have different micro-normals: no sharing.
    return r and t and not dr and not pr.thin and pr.ggx


def split(xp: Any, pr: DisneyPrepared, cos: Any, front: Any) -> tuple[Any, Any]:
    """(P_R, P_T): the probabilities of reflecting and transmitting at incidence ``cos``.

    P_R = F_R / (F_R + F_T): F_R the luminance of the specular lobe's Fresnel (Schlick's
    part where the viewer is outside, plus the exact part), F_T = w_g (1 − F). Both 0
    where nothing gets through (F_R + F_T = 0).
    """
    has_r, has_t, _, _ = _has(pr)
    if not has_t:
        return 1.0, 0.0
    f = fr.dielectric(xp, cos, etap(xp, pr, front), inv_etap(xp, pr, front))
    t = pr.glass * (1.0 - f)
    if not has_r:
        r = 0.0
    else:
        lum_a = pr.spec_lum_a
        r = pick(xp, front, pr.spec_c, pr.glass) * f
        if not (xp.known_zero(lum_a) and xp.known_zero(pr.spec_b)):
            w = fr.schlick_weight(xp, cos)
            r = r + times(lum_a + (pr.spec_b - lum_a) * w, front)
    total = r + t
    # A subnormal total (spec_trans = 1e-45 in float32) has no finite reciprocal: r·∞ is NaN
    ok = total > xp.tiny
    inv = xp.select(ok, 1.0 / xp.select(ok, total, 1.0), 0.0)
    return r * inv, t * inv


def delta_reflectance(xp: Any, pr: DisneyPrepared, co: Any, front: Any, scale: Any) -> Any:
    """The smooth specular lobe's weight at the mirror direction: its Fresnel at θo.

    The α → 0 limit of ∫ f cos θi dωi: F_front(θo) = A + (B − A)(1 − cos θo)⁵ + c F(θo)
    outside (:func:`.disney_prepare._fresnel_terms`), w_g F(θo, 1/η) inside a solid,
    times the Conty-Kulla scaling under a sheen.
    """
    a, b = pr.spec_a, pr.spec_b
    col = times(a + (b - a) * fr.schlick_weight(xp, co), front)
    if not xp.known_zero(pr.spec_c):
        f = fr.dielectric(xp, co, etap(xp, pr, front), inv_etap(xp, pr, front))
        col = col + pick(xp, front, pr.spec_c, pr.glass) * f
    return col * scale


def delta_transmittance(xp: Any, pr: DisneyPrepared, co: Any, front: Any) -> Any:
    """The smooth glass's transmitted weight: w_g T (1 − F(θo)), over η² through a solid
    (radiance, as :func:`.microfacet.dielectric_btdf`); a thin sheet does not refract.

    The adjoint (``pr.adjoint``, a light tracer: ``co`` is then the light's side)
    has no 1/η²: Snell pairs have one Fresnel, and radiance/η² is what is conserved,
    so the η² of the radiance form is all that differs (Mitsuba's ``dielectric``).
    """
    inv = inv_etap(xp, pr, front)
    t = pr.glass * (1.0 - fr.dielectric(xp, co, etap(xp, pr, front), inv))
    if not pr.thin and not pr.adjoint:
        t = t * (inv * inv)
    return pr.trans_color * t


def _snell(xp: Any, wo: Any, e: Any) -> tuple[Any, Any]:
    """wo refracted through the macro surface (normal +z), and whether it is not TIR."""
    co = wo[2]
    sin2_t = (1.0 - co * co) / (e * e)
    cos_t = xp.safe_sqrt(1.0 - sin2_t)
    inv = 1.0 / e
    return xp.vec3(-wo[0] * inv, -wo[1] * inv, -cos_t), sin2_t < 1.0


def sample_interface(
    xp: Any, pr: DisneyPrepared, wo: Any, v: Any, u1: Any, u2: Any, front: Any, scale: Any
) -> tuple[Any, Any, Any, Any, Any]:
    """One direction of the interface from ``v`` (the choice) and ``u1, u2`` (its direction).

    Returns ``(wi, valid, delta, value, prob)``: ``delta`` (a bool, or a mask where the
    two lobes differ) marks a delta lobe's direction, ``value`` its weight colour and
    ``prob`` = P_R or P_T, the probability of the choice (the caller multiplies by the
    interface's odds). ``wo`` is up (the oriented frame).
    """
    has_r, has_t, d_r, d_t = _has(pr)
    co = wo[2]
    h = None
    if has_r:
        if d_r:
            wr, ok_r = xp.vec3(-wo[0], -wo[1], co), co > 0.0
        else:
            if pr.ggx:
                h = mf.sample_visible_ggx(xp, wo, pr.ax, pr.ay, u1, u2)
            else:  # visible-normal sampling exists for GGX only: App. B eqs. 2–3
                h = mf.sample_gtr(xp, pr.gamma, pr.a2, u1, u2)
            wr = mf.reflect(xp, wo, h)
            ok_r = wr[2] > 0.0
    if has_t:
        e = etap(xp, pr, front)
        if d_t:
            if pr.thin:
                wt, ok_t = xp.vec3(-wo[0], -wo[1], -co), co > 0.0
            else:
                wt, ok_t = _snell(xp, wo, e)
        else:
            ht = h if h is not None and not pr.thin and pr.ggx else None
            if ht is None:
                ht = mf.sample_visible_ggx(xp, wo, pr.tax, pr.tay, u1, u2)
            if pr.thin:
                m = mf.reflect(xp, wo, ht)
                wt, ok_t = xp.vec3(m[0], m[1], -m[2]), m[2] > 0.0
            else:
                wt, ok_t = mf.refract(xp, wo, ht, e)
                ok_t = ok_t & (wt[2] < 0.0)
    if not has_t:
        value = delta_reflectance(xp, pr, co, front, scale) if d_r else None
        return wr, ok_r, d_r, value, 1.0
    p_r, p_t = split(xp, pr, xp.dot(wo, h) if per_facet(pr) else co, front)
    if not has_r:
        value = delta_transmittance(xp, pr, co, front) if d_t else None
        return wt, ok_t, d_t, value, p_t
    reflect = v < p_r
    wi = xp.vec3(*(xp.select(reflect, wr[k], wt[k]) for k in range(3)))
    valid = xp.select(reflect, ok_r, ok_t)
    delta = d_r if d_r == d_t else xp.select(reflect, d_r, d_t)
    value = None
    if d_r or d_t:
        zero = xp.zeros(co) * pr.trans_color
        vr = delta_reflectance(xp, pr, co, front, scale) if d_r else zero
        vt = delta_transmittance(xp, pr, co, front) if d_t else zero
        value = xp.select(reflect, vr, vt)
    return wi, valid, delta, value, xp.select(reflect, p_r, p_t)


def interface_pdf(
    xp: Any, pr: DisneyPrepared, wi: Any, wo: Any, front: Any, h2: Any, up: Any, down: Any
) -> Any:
    """Density of the interface's glossy lobes producing wi (without the interface odds).

    ``h2`` = |wi + wo|² (4 cos²θd); ``up``/``down``: wi on the viewer's side / across.
    """
    has_r, has_t, d_r, d_t = _has(pr)
    co = wo[2]
    facet = per_facet(pr)
    p = 0.0
    if not facet:
        p_r, p_t = split(xp, pr, co, front)
    if has_r and not d_r:
        h = wi + wo
        if pr.ggx:
            # Visible normals: D_wo(h)/(4 wo·h) = G1(wo) D(h) / (4 cos θo).
            zo2 = co * co
            g1 = mf.g1_over_cos(xp, co, projected(pr, wo, zo2), zo2)
            vndf = 0.25 * mf.ggx_d(xp, h, pr.ax, pr.ay, n2=h2) * g1
        else:
            # GTR (App. B eqs. 2–3): D(h) cos θh / (4 wo·h), cos θh = h_z/|h|, wo·h = |h|/2.
            vndf = xp.select(up, specular_d(xp, pr, h, h2) * h[2] / (2.0 * h2), 0.0)
        if facet:
            p_r = split(xp, pr, 0.5 * xp.sqrt(h2), front)[0]  # wo·h = |wi + wo|/2
        p = xp.select(up, p_r * vndf, 0.0)
    if has_t and not d_t:
        if facet:
            e = etap(xp, pr, front)
            ht = mf.transmission_half(xp, wi, wo, e)
            p_t = split(xp, pr, xp.dot(wo, ht), front)[1]
            inv = inv_etap(xp, pr, front)
            pt = mf.dielectric_btdf(xp, wi, wo, e, pr.tax, pr.tay, True, h=ht, inv_eta=inv)
        else:
            pt = transmission(xp, pr, wi, wo, front, pdf=True)
        p = p + xp.select(down, p_t * pt, 0.0)
    return p
