"""Stability sweep of every reflectance model (``lookdev check``).

Each model found in :data:`MODEL_MODULES` (a missing one is skipped, not an error) is
driven through the stiff and extreme cases of DESIGN.md, "Numerics that need care", in
float32 and float64:

* **parameters** — every field at each end of its range, one at a time from the defaults
  (roughness 0 and 1, black and white colours, each switch and each sheen model …), plus
  the named combinations below where the field names exist (delta metal, tint of a black
  base, glass at η = 1, Conty-Kulla at r → 0, Smits at roughness 0 …);
* **directions** — normal, cos θ = 0.5 (the Conty-Kulla branches meet), 1e-4, 1e-7 and
  exactly 0 (grazing and tangent), below the surface, random ones; the set is closed
  under negation and mirroring, so every pair includes wi = −wo (zero half vector),
  wi = wo and the mirror direction (the peak of a delta-like lobe);
* **uniforms** — the corners 0, ½ and 1 − 2⁻²⁴ of every sampling dimension, and random;
* **maps** — once more with every float and colour field given per element (mixing its
  extremes), the array code path that textures take.

It counts cases where the model raised (a finding, not a stop), queries whose output
(f, pdf, sampled direction, weight) holds a NaN, an infinity or a negative value, and
directional albedos (the model's own importance sampler, 2048 stratified samples per view
at θo = 0, 45, 60, 75, 89, 89.99°, every colour white: a furnace) that exceed 1 + the
model's allowance by more than four standard errors.

Allowances: the Conty-Kulla lobe and Smits' model conserve energy by construction (sheen
0.002: its albedo table's measured interpolation error; pixar 0). The Disney BRDF adds
energy by design; its allowance is the Disney module's ``ENERGY_ALLOWANCE`` when it has
one, else 0.77: tests/test_disney.py measures each lobe's gain up to θo = 89° (rough
white plastic 1.567, sheen +0.09, clearcoat +0.05), and with all of them at once and
``specular`` 1 the albedo keeps rising towards grazing: 1.721 at 89°, 1.758 at 89.9°,
1.762 ± 0.001 at 89.99° and 89.9999° (4·10⁵ samples each). Parameters
pushed past their plausible range (sheen 10, specular 12.5, clearcoat 4) are checked for
NaN, infinity and sign only: Burley allows them precisely to add energy.
"""

from __future__ import annotations

import importlib
import itertools
import typing
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookdev.materials.bsdf import Model, density, draw, evaluate
from lookdev.materials.errors import LookdevError

from .albedo import albedo_monte_carlo

MODEL_MODULES = {
    "disney": "lookdev.materials.disney",
    "sheen": "lookdev.materials.sheen",
    "pixar": "lookdev.materials.pixar",
    "pixar_layered": "lookdev.materials.pixar",
}
MODEL_ATTRS = {"pixar_layered": "LAYERED_MODEL"}
"""The attribute holding the Model, where it is not ``MODEL``."""
ALLOWANCE = {"disney": 0.77, "sheen": 0.002, "pixar": 0.0, "pixar_layered": 0.0}
DTYPES = (np.float32, np.float64)
FURNACE_THETA_DEG = (0.0, 45.0, 60.0, 75.0, 89.0, 89.99)
FURNACE_SAMPLES = 2048
SIGMAS = 4.0
ROUNDING = {"float32": 1e-5, "float64": 1e-12}  # a white Lambertian sums to 1 ± this
MAPS_LABEL = "per-element maps of every field"
UNBOUNDED_HIGH = 10.0  # the "pushed" value of a field with no upper bound

# Named stiff combinations (DESIGN.md), applied where every named field exists.
COMBINATIONS: tuple[dict[str, Any], ...] = (
    {"roughness": 0.0, "metallic": 1.0},  # delta metal (α clamp)
    {"roughness": 0.0, "anisotropic": 1.0},
    {"roughness": 1.0, "anisotropic": 1.0},  # GTR 0/0 at α → 1
    {"base_color": (0.0, 0.0, 0.0), "specular_tint": 1.0, "sheen": 1.0, "sheen_tint": 1.0},
    {"roughness": 1.0, "sheen": 1.0, "clearcoat": 1.0, "clearcoat_gloss": 0.0},
    {"clearcoat": 1.0, "clearcoat_gloss": 1.0},  # α = 0.001 clearcoat
    {"spec_trans": 1.0, "roughness": 0.0},  # smooth glass
    {"spec_trans": 1.0, "ior": 1.0, "roughness": 0.3},  # η = 1: refraction degenerates
    {"spec_trans": 1.0, "thin": True, "roughness": 0.0},
    {"diff_trans": 1.0, "thin": True, "flatness": 1.0},
    {"sheen_model": "conty_kulla", "sheen": 1.0, "sheen_roughness": 0.0},
    {"sheen_model": "conty_kulla", "sheen": 1.0, "sheen_roughness": 1.0},
    {"roughness": 0.0, "terminator_softening": False},
    {"roughness": 0.0, "clear": 1.0, "back": 1.0},  # powerR at its cone floor, refraction
    {"roughness": 0.0, "specular_cone_scale": 0.0, "reflection_cone_scale": 0.0},
    {"roughness": 0.5, "normal_fresnel": 20.0, "grazing_fresnel": 0.0, "clear": 1.0},
)


class CheckError(LookdevError):
    """``lookdev check`` was asked for a model it does not know."""


# -- what is swept -------------------------------------------------------------------------
def available_models(names: list[str] | None = None) -> tuple[dict[str, Model], dict]:
    """({name: Model} of the models that import, {name: why not} for the others)."""
    wanted = list(MODEL_MODULES) if not names else names
    unknown = [n for n in wanted if n not in MODEL_MODULES]
    if unknown:
        raise CheckError(
            f"unknown model {unknown[0]!r}; known: {', '.join(MODEL_MODULES)}", field="--model"
        )
    models, missing = {}, {}
    for name in wanted:
        try:
            module = importlib.import_module(MODEL_MODULES[name])
            models[name] = getattr(module, MODEL_ATTRS.get(name, "MODEL"))
        except (ImportError, AttributeError) as exc:
            missing[name] = f"not available ({exc})"
    return models, missing


def allowance(name: str) -> float:
    """Energy a model may add by design (see the module docstring); 0 if unknown."""
    default = ALLOWANCE.get(name, 0.0)
    if name not in MODEL_MODULES:
        return default
    module = importlib.import_module(MODEL_MODULES[name])
    return float(getattr(module, "ENERGY_ALLOWANCE", default))


def _extremes(info: Any) -> list[Any]:
    """The values at the ends of one schema field's range."""
    annotation = info.annotation
    args = typing.get_args(annotation)
    if annotation is bool:
        return [False, True]
    if typing.get_origin(annotation) is typing.Literal:
        return list(args)
    if tuple in (typing.get_origin(annotation), *map(typing.get_origin, args)):
        return [(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)]
    lo = hi = None
    for m in info.metadata:
        lo = getattr(m, "ge", lo) if getattr(m, "ge", None) is not None else lo
        hi = getattr(m, "le", hi) if getattr(m, "le", None) is not None else hi
    if lo is None:
        return []
    return [float(lo), float(hi) if hi is not None else float(lo) + UNBOUNDED_HIGH]


def _plausible(params: Any) -> bool:
    """Every float field inside 0..1 where its range starts at 0 (Burley's plausible)."""
    for name, info in type(params).model_fields.items():
        value = getattr(params, name)
        ext = _extremes(info)
        if isinstance(value, float) and ext and ext[0] == 0.0 and value > 1.0:
            return False
    return True


def parameter_cases(params_type: type) -> list[tuple[str, Any]]:
    """(label, params): defaults, each field at each extreme, and the named combinations."""
    cases = [("defaults", params_type())]
    fields = params_type.model_fields
    for name, info in fields.items():
        for value in _extremes(info):
            cases.append((f"{name}={_short(value)}", {name: value}))
    for combo in COMBINATIONS:
        if set(combo) <= set(fields):
            cases.append((", ".join(f"{k}={_short(v)}" for k, v in combo.items()), combo))
    out = []
    for label, data in cases:
        if isinstance(data, dict):
            try:
                data = params_type.parse(data)
            except LookdevError:
                continue  # a combination the schema forbids (e.g. specular with ior)
        out.append((label, data))
    return out


def _short(value: Any) -> str:
    if isinstance(value, tuple):
        return "white" if all(v == 1 for v in value) else "black"
    return f"{value:g}" if isinstance(value, float) else str(value)


def directions() -> np.ndarray:
    """Unit directions (M, 3), closed under negation and under mirroring about n."""
    base = [(c, phi) for c in (1.0, 0.5, 1e-4, 1e-7, 0.0) for phi in (0.0, 1.1)]
    rng = np.random.default_rng(11)
    base += list(
        zip(rng.uniform(0.05, 0.95, 4).tolist(), rng.uniform(0, 6, 4).tolist(), strict=True)
    )
    c, phi = np.array(base).T
    s = np.sqrt(1.0 - c * c)
    d = np.stack([s * np.cos(phi), s * np.sin(phi), c], axis=-1)
    mirror = d * np.array([-1.0, -1.0, 1.0])
    d = np.concatenate([d, -d, mirror, -mirror])
    return np.unique(np.round(d, 15), axis=0)


def uniforms() -> np.ndarray:
    """(K, 3) uniforms: every corner of {0, ½, 1 − 2⁻²⁴}³ and sixteen random triples."""
    corners = np.array(list(itertools.product((0.0, 0.5, 1.0 - 2.0**-24), repeat=3)))
    return np.concatenate([corners, np.random.default_rng(12).random((16, 3))])


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


def per_element_maps(params_type: type, lead: tuple[int, ...], seed: int = 13) -> dict:
    """Every float and colour field as a per-element map mixing its extremes and midpoint.

    Constants fold into Python floats and may take other branches than arrays do (the
    Dr.Jit plugin sees textures as arrays), so the sweep runs once with maps as well.
    """
    rng = np.random.default_rng(seed)
    maps = {}
    for name, info in params_type.model_fields.items():
        ext = _extremes(info)
        if ext == [(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)]:
            maps[name] = rng.choice([0.0, 0.5, 1.0], size=(*lead, 3))
        elif len(ext) == 2 and all(isinstance(v, float) for v in ext):
            lo, hi = ext
            hi = min(hi, 1.0) if lo == 0.0 else hi
            maps[name] = rng.choice([lo, 0.5 * (lo + hi), hi], size=lead)
    return maps


def _element(maps: dict[str, np.ndarray], index: tuple[int, ...]) -> str:
    return ", ".join(f"{k}={_short(float(v[index]))}" for k, v in maps.items() if v.ndim == 2)


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


def _white(params: Any) -> Any:
    """The same parameters with every colour white (a furnace)."""
    colours = {
        k: (1.0, 1.0, 1.0)
        for k, info in type(params).model_fields.items()
        if _extremes(info) == [(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)]
    }
    return params.replace(**colours) if colours else params


def _sweep_energy(
    report: ModelReport, model: Model, label: str, params: Any, dtype: Any, whiten: bool = True
) -> None:
    name = np.dtype(dtype).name
    theta = np.radians(FURNACE_THETA_DEG)
    curve = albedo_monte_carlo(
        model,
        _white(params) if whiten else params,
        theta,
        n_samples=FURNACE_SAMPLES,
        hemisphere="both",
        dtype=dtype,
    )
    mean, err = curve.albedo, curve.stderr
    report.cases += len(theta)
    report.cases_by_dtype[name] += len(theta)
    excess = mean - SIGMAS * err - (1.0 + report.allowance + ROUNDING[name])
    k, c = np.unravel_index(np.argmax(mean), mean.shape)
    top = float(mean[k, c])
    if report.max_albedo is None or top > (report.max_albedo.value or 0.0):
        case = f"{label} (white); {name}; θo = {FURNACE_THETA_DEG[k]:g}° ± {err[k, c]:.2g}"
        report.max_albedo = Finding("max_albedo", case, top)
    gained = (excess > 0).any(axis=-1)
    if gained.any():
        k = int(np.argmax(excess.max(axis=-1)))
        value = float(mean[k].max())
        case = f"{label} (white); {name}; θo = {FURNACE_THETA_DEG[k]:g}°, albedo {value:.4g}"
        report._count(name, "energy_gain", int(gained.sum()), Finding("energy_gain", case, value))


def check_model(
    name: str, model: Model, progress: Callable[[str], None] = lambda label: None
) -> ModelReport:
    """The full sweep of one model."""
    report = ModelReport(name, allowance(name))
    for dtype in DTYPES:
        report.by_dtype[np.dtype(dtype).name] = dict.fromkeys(KINDS, 0)
        report.cases_by_dtype[np.dtype(dtype).name] = 0
    cases = [(label, params, False) for label, params in parameter_cases(model.params_type)]
    for label, params, with_maps in [*cases, (MAPS_LABEL, model.params_type(), True)]:
        progress(label)
        for dtype in DTYPES:
            try:
                with np.errstate(all="ignore"):
                    _sweep_queries(report, model, label, params, dtype, with_maps)
                    if _plausible(params) and not with_maps:
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


def furnace_cases(name: str) -> list[tuple[str, Any]]:
    """Extra furnace inputs (already white) for a model whose own inputs need not
    conserve energy.

    Composited Pixar lobe weights partition energy only as compositing produces them, so
    ``pixar_layered`` is put in the furnace with the weights of every plausible Pixar
    parameter case made white (what a one-layer stack composites to), not with arbitrary
    weights (twelve white weights would reflect several times the light).
    """
    if name != "pixar_layered":
        return []
    from lookdev.materials.pixar import PixarParams, as_lobe_weights

    cases = parameter_cases(PixarParams)
    return [
        (f"weights of {label}", as_lobe_weights(_white(p))) for label, p in cases if _plausible(p)
    ]


def run(
    names: list[str] | None = None, progress: Callable[[str, str], None] = lambda m, c: None
) -> tuple[dict[str, ModelReport], dict[str, str]]:
    """Reports for every available (or named) model, and why any are missing."""
    models, missing = available_models(names)
    reports = {}
    for name, model in models.items():
        reports[name] = check_model(name, model, lambda label, n=name: progress(n, label))
    return reports, missing


def case_count(names: list[str] | None = None) -> int:
    """How many parameter sets :func:`run` will sweep (for a progress bar)."""
    models, _ = available_models(names)
    return sum(len(parameter_cases(m.params_type)) + 1 for m in models.values())
