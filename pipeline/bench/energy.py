"""``lookdev bench error --item energy``: the white furnace of a rough white metal with
``energy_compensation`` off and on (:mod:`lookdev.materials.energy`), by roughness.

Each row is one roughness and one setting of the switch: its error is the worst |1 − E(θ)|
over views from normal incidence to 89.9° (E by the model's own importance sampler, the
estimator ``lookdev check`` uses), its time that of evaluating the BSDF at ``pairs``
direction pairs (what the table look-up adds to a render's shading), and its reference
the switch off in the same run, so "× faster" is the ratio of the two.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lookdev.materials.bsdf import evaluate
from lookdev.materials.disney import MODEL
from lookdev.materials.params import DisneyParams
from lookdev.pipeline.analysis.albedo import albedo_monte_carlo

from .measure import Row, direction_pairs, timed

__all__ = ["FURNACE_THETA_DEG", "ROUGHNESS", "bench_energy", "furnace"]

ROUGHNESS = (0.0, 0.1, 0.3, 0.5, 0.7, 1.0)
FURNACE_THETA_DEG = (0.0, 30.0, 60.0, 75.0, 85.0, 89.0, 89.9)


def furnace(
    roughness: float, on: bool, *, samples: int = 16384, dtype: Any = np.float64
) -> np.ndarray:
    """Directional albedo of a white metal at :data:`FURNACE_THETA_DEG`, one channel."""
    params = DisneyParams(
        metallic=1.0, base_color=(1.0, 1.0, 1.0), roughness=roughness, energy_compensation=on
    )
    theta = np.radians(FURNACE_THETA_DEG)
    return albedo_monte_carlo(MODEL, params, theta, n_samples=samples, dtype=dtype).albedo[:, 0]


def bench_energy(*, samples: int = 16384, pairs: int = 20000) -> list[Row]:
    """Rows of furnace error and eval time, off then on, for each of :data:`ROUGHNESS`."""
    wi, wo = direction_pairs(pairs)
    rows = []
    for r in ROUGHNESS:
        times = {}
        for on in (False, True):
            params = DisneyParams(
                metallic=1.0, base_color=(1.0, 1.0, 1.0), roughness=r, energy_compensation=on
            )
            _, times[on] = timed(lambda p=params: evaluate(MODEL, p, wi, wo))
        for on in (False, True):
            e = furnace(r, on, samples=samples)
            rows.append(
                Row(
                    "energy",
                    f"white metal roughness {r:g}",
                    "compensated" if on else "single scattering",
                    "θ 0–89.9°",
                    float(np.max(np.abs(1.0 - e))),
                    times[on],
                    pairs,
                    "switch off (eval time)",
                    times[False],
                )
            )
    return rows
