"""Measurements behind ``lookdev bench error``: each approximation against its reference.

* proof renders — relative MSE against a high-sample reference, for a ladder of samples
  per pixel, against render time;
* directional albedo — quadrature, Monte Carlo with the model's own importance sampling,
  and a shipped table, against a converged quadrature;
* the Conty-Kulla Λ fit (2017, eq. 3, Table 1) against numerical integration of the
  projected area of their D (eq. 2), per evaluation;
* float32 against float64 evaluation of a model.

Each function returns :class:`Row` s measured when it is called: errors are relative and
dimensionless; ``seconds`` is the best of a few calls after a warm-up.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lookdev.materials.bsdf import Model, evaluate
from lookdev.pipeline.analysis.albedo import albedo_monte_carlo, albedo_quadrature, albedo_tabulated

from .timing import best_time

__all__ = [
    "ALBEDO_ANGLES",
    "LAMBDA_COS",
    "LAMBDA_ROUGHNESS",
    "Row",
    "SHEEN_LAMBDA_ROUGHNESS",
    "albedo_reference",
    "bench_albedo",
    "bench_lambda",
    "bench_precision",
    "bench_render",
    "bench_sheen_lambda",
    "direction_pairs",
    "once",
    "relative_mse",
    "relative_rms",
    "timed",
]


@dataclass(frozen=True)
class Row:
    """One measurement: ``case`` computed by ``method`` at ``setting``."""

    item: str
    case: str
    method: str
    setting: str
    error: float
    seconds: float
    evaluations: int = 1
    reference: str = ""  # what the error is measured against
    reference_seconds: float = 0.0  # what computing that reference took, same run

    @property
    def seconds_per_evaluation(self) -> float:
        return self.seconds / max(self.evaluations, 1)

    @property
    def speedup(self) -> float:
        """How many times faster than its reference (0 when the reference is untimed)."""
        return self.reference_seconds / self.seconds if self.seconds > 0 else 0.0


def timed(fn: Callable[[], Any], repeat: int = 3) -> tuple[Any, float]:
    """(result, best wall time of ``repeat`` calls after a warm-up)."""
    result = fn()
    return result, best_time(fn, repeat=repeat, min_time=2.0)


def once(fn: Callable[[], Any]) -> tuple[Any, float]:
    """(result, wall time) of a single call: for references too costly to repeat."""
    t0 = time.perf_counter()
    result = fn()
    return result, time.perf_counter() - t0


def relative_rms(estimate: np.ndarray, reference: np.ndarray, floor: float = 1e-3) -> float:
    """√mean(((x − ref) / max(|ref|, floor))²) over every element.

    >>> round(relative_rms(np.array([1.1, 2.0]), np.array([1.0, 2.0])), 6)
    0.070711
    """
    rel = (estimate - reference) / np.maximum(np.abs(reference), floor)
    return float(np.sqrt(np.mean(rel * rel)))


# -- albedo ----------------------------------------------------------------------------
ALBEDO_ANGLES = np.radians([0.0, 20.0, 40.0, 60.0, 75.0, 85.0])


def albedo_reference(
    model: Model, params: Any, theta: np.ndarray, nodes: int, samples: int
) -> tuple[np.ndarray, str, float]:
    """The converged albedo, how it was obtained and how long that took.

    A fine quadrature is the most precise reference for smooth lobes, but no fixed grid
    resolves a near-delta lobe (roughness 0, a glossy clearcoat): there it is simply
    wrong. So it is checked against an independent many-sample Monte Carlo estimate and
    used only where the two agree within 4σ; otherwise the Monte Carlo one is.
    """
    quad, t_quad = once(lambda: albedo_quadrature(model, params, theta, n_mu=nodes, n_phi=nodes))
    mc, t_mc = once(lambda: albedo_monte_carlo(model, params, theta, n_samples=samples, seed=7919))
    if np.all(np.abs(quad.albedo - mc.albedo) <= 4.0 * mc.stderr + 1e-9):
        return quad.albedo, f"quadrature {nodes}×{nodes}", t_quad
    return mc.albedo, f"monte carlo {samples} spp", t_mc


def bench_albedo(
    case: str,
    model: Model,
    params: Any,
    *,
    quadrature: Sequence[int] = (8, 16, 32, 64, 128),
    samples: Sequence[int] = (64, 256, 1024, 4096),
    reference_nodes: int = 512,
    reference_samples: int = 65536,
) -> list[Row]:
    """Error against time of each albedo estimator for one material."""
    theta = ALBEDO_ANGLES
    reference, against, t_ref = albedo_reference(
        model, params, theta, reference_nodes, reference_samples
    )
    rows = []
    for n in quadrature:
        curve, t = timed(lambda n=n: albedo_quadrature(model, params, theta, n_mu=n, n_phi=n))
        rows.append(
            Row(
                "albedo",
                case,
                "quadrature",
                f"{n}×{n}",
                relative_rms(curve.albedo, reference),
                t,
                n * n * len(theta),
                against,
                t_ref,
            )
        )
    for n in samples:
        curve, t = timed(lambda n=n: albedo_monte_carlo(model, params, theta, n_samples=n))
        rows.append(
            Row(
                "albedo",
                case,
                "monte carlo",
                f"{n} spp",
                relative_rms(curve.albedo, reference),
                t,
                n * len(theta),
                against,
                t_ref,
            )
        )
    table, t = timed(lambda: albedo_tabulated(model, params, theta))
    if table is not None:
        rows.append(
            Row(
                "albedo",
                case,
                "table",
                "shipped",
                relative_rms(table.albedo, reference),
                t,
                len(theta),
                against,
                t_ref,
            )
        )
    return rows


# -- Conty-Kulla Λ -------------------------------------------------------------------
LAMBDA_COS = np.linspace(0.02, 1.0, 50)
LAMBDA_ROUGHNESS = (0.1, 0.3, 0.5, 1.0)


def bench_lambda(
    fit: Callable[[np.ndarray, float], np.ndarray] | None,
    *,
    nodes: Sequence[int] = (4, 8, 16, 32),
    reference_nodes: int = 2048,
) -> list[Row]:
    """The Λ fit, and the projected-area integral at a ladder of Gauss-Legendre nodes,
    against that integral converged
    (:func:`~lookdev.pipeline.analysis.sheen_fit.lambda_integrated`, Heitz 2014: 1 + Λ(ω) =
    ∫ ⟨ω·m⟩ D(m) dm / cos θ)."""
    from lookdev.pipeline.analysis.sheen_fit import lambda_integrated

    rows = []
    n_eval = len(LAMBDA_COS)
    for r in LAMBDA_ROUGHNESS:
        ref, t_ref = timed(lambda r=r: lambda_integrated(LAMBDA_COS, r, reference_nodes))
        against = f"integral {reference_nodes} nodes"
        case = f"r = {r:g}"
        if fit is not None:
            value, t = timed(lambda r=r: np.asarray(fit(LAMBDA_COS, r), dtype=np.float64))
            rows.append(
                Row(
                    "lambda",
                    case,
                    "fit (eq. 3)",
                    "Table 1",
                    relative_rms(value, ref),
                    t,
                    n_eval,
                    against,
                    t_ref,
                )
            )
        for n in nodes:
            value, t = timed(lambda n=n, r=r: lambda_integrated(LAMBDA_COS, r, n))
            rows.append(
                Row(
                    "lambda",
                    case,
                    "integral",
                    f"{n} nodes",
                    relative_rms(value, ref),
                    t,
                    n_eval,
                    against,
                    t_ref,
                )
            )
    return rows


SHEEN_LAMBDA_ROUGHNESS = (0.01, 0.03, 0.08, 0.3, 1.0)
"""Down to the exact mode's floor; the fit reads r < 0.08 as 0.08 (its rows show that)."""


def bench_sheen_lambda(
    *, roughness: Sequence[float] = SHEEN_LAMBDA_ROUGHNESS, reference_nodes: int = 2048
) -> list[Row]:
    """Both modes of ``sheen_lambda``, Λ as the lobe evaluates it (the fit of eq. 3 with
    its floor 0.08, the exact mode's table with its floor 0.01), against the converged
    projected-area integral at the roughness asked for, and each one's run time (per
    value, over 10⁵ directions: a render's batch, not Python's call overhead)."""
    from lookdev.materials import sheen
    from lookdev.pipeline.analysis.sheen_fit import lambda_integrated

    modes = {"fit (eq. 3)": sheen.lambda_fit, "table": sheen.lambda_table}
    settings = {"fit (eq. 3)": "Table 1, r ≥ 0.08", "table": "exact, r ≥ 0.01"}
    batch = np.tile(LAMBDA_COS, 2000)
    backends = {"numpy": modes, **_drjit_lambdas(batch)}
    rows = []
    for r in roughness:
        ref, t_ref = timed(lambda r=r: lambda_integrated(LAMBDA_COS, r, reference_nodes))
        for backend, fns in backends.items():
            for method, fn in fns.items():
                value, t = timed(lambda fn=fn, r=r: np.asarray(fn(batch, r), dtype=np.float64))
                rows.append(
                    Row(
                        "sheen_lambda",
                        f"r = {r:g}",
                        method,
                        f"{settings[method]}, {backend}",
                        relative_rms(value[: len(LAMBDA_COS)], ref),
                        t,
                        len(batch),
                        f"integral {reference_nodes} nodes",
                        t_ref,
                    )
                )
    return rows


def _drjit_lambdas(batch: np.ndarray) -> dict[str, dict[str, Callable[..., Any]]]:
    """Both Λ modes on the renderer's backend (Dr.Jit, float32, forced and waited for),
    or nothing where Mitsuba is not installed."""
    try:
        from lookdev.pipeline.variant import use_mitsuba

        use_mitsuba()
        import drjit as dr
    except ImportError:
        return {}
    from lookdev.materials import sheen
    from lookdev.materials.arrays import DrJitOps

    xp = DrJitOps.for_mitsuba()
    cos = xp.Float(batch)

    def run(fn: Callable[..., Any]) -> Callable[[np.ndarray, float], np.ndarray]:
        def call(_: np.ndarray, r: float) -> np.ndarray:
            out = fn(xp, cos, xp.Float(r))
            dr.eval(out)
            dr.sync_thread()
            return np.asarray(out)

        return call

    def fit(xp: Any, c: Any, r: Any) -> Any:
        coeffs = sheen.fit_coefficients(xp, sheen.clamp_roughness(xp, r))
        return xp.exp(sheen.log_lambda(xp, c, coeffs))

    return {"Dr.Jit": {"fit (eq. 3)": run(fit), "table": run(sheen.lambda_exact)}}


# -- float32 against float64 -----------------------------------------------------------
def direction_pairs(n: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Random (wi, wo) pairs over both hemispheres, plus the edge cases :doc:`/design` lists:
    normal incidence, grazing (cos θ = 1e-4), retro-reflection and wi = −wo."""
    rng = np.random.default_rng(seed)
    v = rng.normal(size=(2, n, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[..., 2] = np.abs(v[..., 2])
    v[1, : n // 10, 2] *= -1  # transmission pairs
    g = math.sqrt(1.0 - 1e-8)
    edges = np.array(
        [
            [[0, 0, 1.0], [0, 0, 1.0]],
            [[g, 0, 1e-4], [0, 0, 1.0]],
            [[g, 0, 1e-4], [-g, 0, 1e-4]],
            [[0.6, 0, 0.8], [0.6, 0, 0.8]],
            [[0.6, 0, 0.8], [-0.6, 0, -0.8]],
        ]
    ).transpose(1, 0, 2)
    out = np.concatenate([v, edges], axis=1)
    return out[0], out[1]


def bench_precision(case: str, model: Model, params: Any, n: int = 20000) -> list[Row]:
    """Relative difference of float32 evaluation against float64, and both times."""
    wi, wo = direction_pairs(n)
    f64, t64 = timed(lambda: evaluate(model, params, wi, wo, dtype=np.float64))
    f32, t32 = timed(lambda: evaluate(model, params, wi, wo, dtype=np.float32))
    finite = np.isfinite(f64)
    scale = np.maximum(np.abs(f64), 1e-6 * max(float(np.abs(f64[finite]).max(initial=0)), 1e-30))
    rel = np.where(finite, np.abs(f32.astype(np.float64) - f64) / scale, 0.0)
    # float32 overflowing or NaN where float64 is finite is an infinite error, not a skip
    rel = np.where(finite & ~np.isfinite(f32), np.inf, rel)
    bad32 = int((~np.isfinite(f32)).sum())
    per_pair = rel.max(axis=-1)
    worst = int(np.argmax(per_pair))
    note = (
        f"{int(np.sum(per_pair > 1e-4))}/{len(wi)} pairs >1e-4; worst at cos θi, θo = "
        f"{wi[worst, 2]:.2g}, {wo[worst, 2]:.2g}" + (f"; {bad32} non-finite" if bad32 else "")
    )
    return [
        Row("precision", case, "float64", note, 0.0, t64, n + 5, "float64", t64),
        Row(
            "precision",
            case,
            "float32",
            note,
            float(np.max(rel, initial=0.0)),
            t32,
            n + 5,
            "float64",
            t64,
        ),
    ]


# -- proof renders ---------------------------------------------------------------------
def relative_mse(image: np.ndarray, reference: np.ndarray, eps: float = 1e-2) -> float:
    """mean((x − ref)² / (ref² + ε)): relMSE as in Rousselle et al. 2011, §6.

    >>> round(relative_mse(np.full(4, 1.1), np.ones(4), eps=0.0), 6)
    0.01
    """
    return float(np.mean((image - reference) ** 2 / (reference**2 + eps)))


def bench_render(
    case: str,
    bsdf: dict,
    environment: np.ndarray,
    *,
    max_depth: int = 8,
    ladder: Sequence[int] = (1, 4, 16, 64),
    reference_spp: int = 1024,
    resolution: int = 32,
) -> list[Row]:
    """relMSE against a ``reference_spp`` render, and render time, for each rung.

    The scene is the proofs' own (:class:`lookdev.pipeline.proof.turntable.Turntable`:
    shader ball and cup under ``environment``) at ``2·resolution × resolution``, and the
    error is taken over the whole frame, as the proofs' noise estimate is. The
    reference's own noise adds about ``spp / reference_spp`` of a rung's relMSE (6 % at
    64 against 1024 spp); the time is the best of two renders after a warm-up render
    that compiles the kernels.
    """
    from lookdev.pipeline.proof.turntable import Turntable

    size = (2 * resolution, resolution)
    table = Turntable(bsdf, np.asarray(environment, dtype=np.float32), size, max_depth)

    def render(spp: int, seed: int) -> np.ndarray:
        return table.render(spp, seed).astype(np.float64)

    render(1, seed=0)  # compiles the kernels, so the reference's time is rendering only
    reference, t_ref = once(lambda: render(reference_spp, seed=10_000))
    rows = []
    for k, spp in enumerate(ladder):
        image, t = timed(lambda spp=spp, k=k: render(spp, seed=k + 1), repeat=2)
        rows.append(
            Row(
                "render",
                case,
                "path tracer",
                f"{spp} spp",
                relative_mse(image, reference),
                t,
                size[0] * size[1] * spp,
                f"{reference_spp} spp render",
                t_ref,
            )
        )
    return rows
