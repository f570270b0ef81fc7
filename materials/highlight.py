"""The width of a Disney specular highlight, measured, and the GGX roughness that matches it.

No DCC target has the GTR γ of ``specular_gamma`` (Burley 2012 App. B): an export writes
the GGX (γ = 2) roughness whose highlight is as wide. *Width* is measured on the model's
own specular lobe, not on D alone: the in-plane BRDF slice seen from the normal,
f(θi) with wo = n, and the half-vector angle θh = θi/2 where it falls to half its peak.
That includes the shadowing and the Fresnel, which differ between the V-cavity G of
γ ≠ 2 and the Smith G of GGX (7 % of the width at γ = 1, roughness 0.5). The GGX
roughness is then found by bisection, started from the closed form for D alone
(:func:`~.microfacet.ggx_roughness_like_gtr`).

>>> from .params import DisneyParams
>>> round(ggx_roughness_like(DisneyParams(metallic=1.0, roughness=0.4)), 6)
0.4
"""

from __future__ import annotations

import math

import numpy as np

from . import disney
from .arrays import NumpyOps
from .microfacet import ggx_roughness_like_gtr
from .params import DisneyParams

__all__ = ["ggx_roughness_like", "half_width"]

_SLICE = 20_000  # θh nodes, geometric on [10⁻⁶, π/4]: the half width to 0.07 %
_SPECULAR = disney.lobe_model("specular")


def half_width(params: DisneyParams) -> float:
    """θh (radians) where the specular lobe's slice at normal view halves (π/4 if never,
    0 for a delta)."""
    xp = NumpyOps()
    th = np.concatenate([[0.0], np.geomspace(1e-6, 0.25 * math.pi, _SLICE)])
    wi = np.stack([np.sin(2.0 * th), 0.0 * th, np.cos(2.0 * th)])
    wo = np.array([[0.0], [0.0], [1.0]])
    prepared = _SPECULAR.prepare(xp, params)
    if "specular" in prepared.delta:
        return 0.0  # a smooth GGX lobe is a delta (microfacet.is_delta): no width
    f = _SPECULAR.eval(xp, prepared, wi, wo)[1]  # green: any channel
    below = np.flatnonzero(f < 0.5 * f[0])
    if below.size == 0:
        return 0.25 * math.pi
    i = below[0]  # linear interpolation between the last node above half and the first below
    t = (f[i - 1] - 0.5 * f[0]) / (f[i - 1] - f[i])
    return float(th[i - 1] + t * (th[i] - th[i - 1]))


def ggx_roughness_like(params: DisneyParams, tol: float = 1e-5) -> float:
    """The roughness at which the GGX lobe (γ = 2, same other parameters) is as wide as
    ``params``' lobe by :func:`half_width`; the roughness itself at γ = 2.

    A lobe so rough that its slice does not halve before grazing (θh = π/4) has no
    measured width, and GGX reaches no width between ≈ 0.60 rad and π/4: there the
    closed form for D alone is used, as it is for a target narrower than the narrowest
    glossy GGX (smoother ones are deltas, of width 0).
    """
    gamma = params.specular_gamma
    closed = ggx_roughness_like_gtr(gamma, params.roughness)
    if gamma == 2.0:
        return params.roughness
    target = half_width(params)
    ggx = params.replace(specular_gamma=2.0)
    lo, hi = 0.0, min(1.0, 2.0 * closed + 0.05)
    if target >= 0.25 * math.pi or half_width(ggx.replace(roughness=hi)) < target:
        return closed
    if half_width(ggx.replace(roughness=lo)) >= target:
        return 0.0
    while hi - lo > tol:  # the width grows with roughness up to hi
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if half_width(ggx.replace(roughness=mid)) < target else (lo, mid)
    found = 0.5 * (lo + hi)
    # GGX's slice stops halving before grazing at roughness ≈ 0.69, where its width jumps
    # from ≈ 0.60 rad to "none": a wider target has no GGX match by width.
    if abs(half_width(ggx.replace(roughness=found)) - target) > 0.01 * target:
        return closed
    return found
