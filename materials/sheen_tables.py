"""The Conty-Kulla sheen's roughness floors and tables, read on either backend.

The roughness floors of the two Smith Λ (:data:`R_MIN` for Table 1's fit, :data:`R_MIN_EXACT`
for the integrated one), the exact Λ from its projected-area table (:mod:`.sheen_exact`),
and the bilinear table read that :mod:`.sheen` also uses for its albedo tables
(:func:`.tables.bilinear`, shared with :mod:`.energy`, re-exported here).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .sheen_exact import AREA as _AREA
from .sheen_exact import N_R_AREA as _N_R_AREA
from .sheen_exact import N_THETA as _N_THETA
from .tables import bilinear  # the one bilinear read of every shipped table

__all__ = [
    "COS_MIN",
    "R_MIN",
    "R_MIN_EXACT",
    "area_nodes",
    "bilinear",
    "clamp_roughness",
    "exact_roughness_nodes",
    "lambda_exact",
    "log_r_index",
    "projected_area",
    "roughness_floor",
]

R_MIN = 0.08
"""Roughness floor of the fitted Λ (below it Table 1's fit gains energy)."""
R_MIN_EXACT = 0.01
"""Roughness floor of the exact (tabulated) Λ."""
COS_MIN = 1e-5


def roughness_floor(exact: bool) -> float:
    """The smallest r of a Λ mode: :data:`R_MIN_EXACT` exact, :data:`R_MIN` fitted."""
    return R_MIN_EXACT if exact else R_MIN


def clamp_roughness(xp: Any, r: Any, r_min: float = R_MIN) -> Any:
    """r in [r_min, 1]: the paper's (0, 1] with the delta limit kept out."""
    return xp.clip(r, r_min, 1.0)


# The exact Λ is tabulated as the projected area A(θ, r) = ∫⟨ω·m⟩ D(m) dm = cos θ (1 + Λ)
# (Heitz 2014 eq. 3): bounded (0.64 .. 4.05 over r ∈ [0.01, 1]) and smooth in θ, where Λ
# itself diverges as 1/cos θ and G1 = cos θ / A vanishes at grazing; Λ = A / cos θ − 1
# costs one division, and the table's relative error is G1's and (1 + Λ)'s.
_AREA_TABLE = np.asarray(_AREA, dtype=np.float64).reshape(_N_R_AREA, _N_THETA)
_LOG_R_SPAN = math.log(1.0 / R_MIN_EXACT)


def area_nodes(n_theta: int, n_r: int) -> tuple[np.ndarray, np.ndarray]:
    """(cos θ, r) of the projected-area table: θ uniform in [0, π/2], log r uniform."""
    theta = np.linspace(0.0, 0.5 * math.pi, n_theta)
    return np.cos(theta), exact_roughness_nodes(n_r)


def exact_roughness_nodes(n_r: int) -> np.ndarray:
    """r uniform in log r from :data:`R_MIN_EXACT` to 1: the exact mode's r axis."""
    return R_MIN_EXACT * np.exp(_LOG_R_SPAN * np.linspace(0.0, 1.0, n_r))


def log_r_index(xp: Any, r: Any, n_r: int) -> Any:
    """Fractional index of r on :func:`exact_roughness_nodes` (``n_r`` of them)."""
    r = clamp_roughness(xp, r, R_MIN_EXACT)
    return xp.log(r * (1.0 / R_MIN_EXACT)) * ((n_r - 1) / _LOG_R_SPAN)


def projected_area(xp: Any, cos_theta: Any, r: Any, table: np.ndarray | None = None) -> Any:
    """A(θ, r) = cos θ (1 + Λ(θ)), bilinear in (θ, log r) from ``table`` (:func:`area_nodes`)."""
    table = _AREA_TABLE if table is None else table
    n_r, n_theta = table.shape
    theta = xp.acos(xp.clip(cos_theta, 0.0, 1.0))
    x = theta * ((n_theta - 1) / (0.5 * math.pi))
    return bilinear(xp, table, x, log_r_index(xp, r, n_r) + 0.0 * x)


def lambda_exact(xp: Any, cos_theta: Any, r: Any) -> Any:
    """Λ(θ) = A(θ, r) / cos θ − 1 from the integrated projected area (Heitz 2014 eq. 3).

    cos θ is floored at :data:`COS_MIN` like the lobe's cosines, so Λ ≤ 4.1·10⁵ stays a
    finite float32; the floor of 0 keeps a table value a hair under cos θ at the normal
    from giving a negative Λ.
    """
    mu = xp.clip(cos_theta, COS_MIN, 1.0)
    return xp.maximum(projected_area(xp, mu, r) / mu - 1.0, 0.0)
