"""Smits' Pixar model for the exporters: the weights and cone angles targets are fed.

RenderMan's ``PxrSurface`` and MaterialX's OpenPBR take lobe *colours* and *roughnesses*,
not Smits' parameters, so a Pixar material is exported through quantities derived once
here: his view-independent lobe weights (the normal/grazing pairs ``specN``/``specG``,
``reflN``/``reflG`` …, computed by :mod:`lookdev.materials.pixar` itself, not re-derived)
and a GGX roughness per highlight lobe.

Highlight shapes: Smits' lobes are Gaussians in sin θh, ``exp(-p sin²θh)``, with the
power p of powerS/powerR. Near the peak that is ``exp(-p θ²)``, and a GGX lobe
``α²/(α² + tan²θ)²`` is ``exp(-2θ²/α²)``: equal curvature at the peak gives
``α = √(2/p)``, and the perceptual roughness ``r = √α`` (α = r², as PxrSurface and
UsdPreviewSurface use it).

>>> round(ggx_roughness(2.0), 6)  # p = 2 ↦ α = 1
1.0
"""

from __future__ import annotations

import math
from typing import Any

from lookdev.materials.arrays import NumpyOps
from lookdev.materials.fresnel import ior_to_f0
from lookdev.materials.pixar import (
    DIELECTRIC_REFL,
    PixarParams,
    _values,
    view_independent,
    weights,
)
from lookdev.materials.pixar_lobes import power_reflection, power_specular

WEIGHTS = ("specN", "specG", "reflN", "reflG", "reflTN")
"""Smits' view-independent weights a target reads (RGB)."""


def ggx_roughness(power: float) -> float:
    """Perceptual GGX roughness matching a Smits lobe of power ``p`` at its peak (≤ 1)."""
    if power <= 2.0:
        return 1.0
    return math.sqrt(math.sqrt(2.0 / power))


def derived(params: PixarParams) -> dict[str, Any]:
    """Smits' weights (RGB tuples) and the GGX roughness of each highlight lobe.

    ``front``/``behind`` are the diffuse and transmitted-diffuse weights for a view at
    normal incidence (diffN, diffTN): what a Lambert lobe can carry of his diffuse.
    """
    xp = NumpyOps()
    w = view_independent(xp, _values(xp, params, {}))
    out: dict[str, Any] = {k: _rgb(w[k]) for k in WEIGHTS}
    head_on = weights(xp, w, 1.0)  # the diffuse weights seen at normal incidence
    out["front"], out["behind"] = _rgb(head_on["diffN"]), _rgb(head_on["diffTN"])
    r = params.roughness
    diffuse = max(w["diff_n"], w["diff_g"]) * (1.0 - r) + r  # Mix[max(dN, dG), 1, rough]
    amplitude = {
        "diffuse": max(_rgb(w["front"])) * diffuse,
        "diffuse_t": max(_rgb(w["behind"])) * diffuse,
        "specular": max(out["specN"] + out["specG"]),
        "reflection": max(out["reflN"] + out["reflG"]),
        "specular_t": max(_rgb(w["specTN"]) + _rgb(w["specTG"])),
        "reflection_t": max(_rgb(w["reflTN"]) + _rgb(w["reflTG"])),
    }
    out.update({f"amp_{k}": float(v) for k, v in amplitude.items()})
    out["spec_roughness"] = ggx_roughness(float(power_specular(xp, r, params.specular_cone_scale)))
    out["refl_roughness"] = ggx_roughness(
        float(power_reflection(xp, r, params.reflection_cone_scale))
    )
    return out


def _rgb(value: Any) -> tuple[float, float, float]:
    import numpy as np

    v = np.broadcast_to(np.asarray(value, dtype=np.float64).reshape(-1), (3,))
    return (float(v[0]), float(v[1]), float(v[2]))


def cone_roughness(cone_deg: Any) -> Any:
    """GGX roughness of a blended highlight given only its cone (degrees, ``(…)`` arrays).

    A blend of layers keeps Smits' cone angles but not the roughness behind each lobe's
    falloff, so the lobe is taken to fall to 10 % at its cone (powerR's definition):
    p = ln 10 / sin²(cone), α = √(2/p) = sin(cone)·√(2 / ln 10), r = √α (≤ 1).

    >>> round(float(cone_roughness(0.0)), 6)
    0.0
    """
    import numpy as np

    alpha = np.sin(np.radians(np.asarray(cone_deg, dtype=np.float64))) * math.sqrt(2 / math.log(10))
    return np.sqrt(np.minimum(alpha, 1.0))


def from_weights(w: dict[str, Any]) -> dict[str, Any]:
    """Target quantities of a lobe-weight blend (:mod:`lookdev.pipeline.blend.pixar`).

    ``w`` holds the blend's arrays by name (constants as arrays too). Returns the same
    keys :func:`derived` gives for one material, plus ``f0`` (the highlight colour at
    normal incidence, both lobes) and ``highlight_roughness`` (their energy-weighted
    roughness) for surfaces with a single highlight lobe.
    """
    import numpy as np

    def rgb(name: str) -> np.ndarray:
        return np.asarray(w[name], dtype=np.float64)

    out = {
        "front": rgb("diffN"),
        "behind": rgb("diffTN"),
        **{k: rgb(k) for k in ("specN", "specG", "reflN", "reflG", "reflTN")},
        "spec_roughness": cone_roughness(w["specular_cone"]),
        "refl_roughness": cone_roughness(w["reflection_cone"]),
    }
    out["f0"] = out["specN"] + out["reflN"]
    e_spec = (out["specN"] + out["specG"]).mean(axis=-1)
    e_refl = (out["reflN"] + out["reflG"]).mean(axis=-1)
    total = np.where(e_spec + e_refl > 0.0, e_spec + e_refl, 1.0)
    out["highlight_roughness"] = (
        e_spec * out["spec_roughness"] + e_refl * out["refl_roughness"]
    ) / total
    amplitude = {
        "diffuse": [rgb("diffN"), rgb("diffG")],
        "diffuse_t": [rgb("diffTN"), rgb("diffTG")],
        "specular": [rgb("specN"), rgb("specG")],
        "reflection": [rgb("reflN"), rgb("reflG")],
        "specular_t": [rgb("specTN"), rgb("specTG")],
        "reflection_t": [rgb("reflTN"), rgb("reflTG")],
    }
    out.update({f"amp_{k}": float(max(a.max() for a in v)) for k, v in amplitude.items()})
    return out


def ior_to_normal_fresnel(ior: float) -> float:
    """The ``normal_fresnel`` whose dielectric nRefl (0.05 × it) is the F0 of ``ior``.

    >>> round(ior_to_normal_fresnel(1.5), 6)  # F0 0.04
    0.8
    """
    return ior_to_f0(ior) / DIELECTRIC_REFL
