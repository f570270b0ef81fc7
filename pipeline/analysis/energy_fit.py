"""The directional-albedo table behind ``energy_compensation`` (:mod:`lookdev.materials.energy`).

E(μ, r) = ∫ f_ss(ωi, ωo) cos θi dωi of the Disney ``specular`` lobe of a white metal
(F = 1), computed from the model's own lobe: the mean of its sampler's weights f·cos/pdf
over a midpoint grid of n × n uniforms (visible-normal sampling, so for F = 1 the weight
is Smith's G1 of the light, smooth in the uniforms but for the horizon's cut). n = 256
agrees with n = 1024 to within 4.9e-4 (:func:`quadrature_error` measures it).
:func:`build_table`, :func:`table_error` and :func:`write_table_module` make and measure
the shipped table; ``python -m lookdev.pipeline.analysis.energy_fit`` rewrites it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials import energy
from lookdev.materials.bsdf import draw
from lookdev.materials.disney import lobe_model
from lookdev.materials.params import DisneyParams

from .sheen_fit import FitError, _worst
from .table_module import write_module

__all__ = [
    "TABLE_SHAPE",
    "albedo_integrated",
    "build_table",
    "quadrature_error",
    "table_error",
    "write_table_module",
]

TABLE_SHAPE = (64, 32)  # (μ, r) nodes: chosen by table_error, see energy_albedo
N_GRID = 256

_SPECULAR = lobe_model("specular")


def albedo_integrated(cos_theta: Any, r: float, *, n: int = N_GRID) -> np.ndarray:
    """E(μ) of the white-metal specular lobe at roughness ``r`` (≥ R_MIN: glossy)."""
    mu = np.atleast_1d(np.asarray(cos_theta, dtype=np.float64))
    # R_MIN itself may round to a delta in float32 (is_delta); α is clamped there anyway.
    r = max(float(r), energy.R_MIN * (1.0 + 1e-6))
    params = DisneyParams(metallic=1.0, base_color=(1.0, 1.0, 1.0), roughness=r)
    g = (np.arange(n) + 0.5) / n
    u = np.stack(np.meshgrid(g, g, indexing="ij"), -1).reshape(-1, 2)
    u = np.concatenate([np.full((len(u), 1), 0.5), u], axis=1)
    mu_o = np.maximum(mu, 1e-7)  # the tangent view itself has no reflected light
    wo = np.stack([np.sqrt(1.0 - mu_o * mu_o), np.zeros_like(mu_o), mu_o], axis=-1)
    out = np.empty_like(mu)
    for k in range(len(mu)):  # one view at a time: n² samples each
        wi, w, pdf = draw(_SPECULAR, params, wo[k], u)
        ok = (pdf > 0.0) & (wi[:, 2] > 0.0)
        out[k] = float(np.mean(np.where(ok, w[:, 0], 0.0)))
    return out


def build_table(n_mu: int, n_r: int, *, n: int = N_GRID) -> np.ndarray:
    """E at the table's nodes (:func:`~lookdev.materials.energy.table_nodes`), (n_r, n_mu)."""
    mu, r = energy.table_nodes(n_mu, n_r)
    return np.stack([albedo_integrated(mu, rr, n=n) for rr in r])


def _off_node(n_mu: int, n_r: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    mu = np.sort(np.concatenate([rng.random(n_mu - 4) ** 4, [0.0, 1e-5, 1e-3, 1.0]]))
    r = np.sort(np.concatenate([rng.uniform(energy.R_MIN, 1.0, n_r - 2), [energy.R_MIN, 1.0]]))
    return mu, r


def table_error(
    table: np.ndarray, *, n_mu: int = 41, n_r: int = 17, n: int = N_GRID, seed: int = 0
) -> FitError:
    """Interpolated ``table`` against direct integration at off-node (μ, r) points."""
    from lookdev.materials.arrays import NumpyOps

    mu, r = _off_node(n_mu, n_r, seed)
    ref = np.stack([albedo_integrated(mu, rr, n=n) for rr in r])
    got = energy.interpolate(NumpyOps(), table, mu[None, :], r[:, None])
    err = np.abs(got - ref)
    return _worst(err, err / np.maximum(ref, 1e-3), mu, r)


def quadrature_error(n: int = N_GRID, fine: int = 1024) -> float:
    """Worst |E_n − E_fine| over a few (μ, r): the integration's own error."""
    mu = np.array([0.0, 1e-4, 0.01, 0.1, 0.5, 1.0])
    return max(
        float(np.max(np.abs(albedo_integrated(mu, r, n=n) - albedo_integrated(mu, r, n=fine))))
        for r in (energy.R_MIN, 0.1, 0.3, 0.6, 1.0)
    )


GENERATOR = "lookdev.pipeline.analysis.energy_fit"  # named in the data modules it writes


def write_table_module(path: Path, table: np.ndarray, error: FitError) -> None:
    """Rewrite the table's data module."""
    n_r, n_mu = table.shape
    doc = (
        "Directional albedo E(μ, r) of the Disney specular lobe of a white metal (F = 1),\n"
        f"row-major ({n_r} r, {n_mu} μ) at :func:`lookdev.materials.energy.table_nodes`.\n"
        f"Measured interpolation error against direct integration:\n{error}.\n"
    )
    write_module(path, GENERATOR, doc, {"N_MU": n_mu, "N_R": n_r}, {"VALUES": table})


def main() -> None:
    """Rebuild ``materials/energy_albedo.py`` and print its measured error."""
    n_mu, n_r = TABLE_SHAPE
    table = build_table(n_mu, n_r)
    error = table_error(table)
    print(f"quadrature n = {N_GRID} vs 1024: {quadrature_error():.3g}")
    print(f"energy table {n_mu}x{n_r}: {error}")
    write_table_module(Path(energy.__file__).with_name("energy_albedo.py"), table, error)


if __name__ == "__main__":
    main()
