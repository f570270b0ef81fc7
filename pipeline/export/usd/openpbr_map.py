"""Disney (Burley 2012 and 2015, Conty–Kulla sheen) → OpenPBR Surface: the one mapping.

No published mapping exists (only Standard Surface ↔ OpenPBR), so this one is derived
term by term from the two models as lookdev evaluates them (:mod:`lookdev.materials.disney`,
:mod:`lookdev.materials.openpbr`). :func:`openpbr_values` is the mapping; :data:`DIRECT`
the inputs that take one Disney parameter each (so a map or a live mask chain of that
parameter reaches them as a texture); the rest are *derived* from several parameters and
written as constants (the material's live values; under a live layer stack, each layer's
derived value mixed by the masks). Every term that does not carry over exactly is a
:class:`Loss` in :data:`LOSSES`, with the reason; ``docs/measurements/contexts.md`` gives
each one's measured size (:func:`lookdev.pipeline.analysis.openpbr_losses.term_losses`).

=====================  ==================================================================
OpenPBR input          from
=====================  ==================================================================
base_color             base_color
base_metalness         metallic (F82 with specular_color 1 is Schlick on base_color: exact)
specular_roughness     roughness, raised so the mean α of an anisotropic lobe is kept
specular_roughness_    0.9·anisotropic (Burley's aspect² = 1 − 0.9·anisotropic = α_y/α_x)
anisotropy
specular_ior           the IOR of F0 = 0.08·specular (Burley §5.4); ior under spec_trans
specular_color         lerp(1, base_color/lum, specular_tint) (Burley's tint, whole curve)
coat_weight            0.25·clearcoat (Burley's lobe weight), at most 1
coat_roughness         the GGX roughness as wide as GTR1's α = mix(0.1, 0.001, gloss)
coat_ior               1.5 (Burley's fixed clearcoat F0 = 0.04)
coat_darkening         0 (Burley's clearcoat neither darkens nor tints its base)
fuzz_weight            min(sheen, 1)
fuzz_color             lerp(1, base_color/lum, sheen_tint)
fuzz_roughness         sheen_roughness (Conty–Kulla); 0.5 for Burley's Schlick sheen
transmission_weight    spec_trans
transmission_color     base_color (Burley 2015 tints the refraction by it)
subsurface_weight      1 for a solid with a scatter distance; diff_trans on thin sheets
subsurface_color       base_color
subsurface_radius      scatter_distance (scene units)
subsurface_radius_     scatter_distance_scale (the same per-channel split as OpenPBR's)
scale
geometry_thin_walled   thin
=====================  ==================================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from lookdev.materials.colour import luminance
from lookdev.materials.fresnel import specular_to_ior
from lookdev.materials.microfacet import ggx_roughness_like_gtr

from .names import CLEARCOAT_ALPHA, CLEARCOAT_PREVIEW_SCALE, Slot

__all__ = [
    "DERIVED_SOURCES",
    "DIRECT",
    "GATES",
    "LOSSES",
    "MAPPED",
    "SURFACE_ID",
    "Loss",
    "losses_of",
    "openpbr_values",
]

SURFACE_ID = "ND_open_pbr_surface_surfaceshader"
ANISOTROPY_SCALE = 0.9  # Burley 2014 addendum: aspect = √(1 − 0.9·anisotropic)
BURLEY_SHEEN_FUZZ_ROUGHNESS = 0.5  # OpenPBR's default: Burley's sheen has no roughness


def _tint(base: Any) -> tuple[float, float, float]:
    """Burley's C_tint: the base colour normalised by its luminance (white when black)."""
    lum = float(luminance(base))
    return tuple(float(c) / lum for c in base) if lum > 0.0 else (1.0, 1.0, 1.0)


def _mix_white(colour: tuple[float, ...], t: float) -> tuple[float, float, float]:
    return tuple(min(max(1.0 + (c - 1.0) * t, 0.0), 1.0) for c in colour)


def coat_roughness(gloss: float) -> float:
    """GGX roughness whose highlight is as wide as Burley's GTR1 clearcoat at ``gloss``
    (:func:`lookdev.materials.microfacet.ggx_roughness_like_gtr` at γ = 1)."""
    lo, hi = CLEARCOAT_ALPHA
    alpha = lo + (hi - lo) * gloss
    return ggx_roughness_like_gtr(1.0, math.sqrt(alpha))


def anisotropic_roughness(roughness: float, anisotropic: float) -> float:
    """The roughness keeping Burley's mean α = r² under OpenPBR's anisotropy stretch
    (α_x α_y = 2(1 − a)/(1 + (1 − a)²) r⁴ there), at most 1."""
    a = ANISOTROPY_SCALE * anisotropic
    keep = 2.0 * (1.0 - a) / (1.0 + (1.0 - a) ** 2)
    return min(roughness / max(keep, 1e-12) ** 0.25, 1.0)


DIRECT: tuple[Slot, ...] = (
    Slot("base_color", "base_color", "color3f"),
    Slot("metallic", "base_metalness", "float"),
    Slot("roughness", "specular_roughness", "float"),
    Slot(
        "specular",
        "specular_ior",
        "float",
        lobe="dielectric",
        to_target=lambda v: max(float(specular_to_ior(v)), 1.0),
        texture_linear=None,
    ),
    # glass: the IOR refracts, so it sets the F0 too (after the slot above: it wins)
    Slot("ior", "specular_ior", "float", lobe="spec_trans"),
    Slot(
        "clearcoat",
        "coat_weight",
        "float",
        lobe="clearcoat",
        to_target=lambda v: min(v * CLEARCOAT_PREVIEW_SCALE, 1.0),
        from_target=lambda v: v / CLEARCOAT_PREVIEW_SCALE,
        texture_linear=(CLEARCOAT_PREVIEW_SCALE, 0.0),
    ),
    Slot(
        "clearcoat_gloss",
        "coat_roughness",
        "float",
        lobe="clearcoat",
        to_target=coat_roughness,
        texture_linear=None,
    ),
    Slot("spec_trans", "transmission_weight", "float", lobe="spec_trans"),
    Slot(
        "sheen",
        "fuzz_weight",
        "float",
        lobe="sheen",
        to_target=lambda v: min(v, 1.0),
        texture_linear=None,
    ),
    Slot("base_color", "transmission_color", "color3f", lobe="spec_trans"),
    Slot("base_color", "subsurface_color", "color3f", lobe="subsurface_any"),
)
"""One Disney parameter → one OpenPBR input (a map or mask chain of it reaches the input)."""


def openpbr_values(values: dict[str, Any], lobes: dict[str, bool]) -> dict[str, Any]:
    """The OpenPBR inputs of live canonical Disney ``values`` (every input, defaults too)."""
    v = values
    base = tuple(float(c) for c in v["base_color"])
    tint = _tint(base)
    out: dict[str, Any] = {s.input: s.to_target(v[s.param]) for s in DIRECT}
    if not lobes.get("clearcoat"):
        out["coat_weight"] = 0.0
    if not lobes.get("spec_trans"):
        out["transmission_weight"] = 0.0
    if not lobes.get("sheen"):
        out["fuzz_weight"] = 0.0
    aniso = float(v["anisotropic"])
    if aniso > 0.0:
        out["specular_roughness"] = anisotropic_roughness(float(v["roughness"]), aniso)
    out["specular_roughness_anisotropy"] = ANISOTROPY_SCALE * aniso
    ior = float(v["ior"]) if lobes.get("spec_trans") else float(specular_to_ior(v["specular"]))
    out["specular_ior"] = max(ior, 1.0)
    out["specular_color"] = _mix_white(tint, float(v["specular_tint"]))
    out["coat_ior"] = 1.5
    out["coat_darkening"] = 0.0
    out["fuzz_color"] = _mix_white(tint, float(v["sheen_tint"]))
    conty = v["sheen_model"] == "conty_kulla"
    out["fuzz_roughness"] = float(v["sheen_roughness"]) if conty else BURLEY_SHEEN_FUZZ_ROUGHNESS
    thin = bool(v["thin"])
    out["geometry_thin_walled"] = thin
    if thin and lobes.get("diff_trans"):
        out["subsurface_weight"] = float(v["diff_trans"])
    elif lobes.get("scatter"):
        # a solid with a scatter distance sends its whole diffuse into its interior
        out["subsurface_weight"] = 1.0
        out["subsurface_radius"] = float(v["scatter_distance"])
        out["subsurface_radius_scale"] = tuple(float(x) for x in v["scatter_distance_scale"])
    else:
        out["subsurface_weight"] = 0.0
    return out


MAPPED: frozenset[str] = frozenset(
    (
        "base_color metallic roughness anisotropic specular specular_tint ior sheen "
        "sheen_tint sheen_model sheen_roughness clearcoat clearcoat_gloss spec_trans "
        "diff_trans thin subsurface scatter_distance scatter_distance_scale flatness "
        "energy_compensation"
    ).split()
)
"""The Disney parameters the mapping reads (``flatness`` and the 2012 ``subsurface``
only to name them in :data:`LOSSES`); any other live one is named as not expressed."""

DERIVED_SOURCES: dict[str, tuple[str, ...]] = {
    "specular_color": ("base_color", "specular_tint"),
    "fuzz_color": ("base_color", "sheen_tint"),
    "specular_roughness": ("roughness", "anisotropic"),
    "specular_roughness_anisotropy": ("anisotropic",),
    "fuzz_roughness": ("sheen_roughness",),
    "subsurface_weight": ("subsurface", "diff_trans"),
    "subsurface_radius": ("scatter_distance", "scatter_distance_scale"),
    "subsurface_radius_scale": ("scatter_distance", "scatter_distance_scale"),
}
"""Derived input → the parameters it is made from (a map of any of them is written as
the material's mean value, and named)."""

GATES: dict[str, str] = {
    "specular_color": "dielectric",
    "coat_ior": "clearcoat",
    "coat_darkening": "clearcoat",
    "fuzz_color": "sheen",
    "fuzz_roughness": "sheen",
    "subsurface_radius": "scatter",
    "subsurface_radius_scale": "scatter",
}
"""Derived input → the exporter's lobe (:mod:`.lobes`) without which it is not written."""


@dataclass(frozen=True)
class Loss:
    """A Disney term that does not carry over exactly: its name, when it applies (the
    live values and lobes), and why."""

    name: str
    applies: Any
    why: str


def _on(lobe: str):
    return lambda v, lobes: bool(lobes.get(lobe))


LOSSES: tuple[Loss, ...] = (
    Loss(
        "diffuse",
        lambda v, lobes: bool(lobes.get("diffuse")) and v["metallic"] < 1.0,
        "Burley's diffuse (retro-reflection 2·r·cos²θd at grazing) → OpenPBR's Lambertian",
    ),
    Loss(
        "specular",
        _on("dielectric"),
        "specular → specular_ior: Schlick's curve from F0 = 0.08·specular → the exact "
        "Fresnel of the same F0's IOR",
    ),
    Loss(
        "specular_tint",
        lambda v, lobes: bool(lobes.get("dielectric")) and v["specular_tint"] > 0.0,
        "specular_tint → specular_color: Burley tints F0 only (white at grazing); "
        "specular_color tints the whole dielectric curve",
    ),
    Loss(
        "metallic",
        lambda v, lobes: 0.0 < v["metallic"] < 1.0 and v["specular_tint"] > 0.0,
        "metallic → base_metalness: specular_color (the dielectric's tint) also tints "
        "the F82 edge of the metal",
    ),
    Loss(
        "multiple_scattering",
        lambda v, lobes: not v.get("energy_compensation") and v["roughness"] > 0.0,
        "OpenPBR's microfacet lobes keep the light that scatters between microfacets "
        "(energy-preserving); Burley's single-scattering lobes lose it (energy_compensation "
        "off): rough metals and glossy dielectrics are brighter in OpenPBR",
    ),
    Loss(
        "anisotropic",
        lambda v, lobes: v["anisotropic"] > 0.0,
        "anisotropic → specular_roughness_anisotropy: α_y/α_x and the mean α kept "
        "(roughness raised), up to specular_roughness 1",
    ),
    Loss(
        "clearcoat",
        _on("clearcoat"),
        "clearcoat (GTR1, η 1.5, weight 0.25, no darkening) → coat_* (GGX as wide, "
        "coat_ior 1.5, coat_weight 0.25·clearcoat, coat_darkening 0): the coat also "
        "scales its base by 1 − E_coat",
    ),
    Loss(
        "sheen",
        _on("sheen"),
        "sheen → fuzz_*: OpenPBR's fuzz is a layer (the base scaled by 1 − E_fuzz), "
        "Burley's (1 − cos θd)⁵ sheen is added; fuzz_weight is capped at 1",
    ),
    Loss(
        "spec_trans",
        _on("spec_trans"),
        "spec_trans → transmission_*: F0 from ior, not 0.08·specular; refraction tinted "
        "by base_color at the surface (transmission_depth 0)",
    ),
    Loss(
        "diff_trans",
        lambda v, lobes: bool(lobes.get("diff_trans")) and bool(v["thin"]),
        "diff_trans → geometry_thin_walled + subsurface_weight: the split between "
        "transmitted and reflected diffuse is OpenPBR's, not Burley's",
    ),
    Loss(
        "scatter_distance",
        _on("scatter"),
        "scatter_distance → subsurface_radius/_scale: OpenPBR's radius is a mean free "
        "path of its own volume model",
    ),
    Loss(
        "flatness",
        _on("flatness"),
        "flatness (Burley 2015's thin-surface diffuse) has no OpenPBR input: dropped",
    ),
    Loss(
        "subsurface",
        _on("subsurface"),
        "Burley 2012's subsurface (Hanrahan–Krueger flattening of the diffuse) has no "
        "OpenPBR input: dropped",
    ),
)
"""Every Disney → OpenPBR term that is not exact (sizes: docs/measurements/contexts.md)."""


def losses_of(values: dict[str, Any], lobes: dict[str, bool]) -> list[Loss]:
    """The :data:`LOSSES` that apply to live canonical Disney ``values``."""
    return [loss for loss in LOSSES if loss.applies(values, lobes)]
