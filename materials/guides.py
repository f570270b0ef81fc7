"""The albedo a denoiser is guided by: one rule for every model, in the shared model code.

Intel Open Image Denoise (OIDN) takes, beside the noisy image, an *albedo* image: "the
approximate color of the surfaces independent of illumination and viewing angle", in
[0, 1]. Its documentation (``doc/api.md`` of OIDN 2.x, "Albedos") says what that is:

* matte surfaces: the diffuse colour;
* metals: the reflectivity at normal incidence (or the average reflectivity);
* dielectrics (glass): 1, or for a perfect specular surface the Fresnel blend of the
  reflected and the transmitted albedo;
* layered surfaces: the weighted sum of the layers' albedos; a non-absorbing clear coat
  may simply be ignored.

Mitsuba's ``aov`` integrator fills its ``albedo`` channel from
``BSDF::eval_diffuse_reflectance``, whose default is π·f(wi = n) of the *whole* BSDF: the
highlight is baked into it (it depends on the view and is lit by nothing), and glass,
which reflects almost nothing towards the normal, comes out black. :func:`guide_albedo`
is what the lookdev plugins return there instead:

* the **diffuse-like lobes** (those the registry flags ``diffuse``, reflected and
  transmitted) by Mitsuba's own definition restricted to them: π·f(wi = ±n, wo), through
  the model's ``eval`` — so the base colour times the model's diffuse albedo, textures
  and retro-reflection included, and nothing of any highlight;
* the **glossy lobes** by the model's :attr:`~.bsdf.Model.guide` (OIDN's rules above:
  metals their colour at normal incidence, glass the Fresnel blend of 1 and its
  transmission colour, dielectric coats and the specular of plastics nothing).

The result is clipped to [0, 1] as OIDN requires.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .arrays import NumpyOps, from_channel_first, to_channel_first
from .bsdf import Model, _flatten_maps

__all__ = ["diffuse_lobes", "guide_albedo", "albedo_guide"]


def diffuse_lobes(model: Model, prepared: Any) -> tuple[str, ...]:
    """The kept lobes of ``prepared`` that the registry calls diffuse (Mitsuba's
    ``DiffuseReflection`` / ``DiffuseTransmission`` flags)."""
    kept = prepared.lobes
    return tuple(
        lobe.name for lobe in model.lobes if lobe.scattering == "diffuse" and lobe.name in kept
    )


def guide_albedo(xp: Any, model: Model, prepared: Any, wo: Any) -> Any:
    """The albedo guide (colour, channel-first, in [0, 1]) of a prepared material seen
    from ``wo`` (towards the viewer, local frame): see the module docstring."""
    zero = wo[2] * 0.0
    side = xp.copysign(1.0, wo[2])  # the viewer's side: a two-sided sheet seen from below
    total = None
    diffuse = diffuse_lobes(model, prepared)
    if diffuse:
        only = model.restrict(xp, prepared, diffuse)
        up, down = xp.vec3(zero, zero, zero + side), xp.vec3(zero, zero, zero - side)
        # Mitsuba's eval_diffuse_reflectance, π·f(wi = n), on the diffuse lobes alone;
        # wi = −n adds a diffuse transmission (0 for a lobe that only reflects).
        total = (model.eval(xp, only, up, wo) + model.eval(xp, only, down, wo)) * math.pi
    if model.guide is not None:
        glossy = model.guide(xp, prepared, wo)
        if glossy is not None:
            total = glossy if total is None else total + glossy
    if total is None:
        return xp.vec3(zero, zero, zero)
    return xp.clip(total + zero, 0.0, 1.0)


def albedo_guide(
    model: Model, params: Any, wo: Any, *, dtype: Any = np.float64, **maps: Any
) -> np.ndarray:
    """numpy front door of :func:`guide_albedo`: ``wo`` of shape (..., 3) → (..., 3)."""
    xp = NumpyOps(dtype)
    wo_, lead = to_channel_first(wo, dtype)
    with np.errstate(all="ignore"):
        prepared = model.prepare(xp, params, **_flatten_maps(maps, lead, dtype))
        out = guide_albedo(xp, model, prepared, wo_)
    return from_channel_first(np.broadcast_to(out, (3, wo_.shape[1])), lead)
