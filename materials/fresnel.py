"""Fresnel reflectance: Schlick's approximation and the exact dielectric equations.

Both are written once over the array shim (:mod:`.arrays`). ``cos`` is the cosine between
a direction and the micro-normal it reflects about (θd in Burley 2012, the angle between
the light and the half vector).

>>> import numpy as np
>>> from .arrays import NumpyOps
>>> xp = NumpyOps()
>>> float(schlick(xp, 0.04, np.float64(1.0)))
0.04
>>> round(float(dielectric(xp, np.float64(1.0), 1.5)), 6)  # ((η − 1)/(η + 1))²
0.04
>>> float(dielectric(xp, np.float64(0.1), 1.0 / 1.5))  # total internal reflection
1.0
"""

from __future__ import annotations

from typing import Any


def schlick_weight(xp: Any, cos: Any) -> Any:
    """(1 − cos θ)⁵ (Schlick 1994), 0 where rounding makes cos θ exceed 1.

    >>> import numpy as np
    >>> from .arrays import NumpyOps
    >>> float(schlick_weight(NumpyOps(), np.float64(0.0)))
    1.0
    """
    m = xp.maximum(1.0 - cos, 0.0)  # cos ≤ 1 for unit vectors: one bound is enough
    m2 = m * m
    return m2 * m2 * m


def schlick(xp: Any, f0: Any, cos: Any) -> Any:
    """F = F0 + (1 − F0)(1 − cos θd)⁵ (Burley 2012 §5.5; Schlick 1994 eq. 24).

    ``f0`` may be a scalar or a colour; the result has its shape broadcast with ``cos``.
    Linear in F0, so mixing two F0s mixes the two Fresnel curves the same way.
    """
    return f0 + (1.0 - f0) * schlick_weight(xp, cos)


def schlick_f0(ior: Any) -> Any:
    """Normal-incidence reflectance ((η − 1)/(η + 1))² of a dielectric of relative IOR η.

    >>> round(schlick_f0(1.5), 6)
    0.04
    """
    r = (ior - 1.0) / (ior + 1.0)
    return r * r


def dielectric(xp: Any, cos_i: Any, eta: Any) -> Any:
    """Unpolarised Fresnel reflectance of a smooth dielectric interface (pbrt-v4 eq. 9.6).

    ``cos_i`` is the cosine of the incident direction with the (micro-)normal on the side
    it arrives from (its sign is ignored); ``eta`` = η_t/η_i, the IOR of the far side over
    that of the near side. Returns 1 under total internal reflection.
    """
    c_i = xp.minimum(xp.abs(cos_i), 1.0)
    sin2_t = (1.0 - c_i * c_i) / (eta * eta)
    c_t = xp.safe_sqrt(1.0 - sin2_t)
    # Both denominators vanish only at grazing incidence with η = 1, which is TIR here.
    r_par = (eta * c_i - c_t) / xp.maximum(eta * c_i + c_t, xp.tiny)
    r_perp = (c_i - eta * c_t) / xp.maximum(c_i + eta * c_t, xp.tiny)
    f = 0.5 * (r_par * r_par + r_perp * r_perp)
    return xp.select(sin2_t >= 1.0, 1.0, f)
