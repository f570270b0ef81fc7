"""Scattering by Smits' six lobes once their weights are known: f, pdf and sampling.

Both Pixar models (:mod:`.pixar`) reduce a material to one :class:`PixarPrepared`
(:func:`prepared`): the twelve weights at the two ends of the view, each highlight lobe's
exponent, the IOR and the lobes whose weights are not known to be zero. The functions
here read only that, so a plain material and a composited stack scatter by the same
code. Lobe shapes are in :mod:`.pixar_lobes`; the surface is two-sided (the view's side
is +z), and a lobe is sampled with the probability of its estimated albedo at the view.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from . import pixar_lobes as lobes
from .bsdf import Lobe, Prepared

__all__ = [
    "LOBES",
    "PixarPrepared",
    "PIXAR_LOBES",
    "PREFIX",
    "at_view",
    "delta_lobes",
    "kept_lobes",
    "prepared",
    "scatter_eval",
    "scatter_guide",
    "scatter_pdf",
    "scatter_sample",
]

PIXAR_LOBES = (
    Lobe("diffuse", "diffuse", family="diffuse", params=("diffuse_scale",)),
    Lobe(
        "specular",
        "glossy",
        highlight=True,
        family="specular",
        params=("specular_scale", "specular_cone_scale", "specular_tint"),
    ),
    Lobe(
        "reflection",
        "glossy",
        highlight=True,
        family="reflection",
        params=("reflection_scale", "reflection_cone_scale", "specular_tint"),
    ),
    Lobe(
        "diffuse_t",
        "diffuse",
        True,
        family="diffuse",
        params=("back", "diffuse_t_scale"),
        switches=("back",),
    ),
    Lobe(
        "specular_t",
        "glossy",
        True,
        highlight=True,
        family="specular",
        params=("specular_t_scale", "transmission_tint", "ior"),
        switches=("clear",),
        reciprocal=False,
    ),
    Lobe(
        "reflection_t",
        "glossy",
        True,
        highlight=True,
        family="reflection",
        params=("reflection_t_scale", "transmission_tint", "ior"),
        switches=("clear",),
        reciprocal=False,
    ),
)
"""Smits' three lobes and their transmitted twins; a lobe's ``family`` is its type in
his interaction table. Parameters named by a lobe act through it (and its listed peers)."""
LOBES = tuple(lobe.name for lobe in PIXAR_LOBES)
PREFIX = dict(zip(LOBES, ("diff", "spec", "refl", "diffT", "specT", "reflT"), strict=True))
"""lobe → the stem of its weights in Smits' notebook (``diffN``, ``diffG`` …)."""


def at_view(xp: Any, pairs: dict[str, tuple[Any, Any]], cos_view: Any) -> dict[str, Any]:
    """The twelve weights for a view at ``cos_view`` from their two ends (:func:`.pixar.ends`):
    (1 − s) W(s=0) + s W(s=1) with s = (1 − V·n)⁵, exact at both ends."""
    s = lobes.schlick_weight(xp, cos_view)
    return {k: n if g is None else n * (1.0 - s) + g * s for k, (n, g) in pairs.items()}


def kept_lobes(xp: Any, pairs: dict[str, tuple[Any, Any]]) -> tuple[str, ...]:
    """Lobes whose weights are not known to be zero (:doc:`/design`: nothing unneeded)."""
    kept = []
    for lobe in LOBES:
        values = [v for end in "NG" for v in pairs[PREFIX[lobe] + end] if v is not None]
        if not all(xp.known_zero(v) for v in values):
            kept.append(lobe)
    return tuple(kept)


def delta_lobes(cones: dict[str, Any], falloffs: dict[str, Any]) -> tuple[str, ...]:
    """Highlight lobes that are deltas: a constant cone at most
    :data:`~.pixar_lobes.CONE_MIN_DEG`, with a positive falloff.

    Smits' reflection cone "goes between 0 (or epsilon in practice) and 10 degrees": the
    cone used to be floored at 0.5° (the blend still floors it, for its energy-weighted
    means, :mod:`lookdev.pipeline.blend.pixar_composite`, hence "at most" here, so a lone
    layer stays its preset), and every narrower cone rendered alike as a glossy
    lobe the renderer sampled lights for at every vertex (as the Disney glass did).
    Below the floor the lobe is now its p → ∞ limit, a mirror (or, for a transmitted
    lobe, the view refracted by the IOR), whose weight is FrnBlend[N, G, cos θo]: the
    lobe's albedo in that limit. A cone or falloff that varies per element stays glossy
    (the kernel's lobe kinds are fixed when it is traced); a falloff of 0 is a flat lobe.
    """
    out = []
    for lobe, cone in cones.items():
        fall = falloffs.get(lobe)
        if isinstance(cone, float) and isinstance(fall, float):
            if cone <= lobes.CONE_MIN_DEG and fall > 0.0:
                out.append(lobe)
    return tuple(out)


@dataclass(frozen=True, kw_only=True)
class PixarPrepared(Prepared):
    """What Smits' lobes read, for plain and composited (layered) Pixar materials alike;
    ``eta`` is the IOR the transmitted highlights refract the view by."""

    ends: dict[str, Any]
    """Each of the twelve weights (``specN``, ``specG`` …, :data:`PREFIX`) at normal and
    grazing view (None at grazing where it is view-independent), interpolated by
    :func:`at_view`."""
    power: dict[str, Any]
    """Each highlight lobe's Phong-like exponent (:mod:`.pixar_lobes`)."""


def prepared(
    xp: Any, pairs: dict, powers: dict[str, Any], eta: Any, delta: tuple[str, ...] = ()
) -> PixarPrepared:
    """What eval/pdf/sample consume, from the weights' two ends, each highlight lobe's
    exponent, the IOR and the delta lobes (:func:`delta_lobes`): the one path for plain
    and composited materials."""
    kept = kept_lobes(xp, pairs)
    return PixarPrepared(
        lobes=kept,
        delta=tuple(k for k in delta if k in kept),
        eta=eta,
        ends=pairs,
        power=powers,
    )


def _upper(xp: Any, wi: Any, wo: Any) -> tuple[Any, Any]:
    """Both directions with the view's side as +z (the surface is two-sided)."""
    s = xp.select(wo[2] < 0.0, -1.0, 1.0)
    return xp.vec3(wi[0], wi[1], wi[2] * s), xp.vec3(wo[0], wo[1], wo[2] * s)


def _power(prep: PixarPrepared, lobe: str) -> Any:
    return prep.power[lobe]


def _lobe_value(xp: Any, prep: PixarPrepared, w: dict, lobe: str, wi: Any, wo: Any) -> Any:
    """One lobe's f(wi, wo) (colour), zero on the side it does not cover."""
    p = PREFIX[lobe]
    n, g = w[p + "N"], w[p + "G"]
    if lobe.endswith("_t"):
        side = wi[2] < 0.0
        if lobe == "diffuse_t":
            f = lobes.frn_blend(xp, n, g, -wi[2]) * lobes.INV_PI
        else:
            # Blended by the view's incidence on the front, where the light crosses: the
            # transmitted weights are the share the front Fresnel did not reflect.
            back_i, back_o = lobes.to_back(xp, wi), lobes.back_view(xp, wo, prep.eta)
            f = lobes.p_specular(xp, back_i, back_o, _power(prep, lobe), n, g, wo[2])
    else:
        side = wi[2] > 0.0
        if lobe == "diffuse":
            f = lobes.frn_blend(xp, n, g, wi[2]) * lobes.INV_PI
        else:
            f = lobes.p_specular(xp, wi, wo, _power(prep, lobe), n, g)
    return xp.select(side & (wo[2] > 0.0), f, 0.0)


def scatter_eval(xp: Any, prep: PixarPrepared, wi: Any, wo: Any) -> Any:
    wi, wo = _upper(xp, wi, wo)
    w = at_view(xp, prep.ends, wo[2])
    f = xp.zeros(wi[2]) * w["specN"]
    for lobe in prep.lobes:
        if lobe not in prep.delta:  # a delta has no value at any given direction
            f = f + _lobe_value(xp, prep, w, lobe, wi, wo)
    return f


def _mean(c: Any) -> Any:
    return (c[0] + c[1] + c[2]) * (1.0 / 3.0)


def _selection(xp: Any, prep: PixarPrepared, wo: Any) -> dict[str, Any]:
    """Probability of sampling each kept lobe: its estimated albedo at this view."""
    w = at_view(xp, prep.ends, wo[2])
    est = {}
    for lobe in prep.lobes:
        n, g = w[PREFIX[lobe] + "N"], w[PREFIX[lobe] + "G"]
        if lobe.startswith("diffuse"):
            albedo = n + (g - n) / 21.0  # exact: ∫ 2(1 − μ)⁵ μ dμ = 1/21
        else:
            albedo = lobes.frn_blend(xp, n, g, wo[2])  # the highlight's weight at its peak
        est[lobe] = _mean(albedo)
    total = sum(est.values()) if est else 0.0
    inv = xp.select(total > 0.0, 1.0 / xp.maximum(total, xp.tiny), 0.0)
    return {lobe: e * inv for lobe, e in est.items()}


def _lobe_pdf(xp: Any, prep: PixarPrepared, lobe: str, wi: Any, wo: Any) -> Any:
    if lobe == "diffuse":
        return xp.maximum(wi[2], 0.0) * lobes.INV_PI
    if lobe == "diffuse_t":
        return xp.maximum(-wi[2], 0.0) * lobes.INV_PI
    if lobe.endswith("_t"):
        back_i, back_o = lobes.to_back(xp, wi), lobes.back_view(xp, wo, prep.eta)
        pdf = lobes.half_vector_pdf(xp, back_i, back_o, _power(prep, lobe))
        return xp.select(wi[2] < 0.0, pdf, 0.0)
    return xp.select(wi[2] > 0.0, lobes.half_vector_pdf(xp, wi, wo, _power(prep, lobe)), 0.0)


def _mixture_pdf(xp: Any, prep: PixarPrepared, wi: Any, wo: Any) -> Any:
    probs = _selection(xp, prep, wo)
    pdf = xp.zeros(wi[2])
    for lobe, prob in probs.items():
        if lobe not in prep.delta:
            pdf = pdf + prob * _lobe_pdf(xp, prep, lobe, wi, wo)
    return xp.select(wo[2] > 0.0, pdf, 0.0)


def scatter_pdf(xp: Any, prep: PixarPrepared, wi: Any, wo: Any) -> Any:
    wi, wo = _upper(xp, wi, wo)
    return _mixture_pdf(xp, prep, wi, wo)


def _candidate(xp: Any, prep: PixarPrepared, lobe: str, wo: Any, u1: Any, u2: Any) -> Any:
    """The direction lobe ``lobe`` would sample (upper side = the view's side)."""
    if lobe == "diffuse":
        return lobes.cosine_hemisphere(xp, u1, u2)
    if lobe == "diffuse_t":
        return lobes.to_back(xp, lobes.cosine_hemisphere(xp, u1, u2))
    if lobe in prep.delta:  # the lobe's axis itself: the mirror, or the refracted view
        view = lobes.back_view(xp, wo, prep.eta) if lobe.endswith("_t") else wo
        mirror = xp.vec3(-view[0], -view[1], view[2])
        return lobes.to_back(xp, mirror) if lobe.endswith("_t") else mirror
    h = lobes.sample_half_vector(xp, _power(prep, lobe), u1, u2)
    if lobe.endswith("_t"):
        view = lobes.back_view(xp, wo, prep.eta)
        return lobes.to_back(xp, lobes.reflect(xp, view, h))
    return lobes.reflect(xp, wo, h)


def _delta_weight(xp: Any, prep: PixarPrepared, lobe: str, wo: Any) -> Any:
    """A delta lobe's weight: FrnBlend[N, G, cos θo], its albedo as the cone closes."""
    w = at_view(xp, prep.ends, wo[2])
    p = PREFIX[lobe]
    return lobes.frn_blend(xp, w[p + "N"], w[p + "G"], wo[2])


def _adjoint_refraction(xp: Any, prep: PixarPrepared, lobe: str, wl: Any) -> tuple[Any, Any]:
    """The adjoint of a delta transmitted lobe, for light arriving from ``wl`` (+z side):
    (the viewer's direction, its weight).

    The lobe sends the view v to g(v) = (−vx/η, −vy/η, −cos θt), sin θt = sin θv/η. Its
    adjoint sends light from l to the one viewer that sees it, v* = g⁻¹(l): (−η lx,
    −η ly, −√(1 − η² sin²θl)), none where η sin θl > 1 (that light reaches no viewer
    through this lobe). Projected solid angle scales as sin²θ, so dσ(v) = η² dσ(l) and
    the weight is η² W(v*), W the radiance weight FrnBlend[N, G, cos θv*] (Veach 1997
    §5.2: the adjoint of a bending without the 1/η² of radiance transport).
    """
    eta = prep.eta
    sin2 = eta * eta * (1.0 - wl[2] * wl[2])
    cos_v = xp.safe_sqrt(1.0 - sin2)
    view = xp.vec3(-wl[0] * eta, -wl[1] * eta, -cos_v)
    weight = _delta_weight(xp, prep, lobe, xp.vec3(view[0], view[1], cos_v)) * (eta * eta)
    return view, xp.select(sin2 < 1.0, weight, 0.0)


def scatter_sample(xp: Any, prep: PixarPrepared, wo: Any, u: Any) -> tuple[Any, Any, Any, Any]:
    """One sampled direction; with ``prep.adjoint`` the delta lobes' adjoint (``wo`` is
    then where the light comes from, :class:`~.bsdf.Model`): the mirror is its own,
    a transmitted lobe's is :func:`_adjoint_refraction`."""
    adjoint = prep.adjoint
    s = xp.select(wo[2] < 0.0, -1.0, 1.0)
    wo = xp.vec3(wo[0], wo[1], wo[2] * s)
    wi = xp.vec3(xp.zeros(u[0]), xp.zeros(u[0]), xp.zeros(u[0]) + 1.0)
    transmitted = u[0] < 0.0  # all False: the chosen lobe's side, filled in below
    delta = u[0] < 0.0
    delta_value = xp.zeros(u[0]) * prep.ends["specN"][0]
    delta_prob = xp.zeros(u[0])
    cumulative = 0.0
    for lobe, prob in _selection(xp, prep, wo).items():
        chosen = (u[0] >= cumulative) & (u[0] < cumulative + prob)
        cumulative = cumulative + prob
        if adjoint and lobe in prep.delta and lobe.endswith("_t"):
            candidate, value = _adjoint_refraction(xp, prep, lobe, wo)
        else:
            candidate = _candidate(xp, prep, lobe, wo, u[1], u[2])
            value = _delta_weight(xp, prep, lobe, wo) if lobe in prep.delta else None
        wi = xp.select(chosen, candidate, wi)
        if lobe.endswith("_t"):
            transmitted = transmitted | chosen
        if lobe in prep.delta:
            delta = delta | chosen
            delta_value = xp.select(chosen, value, delta_value)
            delta_prob = xp.select(chosen, prob, delta_prob)
    # A highlight sample that leaves its own side failed (pdf 0), as in a renderer.
    ok = (u[0] < cumulative) & xp.select(transmitted, wi[2] < 0.0, wi[2] > 0.0)
    pdf = xp.select(ok, _mixture_pdf(xp, prep, wi, wo), 0.0)
    f = scatter_eval(xp, prep, wi, wo)
    weight = f * xp.select(pdf > 0.0, xp.abs(wi[2]) / xp.maximum(pdf, xp.tiny), 0.0)
    if prep.delta:
        ok_d = ok & delta & (delta_prob > 0.0)
        w_d = delta_value * xp.select(ok_d, 1.0 / xp.maximum(delta_prob, xp.tiny), 0.0)
        weight = xp.select(delta, w_d, weight)
        pdf = xp.select(delta, xp.select(ok_d, delta_prob, 0.0), pdf)
        delta = delta & ok_d
    else:
        delta = False
    return xp.vec3(wi[0], wi[1], wi[2] * s), weight, pdf, delta


def scatter_guide(xp: Any, prep: PixarPrepared, wo: Any) -> Any:
    """The highlight lobes' share of a denoiser's albedo guide (:mod:`.guides`): each
    one's weight at the view, FrnBlend[N, G, cos θo]. Smits' weights already partition
    the energy by Fresnel, so a metal gives its coloured reflectance and a glass the
    Fresnel blend of its reflection and its tinted transmission, as OIDN asks; a
    dielectric's reflection adds its few percent of white. None without highlights."""
    cos_v = xp.abs(wo[2])
    w = at_view(xp, prep.ends, cos_v)
    out = None
    for lobe in prep.lobes:
        if not lobe.startswith("diffuse"):
            a = lobes.frn_blend(xp, w[PREFIX[lobe] + "N"], w[PREFIX[lobe] + "G"], cos_v)
            out = a if out is None else out + a
    return out
