"""Measurements behind the Conty-Kulla sheen (:mod:`lookdev.materials.sheen`).

* :func:`lambda_integrated` is Smith's Λ computed from the distribution itself by the
  projected-area normalisation of Heitz 2014 (eq. 3 there, "the projected area of the
  visible microsurface equals that of the geometric surface"):

      1 + Λ(ωo) = (1 / cos θo) ∫ ⟨ωo·m⟩ D(m) dm.

  The azimuthal integral of the clamped cosine is closed-form, so only θm is left to
  quadrature, split where ⟨ωo·m⟩ starts to clip (θm = 90° − θo); 128 Gauss-Legendre
  nodes per piece agree with 1600 to 1.3e-10 relative over cos θ ∈ [0.01, 1], r = 0.08, 1.
* :func:`lambda_fit_error` compares Conty-Kulla's fitted Λ (eq. 3, Table 1) against it.
* :func:`albedo_integrated` is the lobe's directional albedo by product quadrature, the
  reference for the shipped albedo table; :func:`build_albedo_table`,
  :func:`albedo_table_error` and :func:`write_albedo_module` make and measure the table
  (``python -m lookdev.pipeline.analysis.sheen_fit`` rewrites it).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials import sheen, sheen_tables
from lookdev.materials.arrays import NumpyOps

from .table_module import write_module

__all__ = [
    "AREA_SHAPE",
    "EXACT_TABLE_SHAPE",
    "FitError",
    "GENERATOR",
    "TABLE_SHAPE",
    "albedo_integrated",
    "albedo_table_error",
    "area_table_error",
    "build_albedo_table",
    "build_area_table",
    "build_exact",
    "gauss_legendre",
    "lambda_fit_error",
    "lambda_integrated",
    "lambda_table_error",
    "main",
    "projected_area_integrated",
    "write_albedo_module",
    "write_exact_module",
]


@functools.cache
def gauss_legendre(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Nodes and weights on [−1, 1], computed once per n (an eigenproblem of size n)."""
    return np.polynomial.legendre.leggauss(n)


def _clamped_cosine_azimuthal(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """∫₀^2π max(0, a cos φ + b) dφ for a ≥ 0, b ≥ 0.

    With b ≥ a nothing clips: 2πb. Otherwise the positive arc is |φ| < φ₀ with
    cos φ₀ = −b/a, giving 2(a sin φ₀ + b φ₀).
    """
    safe_a = np.where(a > 0, a, 1.0)
    phi0 = np.arccos(np.clip(-b / safe_a, -1.0, 1.0))
    return np.where(b >= a, 2.0 * math.pi * b, 2.0 * (a * np.sin(phi0) + b * phi0))


def lambda_integrated(
    cos_theta: Any, r: float, n: int = 128, r_min: float = sheen.R_MIN_EXACT
) -> np.ndarray:
    """Λ(θ) of eq. 2's distribution by the projected-area integral (Heitz 2014), for the
    roughness r clamped to ``r_min`` (the exact mode's floor: the true Λ of every r the
    model renders)."""
    mu = np.atleast_1d(np.asarray(cos_theta, dtype=np.float64))
    return projected_area_integrated(mu, r, n, r_min) / mu - 1.0


def projected_area_integrated(
    cos_theta: Any, r: float, n: int = 128, r_min: float = sheen.R_MIN_EXACT
) -> np.ndarray:
    """A(θ) = ∫ ⟨ω·m⟩ D(m) dm = cos θ (1 + Λ(θ)) (Heitz 2014 eq. 3), finite at cos θ = 0."""
    mu = np.atleast_1d(np.asarray(cos_theta, dtype=np.float64))
    x, w = gauss_legendre(n)
    sin_o = np.sqrt(np.maximum(0.0, 1.0 - mu * mu))
    split = np.arcsin(np.clip(mu, 0.0, 1.0))  # = 90° − θo
    total = np.zeros_like(mu)
    for lo, hi in ((np.zeros_like(mu), split), (split, np.full_like(mu, math.pi / 2))):
        half = 0.5 * (hi - lo)
        t = (0.5 * (lo + hi))[:, None] + half[:, None] * x[None, :]
        a = sin_o[:, None] * np.sin(t)
        b = mu[:, None] * np.cos(t)
        d = sheen.D(np.cos(t), r, r_min)
        total += half * np.sum(w * d * np.sin(t) * _clamped_cosine_azimuthal(a, b), axis=1)
    return total


@dataclass(frozen=True)
class FitError:
    """Worst absolute and relative error of a fit over a (cos θ, r) grid, and where."""

    max_abs: float
    at_abs: tuple[float, float]  # (cos θ, r)
    max_rel: float
    at_rel: tuple[float, float]

    def __str__(self) -> str:
        (ma, ra), (mr, rr) = self.at_abs, self.at_rel
        return (
            f"max abs {self.max_abs:.4g} at cos θ = {ma:.3g}, r = {ra:.3g};\n"
            f"max rel {self.max_rel:.3g} at cos θ = {mr:.3g}, r = {rr:.3g}"
        )


def _worst(err_abs: np.ndarray, err_rel: np.ndarray, mu: np.ndarray, r: np.ndarray) -> FitError:
    ia = np.unravel_index(np.argmax(err_abs), err_abs.shape)
    ir = np.unravel_index(np.argmax(err_rel), err_rel.shape)
    return FitError(
        float(err_abs[ia]),
        (float(mu[ia[1]]), float(r[ia[0]])),
        float(err_rel[ir]),
        (float(mu[ir[1]]), float(r[ir[0]])),
    )


def lambda_fit_error(cos_theta: Any = None, roughness: Any = None, *, n: int = 128) -> FitError:
    """Conty-Kulla's fitted Λ against :func:`lambda_integrated` over θ × r.

    Defaults: cos θ from 0.01 (the fit is finite at 0, where Λ is not) to 1, r from
    :data:`~lookdev.materials.sheen.R_MIN` to 1. The relative error counts only where
    Λ ≥ 0.01: below that Λ moves G = 1/(1 + Λo + Λi) by under 1% whatever its relative
    error (at cos θ = 1, Λ = 0 exactly and every fit is "infinitely" wrong).
    """
    mu = np.linspace(0.01, 1.0, 34) if cos_theta is None else np.asarray(cos_theta, float)
    r = np.linspace(sheen.R_MIN, 1.0, 20) if roughness is None else np.asarray(roughness, float)
    ref = np.stack([lambda_integrated(mu, rr, n) for rr in r])
    fit = sheen.lambda_fit(mu[None, :], r[:, None])
    err = np.abs(fit - ref)
    return _worst(err, np.where(ref >= 0.01, err / np.maximum(ref, 0.01), 0.0), mu, r)


# -- directional albedo --------------------------------------------------------------------
def albedo_integrated(
    cos_theta: Any, r: float, *, n: int = 96, soften: bool = True, exact: bool = False
) -> np.ndarray:
    """E(μ) = ∫ f(ωi, ωo) cos θi dωi (F = 1) by Gauss-Legendre × trapezoid quadrature.

    μi = s² concentrates nodes near grazing light, where the lobe peaks; the integrand is
    even in φ, so [0, π] is doubled.
    """
    mu_o = np.atleast_1d(np.asarray(cos_theta, dtype=np.float64))
    x, w = gauss_legendre(n)
    s, ws = 0.5 * (x + 1.0), 0.5 * w
    mu, wmu = s * s, ws * 2.0 * s
    phi = (np.arange(n) + 0.5) * (math.pi / n)
    sin_i = np.sqrt(1.0 - mu * mu)
    wi = np.stack(
        [np.outer(sin_i, np.cos(phi)), np.outer(sin_i, np.sin(phi)), np.outer(mu, np.ones(n))]
    ).reshape(3, 1, -1)
    weights = np.outer(wmu * mu, np.full(n, 2.0 * math.pi / n)).reshape(1, -1)
    wo = np.stack([np.sqrt(1.0 - mu_o * mu_o), np.zeros_like(mu_o), mu_o])[:, :, None]
    with np.errstate(all="ignore"):
        f = sheen.lobe(NumpyOps(), wi, wo, r, soften, exact)
    return np.sum(f * weights, axis=-1)


def build_albedo_table(
    n_mu: int, n_r: int, *, soften: bool = True, n: int = 96, exact: bool = False
) -> np.ndarray:
    """E at the table's nodes (:func:`~lookdev.materials.sheen.table_nodes`), (n_r, n_mu),
    of the lobe with the fitted Λ or (``exact``) the tabulated one, from its floor."""
    mu, r = sheen.table_nodes(n_mu, n_r, exact)
    return np.stack([albedo_integrated(mu, rr, n=n, soften=soften, exact=exact) for rr in r])


def albedo_table_error(
    table: np.ndarray,
    *,
    soften: bool = True,
    n_mu: int = 61,
    n_r: int = 23,
    n: int = 96,
    seed: int = 0,
    exact: bool = False,
) -> FitError:
    """Interpolated ``table`` against direct quadrature at off-node (μ, r) points."""
    rng = np.random.default_rng(seed)
    floor = sheen.roughness_floor(exact)
    mu = np.sort(np.concatenate([rng.random(n_mu - 4) ** 4, [0.0, 1e-5, 1e-3, 1.0]]))
    r = np.sort(rng.uniform(floor, 1.0, n_r))
    if exact:  # the floor itself, where the lobe is sharpest, and every cell's middle
        nodes = np.log(sheen.exact_roughness_nodes(table.shape[0]))
        r = np.sort(np.concatenate([r, [floor], np.exp(0.5 * (nodes[1:] + nodes[:-1]))]))
    mu_ref = np.maximum(mu, sheen.COS_MIN)
    ref = np.stack([albedo_integrated(mu_ref, rr, n=n, soften=soften, exact=exact) for rr in r])
    xp = NumpyOps()
    got = sheen.interpolate(xp, table, mu[None, :], r[:, None], exact)
    err = np.abs(got - ref)
    return _worst(err, err / np.maximum(ref, 1e-3), mu, r)


GENERATOR = "lookdev.pipeline.analysis.sheen_fit"  # named in the data modules it writes


def write_albedo_module(path: Path, tables: np.ndarray, errors: list[FitError]) -> None:
    """Rewrite the table's data module."""
    _, n_r, n_mu = tables.shape
    doc = (
        "Conty-Kulla sheen albedo E(μ, r) without and with terminator softening, row-major\n"
        f"(2, {n_r} r, {n_mu} μ) at :func:`lookdev.materials.sheen.table_nodes`.\n"
        "Measured interpolation error against direct quadrature, without softening:\n"
        f"{errors[0]};\nwith softening:\n{errors[1]}.\n"
    )
    write_module(path, GENERATOR, doc, {"N_MU": n_mu, "N_R": n_r}, {"VALUES": tables})


TABLE_SHAPE = (64, 32)  # (μ, r) nodes: chosen by albedo_table_error, see sheen_albedo


# -- the exact Λ (sheen_lambda = "exact") ----------------------------------------------------
def build_area_table(n_theta: int, n_r: int, n: int = 128) -> np.ndarray:
    """A(θ, r) = cos θ (1 + Λ) at :func:`~lookdev.materials.sheen.area_nodes`, (n_r, n_θ)."""
    mu, r = sheen.area_nodes(n_theta, n_r)
    return np.stack([projected_area_integrated(mu, rr, n) for rr in r])


def area_table_error(table: np.ndarray, *, n_theta: int = 97, n_r: int = 41, seed: int = 0):
    """The interpolated projected area against the integral at off-node (θ, r) points,
    θ uniform and r log-uniform over [0.01, 1], the ends included. Its relative error is
    that of 1 + Λ and of G1 = cos θ / A."""
    rng = np.random.default_rng(seed)
    theta = np.sort(np.concatenate([rng.uniform(0.0, 0.5 * math.pi, n_theta - 2), [0.0, 1.5]]))
    mu = np.concatenate([np.cos(theta), [sheen.COS_MIN]])
    lo = math.log(sheen.R_MIN_EXACT)
    r = np.sort(np.concatenate([np.exp(rng.uniform(lo, 0.0, n_r - 2)), [sheen.R_MIN_EXACT, 1.0]]))
    ref = np.stack([projected_area_integrated(mu, rr) for rr in r])
    got = sheen.projected_area(NumpyOps(), mu[None, :], r[:, None], table)
    err = np.abs(got - ref)
    return _worst(err, err / ref, mu, r)


def lambda_table_error(cos_theta: Any = None, roughness: Any = None) -> FitError:
    """The shipped exact-mode Λ (:func:`~lookdev.materials.sheen.lambda_table`) against
    :func:`lambda_integrated`, counted as :func:`lambda_fit_error` counts the fit."""
    mu = np.linspace(0.01, 1.0, 34) if cos_theta is None else np.asarray(cos_theta, float)
    r = np.geomspace(0.01, 1.0, 20) if roughness is None else np.asarray(roughness, float)
    ref = np.stack([lambda_integrated(mu, rr) for rr in r])
    err = np.abs(sheen.lambda_table(mu[None, :], r[:, None]) - ref)
    return _worst(err, np.where(ref >= 0.01, err / np.maximum(ref, 0.01), 0.0), mu, r)


AREA_SHAPE = (64, 24)  # (θ, r) nodes of the exact Λ: chosen by area_table_error
EXACT_TABLE_SHAPE = (64, AREA_SHAPE[1])  # (μ, r) of the exact albedo: r nodes the area's


def _indent(error: FitError) -> str:
    return str(error).replace("\n", "\n  ")


def write_exact_module(
    path: Path, area: np.ndarray, albedo: np.ndarray, errors: list[FitError]
) -> None:
    """Rewrite the exact mode's data module (projected area and albedo, row-major)."""
    (n_ra, n_th), (_, n_r, n_mu) = area.shape, albedo.shape
    doc = (
        'The exact-Λ Conty-Kulla sheen (``sheen_lambda = "exact"``, r ≥ 0.01):\n\n'
        f"* AREA: projected area A = cos θ (1 + Λ), ({n_ra} r, {n_th} θ) at\n"
        "  :func:`lookdev.materials.sheen.area_nodes`; interpolated against the integral:\n"
        f"  {_indent(errors[0])}.\n"
        f"* ALBEDO: E(μ, r) without and with softening, (2, {n_r} r, {n_mu} μ) at\n"
        "  :func:`lookdev.materials.sheen.table_nodes` (exact); against quadrature,\n"
        f"  without softening: {_indent(errors[1])};\n"
        f"  with softening: {_indent(errors[2])}.\n"
    )
    sizes = {"N_THETA": n_th, "N_R_AREA": n_ra, "N_MU": n_mu, "N_R": n_r}
    write_module(
        path, GENERATOR, doc, sizes, {"AREA": area, "ALBEDO": albedo}, digits=7, per_line=6
    )


def build_exact(n: int = 96) -> tuple[np.ndarray, np.ndarray, list[FitError]]:
    """The exact mode's tables and their measured errors.

    The albedo tabulates the lobe as it renders, with the *interpolated* Λ, so the area
    table is put in place first (generation only: the shipped module is rewritten after).
    """
    area = build_area_table(*AREA_SHAPE)
    errors = [area_table_error(area)]
    shipped, sheen_tables._AREA_TABLE = sheen_tables._AREA_TABLE, area
    try:
        n_mu, n_r = EXACT_TABLE_SHAPE
        albedo = np.stack(
            [build_albedo_table(n_mu, n_r, soften=s, n=n, exact=True) for s in (False, True)]
        )
        errors += [
            albedo_table_error(t, soften=s, n=n, exact=True)
            for t, s in zip(albedo, (False, True), strict=True)
        ]
    finally:
        sheen_tables._AREA_TABLE = shipped
    return area, albedo, errors


def main() -> None:
    """Rebuild ``materials/sheen_albedo.py`` and ``sheen_exact.py``; print their errors."""
    n_mu, n_r = TABLE_SHAPE
    tables = np.stack([build_albedo_table(n_mu, n_r, soften=s) for s in (False, True)])
    errors = [albedo_table_error(t, soften=s) for t, s in zip(tables, (False, True), strict=True)]
    print(f"lambda fit vs integrated: {lambda_fit_error()}")
    for soften, error in zip((False, True), errors, strict=True):
        print(f"albedo table {n_mu}x{n_r}, softening {soften}: {error}")
    write_albedo_module(Path(sheen.__file__).with_name("sheen_albedo.py"), tables, errors)
    area, albedo, exact_errors = build_exact()
    for what, error in zip(("area", "albedo", "albedo softened"), exact_errors, strict=True):
        print(f"exact {what}: {error}")
    write_exact_module(Path(sheen.__file__).with_name("sheen_exact.py"), area, albedo, exact_errors)


if __name__ == "__main__":
    main()
