"""Smits' Wall-E/Up lobe-weight model ("Reflection Model Design for Wall-E and Up").

A fixed set of six lobes (diffuse, specular, reflection and their transmitted twins)
whose weights, at normal (``…N``) and grazing (``…G``) incidence, partition the incoming
energy. :func:`weights` computes Smits' twelve weights exactly as his notebook does,
with the "Additional Parameters" (Fresnel scaling, tints, lobe and cone-angle scales);
the lobe shapes are in :mod:`.pixar_lobes`.

Lobes at a view ωo and light ωi (both as BRDFs, i.e. Smits' lobes / π):

* diffuse  FrnBlend[diffN, diffG, ωi·n] / π, where diffN/diffG carry the view's Fresnel
  (Smits' "move all of the terms into the FrnlBlend term for the light");
* specular and reflection  PSpecular with powerS and powerR, weights spec…/refl…;
* transmitted twins on the far side: Lambertian for diffuse, and for the highlights the
  view refracted by the IOR and reflected to the back side (:func:`.pixar_lobes.back_view`).
  Like Smits, no change of cone angle with the IOR and no total internal reflection.
  Smits does not say at which angle the transmitted highlights blend their N/G weights;
  we take the view's incidence on the front, where the light crosses the interface, so
  the twelve weights partition energy at every incidence (blending by the back-side
  half vector let a white glass reflect 1.8 at grazing: found by ``lookdev check``).

The surface is two-sided: seen from below, the roles of the sides swap.

>>> w = lobe_weights(PixarParams(surface_color=1.0, metallic=0.0, roughness=0.0))
>>> round(float(w["diffN"][0]), 6), float(w["diffG"][0])  # Smits' printed 0.9025 check
(0.9025, 0.0)
"""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import Field

from . import pixar_lobes as lobes
from .arrays import NumpyOps
from .bsdf import Model, density, draw, evaluate
from .params import Color, Params, register_schema

DIELECTRIC_REFL = 0.05  # Smits' default normal reflectance of a dielectric

WEIGHT_NAMES = (
    "diffN diffG specN specG reflN reflG diffTN diffTG specTN specTG reflTN reflTG".split()
)
LOBES = ("diffuse", "specular", "reflection", "diffuse_t", "specular_t", "reflection_t")
_PREFIX = dict(zip(LOBES, ("diff", "spec", "refl", "diffT", "specT", "reflT"), strict=True))


def _scale(description: str, le: float | None = None) -> Any:
    return Field(1.0, ge=0.0, le=le, description=description)


@register_schema
class PixarParams(Params):
    """Smits' parameters; 0..1 is the plausible range unless a field says otherwise."""

    surface_color: Color = Field((0.5, 0.5, 0.5), description="surfColor, linear RGB.")
    metallic: float = Field(0.0, ge=0.0, le=1.0, description="0 dielectric, 1 metal.")
    roughness: float = Field(0.5, ge=0.0, le=1.0, description="0 mirror-like, 1 all diffuse.")
    clear: float = Field(
        0.0, ge=0.0, le=1.0, description="Share of entering light that passes straight through."
    )
    back: float = Field(
        0.0, ge=0.0, le=1.0, description="Share of scattered light leaving on the far side."
    )
    normal_fresnel: float = _scale(
        "Scales nRefl (0.05 dielectric, surface colour metal); 20 reaches 1.", le=20.0
    )
    grazing_fresnel: float = _scale("Scales gRefl (1): tames hot grazing highlights.", le=1.0)
    specular_tint: Color = Field((1.0, 1.0, 1.0), description="Tint of specular and reflection.")
    transmission_tint: Color = Field(
        (1.0, 1.0, 1.0), description="Tint of transmitted specular and refraction."
    )
    diffuse_scale: float = _scale("Scale of the diffuse lobe (above 1 may add energy).")
    specular_scale: float = _scale("Scale of the specular lobe.")
    reflection_scale: float = _scale("Scale of the reflection lobe.")
    diffuse_t_scale: float = _scale("Scale of the transmitted diffuse lobe.")
    specular_t_scale: float = _scale("Scale of the transmitted specular lobe.")
    reflection_t_scale: float = _scale("Scale of the refraction lobe.")
    specular_cone_scale: float = _scale("Scales the specular cone, (30 r + 5)°.", le=2.5)
    reflection_cone_scale: float = _scale("Scales the reflection cone, 10 r°.", le=2.5)
    ior: float | None = Field(
        None,
        ge=1.0,
        le=10.0,
        description="Refraction of the transmitted lobes; default from 0.05 × normal_fresnel.",
    )

    @property
    def eta(self) -> float:
        """The IOR: given, or the one whose normal reflectance is the dielectric nRefl."""
        if self.ior is not None:
            return self.ior
        f0 = min(DIELECTRIC_REFL * self.normal_fresnel, 1.0 - 1e-6) ** 0.5
        return (1.0 + f0) / (1.0 - f0)


_COLORS = ("surface_color", "specular_tint", "transmission_tint")


def _values(xp: Any, params: PixarParams, maps: dict[str, Any]) -> dict[str, Any]:
    """Every numeric parameter, a per-element map where one is given."""
    out = {}
    for name in PixarParams.model_fields:
        if name == "ior":
            continue
        value = maps.get(name, getattr(params, name))
        out[name] = xp.color(value) if name in _COLORS else xp.scalar(value)
    return out


# -- Smits' weights ------------------------------------------------------------------------
def view_independent(xp: Any, v: dict[str, Any]) -> dict[str, Any]:
    """The parts of the twelve weights that do not depend on the view (Smits' notebook)."""
    surf, metal, rough = v["surface_color"], v["metallic"], v["roughness"]
    # Fresnel reflectances: the diffuse section mixes the metal's to 1, the specular one
    # to the surface colour; both scaled by the "normal scaling term" and kept ≤ 1.
    n_refl_d = xp.minimum(v["normal_fresnel"] * xp.lerp(DIELECTRIC_REFL, 1.0, metal), 1.0)
    n_refl_s = xp.minimum(v["normal_fresnel"] * xp.lerp(DIELECTRIC_REFL, surf, metal), 1.0)
    g_refl = v["grazing_fresnel"] * 1.0
    t = xp.maximum(1.0 - 2.0 * rough, 0.0)
    refl_ratio = t * t * t  # reflRatio = Max[(1 − 2 rough)³, 0]
    fade = 1.0 - rough
    clear = v["clear"]
    spec = (1.0 - refl_ratio) * fade * v["specular_tint"]
    refl = refl_ratio * fade * v["specular_tint"]
    trans = surf * fade * clear * v["transmission_tint"]
    return {
        "n_refl_d": n_refl_d,
        "g_refl": g_refl,
        "rough": rough,
        "diff_n": (1.0 - clear) * (1.0 - n_refl_d),
        "diff_g": (1.0 - clear) * (1.0 - g_refl),
        "front": surf * (1.0 - v["back"]) * v["diffuse_scale"],
        "behind": surf * v["back"] * v["diffuse_t_scale"],
        "specN": spec * n_refl_s * v["specular_scale"],
        "specG": spec * g_refl * v["specular_scale"],
        "reflN": refl * n_refl_s * v["reflection_scale"],
        "reflG": refl * g_refl * v["reflection_scale"],
        "specTN": trans * (1.0 - refl_ratio) * (1.0 - n_refl_s) * v["specular_t_scale"],
        "specTG": trans * (1.0 - refl_ratio) * (1.0 - g_refl) * v["specular_t_scale"],
        "reflTN": trans * refl_ratio * (1.0 - n_refl_s) * v["reflection_t_scale"],
        "reflTG": trans * refl_ratio * (1.0 - g_refl) * v["reflection_t_scale"],
    }


def weights(xp: Any, w: dict[str, Any], cos_view: Any) -> dict[str, Any]:
    """Smits' twelve weights for a view at ``cos_view`` (only the diffuse ones vary).

    dN = Mix[(1 − clear)(1 − nRefl) FrnlBlend[1 − nRefl, 1 − gRefl, V·n], 1, rough]
    (the seed's ``1 rough`` lost its comma, DESIGN.md), dG likewise with (1 − gRefl);
    diffN/diffG take (1 − back), diffTN/diffTG take back.
    """
    f_view = lobes.frn_blend(xp, 1.0 - w["n_refl_d"], 1.0 - w["g_refl"], cos_view)
    d_n = xp.lerp(w["diff_n"] * f_view, 1.0, w["rough"])
    d_g = xp.lerp(w["diff_g"] * f_view, 1.0, w["rough"])
    out = {name: w[name] for name in WEIGHT_NAMES if name in w}
    out.update(
        diffN=w["front"] * d_n,
        diffG=w["front"] * d_g,
        diffTN=w["behind"] * d_n,
        diffTG=w["behind"] * d_g,
    )
    return out


def _kept_lobes(xp: Any, w: dict[str, Any]) -> tuple[str, ...]:
    """Lobes whose weights are not known to be zero (DESIGN.md: nothing unneeded)."""
    diffuse_amp = xp.lerp(xp.maximum(w["diff_n"], w["diff_g"]), 1.0, w["rough"])
    amplitude = {
        "diffuse": w["front"] * diffuse_amp,
        "diffuse_t": w["behind"] * diffuse_amp,
    }
    for lobe in LOBES[1:3] + LOBES[4:]:
        p = _PREFIX[lobe]
        amplitude[lobe] = xp.maximum(w[p + "N"], w[p + "G"])
    return tuple(lobe for lobe in LOBES if not xp.known_zero(amplitude[lobe]))


# -- the Model -----------------------------------------------------------------------------
def _prepare(xp: Any, params: PixarParams, **maps: Any) -> dict[str, Any]:
    v = _values(xp, params, maps)
    w = view_independent(xp, v)
    r = v["roughness"]
    return {
        "w": w,
        "power_s": lobes.power_specular(xp, r, v["specular_cone_scale"]),
        "power_r": lobes.power_reflection(xp, r, v["reflection_cone_scale"]),
        "eta": xp.scalar(maps.get("ior", params.eta)),
        "lobes": _kept_lobes(xp, w),
    }


def _upper(xp: Any, wi: Any, wo: Any) -> tuple[Any, Any]:
    """Both directions with the view's side as +z (the surface is two-sided)."""
    s = xp.select(wo[2] < 0.0, -1.0, 1.0)
    return xp.vec3(wi[0], wi[1], wi[2] * s), xp.vec3(wo[0], wo[1], wo[2] * s)


def _power(prep: dict[str, Any], lobe: str) -> Any:
    return prep["power_r"] if lobe.startswith("reflection") else prep["power_s"]


def _lobe_value(xp: Any, prep: dict[str, Any], w: dict, lobe: str, wi: Any, wo: Any) -> Any:
    """One lobe's f(wi, wo) (colour), zero on the side it does not cover."""
    p = _PREFIX[lobe]
    n, g = w[p + "N"], w[p + "G"]
    if lobe.endswith("_t"):
        side = wi[2] < 0.0
        if lobe == "diffuse_t":
            f = lobes.frn_blend(xp, n, g, -wi[2]) * lobes.INV_PI
        else:
            # Blended by the view's incidence on the front, where the light crosses: the
            # transmitted weights are the share the front Fresnel did not reflect.
            back_i, back_o = lobes.to_back(xp, wi), lobes.back_view(xp, wo, prep["eta"])
            f = lobes.p_specular(xp, back_i, back_o, _power(prep, lobe), n, g, wo[2])
    else:
        side = wi[2] > 0.0
        if lobe == "diffuse":
            f = lobes.frn_blend(xp, n, g, wi[2]) * lobes.INV_PI
        else:
            f = lobes.p_specular(xp, wi, wo, _power(prep, lobe), n, g)
    return xp.select(side & (wo[2] > 0.0), f, 0.0)


def _eval(xp: Any, prep: dict[str, Any], wi: Any, wo: Any) -> Any:
    wi, wo = _upper(xp, wi, wo)
    w = weights(xp, prep["w"], wo[2])
    f = xp.zeros(wi[2]) * w["specN"]
    for lobe in prep["lobes"]:
        f = f + _lobe_value(xp, prep, w, lobe, wi, wo)
    return f


def _mean(c: Any) -> Any:
    return (c[0] + c[1] + c[2]) * (1.0 / 3.0)


def _selection(xp: Any, prep: dict[str, Any], wo: Any) -> dict[str, Any]:
    """Probability of sampling each kept lobe: its estimated albedo at this view."""
    w = weights(xp, prep["w"], wo[2])
    est = {}
    for lobe in prep["lobes"]:
        n, g = w[_PREFIX[lobe] + "N"], w[_PREFIX[lobe] + "G"]
        if lobe.startswith("diffuse"):
            albedo = n + (g - n) / 21.0  # exact: ∫ 2(1 − μ)⁵ μ dμ = 1/21
        else:
            albedo = lobes.frn_blend(xp, n, g, wo[2])  # the highlight's weight at its peak
        est[lobe] = _mean(albedo)
    total = sum(est.values()) if est else 0.0
    inv = xp.select(total > 0.0, 1.0 / xp.maximum(total, xp.tiny), 0.0)
    return {lobe: e * inv for lobe, e in est.items()}


def _lobe_pdf(xp: Any, prep: dict[str, Any], lobe: str, wi: Any, wo: Any) -> Any:
    if lobe == "diffuse":
        return xp.maximum(wi[2], 0.0) * lobes.INV_PI
    if lobe == "diffuse_t":
        return xp.maximum(-wi[2], 0.0) * lobes.INV_PI
    if lobe.endswith("_t"):
        back_i, back_o = lobes.to_back(xp, wi), lobes.back_view(xp, wo, prep["eta"])
        pdf = lobes.half_vector_pdf(xp, back_i, back_o, _power(prep, lobe))
        return xp.select(wi[2] < 0.0, pdf, 0.0)
    return xp.select(wi[2] > 0.0, lobes.half_vector_pdf(xp, wi, wo, _power(prep, lobe)), 0.0)


def _mixture_pdf(xp: Any, prep: dict[str, Any], wi: Any, wo: Any) -> Any:
    probs = _selection(xp, prep, wo)
    pdf = xp.zeros(wi[2])
    for lobe, prob in probs.items():
        pdf = pdf + prob * _lobe_pdf(xp, prep, lobe, wi, wo)
    return xp.select(wo[2] > 0.0, pdf, 0.0)


def _pdf(xp: Any, prep: dict[str, Any], wi: Any, wo: Any) -> Any:
    wi, wo = _upper(xp, wi, wo)
    return _mixture_pdf(xp, prep, wi, wo)


def _candidate(xp: Any, prep: dict[str, Any], lobe: str, wo: Any, u1: Any, u2: Any) -> Any:
    """The direction lobe ``lobe`` would sample (upper side = the view's side)."""
    if lobe == "diffuse":
        return lobes.cosine_hemisphere(xp, u1, u2)
    if lobe == "diffuse_t":
        return lobes.to_back(xp, lobes.cosine_hemisphere(xp, u1, u2))
    h = lobes.sample_half_vector(xp, _power(prep, lobe), u1, u2)
    if lobe.endswith("_t"):
        view = lobes.back_view(xp, wo, prep["eta"])
        return lobes.to_back(xp, lobes.reflect(xp, view, h))
    return lobes.reflect(xp, wo, h)


def _sample(xp: Any, prep: dict[str, Any], wo: Any, u: Any) -> tuple[Any, Any, Any]:
    s = xp.select(wo[2] < 0.0, -1.0, 1.0)
    wo = xp.vec3(wo[0], wo[1], wo[2] * s)
    wi = xp.vec3(xp.zeros(u[0]), xp.zeros(u[0]), xp.zeros(u[0]) + 1.0)
    transmitted = u[0] < 0.0  # all False: the chosen lobe's side, filled in below
    cumulative = 0.0
    for lobe, prob in _selection(xp, prep, wo).items():
        chosen = (u[0] >= cumulative) & (u[0] < cumulative + prob)
        cumulative = cumulative + prob
        wi = xp.select(chosen, _candidate(xp, prep, lobe, wo, u[1], u[2]), wi)
        if lobe.endswith("_t"):
            transmitted = transmitted | chosen
    # A highlight sample that leaves its own side failed (pdf 0), as in a renderer.
    ok = (u[0] < cumulative) & xp.select(transmitted, wi[2] < 0.0, wi[2] > 0.0)
    pdf = xp.select(ok, _mixture_pdf(xp, prep, wi, wo), 0.0)
    f = _eval(xp, prep, wi, wo)
    weight = f * xp.select(pdf > 0.0, xp.abs(wi[2]) / xp.maximum(pdf, xp.tiny), 0.0)
    return xp.vec3(wi[0], wi[1], wi[2] * s), weight, pdf


MODEL = Model("pixar", PixarParams, _prepare, _eval, _pdf, _sample)


# -- public numpy API ----------------------------------------------------------------------
def lobe_weights(params: PixarParams, cos_view: Any = 1.0) -> dict[str, np.ndarray]:
    """Smits' twelve weights by his names, each an RGB colour (shape (3,) or (..., 3))."""
    xp = NumpyOps()
    c = np.asarray(cos_view, dtype=np.float64)
    w = weights(xp, view_independent(xp, _values(xp, params, {})), c.reshape(-1))
    shape = (*c.shape, 3)
    return {k: np.broadcast_to(np.asarray(w[k]).T, (c.size, 3)).reshape(shape) for k in w}


def eval(params: PixarParams, wi: Any, wo: Any, **kw: Any) -> np.ndarray:  # noqa: A001
    """f(ωi, ωo) without the cosine, (..., 3); see :func:`lookdev.materials.bsdf.evaluate`."""
    return evaluate(MODEL, params, wi, wo, **kw)


def pdf(params: PixarParams, wi: Any, wo: Any, **kw: Any) -> np.ndarray:
    """Density of :func:`sample` producing ωi given ωo (solid angle)."""
    return density(MODEL, params, wi, wo, **kw)


def sample(params: PixarParams, wo: Any, u: Any, **kw: Any) -> tuple[np.ndarray, ...]:
    """(ωi, f·|cos θi|/pdf, pdf) from uniforms u of shape (..., 3)."""
    return draw(MODEL, params, wo, u, **kw)
