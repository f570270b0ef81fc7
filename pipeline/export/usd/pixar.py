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
from lookdev.materials.pixar import DIELECTRIC_REFL, PixarParams, _values, view_independent
from lookdev.materials.pixar_lobes import power_reflection, power_specular

WEIGHTS = ("front", "behind", "specN", "specG", "reflN", "reflG", "specTN", "reflTN")
"""Derived colours a target reads (``front``/``behind``: diffuse colour either side)."""


def ggx_roughness(power: float) -> float:
    """Perceptual GGX roughness matching a Smits lobe of power ``p`` at its peak (≤ 1)."""
    if power <= 2.0:
        return 1.0
    return math.sqrt(math.sqrt(2.0 / power))


def derived(params: PixarParams) -> dict[str, Any]:
    """Smits' weights (RGB tuples) and the GGX roughness of each highlight lobe."""
    xp = NumpyOps()
    w = view_independent(xp, _values(xp, params, {}))
    out: dict[str, Any] = {k: _rgb(w[k]) for k in WEIGHTS}
    r = params.roughness
    diffuse = max(w["diff_n"], w["diff_g"]) * (1.0 - r) + r  # Mix[max(dN, dG), 1, rough]
    amplitude = {
        "diffuse": max(out["front"]) * diffuse,
        "diffuse_t": max(out["behind"]) * diffuse,
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


def ior_to_normal_fresnel(ior: float) -> float:
    """The ``normal_fresnel`` whose dielectric nRefl (0.05 × it) is the F0 of ``ior``.

    >>> round(ior_to_normal_fresnel(1.5), 6)  # F0 0.04
    0.8
    """
    return ((ior - 1.0) / (ior + 1.0)) ** 2 / DIELECTRIC_REFL
