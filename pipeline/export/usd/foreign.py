"""What other tools write, read into Disney parameters: OpenPBR and Standard Surface
networks, the inputs no preset holds, and the specular workflow of UsdPreviewSurface.

Current DCCs (Houdini, Maya, Omniverse, Blender 4) write MaterialX
``ND_open_pbr_surface_surfaceshader`` or ``ND_standard_surface_surfaceshader`` (glTF
exporters ``ND_gltf_pbr_surfaceshader``); lookdev reads them into Burley's parameters by
the tables below (one table per surface, the only place their spelling appears: extend
:data:`TABLES`, :data:`GATES` and :data:`UNREAD` to read another surface). An input
with no Disney parameter (emission, a coloured specular, coat colour, thin-film …) is
named as a loss, never dropped silently.

The documented mapping:

================================  ==========================  ===================================
OpenPBR                           Standard Surface            Disney (Burley 2012/2015)
================================  ==========================  ===================================
base_color × base_weight          base_color × base           base_color (opaque part)
transmission_color                transmission_color          base_color (glass part, see below)
subsurface_color                  subsurface_color            base_color (subsurface part)
base_metalness                    metalness                   metallic
specular_roughness                specular_roughness          roughness
specular_ior                      specular_IOR                ior
specular_roughness_anisotropy     specular_anisotropy         anisotropic
coat_weight × 4                   coat × 4                    clearcoat (Burley weights his 0.25)
coat_roughness                    coat_roughness              clearcoat_gloss (α = r², App. B.2)
transmission_weight               transmission                spec_trans
subsurface_weight                 subsurface                  subsurface
subsurface_radius × _scale        subsurface_radius × _scale  scatter_distance, _scale (RGB × mpu)
fuzz_weight                       sheen                       sheen (sheen_model conty_kulla)
geometry_thin_walled              thin_walled                 thin
================================  ==========================  ===================================

Glass. Burley's ``spec_trans`` tints what it transmits by ``base_color`` (Burley 2015);
OpenPBR and Standard Surface tint it by ``transmission_color`` and keep ``base_color``
for the opaque base, which glass usually leaves at weight 0. So the glass part's colour
is ``transmission_color``: base_color = mix(base_color × weight, transmission_color,
transmission). Clear glass (Standard Surface's ``base = 0``, ``transmission = 1``) stays
clear; where transmission is partial and the two colours differ, one Disney colour holds
both, and that is named. The subsurface likewise: Burley's takes ``base_color``, theirs
``subsurface_color``, mixed in by the subsurface weight.

A dead lobe's inputs are not read (:data:`GATES`): at weight 0 a value (a velvet's
``specular_IOR = 0``) shows nothing, so it neither refuses the material nor reaches the
preset.

MaterialX image nodes (``ND_image_*``, ``ND_tiledimage_*``) feeding an input become the
parameter's texture (file, colour space from the file's ``colorSpace``, the weight and
the table's affine conversion as scale); any other network feeding it is named.

The radius is per channel (OpenPBR: a length times a colour, Standard Surface: a colour
times a length); it becomes lookdev's distance (the largest channel) and scale. It makes
an interior only where the surface scatters: at subsurface weight 0 (the DCCs' default)
the authored or default radius shows nothing, so it is not read; a weight below 1 is
named, since lookdev's solid sends its whole diffuse into its interior (Burley 2015).
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lookdev.materials.colour import luminance
from lookdev.materials.fresnel import F0_MAX, SPECULAR_F0_SCALE
from lookdev.materials.subsurface import split_distances

from .names import CLEARCOAT_PREVIEW_SCALE, roughness_to_gloss
from .network import Connection, Node

__all__ = [
    "FOREIGN_SURFACES",
    "preview_extras",
    "read_foreign",
    "specular_workflow",
]

OPENPBR = "ND_open_pbr_surface_surfaceshader"
STANDARD = "ND_standard_surface_surfaceshader"
GLTF = "ND_gltf_pbr_surfaceshader"

# (our parameter, their input, their weight input or None, conversion)
_COAT = 1.0 / CLEARCOAT_PREVIEW_SCALE


def _mean(v: Any) -> float:
    return sum(v) / 3.0 if isinstance(v, tuple) else float(v)


TABLES: dict[str, dict[str, tuple[str, str | None, Any]]] = {
    OPENPBR: {
        "base_color": ("base_color", "base_weight", None),
        "metallic": ("base_metalness", None, None),
        "roughness": ("specular_roughness", None, None),
        "ior": ("specular_ior", None, None),
        "anisotropic": ("specular_roughness_anisotropy", None, None),
        "clearcoat": ("coat_weight", None, lambda v: v * _COAT),
        "clearcoat_gloss": ("coat_roughness", None, roughness_to_gloss),
        "spec_trans": ("transmission_weight", None, None),
        "subsurface": ("subsurface_weight", None, None),
        "scatter_distance": ("subsurface_radius", "subsurface_radius_scale", None),
        "sheen": ("fuzz_weight", None, None),
        "thin": ("geometry_thin_walled", None, bool),
    },
    STANDARD: {
        "base_color": ("base_color", "base", None),
        "metallic": ("metalness", None, None),
        "roughness": ("specular_roughness", None, None),
        "ior": ("specular_IOR", None, None),
        "anisotropic": ("specular_anisotropy", None, None),
        "clearcoat": ("coat", None, lambda v: v * _COAT),
        "clearcoat_gloss": ("coat_roughness", None, roughness_to_gloss),
        "spec_trans": ("transmission", None, None),
        "subsurface": ("subsurface", None, None),
        "scatter_distance": ("subsurface_radius", "subsurface_scale", None),
        "sheen": ("sheen", None, None),
        "thin": ("thin_walled", None, bool),
    },
    GLTF: {
        "base_color": ("base_color", None, None),
        "metallic": ("metallic", None, None),
        "roughness": ("roughness", None, None),
        "ior": ("ior", None, None),
        "anisotropic": ("anisotropy_strength", None, None),
        "clearcoat": ("clearcoat", None, lambda v: v * _COAT),
        "clearcoat_gloss": ("clearcoat_roughness", None, roughness_to_gloss),
        "spec_trans": ("transmission", None, None),
    },
}
"""surface id → our parameter → (their input, the input that scales it, conversion)."""

AFFINE = {"clearcoat": _COAT}
"""Our parameters whose conversion is a scale (a map keeps it as its ``scale``); any other
conversion has no texture form."""

SPECULAR_WEIGHT = {OPENPBR: "specular_weight", STANDARD: "specular", GLTF: "specular"}
"""The weight of the dielectric specular: at 0 (and no glass) it is Burley's ``specular``
0; any other value below 1 has no Disney parameter (named)."""

TINTS: dict[str, tuple[tuple[str, str], ...]] = {
    OPENPBR: (("spec_trans", "transmission_color"), ("subsurface", "subsurface_color")),
    STANDARD: (("spec_trans", "transmission_color"), ("subsurface", "subsurface_color")),
}
"""Per surface, (our weight, their colour input): the colour of the glass and of the
subsurface, which Burley takes from ``base_color`` (see the module note), in order."""

GATES: dict[str, dict[str, tuple[str, ...]]] = {
    OPENPBR: {
        "ior": ("specular_weight", "transmission_weight"),
        "roughness": ("specular_weight", "transmission_weight", "base_metalness"),
        "anisotropic": ("specular_weight", "transmission_weight", "base_metalness"),
        "clearcoat_gloss": ("coat_weight",),
        "scatter_distance": ("subsurface_weight",),
    },
    STANDARD: {
        "ior": ("specular", "transmission"),
        "roughness": ("specular", "transmission", "metalness"),
        "anisotropic": ("specular", "transmission", "metalness"),
        "clearcoat_gloss": ("coat",),
        "scatter_distance": ("subsurface",),
    },
    GLTF: {
        "clearcoat_gloss": ("clearcoat",),
    },
}
"""Our parameter → the weights of the lobes that read it: when every one is 0 the
parameter is not read (the lobe is dead; its inputs show nothing)."""

UNREAD: dict[str, tuple[str, ...]] = {
    OPENPBR: (
        "emission_luminance",
        "emission_color",
        "specular_color",
        "specular_weight",
        "coat_color",
        "coat_ior",
        "thin_film_weight",
        "geometry_normal",
        "geometry_coat_normal",
        "geometry_opacity",
        "transmission_depth",
        "subsurface_color",
        "fuzz_color",
        "fuzz_roughness",
        "base_diffuse_roughness",
    ),
    STANDARD: (
        "emission",
        "emission_color",
        "specular",
        "specular_color",
        "coat_color",
        "coat_IOR",
        "thin_film_thickness",
        "normal",
        "coat_normal",
        "opacity",
        "transmission_depth",
        "subsurface_color",
        "sheen_color",
        "sheen_roughness",
        "diffuse_roughness",
    ),
    GLTF: (
        "emissive",
        "specular",
        "specular_color",
        "sheen_color",
        "iridescence",
        "alpha",
        "normal",
        "occlusion",
        "thickness",
        "attenuation_color",
    ),
}
"""Inputs with no Disney parameter: named as losses when authored away from the default."""

UNREAD_GATES: dict[str, dict[str, str]] = {
    OPENPBR: {
        "specular_color": "specular_weight",
        "coat_color": "coat_weight",
        "coat_ior": "coat_weight",
        "geometry_coat_normal": "coat_weight",
        "thin_film_weight": "thin_film_weight",
        "transmission_depth": "transmission_weight",
        "subsurface_color": "subsurface_weight",
        "fuzz_color": "fuzz_weight",
        "fuzz_roughness": "fuzz_weight",
        "emission_color": "emission_luminance",
    },
    STANDARD: {
        "specular_color": "specular",
        "coat_color": "coat",
        "coat_IOR": "coat",
        "coat_normal": "coat",
        "transmission_depth": "transmission",
        "subsurface_color": "subsurface",
        "sheen_color": "sheen",
        "sheen_roughness": "sheen",
        "emission_color": "emission",
    },
}
"""An unread input → the weight of its lobe: at weight 0 it shows nothing, so it is no
loss (a velvet's ``specular_color`` at ``specular = 0``)."""

FOREIGN_SURFACES = frozenset(TABLES)


def read_foreign(
    surface: Node, defaults: dict[str, Any], meters_per_unit: float
) -> tuple[dict[str, Any], dict[str, tuple[str, Connection, float]], list[str]]:
    """(values, maps, losses) of an OpenPBR, Standard Surface or glTF shader ``surface``.

    ``defaults`` are the node's MaterialX defaults (an unauthored input renders at its
    default); ``maps`` gives, per parameter fed by a connection, (their input, the
    connection, the scale its weight and conversion put on the texel; 0 when the
    conversion has no texture form); a dead lobe's inputs are skipped (:data:`GATES`);
    lengths are converted to metres by ``meters_per_unit``.
    """
    table = TABLES[surface.id]
    gates = GATES.get(surface.id, {})
    values: dict[str, Any] = {}
    maps: dict[str, tuple[str, Connection, float]] = {}
    losses: list[str] = []

    def given(name: str) -> Any:
        if name in surface.inputs:
            return surface.inputs[name][1]
        return defaults.get(name)

    def dead(param: str) -> bool:
        weights = [given(w) for w in gates.get(param, ())]
        return bool(weights) and all(w is not None and _is_zero(w) for w in weights)

    for param, (name, scale_by, convert) in table.items():
        if dead(param):
            continue
        value, scale = given(name), given(scale_by) if scale_by else None
        if isinstance(scale, Connection):
            maps[param] = (scale_by, scale, 0.0)
            continue
        if isinstance(value, Connection):
            factor = 1.0 if scale is None else _mean(scale)
            affine = 1.0 if convert is None else AFFINE.get(param, 0.0)
            maps[param] = (name, value, factor * affine)
            continue
        if value is None:
            continue
        if param == "scatter_distance":
            value = np.broadcast_to(value, (3,)) * np.broadcast_to(
                1.0 if scale is None else scale, (3,)
            )
        elif scale is not None:
            value = (
                tuple(x * _mean(scale) for x in value)
                if isinstance(value, tuple)
                else value * _mean(scale)
            )
        values[param] = convert(value) if convert else value
    if "sheen" in values:
        values["sheen_model"] = "conty_kulla"
    read_here: set[str] = set()
    for weight, name in TINTS.get(surface.id, ()):
        read_here |= _tint(surface, weight, name, given, values, maps, losses)
    weight_name = SPECULAR_WEIGHT.get(surface.id)
    if weight_name and _is_zero(given(weight_name)) and not values.get("spec_trans", 0.0) > 0:
        values.pop("ior", None)
        values["specular"] = 0.0
        read_here.add(weight_name)
    _read_radius(values, maps, losses, surface.id, meters_per_unit)
    unread_gates = UNREAD_GATES.get(surface.id, {})
    for name in UNREAD[surface.id]:
        gate = unread_gates.get(name)
        if name in read_here or (gate is not None and _is_zero(given(gate))):
            continue
        if name in surface.inputs and not _at_default(surface.inputs[name][1], defaults.get(name)):
            value = surface.inputs[name][1]
            shown = "a connected map" if isinstance(value, Connection) else _short(value)
            losses.append(f"{surface.id} {name} = {shown} has no Disney parameter")
    return values, maps, losses


def _is_zero(value: Any) -> bool:
    if isinstance(value, Connection):
        return False
    return all(v == 0 for v in value) if isinstance(value, tuple) else value == 0


def _tint(surface: Node, param: str, name: str, given, values, maps, losses) -> set[str]:
    """Burley's glass and subsurface take ``base_color``; theirs take ``name``
    (``transmission_color``, ``subsurface_color``): mixed into ``base_color`` by the
    lobe's weight ``param`` (see the module note). The inputs it read."""
    weight = values.get(param, 0.0)
    if param in maps or not weight > 0.0:
        return set()
    tint = given(name)
    if isinstance(tint, Connection):
        losses.append(f"{surface.id} {name} is a connected map: base_color keeps the base's")
        return {name}
    if tint is None:
        return set()
    tint = np.broadcast_to(np.asarray(tint, dtype=np.float64), (3,))
    if weight >= 1.0:
        maps.pop("base_color", None)  # at full weight the base's own colour shows nothing
        values["base_color"] = tuple(float(c) for c in tint)
        return {name}
    if "base_color" in maps:
        losses.append(f"{surface.id} {name}: the {param} part takes the base colour map")
        return {name}
    base = np.broadcast_to(np.asarray(values.get("base_color", 0.0), dtype=np.float64), (3,))
    mixed = (1.0 - weight) * base + weight * tint
    values["base_color"] = tuple(float(c) for c in mixed)
    if np.max(np.abs(base - tint)) > 1e-6:
        losses.append(
            f"{surface.id} {param} {weight:g}: base_color {_short(tuple(base))} and "
            f"{name} {_short(tuple(tint))} share one Disney base_color "
            f"{_short(tuple(round(float(c), 4) for c in mixed))}"
        )
    return {name}


def _read_radius(values, maps, losses, surface_id: str, meters_per_unit: float) -> None:
    """The RGB radius (scene units) in ``values`` → ``scatter_distance`` (metres) and
    ``scatter_distance_scale``, where the surface scatters (see the module note)."""
    radius = values.pop("scatter_distance", None)
    weight = values.get("subsurface", 0.0)
    if radius is None or "subsurface" in maps or values.get("thin"):
        return
    if not weight > 0.0:
        return
    d, values["scatter_distance_scale"] = split_distances(radius * meters_per_unit)
    if d > 0.0:
        values["scatter_distance"] = d
    if weight < 1.0:
        losses.append(
            f"{surface_id} subsurface weight {weight:g}: lookdev's solid sends its whole "
            "diffuse into the interior (Burley 2015), as at weight 1"
        )


def _at_default(value: Any, default: Any) -> bool:
    if isinstance(value, Connection) or default is None:
        return False
    if isinstance(value, tuple) and isinstance(default, tuple):
        return all(abs(a - b) < 1e-6 for a, b in zip(value, default, strict=False))
    try:
        return abs(float(value) - float(default)) < 1e-6
    except (TypeError, ValueError):
        return value == default


def _short(v: Any) -> str:
    if isinstance(v, tuple):
        return "(" + ", ".join(f"{x:g}" for x in v) + ")"
    return f"{v:g}" if isinstance(v, float) else str(v)


PREVIEW_EXTRAS = ("normal", "emissiveColor", "occlusion", "displacement")
"""UsdPreviewSurface inputs with no preset parameter (besides opacity, read apart)."""


def preview_extras(surface: Node, nodes: dict[str, Node], texture_of) -> list[str]:
    """Loss lines for the UsdPreviewSurface inputs a preset cannot hold: the normal,
    emission, occlusion and displacement, and ``opacity`` read as alpha.

    ``opacity`` < 1 is alpha in every DCC importer: with ``opacityThreshold`` > 0 it is
    a cut-out (the spec's masked mode). A preset has neither alpha nor a cut-out, so the
    material is imported opaque and the alpha named; it is never turned into glass.
    """
    out = []
    for name in PREVIEW_EXTRAS:
        if name not in surface.inputs:
            continue
        value = surface.inputs[name][1]
        if isinstance(value, Connection):
            path = texture_of(nodes, value)
            shown = f"the map {path}" if path is not None else "a connected network"
            out.append(f"universal: {name} = {shown}: a preset has no {name} (not imported)")
        elif name == "emissiveColor" and max(value) > 0.0:
            out.append(f"universal: emissiveColor = {_short(value)}: a preset has no emission")
        elif name == "occlusion" and value < 1.0:
            out.append(f"universal: occlusion = {value:g}: a preset has no occlusion")
        elif name == "displacement" and value != 0.0:
            out.append(f"universal: displacement = {value:g}: a preset has no displacement")
    opacity = surface.inputs.get("opacity")
    threshold = surface.inputs.get("opacityThreshold", ("float", 0.0))[1]
    if opacity is not None:
        value = opacity[1]
        if isinstance(value, Connection):
            path = texture_of(nodes, value)
            shown = f"the map {path}" if path is not None else "a connected network"
        elif value >= 1.0:
            return out
        else:
            shown = f"{value:g}"
        cut = (
            f"a cut-out (opacityThreshold {_short(threshold)})"
            if isinstance(threshold, Connection) or threshold > 0.0
            else "alpha"
        )
        out.append(
            f"universal: opacity = {shown} is {cut}: a preset has no alpha or cut-out; "
            "imported opaque (not as transmission)"
        )
    return out


def specular_workflow(
    diffuse: tuple[float, float, float], colour: tuple[float, float, float]
) -> tuple[dict[str, Any], list[str]]:
    """Disney values of a UsdPreviewSurface in its specular workflow, and the losses.

    A grey-ish F0 up to Burley's plausible range (Y(F0) ≤ 0.08, ``specular`` ≤ 1) is a
    dielectric: ``specular`` = Y(F0)/0.08 (§5.4), metallic 0. A brighter F0 (copper
    ≈ 0.95) is a metal: base colour and metallic are solved as the layered Pixar export
    solves them (:func:`.pixar.metallic_workflow`, dielectric F0 0.04), so no IOR beyond
    the preset's range is ever made; F0 is clamped by :data:`~lookdev.materials.fresnel.F0_MAX`
    (the one clamp) before any conversion.
    """
    from .pixar import metallic_workflow

    f0 = min(luminance(colour), F0_MAX)
    losses = []
    if f0 <= SPECULAR_F0_SCALE:
        values = {"metallic": 0.0, "specular": f0 / SPECULAR_F0_SCALE, "base_color": diffuse}
        if max(colour) - min(colour) > 1e-6:
            losses.append(
                f"universal: the tint of specularColor {_short(colour)} (only its luminance "
                "is read, as Burley's specular)"
            )
        return values, losses
    base, metal = metallic_workflow(diffuse, colour, 1.5)
    values = {
        "metallic": float(metal),
        "specular": 0.5,
        "base_color": tuple(float(c) for c in base),
    }
    losses.append(
        f"universal: specular workflow (specularColor {_short(colour)}, F0 luminance "
        f"{f0:.3g} > {SPECULAR_F0_SCALE:g}) converted to metallic {float(metal):.3g}, base "
        f"colour {_short(tuple(round(float(c), 4) for c in base))}: a specular above "
        f"{1.0:g} (IOR > 1.8) would not be a dielectric"
    )
    return values, losses
