"""How far the universal context's look is from the source material, measured.

The universal network's values (the ``UsdPreviewSurface`` a DCC previews) go into
UsdPreviewSurface's BRDF as its specification defines it
(:mod:`lookdev.materials.preview_surface`); the material itself is its own model from the
registry. Both are measured the same way: directional albedo E(θ) = ∫ f |cos θi| dωi at
view angles :data:`ANGLES`, by Monte Carlo over each model's own sampler (fixed seed: a
report is reproducible), per channel; and the highlight, f·cos θi at the mirror direction
of a 30° view: the light reflected within 10° of it (what a person sees first on a
sphere; an energy, so mirrors compare too). The report gives, per material,
the RMS and the worst albedo difference (with angle and channel) and the ratio of the
highlights' luminance, preview over source.

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

from .names import table_for
from .network import Connection, Source, plain_value
from .preview import build, preview_defaults

__all__ = [
    "ANGLES",
    "PREVIEW_SUFFIX",
    "Fidelity",
    "Measured",
    "PreviewHub",
    "fidelity",
    "measure",
    "preview_hub",
    "preview_params",
]

ANGLES = (0.0, 30.0, 45.0, 60.0, 75.0, 85.0)
"""View angles (degrees from the normal) at which albedo is compared."""
SAMPLES = 4096
CHANNELS = "RGB"


@dataclass(frozen=True)
class Fidelity:
    """One material's universal-context fidelity (see the module doc)."""

    material: str
    albedo_source: list[list[float]]  # per angle, RGB
    albedo_preview: list[list[float]]
    rms: float  # over angles and channels
    worst: float  # largest |difference|
    worst_at: str  # "60° G"
    highlight_ratio: float  # preview / source luminance of f·cos at the mirror direction

    def to_json(self) -> dict[str, Any]:
        return {
            "material": self.material,
            "angles_deg": list(ANGLES),
            "albedo_source": self.albedo_source,
            "albedo_preview": self.albedo_preview,
            "rms": self.rms,
            "worst": self.worst,
            "worst_at": self.worst_at,
            "highlight_ratio": self.highlight_ratio,
        }

    def row(self) -> list[str]:
        return [
            self.material,
            f"{self.rms:.3f}",
            f"{self.worst:+.3f} at {self.worst_at}",
            f"{self.highlight_ratio:.2f}",
        ]


def preview_params(source: Source, preview_opacity: str = "keep") -> PreviewParams:
    """The UsdPreviewSurface a DCC reads for ``source``: the universal network's values,
    the surface's defaults where an input is not written, a map's centre texel (else its
    mean) where an input is connected."""
    net = build(source, preview_opacity)
    surface = net.nodes[0]
    values = dict(preview_defaults())
    slots = {s.input: s for s in table_for("universal", source.model, preview_opacity)}
    for name, (_, value) in surface.inputs.items():
        value = plain_value(value)  # an interface input: the value it holds
        if isinstance(value, Connection):
            slot = slots.get(name)
            if slot is None:
                continue
            value = slot.to_target(_centre(source, slot.param))
        values[name] = value
    return PreviewParams(
        diffuse_color=_clip(values["diffuseColor"]),
        use_specular_workflow=bool(values.get("useSpecularWorkflow", 0)),
        specular_color=_clip(values["specularColor"]),
        metallic=min(max(float(values["metallic"]), 0.0), 1.0),
        roughness=min(max(float(values["roughness"]), 0.0), 1.0),
        clearcoat=float(values["clearcoat"]),
        clearcoat_roughness=min(max(float(values["clearcoatRoughness"]), 0.0), 1.0),
        ior=float(values["ior"]),
    )


def _centre(source: Source, param: str) -> Any:
    image = source.maps.get(param)
    if image is None or image.pixels is None:
        return source.live_values[param]
    px = np.asarray(image.pixels, np.float64)
    v = px[px.shape[0] // 2, px.shape[1] // 2]
    return tuple(float(x) for x in v) if np.ndim(v) else float(v)


def _clip(c: Any) -> tuple[float, float, float]:
    c = np.broadcast_to(np.asarray(c, np.float64), (3,))
    return tuple(float(x) for x in np.clip(c, 0.0, 1.0))


HIGHLIGHT_CONE_DEG = 10.0
"""The highlight is the light reflected within this angle of the mirror direction."""


@dataclass(frozen=True)
class Measured:
    """Directional albedo split by where the light leaves, and the highlight's energy,
    each (angles, RGB)."""

    reflected: np.ndarray
    transmitted: np.ndarray
    highlight: np.ndarray

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
    up, down, highlight = [], [], []
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
    return Measured(np.asarray(up), np.asarray(down), np.asarray(highlight))


def _measure(model, params, maps: dict[str, Any]) -> tuple[np.ndarray, np.ndarray]:
    m = measure(model, params, maps)
    return m.albedo, m.highlight


def fidelity(hub: Any, source: Source, preview_opacity: str = "keep") -> Fidelity:
    """Measure the universal context of ``source`` (made from ``hub``) against ``hub``."""
    model = hub.bsdf_model
    params, maps = _source_params(hub)
    preview = preview_params(source, preview_opacity)
    a_src, hl_src = _measure(model, params, maps)
    a_pre, hl_pre = _measure(PREVIEW, preview, {})
    diff = a_pre - a_src
    k = np.unravel_index(np.argmax(np.abs(diff)), diff.shape)
    at = ANGLES.index(30.0)
    h_src, h_pre = float(luminance(hl_src[at])), float(luminance(hl_pre[at]))
    return Fidelity(
        source.name,
        a_src.round(5).tolist(),
        a_pre.round(5).tolist(),
        float(np.sqrt(np.mean(diff * diff))),
        float(diff[k]),
        f"{ANGLES[k[0]]:g}° {CHANNELS[k[1]]}",
        h_pre / h_src if h_src > 0.0 else math.inf if h_pre > 0.0 else 1.0,
    )


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
