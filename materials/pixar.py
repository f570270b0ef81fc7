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

Two models share these lobes. :data:`MODEL` takes Smits' parameters
(:class:`PixarParams`); :data:`LAYERED_MODEL` takes the twelve weights themselves at the
two ends of the view, cones, falloffs and IOR (:data:`PixarLobeWeights`), which is what
compositing a layered stack produces (:mod:`lookdev.pipeline.blend.pixar_composite`). The first
is the second after one step: parameters → weights → the same prepared values
(:func:`.pixar_scatter.prepared`), so a one-layer stack renders as its preset.

>>> w = lobe_weights(PixarParams(surface_color=1.0, metallic=0.0, roughness=0.0))
>>> round(float(w["diffN"][0]), 6), float(w["diffG"][0])  # Smits' printed 0.9025 check
(0.9025, 0.0)
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np

from . import pixar_lobes as lobes
from .arrays import NumpyOps
from .bsdf import Model, density, draw, evaluate
from .fresnel import f0_to_ior
from .pixar_lobes import LN_10, reflection_cone, specular_cone
from .pixar_params import (
    CONE_LOBES,
    DIELECTRIC_REFL,
    FALLOFF_LOBES,
    GRAZING,
    LOBE_SCALE_MAX,
    WEIGHT_NAMES,
    PixarLobeWeights,
    PixarParams,
    Weight,
)
from .pixar_scatter import (
    PIXAR_LOBES,
    PREFIX,
    PixarPrepared,
    at_view,
    delta_lobes,
    prepared,
    scatter_eval,
    scatter_guide,
    scatter_pdf,
    scatter_sample,
)

__all__ = [
    "CONE_LOBES",
    "DIELECTRIC_REFL",
    "FALLOFF_LOBES",
    "GRAZING",
    "LAYERED_MODEL",
    "LOBE_SCALE_MAX",
    "MODEL",
    "PixarLobeWeights",
    "PixarParams",
    "WEIGHT_NAMES",
    "Weight",
    "as_lobe_weights",
    "ends",
    "eta_of",
    "eval",
    "lobe_weights",
    "pdf",
    "sample",
    "view_independent",
    "weights",
]

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


def ends(xp: Any, w: dict[str, Any]) -> dict[str, tuple[Any, Any]]:
    """Smits' twelve weights at the view's two ends, ``{name: (at s = 0, at s = 1)}``.

    Only the diffuse weights depend on the view, through FrnlBlend[…, V·n], which is
    affine in s = (1 − V·n)⁵: dN = Mix[(1 − clear)(1 − nRefl) FrnlBlend[1 − nRefl,
    1 − gRefl, V·n], 1, rough] (the seed's ``1 rough`` lost its comma, :doc:`/design`), dG
    likewise with (1 − gRefl); diffN/diffG take (1 − back), diffTN/diffTG take back.
    So each is affine in s too and its two ends give it exactly at every view
    (:func:`at_view`). The highlight weights have one value: ``(w, None)``.
    """
    d_n, d_g = (
        tuple(
            xp.lerp(w[key] * f_view, 1.0, w["rough"])
            for f_view in (1.0 - w["n_refl_d"], 1.0 - w["g_refl"])
        )
        for key in ("diff_n", "diff_g")
    )
    out = {name: (w[name], None) for name in WEIGHT_NAMES if name in w}
    out.update(
        diffN=(w["front"] * d_n[0], w["front"] * d_n[1]),
        diffG=(w["front"] * d_g[0], w["front"] * d_g[1]),
        diffTN=(w["behind"] * d_n[0], w["behind"] * d_n[1]),
        diffTG=(w["behind"] * d_g[0], w["behind"] * d_g[1]),
    )
    return out


def weights(xp: Any, w: dict[str, Any], cos_view: Any) -> dict[str, Any]:
    """Smits' twelve weights for a view at ``cos_view`` from :func:`view_independent`."""
    return at_view(xp, ends(xp, w), cos_view)


def _prepare(xp: Any, params: PixarParams, **maps: Any) -> PixarPrepared:
    """Parameters → Smits' weights and exponents → :func:`.pixar_scatter.prepared`."""
    v = _values(xp, params, maps)
    r = v["roughness"]
    p_s = lobes.power_specular(xp, r, v["specular_cone_scale"])
    p_r = lobes.power_reflection(xp, r, v["reflection_cone_scale"])
    powers = {"specular": p_s, "specular_t": p_s, "reflection": p_r, "reflection_t": p_r}
    eta = xp.scalar(maps.get("ior", params.eta))
    c_s = specular_cone(r, v["specular_cone_scale"])
    c_r = reflection_cone(r, v["reflection_cone_scale"])
    cones = {"specular": c_s, "specular_t": c_s, "reflection": c_r, "reflection_t": c_r}
    falls = {"specular": r * LN_10, "specular_t": r * LN_10}
    falls.update(reflection=LN_10, reflection_t=LN_10)
    delta = delta_lobes(cones, falls)
    return prepared(xp, ends(xp, view_independent(xp, v)), powers, eta, delta)


def _prepare_weights(xp: Any, params: Any, **maps: Any) -> PixarPrepared:
    """Composited weights (:data:`PixarLobeWeights`) → :func:`.pixar_scatter.prepared`.

    Each weight is taken at the two view ends and interpolated in s = (1 − V·n)⁵
    (:func:`at_view`): exact at every view for a plain material and for simple layering
    (both affine in s), exact at both ends for full layering, whose interactions
    multiply view-dependent weights (lookdev.pipeline.blend.pixar_composite). A weight whose
    ends are the same constant is view-independent and costs no interpolation.
    """
    pairs = {}
    for name in WEIGHT_NAMES:
        n, g = maps.get(name, getattr(params, name)), maps.get(name + GRAZING)
        if g is None:
            g = getattr(params, name + GRAZING)
            g = None if g is None or (name not in maps and g == n) else xp.color(g)
        pairs[name] = (xp.color(n), g)
    powers, cones, falls = {}, {}, {}
    for lobe in CONE_LOBES:
        falloff = _scalar(xp, params, maps, f"{lobe}_falloff") if lobe in FALLOFF_LOBES else LN_10
        cones[lobe], falls[lobe] = _scalar(xp, params, maps, f"{lobe}_cone"), falloff
        powers[lobe] = lobes.cone_power(xp, falloff, cones[lobe])
    eta = _scalar(xp, params, maps, "ior")
    return prepared(xp, pairs, powers, eta, delta_lobes(cones, falls))


def _scalar(xp: Any, params: Any, maps: dict[str, Any], name: str) -> Any:
    return xp.scalar(maps.get(name, getattr(params, name)))


def _weights_of(lobe: str) -> tuple[str, ...]:
    """The composited weights (both ends of the view) that drive one lobe."""
    stems = (PREFIX[lobe] + end for end in "NG")
    return tuple(name for stem in stems for name in (stem, stem + GRAZING))


# -- the Model -----------------------------------------------------------------------------
MODEL = Model(
    "pixar",
    PixarParams,
    _prepare,
    scatter_eval,
    scatter_pdf,
    scatter_sample,
    lobes=PIXAR_LOBES,
    guide=scatter_guide,
)
LAYERED_MODEL = Model(
    "pixar_layered",
    PixarLobeWeights,
    _prepare_weights,
    scatter_eval,
    scatter_pdf,
    scatter_sample,
    lobes=tuple(replace(lobe, params=_weights_of(lobe.name)) for lobe in PIXAR_LOBES),
    guide=scatter_guide,
)
"""The same lobes driven by composited weights: a layered Pixar material's BSDF."""


# -- public numpy API ----------------------------------------------------------------------
def lobe_weights(
    params: PixarParams, cos_view: Any = 1.0, maps: dict[str, Any] | None = None
) -> dict[str, np.ndarray]:
    """Smits' twelve weights by his names, each an RGB colour (shape (3,) or (..., 3)).

    ``maps`` give parameters per texel (scalars (...), colours (..., 3), one leading shape);
    the view is then one ``cos_view`` and the weights are (..., 3) over the texels.
    """
    xp = NumpyOps()
    c = np.asarray(cos_view, dtype=np.float64)
    if maps:
        lead = next(np.shape(v)[: np.ndim(v) - (k in _COLORS)] for k, v in maps.items())
        flat = {
            k: np.reshape(v, (-1, 3)).T if k in _COLORS else np.reshape(v, -1)
            for k, v in maps.items()
        }
        w = weights(xp, view_independent(xp, _values(xp, params, flat)), c.reshape(-1))
        size = int(np.prod(lead))
        return {k: np.broadcast_to(np.asarray(w[k]), (3, size)).T.reshape(*lead, 3) for k in w}
    w = weights(xp, view_independent(xp, _values(xp, params, {})), c.reshape(-1))
    shape = (*c.shape, 3)
    return {k: np.broadcast_to(np.asarray(w[k]).T, (c.size, 3)).reshape(shape) for k in w}


def eta_of(params: PixarParams, maps: dict[str, Any] | None = None) -> Any:
    """:attr:`PixarParams.eta` where ``ior`` or ``normal_fresnel`` may be per-texel maps."""
    maps = maps or {}
    if "ior" in maps:
        return np.asarray(maps["ior"], dtype=np.float64)
    if "normal_fresnel" in maps and params.ior is None:
        return f0_to_ior(DIELECTRIC_REFL * np.asarray(maps["normal_fresnel"], dtype=np.float64))
    return params.eta


def as_lobe_weights(params: PixarParams) -> Any:
    """A plain material as :data:`PixarLobeWeights` (what a one-layer stack composites to).

    >>> w = as_lobe_weights(PixarParams(surface_color=1.0, roughness=0.0))
    >>> round(w.diffN[0], 6), w.diffN_grazing[0], w.reflection_cone
    (0.9025, 0.0, 0.0)
    """
    xp = NumpyOps()
    v = _values(xp, params, {})
    data: dict[str, Any] = {}
    for name, (n, g) in ends(xp, view_independent(xp, v)).items():
        data[name] = tuple(np.asarray(n, dtype=float).ravel())
        if g is not None:
            data[name + GRAZING] = tuple(np.asarray(g, dtype=float).ravel())
    r = params.roughness
    data["specular_cone"] = data["specular_t_cone"] = specular_cone(r, params.specular_cone_scale)
    data["reflection_cone"] = data["reflection_t_cone"] = reflection_cone(
        r, params.reflection_cone_scale
    )
    data["specular_falloff"] = data["specular_t_falloff"] = r * LN_10
    data["ior"] = params.eta
    return PixarLobeWeights.parse(data, where="as_lobe_weights")


def eval(params: PixarParams, wi: Any, wo: Any, **kw: Any) -> np.ndarray:  # noqa: A001
    """f(ωi, ωo) without the cosine, (..., 3); see :func:`lookdev.materials.bsdf.evaluate`."""
    return evaluate(MODEL, params, wi, wo, **kw)


def pdf(params: PixarParams, wi: Any, wo: Any, **kw: Any) -> np.ndarray:
    """Density of :func:`sample` producing ωi given ωo (solid angle)."""
    return density(MODEL, params, wi, wo, **kw)


def sample(params: PixarParams, wo: Any, u: Any, **kw: Any) -> tuple[np.ndarray, ...]:
    """(ωi, f·|cos θi|/pdf, pdf) from uniforms u of shape (..., 3)."""
    return draw(MODEL, params, wo, u, **kw)
