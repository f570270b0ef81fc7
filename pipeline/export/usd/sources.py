"""Library materials → :class:`~.network.Source`: constants, or baked blends.

A disney material is all constants. A layered one goes through the blending engine
(issue 5): :func:`lookdev.pipeline.blend.blend` gives constants where uniform and maps
where a parameter varies, :func:`lookdev.pipeline.blend.bake` writes those maps as EXRs
beside the exported file, and the networks read them. UsdPreviewSurface has no mix node,
so the universal context always reads the baked parameter maps.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials.fresnel import specular_to_ior
from lookdev.materials.params import DisneyParams

from .lobes import DEFAULTS, canonical
from .network import ExportError, Image, Source, source_from_params

SUPPORTED = ("disney", "pixar")  # layered Pixar: see weights_source


def source_for(
    material: Any, texture_dir: Path, resolution: int, *, scratch: Path, bake: bool = True
) -> Source:
    """The :class:`Source` of a library material; layered ones are blended and baked.

    Maps are baked into ``scratch`` and copied to ``texture_dir`` by the writer, so an
    export that fails leaves nothing behind. ``bake=False`` also records the layer stack
    so the MaterialX context mixes the layers live (:mod:`.live`); the universal and
    RenderMan contexts read the baked maps.
    """
    if material.model != "layered":
        _check_model(material.model, material.name)
        return source_from_params(
            material.name, material.model, material.params, material.description
        )
    source = baked_source(material, texture_dir, resolution, scratch)
    if not bake and source.model == "disney":  # Smits' layering is not a parameter mix
        from .live import live_stack

        source.layers = live_stack(material, texture_dir, resolution)
    return source


def _check_model(model: str, name: str) -> None:
    if model not in SUPPORTED:
        raise ExportError(
            f"USD export of {model!r} materials is not implemented yet; "
            f"supported: {', '.join(SUPPORTED)}",
            where=name,
            field="model",
        )


def baked_source(material: Any, texture_dir: Path, resolution: int, scratch: Path) -> Source:
    """Blend ``material``, bake its varying parameters, and read the maps from there."""
    from lookdev.pipeline.blend import bake, blend

    blended = blend(material, resolution)
    _check_model(blended.model, material.name)
    if getattr(blended, "representation", "params") == "lobe_weights":
        return weights_source(material, blended, texture_dir)
    files = bake(blended, scratch)

    def image(name: str, array: np.ndarray) -> Image:
        return Image(texture_dir / files[name].name, np.flipud(array), True, files[name])

    maps = {name: image(name, array) for name, array in blended.maps.items()}
    if "specular" in maps:  # the universal surface reads the same F0 as an IOR
        ior = specular_to_ior(np.asarray(maps["specular"].pixels, np.float64)).astype(np.float32)
        maps["ior"] = Image(texture_dir / f"{material.name}_ior.exr", ior, write=True)
    normal = None if blended.normal_map is None else image("normal_map", blended.normal_map)
    return Source(
        material.name,
        blended.model,
        _constants(blended),
        maps=maps,
        normal_map=normal,
        spelling="specular",
        description=material.description,
        notes=_specular_normal_note(blended),
    )


def _specular_normal_note(blended) -> list[str]:
    """No target has Burley's separate specular normal (§6): say so where a blend has one."""
    if getattr(blended, "specular_normal_map", None) is None:
        return []
    return ["the specular normal map (Burley §6) is not written: no surface has a second normal"]


def _constants(blended) -> dict[str, Any]:
    """Canonical values: the constants, and for mapped parameters their mean (a fallback)."""
    data = dict(blended.constants)
    for name, array in blended.maps.items():
        mean = np.asarray(array, dtype=np.float64).reshape(-1, *np.shape(array)[2:]).mean(axis=0)
        data[name] = tuple(float(x) for x in mean) if np.ndim(mean) else float(mean)
    if "ior" in data and "specular" in data:
        del data["specular"]
    return canonical(DisneyParams.parse(data, where=blended.name))


def weights_source(material: Any, blended, texture_dir: Path) -> Source:
    """A Pixar blend (Smits' lobe weights): the target quantities, maps where they vary.

    Derived quantities (:func:`.pixar.from_weights`) are computed on the blend's arrays
    and written by the exporter beside the file; a quantity varies if any weight behind
    it does. The refraction IOR is the blend's (the uppermost present layer's per texel),
    averaged over the material: the networks carry one IOR.
    """
    from .pixar import from_weights

    arrays = {k: np.asarray(v) for k, v in {**blended.constants, **blended.maps}.items()}
    ior = arrays.pop("ior", None)
    eta = DEFAULTS["pixar_weights"]["eta"] if ior is None else float(np.mean(ior))
    values: dict[str, Any] = {"eta": eta}
    maps: dict[str, Image] = {}
    for name, value in from_weights(arrays).items():
        if np.ndim(value) >= 2:
            path = texture_dir / f"{material.name}_{name}.exr"
            maps[name] = Image(path, np.flipud(value).astype(np.float32), write=True)
            value = value.reshape(-1, *value.shape[2:]).mean(axis=0)
        values[name] = tuple(float(x) for x in value) if np.ndim(value) else float(value)
    normal = None
    if blended.normal_map is not None:  # encoded (n + 1)/2 like every normal map
        pixels = np.flipud(0.5 * blended.normal_map + 0.5).astype(np.float32)
        normal = Image(texture_dir / f"{material.name}_normal_map.exr", pixels, write=True)
    return Source(
        material.name,
        "pixar_weights",
        values,
        maps=maps,
        normal_map=normal,
        description=material.description,
        notes=_specular_normal_note(blended),
    )
