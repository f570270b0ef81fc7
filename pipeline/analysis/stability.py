"""Stability sweep of every reflectance model (``lookdev check``).

Each model of the registry (:data:`lookdev.materials.registry.MODELS`) is driven through
the cases of :mod:`.stability_cases` in float32 and float64.

It counts cases where the model raised (a finding, not a stop), queries whose output
(f, pdf, sampled direction, weight) holds a NaN, an infinity or a negative value, and
directional albedos (the model's own importance sampler, 2048 stratified samples per view
at θo = 0, 45, 60, 75, 89, 89.99° and at azimuths φo = 0, 45, 90° from the tangent — the
tangent, the diagonal and the bitangent, where an anisotropic lobe differs —, every colour
white: a furnace) that exceed 1 + the model's allowance by more than four standard errors.
The largest albedo met is reported per azimuth too.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookdev.materials.bsdf import Model, density, draw, evaluate

from .albedo import albedo_monte_carlo
from .stability_cases import (
    allowance,
    directions,
    furnace_cases,
    models_named,
    parameter_cases,
    per_element_maps,
    plausible,
    short,
    uniforms,
    white,
)

__all__ = [
    "DTYPES",
    "FURNACE_PHI_DEG",
    "FURNACE_SAMPLES",
    "FURNACE_THETA_DEG",
    "Finding",
    "KINDS",
    "MAPS_LABEL",
    "MEDIUM_UNITS",
    "ModelReport",
    "ROUNDING",
    "SIGMAS",
    "case_count",
    "check_model",
    "run",
]

DTYPES = (np.float32, np.float64)
MAPS_LABEL = "per-element maps of every field"
FURNACE_THETA_DEG = (0.0, 45.0, 60.0, 75.0, 89.0, 89.99)
FURNACE_PHI_DEG = (0.0, 45.0, 90.0)  # tangent, diagonal, bitangent
FURNACE_SAMPLES = 2048
SIGMAS = 4.0
ROUNDING = {"float32": 1e-5, "float64": 1e-12}  # a white Lambertian sums to 1 ± this
# -- findings ------------------------------------------------------------------------------
KINDS = ("exception", "nan", "inf", "negative", "energy_gain")


@dataclass
class Finding:
    """One noteworthy case: a failure of some kind, or the largest albedo met."""

    kind: str  # one of KINDS, or "max_albedo"
    case: str
    value: float | None = None

    def to_json(self) -> dict[str, Any]:
        return {"kind": self.kind, "value": self.value, "case": self.case}


@dataclass
class ModelReport:
    """What the sweep found for one model; counts are over both precisions."""

    name: str
    allowance: float
    cases: int = 0
    counts: dict[str, int] = field(default_factory=lambda: dict.fromkeys(KINDS, 0))
    by_dtype: dict[str, dict[str, int]] = field(default_factory=dict)
    cases_by_dtype: dict[str, int] = field(default_factory=dict)
    failures: dict[str, Finding] = field(default_factory=dict)  # first or largest per kind
    max_albedo: Finding | None = None
    max_albedo_by_azimuth: dict[float, Finding] = field(default_factory=dict)  # φo in degrees

    @property
    def failed(self) -> bool:
        return any(self.counts.values())

    @property
    def worst(self) -> Finding | None:
        """The most severe failure (a crash, NaN, ∞, negative, energy), else the top albedo."""
        for kind in KINDS:
            if kind in self.failures:
                return self.failures[kind]
        return self.max_albedo

    def to_json(self) -> dict[str, Any]:
        worst = self.worst
        return {
            "cases": self.cases,
            **self.counts,
            "worst": worst.to_json() if worst else None,
            "allowance": self.allowance,
            "max_albedo_by_azimuth": {
                f"{phi:g}": f.to_json() for phi, f in sorted(self.max_albedo_by_azimuth.items())
            },
            "by_dtype": {
                k: {"cases": self.cases_by_dtype[k], **v} for k, v in self.by_dtype.items()
            },
        }

    def _count(self, dtype: str, kind: str, n: int, finding: Finding) -> None:
        if n <= 0:
            return
        self.counts[kind] += n
        self.by_dtype[dtype][kind] += n
        if kind not in self.failures:
            self.failures[kind] = finding


def _flags(*arrays: np.ndarray, lead: int) -> tuple[np.ndarray, np.ndarray]:
    """Per query (the first ``lead`` axes): any NaN, any ±∞."""

    def per_query(a: np.ndarray, test: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        t = test(a)
        return t.reshape(*t.shape[:lead], -1).any(axis=-1)

    nan = np.logical_or.reduce([per_query(a, np.isnan) for a in arrays])
    inf = np.logical_or.reduce([per_query(a, np.isinf) for a in arrays])
    return nan, inf


def _vec(v: np.ndarray) -> str:
    return "(" + ", ".join(f"{x:.3g}" for x in v) + ")"


def _element(maps: dict[str, np.ndarray], index: tuple[int, ...]) -> str:
    return ", ".join(f"{k}={short(float(v[index]))}" for k, v in maps.items() if v.ndim == 2)


def _sweep_queries(
    report: ModelReport,
    model: Model,
    label: str,
    params: Any,
    dtype: Any,
    with_maps: bool = False,
) -> None:
    """eval and pdf on every direction pair, sample at every (wo, u)."""
    name = np.dtype(dtype).name
    d, u = directions(), uniforms()
    pair_maps = per_element_maps(model.params_type, (len(d), len(d))) if with_maps else {}
    sample_maps = per_element_maps(model.params_type, (len(d), len(u))) if with_maps else {}
    wi, wo = d[:, None, :], d[None, :, :]
    f = evaluate(model, params, wi, wo, dtype=dtype, **pair_maps)
    pdf = density(model, params, wi, wo, dtype=dtype, **pair_maps)
    s_wi, s_w, s_pdf = draw(model, params, d[:, None, :], u[None, :, :], dtype=dtype, **sample_maps)

    def pair(i: int, j: int) -> str:
        return f"wi={_vec(d[i])}, wo={_vec(d[j])}" + (
            f" [{_element(pair_maps, (i, j))}]" if pair_maps else ""
        )

    def draw_at(i: int, j: int) -> str:
        return f"wo={_vec(d[i])}, u={_vec(u[j])}" + (
            f" [{_element(sample_maps, (i, j))}]" if sample_maps else ""
        )

    queries = [
        ("eval", (f,), pair, (f < 0)),
        ("pdf", (pdf[..., None],), pair, (pdf < 0)),
        ("sample", (s_wi, s_w, s_pdf[..., None]), draw_at, (s_w < 0).any(axis=-1) | (s_pdf < 0)),
    ]
    for what, arrays, where, negative in queries:
        nan, inf = _flags(*arrays, lead=2)
        inf &= ~nan
        negative = (negative.any(axis=-1) if negative.ndim == 3 else negative) & ~nan & ~inf
        report.cases += nan.size
        report.cases_by_dtype[name] += nan.size
        for kind, mask in (("nan", nan), ("inf", inf), ("negative", negative)):
            if mask.any():
                i, j = np.argwhere(mask)[0]
                case = f"{label}; {name}; {what} {where(i, j)}"
                report._count(name, kind, int(mask.sum()), Finding(kind, case))


def _sweep_energy(
    report: ModelReport, model: Model, label: str, params: Any, dtype: Any, whiten: bool = True
) -> None:
    """The furnace at every view: each θo at each azimuth of FURNACE_PHI_DEG."""
    furnace = white(params) if whiten else params
    for phi in FURNACE_PHI_DEG:
        _sweep_energy_at(report, model, label, furnace, dtype, phi)


def _sweep_energy_at(
    report: ModelReport, model: Model, label: str, params: Any, dtype: Any, phi: float
) -> None:
    """The furnace views at every θo of one azimuth φo (degrees from the tangent)."""
    name = np.dtype(dtype).name
    theta = np.radians(FURNACE_THETA_DEG)
    curve = albedo_monte_carlo(
        model,
        params,
        theta,
        n_samples=FURNACE_SAMPLES,
        hemisphere="both",
        dtype=dtype,
        phi=float(np.radians(phi)),
    )
    mean, err = curve.albedo, curve.stderr
    report.cases += len(theta)
    report.cases_by_dtype[name] += len(theta)
    excess = mean - SIGMAS * err - (1.0 + report.allowance + ROUNDING[name])
    k, c = np.unravel_index(np.argmax(mean), mean.shape)
    top = float(mean[k, c])
    view = f"θo = {FURNACE_THETA_DEG[k]:g}°, φo = {phi:g}°"
    case = f"{label} (white); {name}; {view} ± {err[k, c]:.2g}"
    if report.max_albedo is None or top > (report.max_albedo.value or 0.0):
        report.max_albedo = Finding("max_albedo", case, top)
    best = report.max_albedo_by_azimuth.get(phi)
    if best is None or top > (best.value or 0.0):
        report.max_albedo_by_azimuth[phi] = Finding("max_albedo", case, top)
    gained = (excess > 0).any(axis=-1)
    if gained.any():
        k = int(np.argmax(excess.max(axis=-1)))
        value = float(mean[k].max())
        view = f"θo = {FURNACE_THETA_DEG[k]:g}°, φo = {phi:g}°"
        case = f"{label} (white); {name}; {view}, albedo {value:.4g}"
        report._count(name, "energy_gain", int(gained.sum()), Finding("energy_gain", case, value))


MEDIUM_UNITS = (1.0, 0.05)
"""Metres per scene unit the interior is checked at: a preset's own and the proof's."""


def _sweep_medium(report: ModelReport, label: str, params: Any, dtype: Any) -> None:
    """A solid's interior medium as the renderer receives it, in ``dtype``: σt finite and
    positive, albedo in [0, 1] (above 1 is an energy gain); nothing for other cases."""
    from lookdev.materials.subsurface import has_interior, interior
    from lookdev.pipeline.export.mitsuba.medium import interior_dict

    if not hasattr(params, "scatter_distance") or not has_interior(params):
        return
    name = np.dtype(dtype).name
    for unit in MEDIUM_UNITS:
        sigma_t, albedo = interior(params, unit)
        medium = interior_dict(params, unit)
        normalised = np.asarray(medium["sigma_t"]["value"]) * medium["scale"]
        for what, value in (("σt", sigma_t), ("albedo", albedo), ("Mitsuba σt", normalised)):
            with np.errstate(over="ignore"):  # an overflow to ∞ is the finding
                v = np.asarray(value, dtype=np.float64).astype(dtype)
            report.cases += 1
            report.cases_by_dtype[name] += 1
            kind = (
                "nan" if np.isnan(v).any() else "inf" if np.isinf(v).any()
                else "negative" if (v < 0).any() or (what != "albedo" and (v <= 0).any())
                else "energy_gain" if what == "albedo" and (v > 1).any() else None
            )  # fmt: skip
            if kind:
                case = f"{label}; {name}; interior {what} {v} at {unit:g} m per unit"
                report._count(name, kind, 1, Finding(kind, case))


def check_model(
    name: str,
    model: Model,
    progress: Callable[[str], None] = lambda label: None,
    measured: Sequence[Any] = (),
) -> ModelReport:
    """The full sweep of one model (``measured``: the tables a measured model sweeps)."""
    report = ModelReport(name, allowance(name))
    for dtype in DTYPES:
        report.by_dtype[np.dtype(dtype).name] = dict.fromkeys(KINDS, 0)
        report.cases_by_dtype[np.dtype(dtype).name] = 0
    cases = [
        (label, params, False) for label, params in parameter_cases(model.params_type, measured)
    ]
    # the maps run starts from the first case: the defaults (a measured model has none)
    for label, params, with_maps in [*cases, (MAPS_LABEL, cases[0][1], True)]:
        progress(label)
        for dtype in DTYPES:
            try:
                with np.errstate(all="ignore"):
                    _sweep_queries(report, model, label, params, dtype, with_maps)
                    if not with_maps:
                        _sweep_medium(report, label, params, dtype)
                    if plausible(params) and not with_maps:
                        _sweep_energy(report, model, label, params, dtype)
            except Exception as exc:  # noqa: BLE001 — a crashing model is a finding, not a stop
                name_ = np.dtype(dtype).name
                case = f"{label}; {name_}: {type(exc).__name__}: {exc}"
                report._count(name_, "exception", 1, Finding("exception", case))
    for label, params in furnace_cases(name):
        for dtype in DTYPES:
            with np.errstate(all="ignore"):
                _sweep_energy(report, model, label, params, dtype, whiten=False)
    return report


def run(
    names: list[str] | None = None,
    progress: Callable[[str, str], None] = lambda m, c: None,
    measured: Sequence[Any] = (),
) -> dict[str, ModelReport]:
    """Reports for every model of the registry (or those named); ``measured``: the
    tables (:class:`~lookdev.materials.measured.MeasuredTable`) the measured model sweeps."""
    reports = {}
    for name, model in models_named(names).items():
        reports[name] = check_model(name, model, lambda label, n=name: progress(n, label), measured)
    return reports


def case_count(names: list[str] | None = None, measured: Sequence[Any] = ()) -> int:
    """How many parameter sets :func:`run` will sweep (for a progress bar)."""
    models = models_named(names).values()
    return sum(len(parameter_cases(m.params_type, measured)) + 1 for m in models)
