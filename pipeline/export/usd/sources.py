"""Blended materials → :class:`~.network.Source`: constants, or baked maps.

The exporter takes the blend (:class:`~lookdev.pipeline.blend.BlendedMaterial`), never a
preset: a plain material is all constants; a layered one has constants where uniform and
maps where a parameter varies, which :func:`lookdev.pipeline.blend.bake` writes as EXRs
beside the exported file for the networks to read. UsdPreviewSurface has no mix node, so
the universal context always reads the baked parameter maps. Which lobes live is the
blend's answer (:attr:`~lookdev.pipeline.blend.BlendedMaterial.live_lobes`).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials import registry
from lookdev.materials.fresnel import specular_to_ior
from lookdev.pipeline.blend.result import LOBE_WEIGHTS, BlendedMaterial

from .live import live_stack
from .lobes import DEFAULTS, canonical
from .network import ExportError, Image, Source, source_from_params, untargeted

__all__ = [
    "CHANNEL_OUTPUTS",
    "SUPPORTED",
    "baked_source",
    "colour_space_of_bake",
    "default_colorspace",
    "referable",
    "referenced_image",
    "source_for",
    "weights_source",
]

SUPPORTED = tuple(m for m in registry.PRESET_MODELS if m != "openpbr")
"""Models with name tables (a layered Pixar blend: see weights_source); an ``openpbr``
preset (an import kept as itself) is proofed, not re-exported."""


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
    if not hub.layered and not hub.arrays:
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
    """The varying parameters of a Disney blend: the preset's own files referenced where
    a parameter is read straight from one (``hub.textures``), the rest baked to maps."""
    from lookdev.pipeline.blend import bake

    referenced = {
        name: referenced_image(hub, name, ti, texture_dir)
        for name, ti in hub.textures.items()
        if referable(ti)
    }
    to_bake = dataclasses.replace(
        hub,
        maps={k: v for k, v in hub.maps.items() if k not in referenced},
        normal_map=None if "normal_map" in referenced else hub.normal_map,
        height_map=None if "height" in referenced else hub.height_map,
    )
    files = bake(to_bake, scratch) if to_bake.arrays else {}

    def image(name: str, array: np.ndarray, colour: bool = False) -> Image:
        space = colour_space_of_bake(colour)
        return Image(
            texture_dir / files[name].name,
            np.flipud(array),
            True,
            files[name],
            colorspace=space,
            fallback=_mean(array),
        )

    maps = {
        name: referenced.get(name) or image(name, array, np.ndim(array) == 3)
        for name, array in hub.maps.items()
    }
    if "specular" in maps:  # the universal surface reads the same F0 as an IOR
        spec = np.asarray(hub.maps["specular"], np.float64)
        ior = np.flipud(specular_to_ior(spec)).astype(np.float32)
        maps["ior"] = Image(texture_dir / f"{hub.name}_ior.exr", ior, write=True)
    normal = referenced.get("normal_map")
    if normal is None and hub.normal_map is not None:
        normal = image("normal_map", hub.normal_map)
    height = referenced.get("height")
    if height is None and hub.height_map is not None:
        height = image("height_map", hub.height_map)
    source = Source(
        hub.name,
        hub.model,
        _constants(hub),
        maps=maps,
        normal_map=normal,
        spelling="specular",
        description=hub.description,
        notes=_specular_normal_note(hub),
        live=hub.live_lobes,
        height=height,
    )
    return untargeted(source)


CHANNEL_OUTPUTS: dict[Any, str] = {
    **{c: c for c in ("r", "g", "b", "a", "rgb")},
    **{i: c for i, c in enumerate("rgba")},
}
"""TextureInput ``channel`` → the texture output that reads it (every target has these
five: UsdUVTexture r/g/b/a/rgb, PxrTexture resultR…resultRGB, MaterialX via extract)."""


def referable(ti: Any) -> bool:
    """True when a texture node can read ``ti`` as it is: its channel is one of a
    texture's five outputs (a named layer such as ``diffuse.R`` is baked instead)."""
    channel = ti.channel.lower() if isinstance(ti.channel, str) else ti.channel
    return channel is None or channel in CHANNEL_OUTPUTS


def referenced_image(hub: BlendedMaterial, name: str, ti: Any, texture_dir: Path) -> Image:
    """The preset's own file for parameter ``name``: its colour space, channel, the
    affine part of its value rule, and the parameter's mean as the fallback."""
    channel = ti.channel.lower() if isinstance(ti.channel, str) else ti.channel
    scale, bias = ti.scale, ti.offset
    if ti.range is not None:  # (x − lo)/(hi − lo)·s + o
        lo, hi = ti.range
        scale, bias = ti.scale / (hi - lo), ti.offset - lo * ti.scale / (hi - lo)
    array = {"normal_map": hub.normal_map, "height": hub.height_map}.get(name)
    if array is None:
        array = hub.maps.get(name)
    colour = array is not None and np.ndim(array) == 3 and name != "normal_map"
    space = ti.colorspace or default_colorspace(Path(ti.texture), colour)
    return Image(
        Path(ti.texture),
        None if array is None else np.flipud(array),
        colorspace=space,
        channel=CHANNEL_OUTPUTS.get(channel, "") if channel is not None else "",
        scale=float(scale),
        bias=float(bias),
        # A missing normal or height map reads as no perturbation, not as the mean.
        fallback=None if array is None or name in ("normal_map", "height") else _mean(array),
        wrap=ti.wrap,
        flip_y=bool(getattr(ti, "flip_y", False)),
        derived_dir=texture_dir,
        reference=True,
    )


def default_colorspace(path: Path, colour: bool) -> str:
    """The colour space of a file its texture input does not name: the one file rule,
    :func:`lookdev.materials.colour.texture_space`, on the file's stored format."""
    from lookdev.materials import colour as cm

    return cm.texture_space(_integer_coded(path), colour, None, str(path))


def _integer_coded(path: Path) -> bool:
    import OpenImageIO as oiio

    from lookdev.pipeline.blend.surface_maps import udim_tiles

    first = next(iter(sorted(udim_tiles(path).values())))
    image = oiio.ImageInput.open(str(first))
    if image is None:
        return False
    basetype = image.spec().format.basetype
    image.close()
    return basetype not in (oiio.HALF, oiio.FLOAT, oiio.DOUBLE)


def colour_space_of_bake(colour: bool) -> str:
    """Baked maps hold working-space values (colours) or data."""
    from lookdev.materials import colour as cm

    return cm.working_space() if colour else cm.RAW


def _mean(array: np.ndarray) -> Any:
    a = np.asarray(array, dtype=np.float64)
    m = a.reshape(-1, *a.shape[2:]).mean(axis=0)
    return tuple(float(x) for x in m) if np.ndim(m) else float(m)


def _specular_normal_note(blended) -> list[str]:
    """No target has Burley's separate specular normal (§6): say so where a blend has one."""
    if getattr(blended, "specular_normal_map", None) is None:
        return []
    return ["the specular normal map (Burley §6) is not written: no surface has a second normal"]


def _constants(hub: BlendedMaterial) -> dict[str, Any]:
    """Canonical values: the constants, and for mapped parameters their mean (a fallback)."""
    data = dict(hub.constants)
    data.update({name: hub.mean(name) for name in hub.maps})
    if "ior" in data and "specular" in data and hub.model == "disney":
        del data["specular"]
    # Means of valid maps and blended constants are valid: not validated again.
    return canonical(hub.bsdf_model.params_type.model_construct(**data))


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
