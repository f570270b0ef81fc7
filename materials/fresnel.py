"""Fresnel reflectance: Schlick's approximation, the exact dielectric equations, and the
one conversion between F0, IOR and Burley's ``specular`` (:func:`specular_to_ior`,
:func:`ior_to_specular`, over :func:`f0_to_ior` / :func:`ior_to_f0`).

All are written once over the array shim (:mod:`.arrays`). ``cos`` is the cosine between
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

import math
from typing import Any

__all__ = [
    "ETA_MAX",
    "F0_MAX",
    "SPECULAR_F0_SCALE",
    "dielectric",
    "f0_to_ior",
    "ior_to_f0",
    "ior_to_specular",
    "schlick",
    "schlick_weight",
    "specular_to_ior",
]

SPECULAR_F0_SCALE = 0.08
"""Burley 2012 §5.4: ``specular`` 0..1 is remapped linearly to F0 0..0.08 (IOR 1.0..1.8)."""

F0_MAX = 1.0 - 1e-6
"""The one clamp of F0 before it becomes an IOR (:func:`f0_to_ior`).

The parameter ceilings allow F0 = 1: ``specular`` up to 12.5 (:class:`~.params.DisneyParams`,
0.08 × 12.5 = 1) and Smits' ``normal_fresnel`` up to 20 (0.05 × 20 = 1), where
η = (1 + √F0)/(1 − √F0) is infinite. So F0 is clamped to 1 − 10⁻⁶, i.e. specular to
12.4999875 (normal_fresnel to 19.99998) for the IOR: the largest η is :data:`ETA_MAX`
≈ 4.0·10⁶ (3.7·10⁶ computed in float32), and η² ≈ 1.6·10¹³ is finite in float32 too.
The clamp is 17 float32 ulps below 1, so a float32 backend keeps it below 1 as well
(1 − 10⁻⁷, which three copies used, is under 2 ulps there). The Schlick F0 of the
2012 BRDF (0.08·specular, up to 1) is not clamped: only the IOR needs this."""


def f0_to_ior(f0: Any, xp: Any = None) -> Any:
    """Relative IOR η whose normal-incidence reflectance is ``f0``: η = (1 + √F0)/(1 − √F0).

    The inverse of :func:`ior_to_f0` (F0 = ((η − 1)/(η + 1))²), with F0 clamped to
    :data:`F0_MAX` so η stays finite. Written once over the array shim: pass the model's
    ``xp`` (numpy or Dr.Jit backend); without it, floats give a float and numpy arrays an
    array of their dtype.

    >>> f0_to_ior(0.0), round(f0_to_ior(0.04), 12), round(f0_to_ior(1.0) / 1e6, 3)
    (1.0, 1.5, 4.0)
    """
    if xp is None and isinstance(f0, int | float):
        # a preset's scalar, checked without numpy (math.sqrt is correctly rounded as numpy's is)
        r = math.sqrt(min(f0, F0_MAX))
        return (1.0 + r) / (1.0 - r)
    if xp is not None:
        r = xp.sqrt(xp.minimum(f0, F0_MAX))
        return (1.0 + r) / (1.0 - r)
    import numpy as np

    r = np.sqrt(np.minimum(f0, F0_MAX))
    out = (1.0 + r) / (1.0 - r)
    return float(out) if np.ndim(out) == 0 and not isinstance(f0, np.ndarray) else out


ETA_MAX = f0_to_ior(F0_MAX)
"""Largest IOR :func:`f0_to_ior` returns (F0 ≥ :data:`F0_MAX`), ≈ 4.0·10⁶."""


def ior_to_f0(ior: Any) -> Any:
    """Normal-incidence reflectance ((η − 1)/(η + 1))² of a dielectric of relative IOR η.

    Arithmetic only, so floats, numpy arrays and Dr.Jit arrays alike; 0 at η = 1.

    >>> round(ior_to_f0(1.5), 6), ior_to_f0(1.0)
    (0.04, 0.0)
    """
    r = (ior - 1.0) / (ior + 1.0)
    return r * r


def specular_to_ior(specular: Any, xp: Any = None) -> Any:
    """IOR of Burley's ``specular`` (§5.4): F0 = 0.08·specular, η = :func:`f0_to_ior` (F0).

    specular 0 is η = 1 (no reflection), 0.5 is η = 1.5, 1 is η ≈ 1.79; from specular
    12.4999875 (F0 = :data:`F0_MAX`) up to the ceiling 12.5, η is :data:`ETA_MAX`.

    >>> specular_to_ior(0.0), round(specular_to_ior(0.5), 12), round(specular_to_ior(1.0), 4)
    (1.0, 1.5, 1.7888)
    """
    return f0_to_ior(SPECULAR_F0_SCALE * specular, xp)


def ior_to_specular(ior: Any) -> Any:
    """Burley's ``specular`` of an IOR (§5.4): ((η − 1)/(η + 1))² / 0.08.

    >>> round(ior_to_specular(1.5), 12), ior_to_specular(1.0)
    (0.5, 0.0)
    """
    return ior_to_f0(ior) / SPECULAR_F0_SCALE


def schlick_weight(xp: Any, cos: Any) -> Any:
    """(1 − cos θ)⁵ :cite:p:`Schlick1994`, 0 where rounding makes cos θ exceed 1.

    >>> import numpy as np
    >>> from .arrays import NumpyOps
    >>> float(schlick_weight(NumpyOps(), np.float64(0.0)))
    1.0
    """
    m = xp.maximum(1.0 - cos, 0.0)  # cos ≤ 1 for unit vectors: one bound is enough
    m2 = m * m
    return m2 * m2 * m


def schlick(xp: Any, f0: Any, cos: Any) -> Any:
    """F = F0 + (1 − F0)(1 − cos θd)⁵ (:cite:t:`Burley2012` §5.5; :cite:t:`Schlick1994` eq. 24).

    ``f0`` may be a scalar or a colour; the result has its shape broadcast with ``cos``.
    Linear in F0, so mixing two F0s mixes the two Fresnel curves the same way.
    """
    return f0 + (1.0 - f0) * schlick_weight(xp, cos)


def dielectric(xp: Any, cos_i: Any, eta: Any, inv_eta: Any = None) -> Any:
    """Unpolarised Fresnel reflectance of a smooth dielectric interface (pbrt-v4 eq. 9.6).

    ``cos_i`` is the cosine of the incident direction with the (micro-)normal on the side
    it arrives from (its sign is ignored); ``eta`` = η_t/η_i, the IOR of the far side over
    that of the near side. Returns 1 under total internal reflection. ``inv_eta`` = 1/η
    when the caller has it as cheaply as η (a per-side pick of two constants): a kernel
    then multiplies instead of dividing by a per-element η.
    """
    if inv_eta is None:
        inv_eta = 1.0 / eta
    c_i = xp.minimum(xp.abs(cos_i), 1.0)
    sin2_t = (1.0 - c_i * c_i) * (inv_eta * inv_eta)
    c_t = xp.safe_sqrt(1.0 - sin2_t)
    # Both denominators vanish only at grazing incidence with η = 1, which is TIR here;
    # elsewhere each is ≥ c_t ≥ 2.4·10⁻⁴ (float32) and at most 2η, so r_par² + r_perp² is
    # taken over one common denominator: one division instead of two.
    d_par = xp.maximum(eta * c_i + c_t, xp.tiny)
    d_perp = xp.maximum(c_i + eta * c_t, xp.tiny)
    n_par, n_perp = (eta * c_i - c_t) * d_perp, (c_i - eta * c_t) * d_par
    d = d_par * d_perp
    f = 0.5 * (n_par * n_par + n_perp * n_perp) / xp.maximum(d * d, xp.tiny)
    return xp.select(sin2_t >= 1.0, 1.0, f)
