"""Blended materials → :class:`~.network.Source`: constants, or baked maps.

The exporter takes the blend (:class:`~lookdev.pipeline.blend.BlendedMaterial`), never a
preset: a plain material is all constants; a layered one has constants where uniform and
maps where a parameter varies, which :func:`lookdev.pipeline.blend.bake` writes as EXRs
beside the exported file for the networks to read. UsdPreviewSurface has no mix node, so
the universal context always reads the baked parameter maps. Which lobes live is the
blend's answer (:attr:`~lookdev.pipeline.blend.BlendedMaterial.live_lobes`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials import registry
from lookdev.materials.fresnel import specular_to_ior
from lookdev.materials.params import DisneyParams
from lookdev.pipeline.blend.result import LOBE_WEIGHTS, BlendedMaterial

from .live import live_stack
from .lobes import DEFAULTS, canonical
from .network import ExportError, Image, Source, source_from_params

SUPPORTED = registry.PRESET_MODELS  # a layered Pixar blend: see weights_source


def source_for(
    hub: BlendedMaterial, texture_dir: Path, *, scratch: Path, bake: bool = True
) -> Source:
    """The :class:`Source` of a blended material; varying parameters are baked to maps.

    Maps are baked into ``scratch`` and copied to ``texture_dir`` by the writer, so an
    export that fails leaves nothing behind. ``bake=False`` also records the kept layers
    so the MaterialX context mixes them live (:mod:`.live`); the universal and RenderMan
    contexts read the baked maps.
    """
    _check_model(hub.model, hub.name)
    if hub.representation == LOBE_WEIGHTS:
        return weights_source(hub, texture_dir)
    if not hub.layered:
        source = source_from_params(hub.name, hub.model, hub.params, hub.description)
        source.live = hub.live_lobes
        return source
    source = baked_source(hub, texture_dir, scratch)
    if not bake and len(hub.layers) > 1:
        source.layers = live_stack(hub, texture_dir)
    return source


def _check_model(model: str, name: str) -> None:
    if model not in SUPPORTED:
        raise ExportError(
            f"USD export of {model!r} materials is not implemented yet; "
            f"supported: {', '.join(SUPPORTED)}",
            where=name,
            field="model",
        )


def baked_source(hub: BlendedMaterial, texture_dir: Path, scratch: Path) -> Source:
    """Bake the varying parameters of a Disney blend and read the maps from there."""
    from lookdev.pipeline.blend import bake

    files = bake(hub, scratch)

    def image(name: str, array: np.ndarray) -> Image:
        return Image(texture_dir / files[name].name, np.flipud(array), True, files[name])

    maps = {name: image(name, array) for name, array in hub.maps.items()}
    if "specular" in maps:  # the universal surface reads the same F0 as an IOR
        ior = specular_to_ior(np.asarray(maps["specular"].pixels, np.float64)).astype(np.float32)
        maps["ior"] = Image(texture_dir / f"{hub.name}_ior.exr", ior, write=True)
    normal = None if hub.normal_map is None else image("normal_map", hub.normal_map)
    return Source(
        hub.name,
        hub.model,
        _constants(hub),
        maps=maps,
        normal_map=normal,
        spelling="specular",
        description=hub.description,
        notes=_specular_normal_note(hub),
        live=hub.live_lobes,
    )


def _specular_normal_note(blended) -> list[str]:
    """No target has Burley's separate specular normal (§6): say so where a blend has one."""
    if getattr(blended, "specular_normal_map", None) is None:
        return []
    return ["the specular normal map (Burley §6) is not written: no surface has a second normal"]


def _constants(hub: BlendedMaterial) -> dict[str, Any]:
    """Canonical values: the constants, and for mapped parameters their mean (a fallback)."""
    data = dict(hub.constants)
    data.update({name: hub.mean(name) for name in hub.maps})
    if "ior" in data and "specular" in data:
        del data["specular"]
    # Means of valid maps and blended constants are valid: not validated again.
    return canonical(DisneyParams.model_construct(**data))


def weights_source(hub: BlendedMaterial, texture_dir: Path) -> Source:
    """A Pixar blend (Smits' lobe weights): the target quantities, maps where they vary.

    Derived quantities (:func:`.pixar.from_weights`) are computed on the blend's arrays
    and written by the exporter beside the file; a quantity varies if any weight behind
    it does. The refraction IOR is the blend's (the uppermost present layer's per texel),
    averaged over the material: the networks carry one IOR.
    """
    from .pixar import from_weights

    arrays = {k: np.asarray(v) for k, v in {**hub.constants, **hub.maps}.items()}
    ior = arrays.pop("ior", None)
    eta = DEFAULTS["pixar_weights"]["eta"] if ior is None else float(np.mean(ior))
    values: dict[str, Any] = {"eta": eta}
    maps: dict[str, Image] = {}
    for name, value in from_weights(arrays, eta).items():
        if np.ndim(value) >= 2:
            path = texture_dir / f"{hub.name}_{name}.exr"
            maps[name] = Image(path, np.flipud(value).astype(np.float32), write=True)
            value = value.reshape(-1, *value.shape[2:]).mean(axis=0)
        values[name] = tuple(float(x) for x in value) if np.ndim(value) else float(value)
    normal = None
    if hub.normal_map is not None:  # encoded (n + 1)/2 like every normal map
        pixels = np.flipud(0.5 * hub.normal_map + 0.5).astype(np.float32)
        normal = Image(texture_dir / f"{hub.name}_normal_map.exr", pixels, write=True)
    return Source(
        hub.name,
        "pixar_weights",
        values,
        maps=maps,
        normal_map=normal,
        description=hub.description,
        notes=_specular_normal_note(hub),
        live=hub.live_lobes,
    )
