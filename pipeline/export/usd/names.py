"""The name tables: one per target, mapping lookdev parameters to shader inputs.

Each :class:`Slot` says which of our parameters feeds which input of the target's
surface, with what USD value type, and how a value converts there and back. A table is
the only place a target's spelling of a parameter appears (:doc:`/design`, Names).

Choice of MaterialX surface per model:

- Disney → ``ND_disney_principled``: MaterialX's port of Burley 2012 takes his eleven
  parameters as they are (plus ``specTrans``/``ior`` of the 2015 BSDF), so nothing is
  refitted; OpenPBR or Standard Surface would need a lossy re-parametrisation of
  ``specular_tint``, ``sheen`` and the GTR1 clearcoat.
- Pixar → ``ND_open_pbr_surface_surfaceshader``: Smits' lobe weights are colours with a
  normal and a grazing value; OpenPBR's ``specular_color`` (F0 tint) and its F82 edge
  behaviour are the closest match of any MaterialX surface, and it has a coat for the
  sharp reflection lobe, which ``disney_principled`` would force through Burley's fixed
  Fresnel.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

__all__ = [
    "CLEARCOAT_ALPHA",
    "CLEARCOAT_PREVIEW_SCALE",
    "DERIVED_FROM",
    "MTLX_DISNEY",
    "MTLX_PIXAR",
    "OPACITY_SLOTS",
    "PREVIEW_DISNEY",
    "PREVIEW_OPACITY",
    "PREVIEW_PIXAR",
    "PREVIEW_WEIGHTS",
    "RI_DISNEY",
    "RI_PIXAR",
    "SUBSURFACE_WEIGHT",
    "SURFACE_IDS",
    "Slot",
    "TABLES",
    "WEIGHTS_DERIVED_FROM",
    "gloss_to_roughness",
    "mapped_params",
    "roughness_to_gloss",
    "table_for",
]

CLEARCOAT_ALPHA = (0.1, 0.001)  # Burley App. B.2: α_c = mix(0.1, 0.001, clearcoat_gloss)
CLEARCOAT_PREVIEW_SCALE = 0.25  # Burley App. B.2: the clearcoat lobe is weighted 0.25·clearcoat


def _same(v):
    return v


@dataclass(frozen=True)
class Slot:
    """One parameter → one shader input, with conversions both ways.

    ``lobe`` names the lobe (see :mod:`.lobes`) whose weight gates the input: when the
    lobe is off the input is not written. ``texture_linear`` is ``(scale, bias)`` when
    ``to_target`` is affine, so a texture can be converted by ``UsdUVTexture``'s
    scale/bias instead of a rewritten image; ``None`` means it is not affine.
    """

    param: str
    input: str
    type: str  # Sdf value type name: float, color3f, int, bool
    lobe: str | None = None
    to_target: Callable = field(default=_same, repr=False)
    from_target: Callable = field(default=_same, repr=False)
    texture_linear: tuple[float, float] | None = (1.0, 0.0)


def gloss_to_roughness(gloss: float) -> float:
    """Burley's clearcoat gloss → the perceptual roughness r of a GGX lobe with α = r².

    Burley App. B.2 gives α = mix(0.1, 0.001, gloss); UsdPreviewSurface (like Burley's
    base lobe) squares its roughness, so r = √α.

    >>> round(gloss_to_roughness(1.0), 6), round(gloss_to_roughness(0.0), 6)
    (0.031623, 0.316228)
    """
    lo, hi = CLEARCOAT_ALPHA
    return math.sqrt(lo + (hi - lo) * gloss)


def roughness_to_gloss(r: float) -> float:
    """Inverse of :func:`gloss_to_roughness`, clamped to the gloss range 0..1.

    >>> round(roughness_to_gloss(gloss_to_roughness(0.3)), 6)
    0.3
    """
    lo, hi = CLEARCOAT_ALPHA
    return min(1.0, max(0.0, (r * r - lo) / (hi - lo)))


def _one_minus(v):
    return 1.0 - v


def _times(k: float) -> Callable[[float], float]:
    return lambda v: v * k


def _grey(v):
    return (v, v, v)


def _flag(v):
    return int(bool(v))


# UsdPreviewSurface in its metallic workflow (UsdPreviewSurface spec, 2.6).
PREVIEW_DISNEY: tuple[Slot, ...] = (
    Slot("base_color", "diffuseColor", "color3f"),
    Slot("metallic", "metallic", "float"),
    Slot("roughness", "roughness", "float"),
    # F0 = ((ior-1)/(ior+1))² in the spec's dielectric; Burley §5.4 F0 = 0.08·specular.
    Slot("ior", "ior", "float", lobe="dielectric"),
    # The spec's clearcoat is a white GGX lobe with F0 0.04 scaled by `clearcoat`;
    # Burley weights his 0.25·clearcoat, so scale by 0.25 to keep the reflected energy.
    Slot(
        "clearcoat",
        "clearcoat",
        "float",
        lobe="clearcoat",
        to_target=_times(CLEARCOAT_PREVIEW_SCALE),
        from_target=_times(1.0 / CLEARCOAT_PREVIEW_SCALE),
        texture_linear=(CLEARCOAT_PREVIEW_SCALE, 0.0),
    ),
    Slot(
        "clearcoat_gloss",
        "clearcoatRoughness",
        "float",
        lobe="clearcoat",
        to_target=gloss_to_roughness,
        from_target=roughness_to_gloss,
        texture_linear=None,
    ),
)

# Burley's parameters under their camelCase names, as both Disney targets spell them.
_BURLEY_CAMEL: tuple[Slot, ...] = (
    Slot("base_color", "baseColor", "color3f"),
    Slot("metallic", "metallic", "float"),
    Slot("roughness", "roughness", "float"),
    Slot("anisotropic", "anisotropic", "float", lobe="specular"),
    Slot("specular", "specular", "float", lobe="dielectric"),
    Slot("specular_tint", "specularTint", "float", lobe="dielectric"),
    Slot("sheen", "sheen", "float", lobe="sheen"),
    Slot("sheen_tint", "sheenTint", "float", lobe="sheen"),
    Slot("clearcoat", "clearcoat", "float", lobe="clearcoat"),
    Slot("clearcoat_gloss", "clearcoatGloss", "float", lobe="clearcoat"),
    Slot("spec_trans", "specTrans", "float", lobe="spec_trans"),
    Slot("ior", "ior", "float", lobe="spec_trans"),
)


def _largest(v):
    return max(v)


def _scatter(target_name: str) -> Slot:
    """The per-channel radius, ``scatter_distance · scatter_distance_scale`` in scene
    units: written whole by :func:`.network.subsurface_inputs` (it needs both parameters
    and the stage's unit); read back as its largest channel, the scale as each over it
    (:func:`lookdev.materials.subsurface.split_distances`). A distance map is written as
    it is (grey)."""
    return Slot(
        "scatter_distance",
        target_name,
        "color3f",
        lobe="scatter",
        to_target=_grey,
        from_target=_largest,
        texture_linear=None,
    )


SUBSURFACE_WEIGHT = "subsurface"
"""The subsurface weight's input on both Disney targets (ND_disney_principled and
PxrDisneyBsdf mix their diffuse towards subsurface by it)."""

# MaterialX 1.39 ND_disney_principled (libraries/bxdf/disney_principled.mtlx).
MTLX_DISNEY: tuple[Slot, ...] = (
    *_BURLEY_CAMEL,
    Slot("subsurface", SUBSURFACE_WEIGHT, "float", lobe="subsurface"),
    _scatter("subsurfaceDistance"),
)

# RenderMan PxrDisneyBsdf: Schutte's 2015 parameter set under RenderMan's own names
# (renderman_inputs.json, checked at export). Like
# Burley 2015 it has no `specular`: its dielectric F0 follows `ior` for reflection and
# refraction alike (RenderMan 24 docs, PxrDisneyBsdf, "Specular Reflect Scale"), so
# Burley 2012's specular reaches it as the IOR of the same F0 (§5.4).
RI_DISNEY: tuple[Slot, ...] = (
    *(s for s in _BURLEY_CAMEL if s.param not in ("specular", "ior")),
    Slot("ior", "ior", "float", lobe="dielectric"),
    Slot("diff_trans", "diffTrans", "float", lobe="diff_trans"),
    Slot("subsurface", SUBSURFACE_WEIGHT, "float", lobe="subsurface"),
    # Burley 2015's subsurface is tinted by the base colour; PxrDisneyBsdf takes that
    # tint as its own input (default: RenderMan's, not ours), so it is written.
    Slot("base_color", "subsurfaceColor", "color3f", lobe="subsurface_any"),
    _scatter("scatterDistances"),
    Slot("thin", "isThin", "int", lobe="thin", to_target=_flag, from_target=bool),
    # PxrDisneyBsdf has no `flatness` input: the loss note names it.
)

# UsdPreviewSurface for Smits' model: his surface colour, metallic blend and roughness
# play the roles of the surface's own (metallic workflow: diffuse goes to 0 and the
# highlight takes the surface colour as metallic → 1, as Smits' nRefl does).
# `roughness` passes as it is: it is the one control of highlight width and fade in
# both. `clear` (light passing straight through) reaches ``opacity`` only under
# ``--preview-opacity transmission`` (:data:`PREVIEW_OPACITY`).
PREVIEW_PIXAR: tuple[Slot, ...] = (
    Slot("surface_color", "diffuseColor", "color3f"),
    Slot("metallic", "metallic", "float"),
    Slot("roughness", "roughness", "float"),
    # Smits' nRefl scales metals too: live whatever the lobes, so not gated.
    Slot("eta", "ior", "float"),
)

PREVIEW_OPACITY = ("keep", "transmission")
"""How the universal context treats transmission. ``keep`` (the default): ``opacity``
stays 1 and the loss is named, because DCC importers read ``opacity`` as alpha (a
cut-out) and glass would arrive invisible. ``transmission``: the spec's own reading
(UsdPreviewSurface spec: opacity < 1 is translucent, refracting by ``ior``),
``opacity = 1 − spec_trans`` (Disney) or ``1 − clear`` (Pixar)."""

OPACITY_SLOTS: dict[str, Slot] = {
    model: Slot(
        param,
        "opacity",
        "float",
        lobe=lobe,
        to_target=_one_minus,
        from_target=_one_minus,
        texture_linear=(-1.0, 1.0),
    )
    for model, param, lobe in (("disney", "spec_trans", "spec_trans"), ("pixar", "clear", None))
}
"""model → the ``opacity`` slot written under ``--preview-opacity transmission``."""

# MaterialX OpenPBR for Smits' model (see the module note for the choice).
MTLX_PIXAR: tuple[Slot, ...] = (
    Slot("surface_color", "base_color", "color3f"),
    Slot("metallic", "base_metalness", "float"),
    # One specular lobe: Smits' two highlight lobes' energy-weighted roughness
    # (:func:`.pixar.highlight_roughness`), not the broad lobe's.
    Slot("highlight_roughness", "specular_roughness", "float", lobe="highlights"),
    Slot("specular_tint", "specular_color", "color3f", lobe="highlights"),
    Slot("eta", "specular_ior", "float", lobe="dielectric"),
    Slot("clear", "transmission_weight", "float", lobe="transmission"),
    Slot("transmission_tint", "transmission_color", "color3f", lobe="transmission"),
)

# RenderMan PxrSurface: its face/edge colours are Smits' normal/grazing weights. His
# broad "specular" is PxrSurface's rough specular, his sharp "reflection" its primary
# specular; his transmitted diffuse is PxrSurface's diffuse transmission and his
# refraction its glass lobe. Weights are written in full (PxrSurface is artistic mode:
# face/edge blended by (1 - cos)^5, Smits' FrnBlend).
RI_PIXAR: tuple[Slot, ...] = (
    Slot("front", "diffuseColor", "color3f", lobe="diffuse"),
    Slot("reflN", "specularFaceColor", "color3f", lobe="reflection"),
    Slot("reflG", "specularEdgeColor", "color3f", lobe="reflection"),
    Slot("refl_roughness", "specularRoughness", "float", lobe="reflection"),
    Slot("specN", "roughSpecularFaceColor", "color3f", lobe="specular"),
    Slot("specG", "roughSpecularEdgeColor", "color3f", lobe="specular"),
    Slot("spec_roughness", "roughSpecularRoughness", "float", lobe="specular"),
    Slot("behind", "diffuseTransmitColor", "color3f", lobe="diffuse_t"),
    Slot("reflTN", "refractionColor", "color3f", lobe="reflection_t"),
    Slot("refl_roughness", "glassRoughness", "float", lobe="reflection_t"),
    Slot("eta", "glassIor", "float", lobe="reflection_t"),
)

# A layered Pixar material blends to Smits' lobe weights, not to parameters (blend.pixar).
# UsdPreviewSurface takes them in its metallic workflow (:func:`.pixar.metallic_workflow`:
# the diffuse weight and the highlight colour at normal incidence, specN + reflN, solved
# per texel for a base colour and a metallic), one roughness for both highlight lobes.
# Not the specular workflow: DCC importers read specularColor as a tint on their own
# dielectric F0, and metal regions arrived ~25x too dark. The base colour is written
# even when black: the surface's default is grey.
PREVIEW_WEIGHTS: tuple[Slot, ...] = (
    Slot("preview_base", "diffuseColor", "color3f"),
    Slot("preview_metallic", "metallic", "float"),
    Slot("highlight_roughness", "roughness", "float", lobe="highlights"),
    Slot("eta", "ior", "float"),
)

# OpenPBR takes the same solved quantities: its metallic workflow mixes a dielectric of
# ``specular_ior`` and a metal of F0 ``base_color`` by ``base_metalness``, one specular
# lobe. Smits' composite is a layered scattering sum, not a mask mix of surfaces, so the
# mtlx network reads the composited weights' maps (no live mix of per-layer surfaces).
OPENPBR_WEIGHTS: tuple[Slot, ...] = (
    Slot("preview_base", "base_color", "color3f"),
    Slot("preview_metallic", "base_metalness", "float"),
    Slot("highlight_roughness", "specular_roughness", "float", lobe="highlights"),
    Slot("eta", "specular_ior", "float"),
)

TABLES: dict[tuple[str, str], tuple[Slot, ...]] = {
    ("universal", "disney"): PREVIEW_DISNEY,
    ("mtlx", "disney"): MTLX_DISNEY,
    ("ri", "disney"): RI_DISNEY,
    ("universal", "pixar"): PREVIEW_PIXAR,
    ("mtlx", "pixar"): MTLX_PIXAR,
    ("ri", "pixar"): RI_PIXAR,
    ("universal", "pixar_weights"): PREVIEW_WEIGHTS,
    ("mtlx", "pixar_weights"): OPENPBR_WEIGHTS,
    ("ri", "pixar_weights"): RI_PIXAR,
}
"""(context, model) → the table of that target."""

SURFACE_IDS: dict[tuple[str, str], str] = {
    ("universal", "disney"): "UsdPreviewSurface",
    ("mtlx", "disney"): "ND_disney_principled",
    ("ri", "disney"): "PxrDisneyBsdf",
    ("universal", "pixar"): "UsdPreviewSurface",
    ("mtlx", "pixar"): "ND_open_pbr_surface_surfaceshader",
    ("ri", "pixar"): "PxrSurface",
    ("universal", "pixar_weights"): "UsdPreviewSurface",
    ("mtlx", "pixar_weights"): "ND_open_pbr_surface_surfaceshader",
    ("ri", "pixar_weights"): "PxrSurface",
}
"""(context, model) → the surface shader's ``info:id``."""


def table_for(context: str, model: str, preview_opacity: str = "keep") -> tuple[Slot, ...]:
    """The name table of ``context`` for ``model`` (see :data:`PREVIEW_OPACITY`)."""
    table = TABLES[(context, model)]
    if context == "universal" and preview_opacity == "transmission" and model in OPACITY_SLOTS:
        return (*table, OPACITY_SLOTS[model])
    return table


_SMITS_WEIGHT = frozenset(
    (
        "surface_color metallic roughness clear back normal_fresnel grazing_fresnel "
        "specular_tint transmission_tint diffuse_scale specular_scale reflection_scale "
        "diffuse_t_scale reflection_t_scale"
    ).split()
)
DERIVED_FROM: dict[str, frozenset[str]] = {
    "spec_roughness": frozenset(("roughness", "specular_cone_scale")),
    "refl_roughness": frozenset(("roughness", "reflection_cone_scale")),
    **{w: _SMITS_WEIGHT for w in ("front", "behind", "specN", "specG", "reflN", "reflG")},
    "reflTN": _SMITS_WEIGHT,
    "eta": frozenset(("ior", "normal_fresnel")),
    "highlight_roughness": frozenset(("roughness", "specular_cone_scale", "reflection_cone_scale")),
    # The RGB radius carries both (Disney targets with a scatter-distance input).
    "scatter_distance": frozenset(("scatter_distance", "scatter_distance_scale")),
}
WEIGHTS_DERIVED_FROM: dict[str, frozenset[str]] = {
    "preview_base": frozenset(("front", "f0", "specN", "reflN")),
    "preview_metallic": frozenset(("front", "f0", "specN", "reflN")),
    "highlight_roughness": frozenset(("spec_roughness", "refl_roughness")),
}
"""A blend's preview quantities → the blended weights they carry (the grazing weights
specG/reflG are not among them: the surface's Schlick edge replaces them)."""
"""Derived target quantity (:mod:`.pixar`) → the parameters it carries."""


def mapped_params(context: str, model: str, preview_opacity: str = "keep") -> set[str]:
    """Our parameters that ``context`` expresses, directly or through derived weights."""
    derived = WEIGHTS_DERIVED_FROM if model == "pixar_weights" else DERIVED_FROM
    out: set[str] = set()
    for slot in table_for(context, model, preview_opacity):
        out |= derived.get(slot.param, {slot.param})
        if model == "pixar_weights":
            out.add(slot.param)
    return out
