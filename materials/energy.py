"""Multiple-scattering energy compensation of the Disney specular lobe (``energy_compensation``).

A single-scattering microfacet lobe loses the light that bounces more than once between
microfacets: a white GGX metal keeps 31 % of the light at normal incidence at roughness 1
(E(1, α = 1) = 0.307, :mod:`.energy_albedo`). With ``energy_compensation`` on (default off:
Burley's look is unchanged) the Disney ``specular`` lobe is scaled as

    f_ms(ωi, ωo) = f_ss(ωi, ωo) · (1 + F0 · (1 − E(μo, α)) / E(μo, α))      (Turquin et al. 2019)

with E(μ, α) the directional albedo of the lobe with F = 1 and F0 the lobe's Fresnel at
normal incidence (the metal's base colour, 0.08·specular, or the exact dielectric F0).
Turquin, not Kulla–Conty 2017: one factor on the existing lobe (no second lobe, so the
sampling and pdf are unchanged and chi-square holds by construction), exact for a white
metal (∫ f_ss (1/E) cos = 1 at every view; MaterialX's GLSL ``mx_ggx_energy_compensation``
is the same factor), a 2D table instead of Kulla–Conty's E, E_avg
and the Fresnel average, and it fits our GGX with Schlick's Fresnel as it stands; the price
is a factor read at the view only, "reciprocal enough" rather than exactly: the lobe
declares itself non-reciprocal when the switch is on (``Lobe.reciprocal_unless``), so a
light tracer evaluates it with the roles as they are (Mitsuba ``NonSymmetric``).

What it covers, and what not (each one a choice measured in tests/materials/test_energy.py):

* **anisotropic**: E is read at the isotropic α = √(αx αy) (the geometric mean, the α the
  GTR path already uses, and MaterialX's ``mx_average_alpha``): an approximation, measured
  on a white metal at 0.84 … 1.023 with ``anisotropic`` 0.5 and only partial at 1, where
  αx reaches 3.2, beyond the table (0.29 … 0.47 at roughness 1, 0.11 off).
* **specular_gamma ≠ 2**: the table is the GGX lobe's; the GTR lobe (V-cavity G) has
  another E, so compensation is off there (``compensated`` is False), named in the
  parameter's description.
* **a smooth (delta) specular**: E = 1, nothing to compensate.
* **not compensated**: the glass's transmission (Turquin's dielectric needs E over
  (μ, α, η) on both sides, and with the reflection a 3D table per side), the reflection seen
  from inside a solid, and the clearcoat (its G has Burley's fixed α = 0.25, whose E this
  table does not hold, and with F0 = 0.04 the factor would add at most 4 % of (1/E − 1)
  of a lobe weighted 0.25).

The table is E(μ, r) over r = √α ∈ [√ALPHA_MIN, 1] (α below ALPHA_MIN is clamped, so is
its E) and μ = cos θo, integrated from the model's own lobe by
:mod:`lookdev.pipeline.analysis.energy_fit`, read bilinearly (:func:`.tables.bilinear`).
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from . import fresnel as fr
from . import microfacet as mf
from .energy_albedo import N_MU, N_R, VALUES
from .tables import bilinear

__all__ = [
    "R_MIN",
    "albedo",
    "albedo_lookup",
    "compensated",
    "factor",
    "table_nodes",
    "table_roughness",
]

R_MIN = math.sqrt(mf.ALPHA_MIN)
"""The smallest roughness the table holds: a glossy α never goes below ALPHA_MIN."""
_EXP = 0.25
"""μ nodes are uniform in μ^¼: E changes fastest at grazing (measured in energy_fit)."""

_TABLE = np.asarray(VALUES, dtype=np.float64).reshape(N_R, N_MU)


def table_nodes(n_mu: int, n_r: int) -> tuple[np.ndarray, np.ndarray]:
    """(μ, r) at which the table is sampled."""
    return np.linspace(0.0, 1.0, n_mu) ** (1.0 / _EXP), np.linspace(R_MIN, 1.0, n_r)


def interpolate(xp: Any, table: np.ndarray, cos_theta: Any, r: Any) -> Any:
    """Bilinear read of ``table`` (shape (n_r, n_mu), nodes :func:`table_nodes`)."""
    n_r, n_mu = table.shape
    x = xp.sqrt(xp.sqrt(xp.clip(cos_theta, 0.0, 1.0))) * (n_mu - 1.0)  # μ^_EXP
    y = (xp.clip(r, R_MIN, 1.0) - R_MIN) * ((n_r - 1.0) / (1.0 - R_MIN))
    return bilinear(xp, table, x, y)


def albedo_lookup(xp: Any, cos_theta: Any, r: Any) -> Any:
    """E(μ, r) = ∫ f_ss(ωi, ωo) cos θi dωi of a white GGX lobe at cos θo = μ, from the table."""
    return interpolate(xp, _TABLE, cos_theta, r)


def table_roughness(xp: Any, ax: Any, ay: Any) -> Any:
    """The table's r for the lobe's (αx, αy): √α with α = √(αx αy)."""
    return xp.sqrt(xp.sqrt(ax * ay)) if not isinstance(ax, float) else math.sqrt(math.sqrt(ax * ay))


def compensated(params: Any, ggx: bool) -> bool:
    """Whether compensation applies: switched on and the lobe is GGX (γ = 2)."""
    return bool(getattr(params, "energy_compensation", False)) and ggx


def factor(xp: Any, f0: Any, cos_o: Any, r: Any) -> Any:
    """Turquin 2019's 1 + F0 (1 − E)/E at the view cos θo (E ≥ 0.05 at every node)."""
    e = albedo_lookup(xp, cos_o, r)
    return 1.0 + f0 * (1.0 / e - 1.0)


def f0_of(xp: Any, spec_a: Any, spec_c: Any, eta: Any) -> Any:
    """The specular lobe's Fresnel at normal incidence, seen from outside (a colour):
    A of the Schlick blend plus the exact-Fresnel part c·F(0, η)."""
    if xp.known_zero(spec_c):
        return spec_a
    return spec_a + spec_c * fr.ior_to_f0(eta)


# -- numpy --------------------------------------------------------------------------------
def albedo(cos_theta: Any, roughness: Any) -> np.ndarray:
    """E(μ, r) from the shipped table, numpy (μ = cos θo, r the Disney roughness)."""
    from .arrays import NumpyOps

    return albedo_lookup(NumpyOps(), np.asarray(cos_theta, float), np.asarray(roughness, float))
