"""What ``lookdev check`` sweeps: the models, their stiff and extreme inputs, allowances.

The cases of :doc:`/design`, "Numerics that need care", for every model:

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
  extremes), the array code path that textures take;
* **interiors** — a solid's medium (σt per unit at metres and at the proof's 5 cm unit,
  albedo, and the Mitsuba dictionary's normalised σt and scale) for every case that has
  one, in both precisions: finite, σt > 0, albedo in [0, 1].

Allowances: the Conty-Kulla lobe and Smits' model conserve energy by construction (sheen
0.002: its albedo table's measured interpolation error; pixar 0). The Disney BRDF adds
energy by design (Burley 2012 fits measured looks, not energy conservation: the
retro-reflective diffuse, the sheen and the clearcoat are added on top), so its allowance is
a measured bound, documented here, not a tuning knob: 0.79. tests/materials/test_disney.py measures
each lobe's gain up to θo = 89° (rough white plastic 1.567, sheen +0.09, clearcoat +0.05).
With all of them at once and ``specular`` 1 the albedo keeps rising towards grazing: 1.721
at 89°, 1.758 at 89.9°, 1.762 ± 0.001 at 89.99° and 89.9999° along the tangent (φo = 0).
The maximum is along the bitangent of an anisotropic lobe: with ``anisotropic`` 1 as well
(roughness 1, sheen 1, clearcoat 1, clearcoat_gloss 0, specular 1), at θo = 89.9999° it is
1.718 ± 0.001 at φo = 0, 1.722 ± 0.001 at 45° and **1.783 ± 0.0014 at 90°** (2.6·10⁵
samples each, float64); 1.783 + 4σ < 1.79, hence 0.79. (White satin, the preset, reaches
1.41 along the bitangent against 1.11 along the tangent.) ``energy_compensation``
(Turquin's factor on the specular, :mod:`lookdev.materials.energy`) adds F0 (1/E − 1) of
the specular lobe on top: ≤ 0.0011 on a white plastic at specular 0.5 (1.5648 → 1.5659 at
89°), ≤ 0.0044 at specular 1, and the maximum above becomes 1.787 ± 0.0014 (same samples),
1.787 − 4σ < 1.79 (tests/materials/test_energy.py). Parameters pushed past their
plausible range (sheen 10, specular 12.5, clearcoat 4) are checked for NaN, infinity and
sign only: Burley allows them precisely to add energy.
"""

from __future__ import annotations

import itertools
import typing
from collections.abc import Sequence
from typing import Any

import numpy as np

from lookdev.materials import registry
from lookdev.materials.bsdf import Model
from lookdev.materials.errors import LookdevError, argument
from lookdev.materials.params import SCATTER_DISTANCE_MAX, SCATTER_DISTANCE_MIN

__all__ = [
    "ALLOWANCE",
    "COMBINATIONS",
    "CheckError",
    "SHEEN_ROUGHNESS",
    "UNBOUNDED_HIGH",
    "allowance",
    "directions",
    "extremes",
    "furnace_cases",
    "measured_cases",
    "models_named",
    "parameter_cases",
    "per_element_maps",
    "plausible",
    "short",
    "uniforms",
    "white",
]

ALLOWANCE = {
    "disney": 0.79,
    "sheen": 0.002,
    "pixar": 0.0,
    "pixar_layered": 0.0,
    # OpenPBR's Turquin factor reads E at the anisotropic lobe's mean α (materials/
    # energy.py): at specular_roughness_anisotropy 1 and θo 89.99° it adds 0.162, measured
    "openpbr": 0.17,
}
UNBOUNDED_HIGH = 10.0
"""The "pushed" value of a field with no upper bound. Every field a preset accepts has a
ceiling (:doc:`/design`, Ranges), so the sweep tests each at its ceiling; only the composited
Pixar lobe weights (model inputs a blend produces, never written in a preset) use this."""

SHEEN_ROUGHNESS = (0.01, 0.05, 0.08, 1.0)
"""Conty-Kulla roughness swept in both Λ modes (``sheen_lambda``)."""

# Named stiff combinations (docs/design.md), applied where every named field exists.
COMBINATIONS: tuple[dict[str, Any], ...] = (
    {"roughness": 0.0, "metallic": 1.0},  # delta metal (α clamp)
    {"roughness": 0.0, "anisotropic": 1.0},
    {"roughness": 1.0, "anisotropic": 1.0},  # GTR 0/0 at α → 1
    {"base_color": (0.0, 0.0, 0.0), "specular_tint": 1.0, "sheen": 1.0, "sheen_tint": 1.0},
    {"roughness": 1.0, "sheen": 1.0, "clearcoat": 1.0, "clearcoat_gloss": 0.0},
    # every lobe on, anisotropic: the largest Disney albedo, along the bitangent
    {
        "roughness": 1.0,
        "sheen": 1.0,
        "clearcoat": 1.0,
        "clearcoat_gloss": 0.0,
        "specular": 1.0,
        "anisotropic": 1.0,
    },
    # the satin preset's lobes (white in the furnace): 1.41 along the bitangent, 1.11 along
    # the tangent
    {"specular": 0.6, "roughness": 0.35, "anisotropic": 0.85, "sheen": 0.5, "sheen_tint": 0.3},
    {"clearcoat": 1.0, "clearcoat_gloss": 1.0},  # α = 0.001 clearcoat
    # the GTR γ of the specular lobe: its 0/0 at γ = 1 ± 1e-6, Burley's 2, and the ceiling
    # 10 (whose normalisation and power overflow float32 separately), sharp and rough
    *(
        {"specular_gamma": g, "roughness": r, "metallic": 1.0}
        for g in (1.0 - 1e-6, 1.0 + 1e-6, 1.5, 2.0, 3.0, 10.0)
        for r in (0.0, 0.5, 1.0)
    ),
    {"specular_gamma": 1.0 - 1e-6, "specular": 1.0, "roughness": 0.3},
    {"specular_gamma": 10.0, "spec_trans": 1.0, "roughness": 0.2},
    # the interior of a solid (Burley 2015, lookdev.materials.subsurface): the distance at
    # its floor and ceiling, the most uneven per-channel scale each allows (the product is
    # bounded, not the scale), black and white colours, the glass and every lobe above it
    {"scatter_distance": SCATTER_DISTANCE_MIN},  # (the ceiling alone is a field extreme)
    {
        "scatter_distance": SCATTER_DISTANCE_MAX,
        "scatter_distance_scale": (1.0, SCATTER_DISTANCE_MIN / SCATTER_DISTANCE_MAX, 0.5),
    },
    {
        "scatter_distance": 1.0,
        "scatter_distance_scale": (SCATTER_DISTANCE_MIN, 1.0, 1.0),
        "base_color": (1.0, 1.0, 1.0),
    },
    {
        "scatter_distance": 0.01,
        "scatter_distance_scale": (1.0, 0.4, 0.2),
        "base_color": (0.0, 0.0, 0.0),
    },
    {"scatter_distance": 0.01, "spec_trans": 1.0, "roughness": 0.0},
    {"scatter_distance": 0.01, "spec_trans": 0.5, "roughness": 0.3, "diff_trans": 1.0},
    {"scatter_distance": 0.01, "roughness": 1.0, "sheen": 1.0, "clearcoat": 1.0, "specular": 1.0},
    # Turquin's energy compensation (materials/energy.py): a white metal at 1 from every
    # view, the table's ends (R_MIN, 1), anisotropic, the most energetic plastic, glass,
    # and γ ≠ 2 (left uncompensated)
    *(
        {"energy_compensation": True, "metallic": 1.0, "roughness": r}
        for r in (0.0, 0.02, 0.0317, 0.5, 1.0)
    ),
    {"energy_compensation": True, "metallic": 1.0, "roughness": 1.0, "anisotropic": 1.0},
    {
        "energy_compensation": True,
        "roughness": 1.0,
        "sheen": 1.0,
        "clearcoat": 1.0,
        "clearcoat_gloss": 0.0,
        "specular": 1.0,
        "anisotropic": 1.0,
    },
    {"energy_compensation": True, "spec_trans": 1.0, "roughness": 0.5},
    {"energy_compensation": True, "specular_gamma": 1.5, "metallic": 1.0, "roughness": 0.5},
    {"spec_trans": 1.0, "roughness": 0.0},  # smooth glass
    {"spec_trans": 1.0, "ior": 1.0, "roughness": 0.3},  # η = 1: refraction degenerates
    {"spec_trans": 1.0, "thin": True, "roughness": 0.0},
    {"diff_trans": 1.0, "thin": True, "flatness": 1.0},
    {"sheen_model": "conty_kulla", "sheen": 1.0, "sheen_roughness": 0.0},
    {"sheen_model": "conty_kulla", "sheen": 1.0, "sheen_roughness": 1.0},
    {"roughness": 0.0, "terminator_softening": False},
    # Conty-Kulla's Λ in both modes at the exact mode's floor 0.01, at 0.05 (where the fit
    # gains energy: it reads r = 0.08 there), at the fit's floor 0.08 and at 1
    *(
        {"sheen_model": "conty_kulla", "sheen": 1.0, "sheen_roughness": r, "sheen_lambda": m}
        for m in ("fit", "exact")
        for r in SHEEN_ROUGHNESS
    ),
    *(
        {"roughness": r, "sheen_lambda": m, "terminator_softening": s}
        for m in ("fit", "exact")
        for r in SHEEN_ROUGHNESS
        for s in (False, True)
    ),
    {"roughness": 0.0, "clear": 1.0, "back": 1.0},  # powerR at its cone floor, refraction
    {"roughness": 0.0, "specular_cone_scale": 0.0, "reflection_cone_scale": 0.0},
    {"roughness": 0.5, "normal_fresnel": 20.0, "grazing_fresnel": 0.0, "clear": 1.0},
)


class CheckError(LookdevError):
    """``lookdev check`` was asked for a model it does not know."""


def models_named(names: list[str] | None = None) -> dict[str, Model]:
    """{name: Model} of the registry's models, or of those named."""
    wanted = list(registry.MODELS) if not names else names
    unknown = [n for n in wanted if n not in registry.MODELS]
    if unknown:
        raise CheckError(
            f"unknown model {unknown[0]!r}; known: {', '.join(registry.MODELS)}",
            field=argument("models"),
        )
    return {name: registry.MODELS[name] for name in wanted}


def allowance(name: str) -> float:
    """Energy a model may add by design (see the module docstring); 0 if unknown."""
    return ALLOWANCE.get(name, 0.0)


def extremes(info: Any) -> list[Any]:
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


def plausible(params: Any) -> bool:
    """Every float field inside 0..1 where its range starts at 0 (Burley's plausible)."""
    for name, info in type(params).model_fields.items():
        value = getattr(params, name)
        ext = extremes(info)
        if isinstance(value, float) and ext and ext[0] == 0.0 and value > 1.0:
            return False
    return True


def measured_cases(measured: Sequence[Any] = ()) -> list[tuple[str, Any]]:
    """The measured model's cases: each measurement given (as read, negative noise
    included: ``lookdev check`` gives the shipped ones) at scale 1 and the first at the
    scale's ceiling, and two synthetic tables on the periodic MERL grid: all zero, and a
    white Lambertian 0.999/π (the furnace's edge)."""
    from lookdev.materials.measured import MeasuredParams, MeasuredTable

    lambert = np.full((5, 5, 7, 3), 0.999 / np.pi, dtype=np.float32)
    tables = list(measured)
    tables += [MeasuredTable.constant(0.0), MeasuredTable("merl", lambert, source="white")]
    cases = [(t.source, MeasuredParams(table=t)) for t in tables]
    ceiling = MeasuredParams.model_fields["scale"].metadata[-1].le
    cases += [
        (f"{t.source}, scale={ceiling:g}", MeasuredParams(table=t, scale=ceiling))
        for t in tables[:1]
    ]
    return cases


def parameter_cases(params_type: type, measured: Sequence[Any] = ()) -> list[tuple[str, Any]]:
    """(label, params): defaults, each field at each extreme, and the named combinations;
    for the measured model, :func:`measured_cases` of the tables ``measured``."""
    from lookdev.materials.measured import MeasuredParams

    if params_type is MeasuredParams:
        return measured_cases(measured)
    cases = [("defaults", params_type())]
    fields = params_type.model_fields
    for name, info in fields.items():
        for value in extremes(info):
            cases.append((f"{name}={short(value)}", {name: value}))
    for combo in COMBINATIONS:
        if set(combo) <= set(fields):
            cases.append((", ".join(f"{k}={short(v)}" for k, v in combo.items()), combo))
    out = []
    for label, data in cases:
        if isinstance(data, dict):
            try:
                data = params_type.parse(data)
            except LookdevError:
                continue  # a combination the schema forbids (e.g. specular with ior)
        out.append((label, data))
    return out


def short(value: Any) -> str:
    if isinstance(value, tuple) and all(v == 1 for v in value):
        return "white"
    if isinstance(value, tuple) and all(v == 0 for v in value):
        return "black"
    if isinstance(value, tuple):
        return "(" + ", ".join(f"{v:g}" for v in value) + ")"
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


def per_element_maps(params_type: type, lead: tuple[int, ...], seed: int = 13) -> dict:
    """Every float and colour field as a per-element map mixing its extremes and midpoint.

    Constants fold into Python floats and may take other branches than arrays do (the
    Dr.Jit plugin sees textures as arrays), so the sweep runs once with maps as well.
    """
    rng = np.random.default_rng(seed)
    maps = {}
    for name, info in params_type.model_fields.items():
        ext = extremes(info)
        if ext == [(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)]:
            maps[name] = rng.choice([0.0, 0.5, 1.0], size=(*lead, 3))
        elif len(ext) == 2 and all(isinstance(v, float) for v in ext):
            lo, hi = ext
            hi = min(hi, 1.0) if lo == 0.0 else hi
            maps[name] = rng.choice([lo, 0.5 * (lo + hi), hi], size=lead)
    return maps


def white(params: Any) -> Any:
    """The same parameters with every colour white (a furnace)."""
    colours = {
        k: (1.0, 1.0, 1.0)
        for k, info in type(params).model_fields.items()
        if extremes(info) == [(0.0, 0.0, 0.0), (1.0, 1.0, 1.0)]
    }
    return params.replace(**colours) if colours else params


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
        (f"weights of {label}", as_lobe_weights(white(p))) for label, p in cases if plausible(p)
    ]
