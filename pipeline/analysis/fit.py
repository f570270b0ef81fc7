"""Fit an analytic model's parameters to a measured BRDF.

The error metric is the one the BRDF-explorer views plot (:mod:`.plots`, ``--view slice``):
per measured direction pair and channel, the difference of log(1 + f·cos θi) between model
and measurement, the cosine-weighted log error of Löw et al. :cite:`Low2012`. The log keeps a
highlight 10⁴ times brighter than the diffuse from outweighing it; the cosine takes the
grazing light, which contributes little to any image, down with it.

Optimiser: a bounded trust-region least-squares (SciPy's ``least_squares``, method ``trf``)
over the model's own numpy implementation, with a finite-difference Jacobian. A fit has at
most a dozen bounded parameters, for which Gauss–Newton steps converge in tens of
iterations where a first-order method on Dr.Jit gradients needs hundreds, and the numpy
backend has no kernel to compile and no thread-order sums, so a seed gives the same fit.
Several starting points (the given one, then random ones from the seed) guard against a
local minimum; the best is kept.

The directions are the measurement's own samples, where it has them: an MBSDF row that
repeats the previous one was extrapolated, not measured (the shipped car paint repeats
θi past 66° and θo past 82°), and MERL marks unmeasured directions negative.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookdev.materials.bsdf import Model, evaluate
from lookdev.materials.errors import LookdevError
from lookdev.materials.measured import MeasuredTable, grid_directions
from lookdev.materials.registry import is_color_field, model_named

__all__ = [
    "ANGLE_BANDS",
    "FIT_FIELDS",
    "Fit",
    "FitError",
    "band_errors",
    "fit",
    "log_error",
    "measured_samples",
]

FIT_FIELDS: dict[str, dict[str, tuple[float, float]]] = {
    "disney": {
        "base_color": (0.0, 1.0),
        "subsurface": (0.0, 1.0),
        "metallic": (0.0, 1.0),
        "specular": (0.0, 2.0),
        "specular_tint": (0.0, 1.0),
        "roughness": (0.0, 1.0),
        "sheen": (0.0, 1.0),
        "sheen_tint": (0.0, 1.0),
        "clearcoat": (0.0, 1.0),
        "clearcoat_gloss": (0.0, 1.0),
    },
    "pixar": {
        "surface_color": (0.0, 1.0),
        "metallic": (0.0, 1.0),
        "roughness": (0.0, 1.0),
        "normal_fresnel": (0.0, 1.0),
        "grazing_fresnel": (0.0, 1.0),
        "specular_tint": (0.0, 1.0),
        "diffuse_scale": (0.0, 2.0),
        "specular_scale": (0.0, 2.0),
    },
}
"""The fields a fit moves, per model, with the range it searches: Burley's plausible 0..1
(specular and the Pixar scales to 2). The rest keep their value: an isotropic measurement
cannot tell ``anisotropic``, and transmission is not measured in reflection."""

ANGLE_BANDS: tuple[tuple[str, float, float], ...] = (
    ("normal", 0.0, 30.0),
    ("45°", 30.0, 60.0),
    ("grazing", 60.0, 90.0),
)
"""Viewer polar-angle bands (degrees) of the per-band error report."""


class FitError(LookdevError):
    """A fit that cannot be run as asked (unknown field, a value out of range …)."""


@dataclass
class Fit:
    """The result: parameters, the metric over all measured samples, and per band."""

    model: str
    params: Any
    error: float
    """RMS of :func:`log_error` over every measured sample (all channels)."""
    bands: dict[str, float]
    starts: list[float] = field(default_factory=list)
    """The RMS each starting point ended at (the best is ``error``)."""
    evaluations: int = 0


def measured_samples(table: MeasuredTable) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(wi, wo, f) at the measured samples of ``table``, each (M, 3): tangent directions
    (cos θ < 10⁻³), extrapolated MBSDF rows and unmeasured MERL values left out."""
    wi, wo = grid_directions(table.grid, table.shape)
    values = np.asarray(table.values, dtype=np.float64)
    keep = np.all(values >= 0, axis=-1) if table.grid == "merl" else np.ones(table.shape, bool)
    if table.grid == "mbsdf":
        v = table.values
        repeat_i = np.r_[False, [np.array_equal(v[k], v[k - 1]) for k in range(1, v.shape[0])]]
        repeat_o = np.r_[
            False, [np.array_equal(v[:, k], v[:, k - 1]) for k in range(1, v.shape[1])]
        ]
        keep &= ~repeat_i[:, None, None] & ~repeat_o[None, :, None]
    keep &= (wi[..., 2] > 1e-3) & (wo[..., 2] > 1e-3)
    return wi[keep], wo[keep], np.maximum(values[keep], 0.0)


def log_error(f_model: np.ndarray, f_measured: np.ndarray, cos_i: np.ndarray) -> np.ndarray:
    """log(1 + f_model cos θi) − log(1 + f_measured cos θi), per sample and channel."""
    c = cos_i[..., None]
    return np.log1p(np.maximum(f_model, 0) * c) - np.log1p(f_measured * c)


def band_errors(wo: np.ndarray, residual: np.ndarray) -> dict[str, float]:
    """RMS of ``residual`` per viewer angle band of :data:`ANGLE_BANDS`."""
    theta = np.degrees(np.arccos(np.clip(wo[:, 2], -1, 1)))
    out = {}
    for name, lo, hi in ANGLE_BANDS:
        sel = (theta >= lo) & (theta < hi if hi < 90 else theta <= hi)
        out[name] = float(np.sqrt(np.mean(residual[sel] ** 2))) if sel.any() else math.nan
    return out


class _Packing:
    """The fitted fields as one vector of numbers within bounds, and back."""

    def __init__(self, model: Model, start: Any, fixed: dict[str, Any]):
        fields = FIT_FIELDS.get(model.name)
        if fields is None:
            raise FitError(f"no fit for model {model.name!r}; known: {', '.join(FIT_FIELDS)}")
        unknown = [k for k in fixed if k not in model.params_type.model_fields]
        if unknown:
            raise FitError(f"{model.name} has no parameter {unknown[0]!r}", field="--fix")
        self.model, self.start = model, start
        self.names = [n for n in fields if n not in fixed]
        self.widths = [3 if is_color_field(model.params_type, n) else 1 for n in self.names]
        lo, hi = [], []
        for n, w in zip(self.names, self.widths, strict=True):
            lo += [fields[n][0]] * w
            hi += [fields[n][1]] * w
        self.lower, self.upper = np.array(lo), np.array(hi)
        self.fixed = fixed

    def vector(self, params: Any) -> np.ndarray:
        out: list[float] = []
        for n in self.names:
            v = getattr(params, n)
            out += list(v) if isinstance(v, tuple) else [float(v)]
        return np.clip(np.array(out, dtype=np.float64), self.lower, self.upper)

    def values(self, x: np.ndarray) -> dict[str, Any]:
        out: dict[str, Any] = {}
        i = 0
        for n, w in zip(self.names, self.widths, strict=True):
            out[n] = tuple(float(v) for v in x[i : i + w]) if w == 3 else float(x[i])
            i += w
        return out

    def params(self, x: np.ndarray) -> Any:
        """Unvalidated (the bounds keep every value legal): the optimiser's inner loop."""
        return self.start.model_copy(update=self.values(x))


def fit(
    table: MeasuredTable,
    model_name: str = "disney",
    *,
    start: Any = None,
    fixed: dict[str, Any] | None = None,
    starts: int = 4,
    seed: int = 0,
    samples: int = 6000,
) -> Fit:
    """Fit ``model_name`` to ``table`` (see the module docstring for the metric).

    ``start``: the parameters of the first starting point (the model's defaults if None);
    ``fixed``: fields held at a value; ``samples``: measured samples the optimiser sees (a
    seeded subset; the reported errors use every measured sample).
    """
    from scipy.optimize import least_squares

    model = model_named(model_name)
    fixed = dict(fixed or {})
    base = model.params_type() if start is None else start
    try:
        base = base.replace(**fixed) if fixed else base
    except LookdevError as exc:
        raise FitError(exc.message, field="--fix") from None
    packing = _Packing(model, base, fixed)
    wi, wo, f = measured_samples(table)
    if len(f) == 0:
        raise FitError("the measurement has no measured samples", where=table.source)
    rng = np.random.default_rng(seed)
    pick = rng.choice(len(f), size=min(samples, len(f)), replace=False)
    s_wi, s_wo, s_f = wi[pick], wo[pick], f[pick]
    count = 0

    def residual(x: np.ndarray) -> np.ndarray:
        nonlocal count
        count += 1
        fm = evaluate(model, packing.params(x), s_wi, s_wo)
        return log_error(fm, s_f, s_wi[:, 2]).ravel()

    x0s = [packing.vector(base)]
    x0s += [rng.uniform(packing.lower, packing.upper) for _ in range(max(starts, 1) - 1)]
    best, ends = None, []
    for x0 in x0s:
        with np.errstate(all="ignore"):
            result = least_squares(
                residual,
                x0,
                bounds=(packing.lower, packing.upper),
                method="trf",
                diff_step=1e-4,
                x_scale="jac",
                max_nfev=60 * len(x0),
            )
        rms = float(np.sqrt(np.mean(result.fun**2)))
        ends.append(rms)
        if best is None or rms < best[0]:
            best = (rms, result.x)
    params = base.replace(**packing.values(best[1]))  # validated, as a preset would be
    full = log_error(evaluate(model, params, wi, wo), f, wi[:, 2])
    return Fit(
        model=model.name,
        params=params,
        error=float(np.sqrt(np.mean(full**2))),
        bands=band_errors(wo, full),
        starts=ends,
        evaluations=count,
    )
