"""What each render context's renderer evaluates: its network read back into a model.

A context is measured by reading the network the writer builds, the way a renderer
reads it: the written values, the surface's own defaults where an input is not written,
a map's centre texel where an input is connected, and the model of that surface:

- ``UsdPreviewSurface`` (universal):
  :mod:`lookdev.materials.preview_surface`;
- ``ND_open_pbr_surface_surfaceshader``: :mod:`lookdev.materials.openpbr`;
- ``ND_disney_principled`` and ``PxrDisneyBsdf``: Burley's model
  (:mod:`lookdev.materials.disney`) with the parameters their name tables carry back:
  what is measured is what the names and the surfaces' defaults lose, not each
  renderer's own implementation of Burley's lobes, which is not available here;
- ``PxrSurface``: not available to evaluate (RenderMan's own lobes); no figure.

Renderer behaviours that change the look are named with the view (:data:`NOTES`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lookdev.materials.errors import LookdevError
from lookdev.materials.params import DisneyParams
from lookdev.materials.preview_surface import PreviewParams
from lookdev.materials.registry import MODELS

from .names import table_for
from .network import Connection, Network, Source, plain_value
from .preview import build, preview_defaults

__all__ = ["MTLX_SUFFIX", "NOTES", "ContextView", "mtlx_hub", "preview_params", "views"]

NOTES = {
    "mtlx_layered": "RenderMan's MaterialX path does not layer (\"we don't support material "
    'layering via MaterialX"): the live mix chains of this network render unlayered there',
    "storm": "Storm renders this context; it ignores material bindings of purpose `full` "
    "only, and lookdev binds all-purpose",
    "medium": "Burley's solid sends light into a scattering interior (its volume colours it "
    "there): its surface albedo counts that light as it enters, where OpenPBR's reduction "
    "and the other surfaces reflect a colour at the surface; the figures compare the two",
}
"""Known renderer behaviours, named where they apply."""


@dataclass
class ContextView:
    """One context as its renderer sees it: the model and parameters, or why not."""

    context: str
    surface: str
    model: Any = None
    params: Any = None
    loss: str = ""
    unavailable: str = ""
    notes: list[str] = field(default_factory=list)


def preview_params(source: Source, preview_opacity: str = "keep") -> PreviewParams:
    """The UsdPreviewSurface a DCC reads for ``source``: the universal network's values,
    the surface's defaults where an input is not written, a map's centre texel (else its
    mean) where an input is connected."""
    net = build(source, preview_opacity)
    table = table_for("universal", source.model, preview_opacity)
    values = {**preview_defaults(), **_surface_values(net, source, table)}
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


def _surface_values(net: Network, source: Source, table) -> dict[str, Any]:
    """Input → value of the network's surface: constants as written, connected inputs
    as their slot converts the parameter's centre texel."""
    surface = net.nodes[0]
    slots = {s.input: s for s in table}
    out = {}
    for name, (_, value) in surface.inputs.items():
        value = plain_value(value)  # an interface input: the value it holds
        if isinstance(value, Connection):
            slot = slots.get(name)
            if slot is None:
                continue
            value = slot.to_target(_centre(source, slot.param))
        out[name] = value
    return out


def _openpbr(net: Network, source: Source) -> Any:
    from .openpbr_import import params_from_values
    from .openpbr_map import DIRECT, openpbr_values

    if source.model == "disney":
        table = DIRECT
        values = _surface_values(net, source, table)
        centre = {
            k: _centre(source, k) if k in source.maps else v for k, v in source.live_values.items()
        }
        derived = openpbr_values(centre, source.lobes)
        for name, (_, value) in net.nodes[0].inputs.items():
            if isinstance(plain_value(value), Connection) and name not in values:
                values[name] = derived[name]  # a mix chain of a derived input: its centre
    else:
        values = _surface_values(net, source, table_for("mtlx", source.model))
    values.pop("geometry_normal", None)
    params, _ = params_from_values(values, source.name)
    return params


def _disney(net: Network, source: Source, context: str) -> DisneyParams:
    """Burley's parameters as a Disney name table carries them back (unwritten inputs:
    lookdev's defaults, which MaterialX's and lookdev's Disney defaults share)."""
    table = table_for(context, "disney")
    values = _surface_values(net, source, table)
    out: dict[str, Any] = {}
    for slot in table:
        if slot.input in values and slot.param not in out:
            v = slot.from_target(values[slot.input])
            number = isinstance(v, int | float) and not isinstance(v, bool)
            out[slot.param] = float(v) if number else v
    if "scatter_distance" in out:
        out.pop("scatter_distance")  # the radius is in scene units: keep the source's
    keep = {"sheen_model", "sheen_roughness", "scatter_distance", "scatter_distance_scale"}
    out.update({k: source.live_values[k] for k in keep if k in source.live_values})
    if "ior" in out and "specular" in out:
        out.pop("ior")
    fields = DisneyParams.model_fields
    return DisneyParams.model_construct(**{k: v for k, v in out.items() if k in fields})


def views(
    source: Source, preview_opacity: str = "keep", meters_per_unit: float = 1.0
) -> list[ContextView]:
    """Every context of ``source`` (both ``mtlx`` surfaces of a Disney material) as the
    renderer sees it."""
    from lookdev.materials.openpbr import MODEL as OPENPBR
    from lookdev.materials.preview_surface import MODEL as PREVIEW

    from . import mtlx, preview, ri

    out = [
        ContextView(
            "universal",
            "UsdPreviewSurface",
            PREVIEW,
            preview_params(source, preview_opacity),
            _loss(preview.build(source, preview_opacity)),
            notes=[NOTES["storm"]],
        )
    ]
    surfaces = ("openpbr", "disney") if source.model == "disney" else ("openpbr",)
    for surface in surfaces:
        net = mtlx.build(source, meters_per_unit, surface)
        node_id = net.nodes[0].id
        view = ContextView("mtlx", node_id, loss=_loss(net))
        if any(n.id.startswith("ND_mix_") for n in net.nodes):
            view.notes.append(NOTES["mtlx_layered"])
        if node_id == "ND_open_pbr_surface_surfaceshader":
            view.model, view.params = OPENPBR, _openpbr(net, source)
        elif node_id == "ND_disney_principled":
            view.model, view.params = MODELS["disney"], _disney(net, source, "mtlx")
        elif node_id == "ND_UsdPreviewSurface_surfaceshader":
            view.model, view.params = PREVIEW, preview_params(source, preview_opacity)
        out.append(view)
    net = ri.build(source, meters_per_unit)
    node_id = net.nodes[0].id
    view = ContextView("ri", node_id, loss=_loss(net))
    if node_id == "PxrDisneyBsdf":
        view.model, view.params = MODELS["disney"], _disney(net, source, "ri")
    else:
        view.unavailable = f"{node_id}'s BSDF (RenderMan's own lobes) is not available to evaluate"
    out.append(view)
    if source.lobes.get("scatter"):
        for view in out:
            view.notes.append(NOTES["medium"])
    return out


def _loss(net: Network) -> str:
    return "; ".join(n.custom["loss"] for n in net.nodes if n.custom.get("loss"))


MTLX_SUFFIX = "-mtlx"
"""Name suffix of a material's ``mtlx``-context proof (``lookdev proof --context mtlx``)."""

_MAPPED_OPENPBR = {"base_color": "base_color", "metallic": "base_metalness"}
"""Disney maps an OpenPBR proof keeps per texel (the rest at their centre value)."""


def mtlx_hub(hub: Any) -> Any:
    """What an OpenPBR renderer shows of ``hub``: its ``mtlx`` context as OpenPBR Surface
    (:mod:`.mtlx_openpbr`, or Smits' table for Pixar presets) rendered by the OpenPBR
    model (:mod:`lookdev.materials.openpbr`), named ``NAME-mtlx``; base colour and
    metalness maps kept per texel, roughness too where no anisotropy changes it."""
    import tempfile
    from pathlib import Path

    from lookdev.pipeline.blend.result import BlendedMaterial

    from .sources import source_for

    with tempfile.TemporaryDirectory(prefix="lookdev-mtlx-") as tmp:
        source = source_for(hub, Path(tmp) / "tex", scratch=Path(tmp), bake=True)
        view = next(v for v in views(source) if v.context == "mtlx")
    if view.model is None or view.model.name != "openpbr":
        raise LookdevError(f"{hub.name}: its mtlx context is {view.surface}, not OpenPBR")
    constants = view.params.model_dump()
    maps: dict[str, np.ndarray] = {}
    mapped = dict(_MAPPED_OPENPBR)
    if source.live_values.get("anisotropic", 0.0) == 0.0:
        mapped["roughness"] = "specular_roughness"
    if source.model == "disney":
        for param, field_name in mapped.items():
            if param in hub.maps:
                maps[field_name] = np.asarray(hub.maps[param], np.float32)
                constants.pop(field_name, None)
    out = BlendedMaterial(f"{hub.name}{MTLX_SUFFIX}", "openpbr", hub.resolution, constants)
    out.maps = maps
    if hub.normal_map is not None:
        out.normal_map = hub.normal_map
    out.description = f"{hub.name} as an OpenPBR renderer shows its mtlx context"
    if not maps:
        out.__dict__["params"] = view.params
    return out
