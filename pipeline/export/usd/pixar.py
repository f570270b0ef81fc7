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
from lookdev.materials.pixar_lobes import power_specular, reflection_cone

__all__ = [
    "DEFAULT_ETA",
    "WEIGHTS",
    "cone_roughness",
    "derived",
    "from_weights",
    "ggx_roughness",
    "highlight_roughness",
    "ior_to_normal_fresnel",
    "metallic_workflow",
]

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
    # The reflection lobe through its cone, unfloored: Smits' cone is 0 at roughness 0
    # ("0, or epsilon in practice"); the model's evaluation floor (CONE_MIN_DEG) is not a
    # width a target should be given (it made a clear glass 0.09 rough).
    out["refl_roughness"] = float(cone_roughness(reflection_cone(r, params.reflection_cone_scale)))
    out["highlight_roughness"] = float(highlight_roughness(out))
    return out


def highlight_roughness(w: dict[str, Any]) -> Any:
    """One roughness for Smits' two highlight lobes: their GGX roughnesses weighted by
    each lobe's energy (the mean over RGB of its normal + grazing weight).

    A surface with one specular lobe (OpenPBR, UsdPreviewSurface) takes this, so the
    lobe that carries the light sets the width: pixar_gold (roughness 0.15) keeps a
    sharp highlight and a clear glass (roughness 0, all in the reflection lobe) stays
    clear. Scalars or ``(…)`` arrays; RGB weights as ``(…, 3)``.

    >>> w = {"specN": (0, 0, 0), "specG": (0, 0, 0), "reflN": (1, 1, 1), "reflG": (0, 0, 0)}
    >>> float(highlight_roughness({**w, "spec_roughness": 0.9, "refl_roughness": 0.0}))
    0.0
    """
    import numpy as np

    def energy(a: str, b: str) -> Any:
        return (np.asarray(w[a], np.float64) + np.asarray(w[b], np.float64)).mean(axis=-1)

    e_spec, e_refl = energy("specN", "specG"), energy("reflN", "reflG")
    total = e_spec + e_refl
    weighted = e_spec * np.asarray(w["spec_roughness"]) + e_refl * np.asarray(w["refl_roughness"])
    return np.where(total > 0.0, weighted / np.where(total > 0.0, total, 1.0), 0.0)


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


def from_weights(w: dict[str, Any], eta: float | None = None) -> dict[str, Any]:
    """Target quantities of a lobe-weight blend (:mod:`lookdev.pipeline.blend.pixar`).

    ``w`` holds the blend's arrays by name (constants as arrays too). Returns the same
    keys :func:`derived` gives for one material, plus ``f0`` (the highlight colour at
    normal incidence, both lobes) and ``highlight_roughness`` (their energy-weighted
    roughness) for surfaces with a single highlight lobe, and the same highlight and
    diffuse in UsdPreviewSurface's metallic workflow (:func:`metallic_workflow`, with
    the dielectric F0 of ``eta``, the blend's IOR).
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
    out["highlight_roughness"] = highlight_roughness(out)
    base, metal = metallic_workflow(out["front"], out["f0"], DEFAULT_ETA if eta is None else eta)
    out["preview_base"], out["preview_metallic"] = base, metal
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


DEFAULT_ETA = PixarParams().eta


def metallic_workflow(front: Any, f0: Any, eta: float) -> tuple[Any, Any]:
    """(diffuseColor, metallic) of UsdPreviewSurface's metallic workflow whose diffuse
    at normal incidence is ``front`` and whose highlight F0 is ``f0`` (RGB ``(…, 3)``).

    UsdPreviewSurface spec 2.5, ``metallic``: at 0, F0 comes from ``ior``
    (a = ((1 − ior)/(1 + ior))²) and the diffuse is ``diffuseColor``; at 1, F0 is
    ``diffuseColor`` and there is no diffuse; "in between, we interpolate" — as USD's
    reference implementation does it (:mod:`lookdev.materials.preview_surface`): with
    base B and metallic m, F0 = ((1 − m) + m·B)·((1 − m)·a + m), and the diffuse seen at
    normal incidence is B·(1 − m)·(1 − F0). m is the root, by bisection per texel, of
    Y(F0(m, B(m))) = Y(f0) with B(m) from the diffuse (0 where Y(f0) ≤ a: a dielectric);
    the colour is then the diffuse's where m is small and the F0's where m is large
    (blended by m²), clamped to 0..1. Only luminances are matched: F0's tint at a
    fractional m is the interpolation's, a loss the export names.

    The specular workflow would carry ``f0`` as it is, but DCC importers read
    ``specularColor`` as a tint on their own dielectric F0 (≈ 0.04), so a metal's F0 of
    ~1 would arrive ~25 times too dark.

    >>> base, m = metallic_workflow((0.0, 0.0, 0.0), (1.0, 0.78, 0.34), 1.5)
    >>> round(float(m), 6), [round(float(c), 2) for c in base]
    (1.0, [1.0, 0.78, 0.34])
    >>> base, m = metallic_workflow((0.5, 0.1, 0.1), (0.04, 0.04, 0.04), 1.5)
    >>> float(m), [round(float(c), 4) for c in base]
    (0.0, [0.5208, 0.1042, 0.1042])
    """
    import numpy as np

    from lookdev.materials.colour import luminance

    d = np.asarray(front, np.float64)
    s = np.asarray(f0, np.float64)
    a = float(ior_to_f0(eta))
    ys = luminance(s)
    dim = 1.0 - np.clip(s, 0.0, 1.0)

    def base_from_diffuse(m: Any) -> Any:
        return np.clip(d / np.maximum((1.0 - m[..., None]) * dim, 1e-6), 0.0, 1.0)

    def excess(m: Any) -> Any:  # Y(F0) of the preview minus the target's, rising in m
        mm = m[..., None]
        spec = (1.0 - mm) + mm * base_from_diffuse(m)
        return luminance(spec * ((1.0 - mm) * a + mm)) - ys

    lo = np.zeros(np.shape(ys))
    hi = np.ones(np.shape(ys))
    for _ in range(40):  # 2^-40: far below float32
        mid = 0.5 * (lo + hi)
        high = excess(mid) > 0.0
        hi = np.where(high, mid, hi)
        lo = np.where(high, lo, mid)
    m = np.where(ys <= a, 0.0, 0.5 * (lo + hi))
    mm = m[..., None]
    from_f0 = (s / np.maximum((1.0 - mm) * a + mm, 1e-6) - (1.0 - mm)) / np.maximum(mm, 1e-6)
    base = base_from_diffuse(m)
    base = np.clip(base + (np.clip(from_f0, 0.0, 1.0) - base) * mm * mm, 0.0, 1.0)
    return base, m


def ior_to_normal_fresnel(ior: float) -> float:
    """The ``normal_fresnel`` whose dielectric nRefl (0.05 × it) is the F0 of ``ior``.

    >>> round(ior_to_normal_fresnel(1.5), 6)  # F0 0.04
    0.8
    """
    return ior_to_f0(ior) / DIELECTRIC_REFL
