"""What a fit costs: ``lookdev fit`` of a model to a measurement, in CPU and wall time.

The baseline of the same run is one evaluation of the model over the fit's sample subset,
so the figure that travels between machines is the ratio (the fit's evaluations, the
optimiser's own work on top). A second fit from the same seed must give the same
parameters: reproducibility is part of the figure.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

from lookdev.materials.bsdf import evaluate
from lookdev.materials.measured import MeasuredTable
from lookdev.materials.registry import model_named
from lookdev.pipeline.analysis.fit import fit, measured_samples

__all__ = ["fit_cost"]


def _timed(call: Any) -> tuple[Any, float, float]:
    cpu, wall = time.process_time(), time.perf_counter()
    out = call()
    return out, time.process_time() - cpu, time.perf_counter() - wall


def fit_cost(
    table: MeasuredTable, model_name: str = "disney", *, starts: int = 4, seed: int = 0
) -> dict[str, Any]:
    """CPU and wall seconds of a fit (twice, same seed), against one model evaluation."""
    model = model_named(model_name)
    wi, wo, _ = measured_samples(table)
    pick = np.random.default_rng(seed).choice(len(wi), size=min(6000, len(wi)), replace=False)
    params = model.params_type()
    _, eval_cpu, _ = _timed(lambda: evaluate(model, params, wi[pick], wo[pick]))
    first, cpu, wall = _timed(lambda: fit(table, model_name, starts=starts, seed=seed))
    second, cpu2, wall2 = _timed(lambda: fit(table, model_name, starts=starts, seed=seed))
    return {
        "measurement": table.source,
        "model": model_name,
        "starts": starts,
        "seed": seed,
        "error": first.error,
        "bands": first.bands,
        "evaluations": first.evaluations,
        "cpu_s": [cpu, cpu2],
        "wall_s": [wall, wall2],
        "one_evaluation_cpu_s": eval_cpu,
        "fit_over_one_evaluation": cpu / max(eval_cpu, 1e-9),
        "reproducible": first.params == second.params and first.error == second.error,
    }
