"""How far the universal context's look is from the source material, measured.

The universal network's values (the ``UsdPreviewSurface`` a DCC previews) go into
UsdPreviewSurface's BRDF as its specification defines it
(:mod:`lookdev.materials.preview_surface`); the material itself is its own model from the
registry. Both are measured the same way: directional albedo E(θ) = ∫ f |cos θi| dωi at
view angles :data:`ANGLES`, by Monte Carlo over each model's own sampler (fixed seed: a
report is reproducible), per channel; and the highlight, f·cos θi at the mirror direction
of a 30° view: the light reflected within 10° of it (what a person sees first on a
sphere; an energy, so mirrors compare too). The report gives, per material,
the RMS and the worst albedo difference (with angle and channel), the ratio of the
highlights' luminance, preview over source, and the relative change of the
bihemispherical albedo's luminance (:func:`sphere_albedo`: what a ball shows under even
light, so it predicts a render's mean colour). :meth:`Fidelity.size` says those figures
in words for the loss note a DCC shows (:func:`.authoring.dcc_loss_note`).

Layered materials are measured at their centre texel; a layered Pixar material
(composited lobe weights) is measured from the preview values at its centre against the
blend's lobe-weight model there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials.colour import luminance
from lookdev.materials.preview_surface import MODEL as PREVIEW
from lookdev.materials.preview_surface import PreviewParams
from lookdev.pipeline.blend.result import BlendedMaterial

from .context_views import NOTES, preview_params, views
from .names import table_for
from .network import Connection, Source, plain_value
from .preview import build

__all__ = [
    "ANGLES",
    "PREVIEW_SUFFIX",
    "Fidelity",
    "Measured",
    "PreviewHub",
    "compared",
    "context_fidelity",
    "fidelity",
    "source_measured",
    "measure",
    "translation_loss",
    "preview_hub",
    "preview_params",
    "sphere_albedo",
]

SHORT = {
    "ND_open_pbr_surface_surfaceshader": "OpenPBR",
    "ND_disney_principled": "disney_principled",
    "ND_UsdPreviewSurface_surfaceshader": "UsdPreviewSurface",
}
"""Surface ids as the report table names them."""

ANGLES = (0.0, 30.0, 45.0, 60.0, 75.0, 85.0)
"""View angles (degrees from the normal) at which albedo is compared."""
SAMPLES = 4096
CHANNELS = "RGB"
FULLY_ALBEDO = 0.01
"""Below this relative albedo change (and :data:`FULLY_HIGHLIGHT`) a context expresses a
material fully: the Monte Carlo figures at :data:`SAMPLES` resolve about that much."""
FULLY_HIGHLIGHT = 0.05
"""… and the highlight's energy within this relative change."""


def sphere_albedo(albedo: Any) -> float:
    """The bihemispherical albedo's luminance, 2∫E(μ)μ dμ over μ = cos θ, from E(θ) at
    :data:`ANGLES` (per angle, RGB): trapezoids in μ, E held at its 85° value down to the
    horizon. It is the mean a sphere shows under even white light (each view angle
    weighted by the area it covers on the sphere's silhouette).

    >>> round(sphere_albedo([[0.5, 0.5, 0.5]] * len(ANGLES)), 6)
    0.5
    """
    lum = np.asarray(luminance(np.asarray(albedo, np.float64)))
    mu = np.concatenate([[0.0], np.cos(np.radians(ANGLES))[::-1]])
    e = np.concatenate([[lum[-1]], lum[::-1]])
    f = 2.0 * mu * e
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(mu)))


@dataclass(frozen=True)
class Fidelity:
    """One material's fidelity in one context (see the module doc). ``albedo_preview``
    is the context's albedo (the name is the universal context's, kept for scripts)."""

    material: str
    albedo_source: list[list[float]]  # per angle, RGB
    albedo_preview: list[list[float]]
    rms: float  # over angles and channels
    worst: float  # largest |difference|
    worst_at: str  # "60° G"
    highlight_ratio: float  # context / source luminance of f·cos near the mirror direction
    context: str = "universal"
    surface: str = "UsdPreviewSurface"
    highlight_width_source: float = 0.0  # degrees: the source's spread near the mirror
    highlight_width: float = 0.0  # degrees: the context's
    loss: str = ""  # what the network could not express (its surface's note)
    notes: tuple[str, ...] = ()  # renderer behaviours that change the look
    unavailable: str = ""  # why there is no figure (the context's model is not known)
    albedo_change: float = 0.0  # relative change of sphere_albedo, context over source

    @property
    def fully(self) -> bool:
        """The context shows the material within what the measurement resolves."""
        return (
            not self.unavailable
            and abs(self.albedo_change) <= FULLY_ALBEDO
            and abs(self.highlight_ratio - 1.0) <= FULLY_HIGHLIGHT
        )

    def size(self) -> str:
        """The figures in words, e.g. ``albedo −3.9 %, highlight −2 %, albedo RMS 0.13``."""
        if self.unavailable:
            return ""
        return (
            f"albedo {_signed(100 * self.albedo_change, 1)} %, highlight "
            f"{_signed(100 * (self.highlight_ratio - 1.0), 0)} %, albedo RMS {self.rms:.2f}"
        )

    def to_json(self) -> dict[str, Any]:
        if self.unavailable:  # no figures: null, not NaN (which JSON does not have)
            blank = dict.fromkeys(
                ("albedo_preview", "rms", "worst", "highlight_ratio", "albedo_change")
            )
            return {**self._json(), **blank, "highlight_width_deg": None}
        return self._json()

    def _json(self) -> dict[str, Any]:
        return {
            "material": self.material,
            "context": self.context,
            "surface": self.surface,
            "angles_deg": list(ANGLES),
            "albedo_source": self.albedo_source,
            "albedo_preview": self.albedo_preview,
            "rms": self.rms,
            "worst": self.worst,
            "worst_at": self.worst_at,
            "highlight_ratio": self.highlight_ratio,
            "highlight_width_source_deg": self.highlight_width_source,
            "highlight_width_deg": self.highlight_width,
            "albedo_change": self.albedo_change,
            "size": self.size(),
            "fully": self.fully,
            "loss": self.loss,
            "notes": list(self.notes),
            "unavailable": self.unavailable,
        }

    def row(self) -> list[str]:
        where = f"{self.context} {SHORT.get(self.surface, self.surface)}"
        if self.unavailable:
            return [self.material, where, "not available", "", "", ""]
        return [
            self.material,
            where,
            f"{self.rms:.3f}",
            f"{self.worst:+.3f} at {self.worst_at}",
            f"{self.highlight_ratio:.2f}",
            f"{self.highlight_width_source:.1f}° → {self.highlight_width:.1f}°",
        ]


HIGHLIGHT_CONE_DEG = 10.0
"""The highlight is the light reflected within this angle of the mirror direction."""
WIDTH_CONE_DEG = 30.0
"""The highlight's width: the RMS angle from the mirror direction of the light (luminance)
reflected within this angle of it (the diffuse within it included, for both sides)."""


@dataclass(frozen=True)
class Measured:
    """Directional albedo split by where the light leaves, and the highlight's energy,
    each (angles, RGB)."""

    reflected: np.ndarray
    transmitted: np.ndarray
    highlight: np.ndarray
    width: np.ndarray  # per angle: RMS angle (degrees) from the mirror within WIDTH_CONE_DEG

    @property
    def albedo(self) -> np.ndarray:
        return self.reflected + self.transmitted


def measure(model, params, maps: dict[str, Any], samples: int = SAMPLES) -> Measured:
    """E(θ) per angle and channel by the model's own sampler (fixed seed), split into the
    light leaving above and below the surface, and the part reflected within
    :data:`HIGHLIGHT_CONE_DEG` of the mirror direction (the highlight's energy: finite
    for mirrors too, unlike a peak value)."""
    from lookdev.materials.bsdf import draw

    rng = np.random.default_rng(7)
    maps = {k: np.broadcast_to(v, (samples, *np.shape(v))) for k, v in maps.items()}
    cone = math.cos(math.radians(HIGHLIGHT_CONE_DEG))
    up, down, highlight, width = [], [], [], []
    wide = math.cos(math.radians(WIDTH_CONE_DEG))
    for deg in ANGLES:
        t = math.radians(deg)
        wo = np.array([math.sin(t), 0.0, math.cos(t)])
        mirror = np.array([-wo[0], 0.0, wo[2]])
        u = rng.random((samples, 3))
        wi, weight, _ = draw(model, params, np.broadcast_to(wo, (samples, 3)), u, **maps)
        weight = np.where(np.isfinite(weight), weight, 0.0)
        above = (wi[:, 2] >= 0.0)[:, None]
        near = (wi @ mirror) >= cone
        up.append((weight * above).mean(axis=0))
        down.append((weight * ~above).mean(axis=0))
        highlight.append((weight * near[:, None]).mean(axis=0))
        cos_m = np.clip(wi @ mirror, -1.0, 1.0)
        lum = np.where(cos_m >= wide, luminance(weight), 0.0)
        theta = np.degrees(np.arccos(cos_m))
        total = lum.sum()
        width.append(math.sqrt(float((lum * theta**2).sum() / total)) if total > 0 else 0.0)
    return Measured(np.asarray(up), np.asarray(down), np.asarray(highlight), np.asarray(width))


def _signed(x: float, digits: int) -> str:
    """``+3.1`` / ``−3.1`` (a minus sign, not a hyphen); zero unsigned."""
    text = f"{abs(x):.{digits}f}"
    if float(text) == 0.0:
        return text
    return ("+" if x > 0 else "\u2212") + text


def _ratio(a: float, b: float) -> float:
    return a / b if b > 0.0 else math.inf if a > 0.0 else 1.0


def compared(name: str, src: Measured, got: Measured, **about: Any) -> Fidelity:
    """The :class:`Fidelity` of ``got`` (a context's model) against ``src`` (the
    material's own): albedo RMS and worst over angles × channels, the highlight's energy
    and width at the 30° view as ratios."""
    a_src, a_got = src.albedo, got.albedo
    diff = a_got - a_src
    k = np.unravel_index(np.argmax(np.abs(diff)), diff.shape)
    at = ANGLES.index(30.0)
    return Fidelity(
        name,
        a_src.round(5).tolist(),
        a_got.round(5).tolist(),
        float(np.sqrt(np.mean(diff * diff))),
        float(diff[k]),
        f"{ANGLES[k[0]]:g}° {CHANNELS[k[1]]}",
        _ratio(float(luminance(got.highlight[at])), float(luminance(src.highlight[at]))),
        highlight_width_source=round(float(src.width[at]), 3),
        highlight_width=round(float(got.width[at]), 3),
        albedo_change=_ratio(sphere_albedo(a_got), sphere_albedo(a_src)) - 1.0,
        **about,
    )


def source_measured(hub: Any) -> Measured:
    """The material's own model measured (at its centre texel when it varies)."""
    params, maps = _source_params(hub)
    return measure(hub.bsdf_model, params, maps)


def fidelity(hub: Any, source: Source, preview_opacity: str = "keep") -> Fidelity:
    """Measure the universal context of ``source`` (made from ``hub``) against ``hub``."""
    preview = preview_params(source, preview_opacity)
    return compared(source.name, source_measured(hub), measure(PREVIEW, preview, {}))


def context_fidelity(
    hub: Any, source: Source, preview_opacity: str = "keep", meters_per_unit: float = 1.0
) -> list[Fidelity]:
    """Every context of ``source`` (both ``mtlx`` surfaces of a Disney material) measured
    against ``hub`` (:mod:`.context_views`); a context whose model is not available gets
    its reason instead of figures."""
    src = source_measured(hub)
    out = []
    for view in views(source, preview_opacity, meters_per_unit):
        about = {
            "context": view.context,
            "surface": view.surface,
            "loss": view.loss,
            "notes": tuple(view.notes),
        }
        if view.model is None:
            nan = [[math.nan] * 3 for _ in ANGLES]
            out.append(
                Fidelity(
                    source.name,
                    src.albedo.round(5).tolist(),
                    nan,
                    math.nan,
                    math.nan,
                    "",
                    math.nan,
                    unavailable=view.unavailable,
                    **about,
                )  # fmt: skip
            )
            continue
        out.append(compared(source.name, src, measure(view.model, view.params, {}), **about))
    return out


TRANSLATION_TOLERANCE = 0.02
"""Albedo RMS above which an OpenPBR → Disney import names its measured loss: twice the
Monte Carlo error of :data:`SAMPLES` samples a view (≈ 0.005 RMS for two estimates)."""


def translation_loss(openpbr: Any, disney: Any, source: str = "OpenPBR") -> str:
    """The loss line of an OpenPBR material imported as Burley's (``disney``, its
    :class:`~lookdev.materials.params.DisneyParams`) when their directional albedos
    differ by more than :data:`TRANSLATION_TOLERANCE` RMS, else ``""``: the measured RMS
    and worst difference, and the terms of :data:`.openpbr_map.LOSSES` the two models do
    not share for these values (the mapping's losses, read the other way). ``source``
    names what the OpenPBR parameters came from."""
    from lookdev.materials import registry

    from .lobes import active_lobes, canonical
    from .openpbr_map import losses_of

    src = measure(registry.model_named("openpbr"), openpbr, {})
    fid = compared("", src, measure(registry.model_named("disney"), disney, {}))
    if not fid.rms > TRANSLATION_TOLERANCE:
        return ""
    values = canonical(disney)
    lobes = active_lobes(values)
    terms = [loss.name for loss in losses_of(values, lobes)]
    line = (
        f"{source} → Burley: the translated material's directional albedo differs from "
        f"the OpenPBR source by RMS {fid.rms:.3f} (worst {fid.worst:+.3f} at "
        f"{fid.worst_at}; tolerance {TRANSLATION_TOLERANCE:g}), from the terms that do "
        f"not carry over exactly: {', '.join(terms) or 'none named'}"
    )
    return f"{line}; {NOTES['medium']}" if lobes.get("scatter") else line


def _source_params(hub: Any) -> tuple[Any, dict[str, Any]]:
    """The source model's parameters at the centre texel (constants where uniform)."""
    if not hub.maps:
        return hub.params, {}
    height, width = next(iter(hub.maps.values())).shape[:2]
    values = hub.values_at(height // 2, width // 2)
    fields = hub.bsdf_model.params_type.model_fields
    if hub.representation == "params":
        return hub.bsdf_model.params_type.model_construct(
            **{k: v for k, v in values.items() if k in fields}
        ), {}
    # Lobe weights: the constants as parameters, the centre texel's weights as maps.
    maps = {k: np.asarray(v, np.float64) for k, v in values.items() if k in hub.maps}
    return hub.params, maps


PREVIEW_SUFFIX = "-universal"
"""Name suffix of a material's universal-context proof (``lookdev proof --context``)."""

_PREVIEW_FIELDS = {
    "diffuseColor": "diffuse_color",
    "metallic": "metallic",
    "roughness": "roughness",
    "clearcoat": "clearcoat",
    "clearcoatRoughness": "clearcoat_roughness",
    "ior": "ior",
    "specularColor": "specular_color",
    "useSpecularWorkflow": "use_specular_workflow",
}
"""UsdPreviewSurface input → :class:`PreviewParams` field."""
PREVIEW_MAPPED = ("diffuse_color", "metallic", "roughness")
"""Fields the preview model takes per texel (the rest as their map's centre value)."""


class PreviewHub(BlendedMaterial):
    """A blended material rendered by UsdPreviewSurface's own BRDF (spec 2.5)."""

    @property
    def bsdf_model(self):
        return PREVIEW


def preview_hub(hub: Any, source: Source | None = None) -> Any:
    """What a DCC's preview shows of ``hub``: its universal context's values rendered by
    UsdPreviewSurface's BRDF (:mod:`lookdev.materials.preview_surface`), named
    ``NAME-universal``, maps of the base colour, metallic and roughness kept per texel.

    ``source`` is the exporter's view of ``hub`` (built here when not given: maps baked to
    a scratch folder that is removed).
    """
    import tempfile

    from .sources import source_for

    if source is None:
        with tempfile.TemporaryDirectory(prefix="lookdev-preview-") as tmp:
            source = source_for(hub, Path(tmp) / "tex", scratch=Path(tmp), bake=True)
            return _preview_hub(hub, source)
    return _preview_hub(hub, source)


def _preview_hub(hub: Any, source: Source) -> Any:
    net = build(source)
    surface = net.nodes[0]
    slots = {s.input: s for s in table_for("universal", source.model)}
    constants = preview_params(source).model_dump()
    maps: dict[str, np.ndarray] = {}
    for name, (_, value) in surface.inputs.items():
        value = plain_value(value)
        field = _PREVIEW_FIELDS.get(name)
        slot = slots.get(name)
        if not isinstance(value, Connection) or field not in PREVIEW_MAPPED or slot is None:
            continue
        image = source.maps.get(slot.param)
        if image is None or image.pixels is None:
            continue
        px = np.flipud(np.asarray(image.pixels, np.float64))  # back to UV order
        converted = np.vectorize(slot.to_target, otypes=[np.float64])(px)
        if field == "diffuse_color":
            converted = np.clip(converted, 0.0, 1.0)
        maps[field] = converted.astype(np.float32)
        constants.pop(field, None)
    width, height = hub.resolution
    out = PreviewHub(f"{hub.name}{PREVIEW_SUFFIX}", PREVIEW.name, hub.resolution, constants)
    out.maps = maps
    if hub.normal_map is not None:
        out.normal_map = hub.normal_map
    out.description = f"{hub.name} as UsdPreviewSurface shows it"
    if not maps:
        out.__dict__["params"] = PreviewParams.parse(constants)
    return out
