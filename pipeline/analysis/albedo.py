"""Directional albedo of any :class:`~lookdev.materials.bsdf.Model`, three ways.

The directional albedo (Burley 2012 §4.4, "directional-hemispherical reflectance") of a
BSDF seen from ``wo`` is

    E(wo) = ∫ f(wi, wo) |cos θi| dωi,

the fraction of light that leaves towards ``wo`` under a uniform white sky, or — by
reciprocity, for every reciprocal model — the fraction of light arriving along ``wo``
that is scattered at all. Burley plots it against the incidence angle (Fig. 11/12); so
do we. Three estimators:

* :func:`albedo_quadrature`: Gauss-Legendre in cos θi × the periodic trapezoid rule in
  φi. Deterministic and fast for smooth lobes; it misses narrow peaks unless the grid is
  fine (the error bench measures how fine).
* :func:`albedo_monte_carlo`: the model's own importance sampler (``sample``), so the
  estimate is unbiased for any roughness and its standard error is reported with it.
* :func:`albedo_tabulated`: a look-up table a model ships for layering (Conty-Kulla
  2017 §5, albedo scaling), where it has one.

Directions are in the shading frame (normal +z); ``wo`` lies at angle θ from the normal
and azimuth φ from the tangent (+x), φ = 0 by default: the x-z plane (φ = 90° is the
bitangent, where an anisotropic lobe differs). ``hemisphere="reflect"`` integrates over
the upper hemisphere only; ``"both"`` adds transmission.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np

from lookdev.materials.bsdf import Model, draw, evaluate

__all__ = [
    "AlbedoCurve",
    "Hemisphere",
    "albedo_monte_carlo",
    "albedo_quadrature",
    "albedo_tabulated",
    "register_table",
    "sheen_table",
    "table_for",
    "view_direction",
]

Hemisphere = Literal["reflect", "both"]


def view_direction(theta: Any, dtype: Any = np.float64, phi: float = 0.0) -> np.ndarray:
    """Unit vectors at polar angle ``theta`` and azimuth ``phi`` (radians), shape (..., 3).

    φ = 0 (the default) is the x-z plane, the tangent side; φ = π/2 the bitangent.

    >>> view_direction(0.0).tolist()
    [0.0, 0.0, 1.0]
    """
    t = np.asarray(theta, dtype=dtype)
    if phi == 0.0:  # exactly the x-z plane (no cos(0)·sin rounding, y exactly 0)
        return np.stack([np.sin(t), np.zeros_like(t), np.cos(t)], axis=-1)
    c, s = np.cos(phi), np.sin(phi)
    return np.stack([np.sin(t) * c, np.sin(t) * s, np.cos(t)], axis=-1).astype(dtype)


@dataclass(frozen=True)
class AlbedoCurve:
    """Albedo per channel against incidence angle, with its statistical error if any."""

    theta: np.ndarray  # (T,) radians
    albedo: np.ndarray  # (T, 3)
    stderr: np.ndarray | None = None  # (T, 3), Monte Carlo only
    method: str = ""


def _hemisphere_grid(
    n_mu: int, n_phi: int, hemisphere: Hemisphere, dtype: Any
) -> tuple[np.ndarray, np.ndarray]:
    """Quadrature directions (M, 3) and their weights (M,) for ∫ g(ω) |cos θ| dω.

    Gauss-Legendre nodes in μ = cos θ (exact for polynomials of degree 2n−1 in μ) and
    equally spaced φ (exponentially accurate for smooth periodic integrands).
    """
    x, w = np.polynomial.legendre.leggauss(n_mu)
    if hemisphere == "reflect":
        mu, wmu = 0.5 * (x + 1.0), 0.5 * w  # [-1, 1] → [0, 1]
    else:
        mu = np.concatenate([0.5 * (x + 1.0), -0.5 * (x + 1.0)])
        wmu = np.concatenate([0.5 * w, 0.5 * w])
    phi = (np.arange(n_phi) + 0.5) * (2.0 * math.pi / n_phi)
    s = np.sqrt(np.maximum(0.0, 1.0 - mu * mu))
    dirs = np.stack(
        [
            np.outer(s, np.cos(phi)),
            np.outer(s, np.sin(phi)),
            np.outer(mu, np.ones_like(phi)),
        ],
        axis=-1,
    ).reshape(-1, 3)
    weights = np.outer(wmu * np.abs(mu), np.full(n_phi, 2.0 * math.pi / n_phi)).reshape(-1)
    return dirs.astype(dtype), weights.astype(dtype)


def albedo_quadrature(
    model: Model,
    params: Any,
    theta: Any,
    *,
    n_mu: int = 64,
    n_phi: int = 64,
    hemisphere: Hemisphere = "reflect",
    dtype: Any = np.float64,
) -> AlbedoCurve:
    """E(θ) by product quadrature over the incoming hemisphere (or sphere)."""
    theta = np.atleast_1d(np.asarray(theta, dtype=np.float64))
    dirs, weights = _hemisphere_grid(n_mu, n_phi, hemisphere, dtype)
    wo = view_direction(theta, dtype)
    f = evaluate(model, params, dirs[None, :, :], wo[:, None, :], dtype=dtype)
    f = np.where(np.isfinite(f), f, 0.0)
    return AlbedoCurve(theta, np.einsum("tmc,m->tc", f, weights), method="quadrature")


def albedo_monte_carlo(
    model: Model,
    params: Any,
    theta: Any,
    *,
    n_samples: int = 4096,
    seed: int = 0,
    hemisphere: Hemisphere = "reflect",
    dtype: Any = np.float64,
    phi: float = 0.0,
) -> AlbedoCurve:
    """E(θ) as the mean of the sampler's weights f·|cos θi|/pdf, with its standard error.

    The views lie at azimuth ``phi`` (radians) from the tangent; 0 by default.

    A failed sample (pdf 0) counts as zero, as it does in a renderer; so does a sample
    in the wrong hemisphere when only reflection is asked for.
    """
    theta = np.atleast_1d(np.asarray(theta, dtype=np.float64))
    rng = np.random.default_rng(seed)
    u = _stratified_uniforms(rng, n_samples).astype(dtype)
    wo = view_direction(theta, dtype, phi)
    wi, weight, pdf = draw(model, params, wo[:, None, :], u[None, :, :], dtype=dtype)
    keep = (pdf > 0) & np.all(np.isfinite(weight), axis=-1)
    if hemisphere == "reflect":
        keep &= wi[..., 2] > 0
    w = np.where(keep[..., None], weight, 0.0).astype(np.float64)
    mean = w.mean(axis=1)
    stderr = w.std(axis=1, ddof=1) / math.sqrt(n_samples)
    return AlbedoCurve(theta, mean, stderr, method="monte carlo")


def _stratified_uniforms(rng: np.random.Generator, n: int) -> np.ndarray:
    """(n, 3) uniforms, jittered-stratified in the two direction dimensions.

    The lobe choice (u[0]) stays independent so lobe selection remains unbiased; the
    direction dimensions are stratified on a √n × √n grid (n need not be square: the
    remainder is plain random) to cut variance at no cost.
    """
    u = rng.random((n, 3))
    k = int(math.isqrt(n))
    i = np.arange(k * k)
    u[: k * k, 1] = (i % k + u[: k * k, 1]) / k
    u[: k * k, 2] = (i // k + u[: k * k, 2]) / k
    return u


def sheen_table(params: Any, cos_theta: np.ndarray) -> np.ndarray:
    """Conty-Kulla sheen: its shipped E(μ, r) table (F = 1) times the sheen colour F.

    The model ships a table with the terminator softening (eq. 4) and one without, for
    each Λ mode; the one matching ``params.terminator_softening`` and
    ``params.sheen_lambda`` is read.
    """
    from lookdev.materials import sheen

    e = sheen.albedo(cos_theta, params.roughness, params.terminator_softening, params.sheen_lambda)
    return e[..., None] * np.asarray(params.color, dtype=np.float64)


# Albedo tables that models ship, by model name: fn(params, cos_theta) → (..., 3) or (...).
_TABLES: dict[str, Callable[[Any, np.ndarray], np.ndarray]] = {"sheen": sheen_table}


def register_table(model_name: str, fn: Callable[[Any, np.ndarray], np.ndarray]) -> None:
    """Declare ``fn(params, cos_theta)`` as the albedo table of the model ``model_name``."""
    _TABLES[model_name] = fn


def table_for(model: Model) -> Callable[[Any, np.ndarray], np.ndarray] | None:
    """The tabulated-albedo function a model ships, or None."""
    return _TABLES.get(model.name)


def albedo_tabulated(model: Model, params: Any, theta: Any) -> AlbedoCurve | None:
    """E(θ) read from the model's own table, or None when the model ships none."""
    fn = table_for(model)
    if fn is None:
        return None
    theta = np.atleast_1d(np.asarray(theta, dtype=np.float64))
    a = np.asarray(fn(params, np.cos(theta)), dtype=np.float64)
    return AlbedoCurve(
        theta, np.broadcast_to(a.reshape(len(theta), -1), (len(theta), 3)), method="table"
    )
