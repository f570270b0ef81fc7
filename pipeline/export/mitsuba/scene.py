"""Materials as Mitsuba BSDF dictionaries and minimal scenes.

:func:`bsdf_dict` turns a blended material (the hub, or a model's parameters) into the dictionary
``mi.load_dict`` takes: our own plugin (:mod:`.plugin`) for the material's model, with
uniform parameters as constants and varying ones as ``bitmap`` textures. Mitsuba's
built-in ``principled`` replaces it only where the two were measured equal (see
:func:`principled_equivalent`). :func:`.depth.max_depth_for` sizes the path tracer to what
the material needs and :func:`.scene.scene_dict` is the small export scene (one
sphere under an environment) that ``lookdev export mitsuba`` writes.

Texture orientation: Mitsuba's bitmap puts an image's row 0 at v = 0, and a blended map's
texel (0, 0) is UV (0, 0), so maps go to Mitsuba row for row, in memory and in EXR files.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library import files
from lookdev.materials import registry
from lookdev.materials.microfacet import is_delta
from lookdev.materials.pixar import GRAZING
from lookdev.materials.registry import is_color_field
from lookdev.pipeline import exr
from lookdev.pipeline.blend.result import LOBE_WEIGHTS, BlendedMaterial, as_hub
from lookdev.pipeline.exr import colour_space_of

from .depth import max_depth_for
from .inputs import FORCE_ALL_LOBES, LIVE, ONLY_LOBES, MitsubaExportError
from .medium import integrator, interior_dict
from .normals import with_normals
from .plugin import register_model

__all__ = [
    "BLEND_ONLY",
    "bsdf_dict",
    "files_of",
    "plugin_inputs",
    "principled_equivalent",
    "register_plugins",
    "scene_dict",
    "uses_our_plugins",
    "with_bump",
    "write_exr",
]

BLEND_ONLY = frozenset({"layering"})
"""Constants a blend records for the record, which no BSDF takes."""


def register_plugins() -> dict[str, str]:
    """Register a Mitsuba plugin per model of the registry; ``{model: plugin name}``.

    Sets the Mitsuba variant first (:func:`lookdev.pipeline.variant.use_mitsuba`) unless one
    is set already. Call this before ``mi.load_dict`` / ``mi.load_file`` of our scenes.
    """
    _ensure_variant()
    return {name: register_model(model) for name, model in registry.MODELS.items()}


def _ensure_variant() -> None:
    import mitsuba as mi

    if mi.variant() is None:
        from lookdev.pipeline.variant import use_mitsuba

        use_mitsuba()


def plugin_inputs(hub: BlendedMaterial) -> tuple[dict[str, Any], dict[str, np.ndarray]]:
    """(constants, maps) the hub's model plugin takes."""
    fields = hub.bsdf_model.params_type.model_fields
    given = set(hub.constants) - BLEND_ONLY
    foreign = sorted(given - set(fields)) + sorted(set(hub.maps) - set(fields))
    if foreign:
        raise MitsubaExportError(
            f"blended material carries {', '.join(foreign[:3])}, which are not inputs of "
            f"the {hub.bsdf_model.name} model",
            where=hub.name,
        )
    # A constant at the schema's default is left to the default: every property the
    # plugin gets becomes a traversed scene parameter, and each costs a frozen render's
    # replay a check per frame (a plain preset's blend spells out all of its fields).
    constants = {
        k: _plain(v)
        for k, v in hub.constants.items()
        if k in given and v is not None and not _is_default(fields[k].default, v)
    }
    maps = {k: np.asarray(v, dtype=np.float32) for k, v in hub.maps.items()}
    if hub.representation == LOBE_WEIGHTS:
        _drop_view_independent(constants, maps)
    return constants, maps


def _is_default(default: Any, value: Any) -> bool:
    return default is not None and _plain(default) == _plain(value)


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


def principled_equivalent(hub: BlendedMaterial) -> dict[str, Any] | None:
    """Mitsuba's ``principled`` parameters where it equals our Disney model, else None.

    Where: untextured metals (``metallic`` = 1 exactly, no clearcoat). There Burley's
    diffuse, sheen and transmission weights carry a factor (1 − metallic) = 0 and the
    specular is Schlick's Fresnel on the base colour with the anisotropic GGX and Smith G
    of the 2014 addendum, which ``principled`` implements the same way (:doc:`/design`, Traps);
    tests/pipeline/export/mitsuba/test_mitsuba_scene.py measures the two equal to float32 precision
    over roughness 0.04..1 and anisotropic 0..1. Tinted and dielectric speculars, clearcoat
    (Mitsuba leaves out its 1/(4 cos θl cos θv)) and transmission differ on purpose and keep our
    plugin, and so does a smooth metal (roughness below √10⁻³): a delta mirror in our model
    (:func:`lookdev.materials.microfacet.is_delta`), a glossy α = 10⁻³ lobe in principled.
    """
    c = hub.constants
    if hub.bsdf_model.name != "disney" or hub.maps or c.get("metallic") != 1.0:
        return None
    if c.get("clearcoat", 0.0) != 0.0:
        return None
    if getattr(hub.params, "specular_gamma", 2.0) != 2.0:
        return None  # ``principled`` is GGX only (γ = 2): the plugin renders any GTR γ
    if getattr(hub.params, "energy_compensation", False):
        return None  # ``principled`` is single-scattering: the plugin compensates
    if is_delta(float(hub.params.roughness), float(hub.params.anisotropic)):
        return None  # a smooth metal is a delta in our model, principled is glossy (α 10⁻³)
    out: dict[str, Any] = {"type": "principled", "metallic": 1.0}
    out["base_color"] = {"type": "rgb", "value": list(hub.params.base_color)}
    for key in ("roughness", "anisotropic"):
        if key in c:
            out[key] = float(c[key])
    return out


def bsdf_dict(
    material: Any,
    texture_dir: str | Path | None = None,
    *,
    force_all_lobes: bool = False,
    allow_principled: bool = True,
    live: bool = False,
) -> dict[str, Any]:
    """The Mitsuba BSDF dict of a blended material (or of a model's parameters).

    Maps become ``bitmap`` textures: EXR files written into ``texture_dir`` when given
    (for XML export), in-memory tensors otherwise. The plugin traces exactly the hub's
    live lobes (:attr:`BlendedMaterial.live_lobes`); ``force_all_lobes`` keeps lobes with
    zero weight traced (the pruning benchmark's baseline) and never takes the
    ``principled`` fast path; ``live`` too, with every continuous parameter a traversed
    value the kernel reads from memory (the plugin's ``live`` property: the designer's
    truth mode edits them in place).
    """
    hub = as_hub(material)
    register_plugins()
    model = hub.bsdf_model
    one_frame = hub.specular_normal_map is None
    every = force_all_lobes or live
    fast = principled_equivalent(hub) if allow_principled and one_frame and not every else None
    out = _plugin_dict(hub, texture_dir) if fast is None else fast
    lobes = model.lobe_names if every else hub.live_lobes
    if live:
        out[LIVE] = True
    elif force_all_lobes:
        out[FORCE_ALL_LOBES] = True
    elif hub.maps and fast is None:
        # A texture's lobes cannot be pruned while the kernel is traced: say which live.
        out[ONLY_LOBES] = ",".join(lobes)

    def normal_texture(normals: np.ndarray, name: str) -> dict[str, Any]:
        encoded = _encode_normals(np.asarray(normals, dtype=np.float32))
        return _tiled(_bitmap(encoded, True, hub.name, name, texture_dir, data_map=True), hub)

    frames = (hub.normal_map, hub.specular_normal_map)
    return with_bump(hub, with_normals(out, model, lobes, frames, normal_texture), texture_dir)


def with_bump(
    hub: BlendedMaterial, bsdf: dict[str, Any], texture_dir: str | Path | None = None
) -> dict[str, Any]:
    """``bsdf`` under Mitsuba's ``bumpmap`` when the material has a height map.

    The map holds heights in scene units (:attr:`BlendedMaterial.height_map`), and
    ``bumpmap`` offsets the surface by ``scale`` × the texture along the normal when it
    differentiates the position (Mitsuba 3 ``bumpmap``: ∂p/∂u + n·∂h/∂u), so ``scale``
    is 1: the proof shows the bump the USD ``displacement`` describes, as shading."""
    if hub.height_map is None:
        return bsdf
    height = _bitmap(hub.height_map, False, hub.name, "height", texture_dir)
    return {"type": "bumpmap", "height": _tiled(height, hub), "scale": 1.0, "bsdf": bsdf}


def _tiled(texture: dict[str, Any], hub: BlendedMaterial) -> dict[str, Any]:
    """A bitmap of a map spanning the hub's UDIM extent (``hub.uv_extent``, (u0, v0, u1, v1))
    with the ``to_uv`` that brings the mesh's UVs onto it, ``(uv − (u0, v0)) / (Δu, Δv)``,
    so each tile's square of the map lands on that tile's UV square of the mesh."""
    if tuple(hub.uv_extent) == (0, 0, 1, 1):
        return texture
    import mitsuba as mi

    u0, v0, u1, v1 = hub.uv_extent
    scale = mi.ScalarTransform4f().scale([1.0 / (u1 - u0), 1.0 / (v1 - v0), 1.0])
    texture["to_uv"] = scale @ mi.ScalarTransform4f().translate([-u0, -v0, 0.0])
    texture["wrap_mode"] = "clamp"  # outside the tiles: the edge texels, not another tile
    return texture


def _plugin_dict(hub: BlendedMaterial, texture_dir: str | Path | None) -> dict[str, Any]:
    """Our plugin for ``hub``: constants as values, maps as ``bitmap`` textures."""
    model = hub.bsdf_model
    constants, maps = plugin_inputs(hub)
    out: dict[str, Any] = {"type": register_model(model)}
    for key, value in constants.items():
        out[key] = _constant(value)
    for key, array in maps.items():
        colour = is_color_field(model.params_type, key)
        out[key] = _tiled(_bitmap(array, colour, hub.name, key, texture_dir), hub)
    return out


def _constant(value: Any) -> Any:
    from lookdev.materials.measured import MeasuredTable

    if isinstance(value, MeasuredTable):  # properties hold strings: the table by its key
        return value.key()
    if isinstance(value, tuple):
        return {"type": "rgb", "value": [float(c) for c in value]}
    if isinstance(value, bool | str):
        return value
    return float(value)


def _encode_normals(normals: np.ndarray) -> np.ndarray:
    """Unit tangent-space normals → Mitsuba's [0, 1] encoding (it decodes 2·t − 1)."""
    return np.clip(0.5 * normals + 0.5, 0.0, 1.0)


def _bitmap(
    array: np.ndarray,
    color: bool,
    name: str,
    key: str,
    texture_dir: str | Path | None,
    *,
    data_map: bool = False,
) -> dict[str, Any]:
    """A ``bitmap`` of a hub map (see :func:`_tiled` for maps over UDIM tiles)."""
    import mitsuba as mi

    data = np.asarray(array, dtype=np.float32)
    if data.ndim == 2:
        data = data[..., None]
    expected = 3 if color else 1
    if data.ndim != 3 or data.shape[-1] != expected:
        raise MitsubaExportError(
            f"map of shape {array.shape}; expected (H, W{', 3' if color else ''})",
            where=name,
            field=key,
        )
    tex: dict[str, Any] = {"type": "bitmap", "raw": True, "wrap_mode": "repeat"}
    if texture_dir is None:
        tex["data"] = mi.TensorXf(np.ascontiguousarray(data))
    else:
        space = colour_space_of(data, data=data_map or not color)
        path = Path(texture_dir) / f"{_slug(name)}_{key}.exr"
        tex["filename"] = str(write_exr(data, path, space))
    return tex


def _slug(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-_" else "_" for ch in name) or "material"


def write_exr(data: np.ndarray, path: Path, space: str | None = None) -> Path:
    """Write a float32 (H, W, C) array in ``space`` as an EXR, row 0 first, atomically."""
    path = Path(path)
    try:
        files.make_folder(path.parent)
        with files.atomic_path(path) as tmp:
            exr.write_exr(tmp, data, space, shown=path)
    except OSError as exc:
        raise MitsubaExportError(
            f"cannot write textures: {exc.strerror}", where=str(path)
        ) from None
    except files.WriteError as exc:
        reason = exc.message.removeprefix(f"cannot write {path}: ")
        raise MitsubaExportError(f"cannot write: {reason}", where=str(path)) from None
    return path


def scene_dict(
    material: Any,
    *,
    resolution: tuple[int, int] = (256, 256),
    spp: int = 64,
    environment: str | Path | None = None,
    texture_dir: str | Path | None = None,
    force_all_lobes: bool = False,
    max_depth: int | None = None,
    ibl_rotation: float = 0.0,
    meters_per_unit: float = 1.0,
) -> dict[str, Any]:
    """A minimal scene: the material on a unit sphere, framed, under an environment.

    ``environment`` is a lat-long image (``envmap``) oriented as in the proofs (y up,
    camera on +z, :data:`lookdev.pipeline.proof.ibl.ORIENTATION`) and turned by
    ``ibl_rotation`` degrees about +y; without one, a constant white sky (the
    white-furnace set-up). The integrator depth follows the material; the film
    holds RGB only (no alpha, no AOVs). A solid subsurface material fills the sphere
    with its medium (:mod:`.medium`; the sphere's radius is 1 unit of ``meters_per_unit``
    metres) and the scene takes ``volpath``; any other keeps ``path``.
    """
    import mitsuba as mi

    hub = as_hub(material)
    _ensure_variant()
    # The BSDF first: it refuses inputs the model does not take in one line, before the
    # depth rule runs the model's prepare on them.
    bsdf = bsdf_dict(hub, texture_dir, force_all_lobes=force_all_lobes)
    medium = interior_dict(hub, meters_per_unit)
    width, height = resolution
    distance = 4.0
    fov = 2.0 * math.degrees(math.asin(1.0 / distance)) * 1.15  # the ball fills ~87%
    emitter: dict[str, Any]
    if environment is None:
        emitter = {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}
    else:
        from lookdev.pipeline.proof.ibl import envmap_to_world

        emitter = {
            "type": "envmap",
            "filename": str(environment),
            "to_world": envmap_to_world(ibl_rotation),
        }
    return {
        "type": "scene",
        "integrator": integrator(max_depth or max_depth_for(hub), medium),
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "to_world": mi.ScalarTransform4f().look_at(
                origin=[0.0, 0.0, distance], target=[0.0, 0.0, 0.0], up=[0.0, 1.0, 0.0]
            ),
            "film": {
                "type": "hdrfilm",
                "width": int(width),
                "height": int(height),
                "pixel_format": "rgb",
                "rfilter": {"type": "gaussian"},
            },
            "sampler": {"type": "independent", "sample_count": int(spp)},
        },
        "environment": emitter,
        "ball": {"type": "sphere", "bsdf": bsdf} | ({"interior": medium} if medium else {}),
    }


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
