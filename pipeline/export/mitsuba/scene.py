"""Materials as Mitsuba BSDF dictionaries and minimal scenes (issue 7).

:func:`bsdf_dict` turns a preset's material (or a blended one) into the dictionary
``mi.load_dict`` takes: our own plugin (:mod:`.plugin`) for the material's model, with
uniform parameters as constants and varying ones as ``bitmap`` textures. Mitsuba's
built-in ``principled`` replaces it only where the two were measured equal (see
:func:`principled_equivalent`). :func:`.depth.max_depth_for` sizes the path tracer to what
the material needs and :func:`.sphere_scene.scene_dict` is the small export scene (one
sphere under an environment) that ``lookdev export mitsuba`` writes.

Texture orientation: Mitsuba's bitmap puts an image's row 0 at v = 0, and a blended map's
texel (0, 0) is UV (0, 0), so maps go to Mitsuba row for row, in memory and in EXR files.
"""

from __future__ import annotations

import importlib
import os
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.materials.bsdf import Model
from lookdev.materials.params import Params
from lookdev.materials.pixar import GRAZING

from .normals import with_normals
from .plugin import (
    FORCE_ALL_LOBES,
    MitsubaExportError,
    is_color_field,
    register_model,
)

MODEL_MODULES = {
    "disney": "lookdev.materials.disney",
    "sheen": "lookdev.materials.sheen",
    "pixar": "lookdev.materials.pixar",
    "pixar_layered": "lookdev.materials.pixar:LAYERED_MODEL",
}
"""Where each model lives (``module`` for its ``MODEL``, or ``module:NAME``); a plugin
``lookdev_<name>`` is registered for each."""

DEFAULT_MAP_RESOLUTION = 512


def model_for(name: str) -> Model:
    """The :class:`Model` called ``name`` (its module's ``MODEL``)."""
    module = MODEL_MODULES.get(name)
    if module is None:
        raise MitsubaExportError(
            f"no Mitsuba plugin for model {name!r}; known: {', '.join(MODEL_MODULES)}"
        )
    module, _, attr = module.partition(":")
    try:
        return getattr(importlib.import_module(module), attr or "MODEL")
    except (ImportError, AttributeError) as exc:
        raise MitsubaExportError(
            f"model {name!r} is not available ({module}.MODEL: {exc})"
        ) from None


def register_plugins() -> dict[str, str]:
    """Register a Mitsuba plugin per available model; ``{model: plugin name}``.

    Sets the Mitsuba variant first (:func:`lookdev.pipeline.variant.use_mitsuba`) unless one
    is set already. Call this before ``mi.load_dict`` / ``mi.load_file`` of our scenes.
    """
    _ensure_variant()
    names = {}
    for name in MODEL_MODULES:
        try:
            names[name] = register_model(model_for(name))
        except MitsubaExportError:
            continue  # a model not written yet simply has no plugin
    return names


def _ensure_variant() -> None:
    import mitsuba as mi

    if mi.variant() is None:
        from lookdev.pipeline.variant import use_mitsuba

        use_mitsuba()


@dataclass
class Flat:
    """A material reduced to what a BSDF needs: model, constants and maps."""

    name: str
    model: str
    constants: dict[str, Any]
    maps: dict[str, np.ndarray] = field(default_factory=dict)
    normal_map: np.ndarray | None = None
    specular_normal_map: np.ndarray | None = None  # the highlights' own (see .normals)


def flatten(material: Any, resolution: int = DEFAULT_MAP_RESOLUTION) -> Flat:
    """A Params object, a library ``Material`` or a ``BlendedMaterial`` as a :class:`Flat`.

    Layered materials are blended first (:func:`lookdev.pipeline.blend.blend`) at
    ``resolution`` texels a side; a :class:`Flat` is returned as it is.
    """
    if isinstance(material, Flat):
        return material
    if isinstance(material, Params):
        return Flat(type(material).__name__, _model_of(material), _given(material))
    if getattr(material, "maps", None) is not None:  # a BlendedMaterial
        return _from_blended(material)
    if getattr(material, "model", None) == "layered":
        from lookdev.pipeline.blend import blend

        return _from_blended(blend(material, resolution))
    if getattr(material, "params", None) is not None:
        return Flat(material.name, material.model, _given(material.params))
    raise MitsubaExportError(f"cannot make a Mitsuba BSDF from {type(material).__name__}")


def _model_of(params: Params) -> str:
    for name in MODEL_MODULES:
        try:
            if isinstance(params, model_for(name).params_type):
                return name
        except MitsubaExportError:
            continue
    raise MitsubaExportError(f"no model takes parameters of type {type(params).__name__}")


def _given(params: Params) -> dict[str, Any]:
    """The parameters a preset gave (defaults are the schema's, on both sides)."""
    return {k: v for k, v in params.model_dump(exclude_unset=True).items() if v is not None}


LAYERED_MODELS = {"pixar": "pixar_layered"}
"""The model that renders a blend of ``representation = "lobe_weights"`` (Smits' weights)."""
BLEND_ONLY = frozenset({"layering"})
"""Constants a blend records for the record, which no BSDF takes."""


def _from_blended(blended: Any) -> Flat:
    model = blended.model
    if getattr(blended, "representation", "params") == "lobe_weights":
        model = LAYERED_MODELS.get(model, model)
    fields = model_for(model).params_type.model_fields
    given = set(blended.constants) - BLEND_ONLY
    foreign = sorted(given - set(fields)) + sorted(set(blended.maps) - set(fields))
    if foreign:
        raise MitsubaExportError(
            f"blended material carries {', '.join(foreign[:3])}, which are not inputs of "
            f"the {model} model",
            where=blended.name,
        )
    constants = {k: _plain(v) for k, v in blended.constants.items() if k in given and v is not None}
    maps = {k: np.asarray(v, dtype=np.float32) for k, v in dict(blended.maps).items()}
    if model != blended.model:
        _drop_view_independent(constants, maps)
    normals = (getattr(blended, k, None) for k in ("normal_map", "specular_normal_map"))
    return Flat(blended.name, model, constants, maps, *normals)


def _drop_view_independent(constants: dict[str, Any], maps: dict[str, np.ndarray]) -> None:
    """Leave out each ``<weight>_grazing`` equal to its normal-view weight (Smits'
    highlight weights do not change with the view): the model then reads one value
    and interpolates nothing (:data:`lookdev.materials.pixar.PixarLobeWeights`)."""
    for key in [k for k in (*constants, *maps) if k.endswith(GRAZING)]:
        base = key.removesuffix(GRAZING)
        for store in (constants, maps):
            if key in store and base in store and np.array_equal(store[key], store[base]):
                del store[key]


def _plain(value: Any) -> Any:
    if isinstance(value, np.ndarray | list | tuple):
        return tuple(float(c) for c in np.asarray(value).ravel())
    return value.item() if isinstance(value, np.generic) else value


def principled_equivalent(flat: Flat) -> dict[str, Any] | None:
    """Mitsuba's ``principled`` parameters where it equals our Disney model, else None.

    Where: untextured metals (``metallic`` = 1 exactly, no clearcoat). There Burley's
    diffuse, sheen and transmission weights carry a factor (1 − metallic) = 0 and the
    specular is Schlick's Fresnel on the base colour with the anisotropic GGX and Smith G
    of the 2014 addendum, which ``principled`` implements the same way (DESIGN.md, Traps);
    tests/test_mitsuba_scene.py measures the two equal to float32 precision over roughness
    0..1 and anisotropic 0..1. Tinted and dielectric speculars, clearcoat (Mitsuba leaves
    out its 1/(4 cos θl cos θv)) and transmission differ on purpose and keep our plugin.
    """
    c = flat.constants
    if flat.model != "disney" or flat.maps or c.get("metallic") != 1.0:
        return None
    if c.get("clearcoat", 0.0) != 0.0:
        return None
    out: dict[str, Any] = {"type": "principled", "metallic": 1.0}
    out["base_color"] = {"type": "rgb", "value": list(c.get("base_color", _default(flat)))}
    for key in ("roughness", "anisotropic"):
        if key in c:
            out[key] = float(c[key])
    return out


def _default(flat: Flat) -> Any:
    return model_for(flat.model).params_type.model_fields["base_color"].default


def bsdf_dict(
    material: Any,
    texture_dir: str | Path | None = None,
    *,
    force_all_lobes: bool = False,
    resolution: int = DEFAULT_MAP_RESOLUTION,
    allow_principled: bool = True,
) -> dict[str, Any]:
    """The Mitsuba BSDF dict of a material (Params, library Material or BlendedMaterial).

    Maps become ``bitmap`` textures: EXR files written into ``texture_dir`` when given
    (for XML export), in-memory tensors otherwise. ``force_all_lobes`` keeps lobes with
    zero weight traced (the pruning benchmark's baseline) and never takes the
    ``principled`` fast path.
    """
    flat = flatten(material, resolution)
    register_plugins()
    model = model_for(flat.model)
    params = model.params_type.parse(flat.constants, where=flat.name)  # one line, here
    one_frame = flat.specular_normal_map is None
    fast = principled_equivalent(flat) if allow_principled and one_frame else None
    out = _plugin_dict(model, flat, texture_dir) if force_all_lobes or fast is None else fast
    if force_all_lobes:
        out[FORCE_ALL_LOBES] = True

    def normal_texture(normals: np.ndarray, name: str) -> dict[str, Any]:
        encoded = _encode_normals(np.asarray(normals, dtype=np.float32))
        return _bitmap(encoded, True, flat, name, texture_dir)

    frames = (flat.normal_map, flat.specular_normal_map)
    return with_normals(out, model, params, flat.maps, frames, normal_texture, force_all_lobes)


def _plugin_dict(model: Model, flat: Flat, texture_dir: str | Path | None) -> dict[str, Any]:
    """Our plugin for ``flat``: constants as values, maps as ``bitmap`` textures."""
    out: dict[str, Any] = {"type": register_model(model)}
    for key, value in flat.constants.items():
        out[key] = _constant(value)
    for key, array in flat.maps.items():
        if key not in model.params_type.model_fields:
            raise MitsubaExportError("unknown parameter map", where=flat.name, field=key)
        out[key] = _bitmap(array, is_color_field(model.params_type, key), flat, key, texture_dir)
    return out


def _constant(value: Any) -> Any:
    if isinstance(value, tuple):
        return {"type": "rgb", "value": [float(c) for c in value]}
    if isinstance(value, bool | str):
        return value
    return float(value)


def _encode_normals(normals: np.ndarray) -> np.ndarray:
    """Unit tangent-space normals → Mitsuba's [0, 1] encoding (it decodes 2·t − 1)."""
    return np.clip(0.5 * normals + 0.5, 0.0, 1.0)


def _bitmap(
    array: np.ndarray, color: bool, flat: Flat, key: str, texture_dir: str | Path | None
) -> dict[str, Any]:
    import mitsuba as mi

    data = np.asarray(array, dtype=np.float32)
    if data.ndim == 2:
        data = data[..., None]
    expected = 3 if color else 1
    if data.ndim != 3 or data.shape[-1] != expected:
        raise MitsubaExportError(
            f"map of shape {array.shape}; expected (H, W{', 3' if color else ''})",
            where=flat.name,
            field=key,
        )
    tex: dict[str, Any] = {"type": "bitmap", "raw": True, "wrap_mode": "repeat"}
    if texture_dir is None:
        tex["data"] = mi.TensorXf(np.ascontiguousarray(data))
    else:
        tex["filename"] = str(write_exr(data, Path(texture_dir) / f"{_slug(flat.name)}_{key}.exr"))
    return tex


def _slug(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in name) or "material"


def write_exr(data: np.ndarray, path: Path) -> Path:
    """Write a float32 (H, W, C) array as a scanline EXR, row 0 first, atomically."""
    import OpenImageIO as oiio

    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(suffix=".exr", prefix=f".{path.stem}.", dir=path.parent)
        os.close(fd)
    except OSError as exc:
        raise MitsubaExportError(
            f"cannot write textures: {exc.strerror}", where=str(path)
        ) from None
    spec = oiio.ImageSpec(data.shape[1], data.shape[0], data.shape[2], oiio.FLOAT)
    out = oiio.ImageOutput.create(tmp)
    try:
        ok = out is not None and out.open(tmp, spec) and out.write_image(data)
        if out is not None:
            out.close()
        if not ok:
            raise MitsubaExportError(
                f"OpenImageIO could not write it: {oiio.geterror()}", where=str(path)
            )
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return path


def uses_our_plugins(tree: Mapping[str, Any]) -> bool:
    """True when a scene or BSDF dict refers to one of our plugins anywhere."""
    if str(tree.get("type", "")).startswith("lookdev_"):
        return True
    return any(isinstance(v, Mapping) and uses_our_plugins(v) for v in tree.values())


def files_of(tree: Mapping[str, Any]) -> list[str]:
    """Every ``filename`` a scene or BSDF dict refers to (textures, environment maps)."""
    out = [str(v) for k, v in tree.items() if k == "filename"]
    for value in tree.values():
        if isinstance(value, Mapping):
            out += files_of(value)
    return out
