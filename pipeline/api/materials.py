"""The API's materials: load presets, blend them, evaluate the BSDF.

See :mod:`lookdev.pipeline.api` for the whole API.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from lookdev.materials.errors import LookdevError

if TYPE_CHECKING:
    from lookdev.library import Library, Material
    from lookdev.materials.bsdf import Model
    from lookdev.pipeline.blend import BlendedMaterial

__all__ = [
    "EVALUATE_RESOLUTION",
    "LookdevError",
    "MaterialError",
    "PathLike",
    "bake",
    "blend",
    "evaluate",
    "hub",
    "library_for",
    "load",
    "measured",
    "models",
    "pdf",
    "sample",
]

PathLike = str | os.PathLike


class MaterialError(LookdevError):
    """A material cannot be used the way a call asks (wrong kind, missing ``uv`` …)."""


# -- the model registry ----------------------------------------------------------------------
class _Models(Mapping):
    """The model registry (:data:`lookdev.materials.registry.MODELS`) as a read-only
    mapping name → :class:`lookdev.materials.bsdf.Model`, imported on first use so that
    ``import lookdev`` stays light.

    >>> import lookdev
    >>> "disney" in lookdev.models, [lobe.name for lobe in lookdev.models["pixar"].lobes][:2]
    (True, ['diffuse', 'specular'])
    """

    def _table(self) -> Mapping[str, Model]:
        from lookdev.materials.registry import MODELS

        return MODELS

    def __getitem__(self, name: str) -> Model:
        return self._table()[name]

    def __iter__(self) -> Iterator[str]:
        return iter(self._table())

    def __len__(self) -> int:
        return len(self._table())

    def __repr__(self) -> str:
        return f"<lookdev models: {', '.join(self)}>"


models: Mapping[str, Model] = _Models()
"""The reflectance models by name (``disney``, ``sheen``, ``pixar``, ``pixar_layered``)."""


# -- presets -----------------------------------------------------------------------------------
def library_for(library: Any = None) -> Library:
    """A :class:`~lookdev.library.Library` searching ``library`` first.

    ``library`` is None, a folder, a list of folders, or a ``Library`` (returned as is).
    """
    from lookdev.library import Library

    if isinstance(library, Library):
        return library
    if library is None:
        folders = None
    elif isinstance(library, str | os.PathLike):
        folders = [library]
    else:
        folders = list(library)
    return Library(folders or None)


def load(name_or_path: PathLike, library: Any = None) -> Material:
    """Load a preset: a name looked up on the library path, or a ``.toml`` file.

    Parameters
    ----------
    name_or_path
        A preset name (``"gold"``), or the path of a preset file (a ``Path``, or a string
        ending in ``.toml`` or containing a ``/``).
    library
        Folders searched before ``$LOOKDEV_LIBRARY_PATH`` and the built-in presets: a
        folder, a list of folders, or a :class:`~lookdev.library.Library`.

    Returns
    -------
    lookdev.library.Material
        The resolved material (``extends`` followed, layers loaded, values validated).

    Examples
    --------
    >>> import lookdev
    >>> lookdev.load("gold").params.metallic
    1.0
    """
    from lookdev.library import load_material

    return load_material(name_or_path, library_for(library))


def _material(material: Any, library: Any = None) -> Any:
    """``material`` itself unless it names a preset, which is then loaded, or a measured
    BRDF file (``.mbsdf``, MERL ``.binary``), which becomes a blended material of the
    ``measured`` model."""
    if isinstance(material, str | os.PathLike):
        from lookdev.library.measured import MEASURED_SUFFIXES

        if Path(material).suffix.lower() in MEASURED_SUFFIXES:
            return measured(material)
        return load(material, library)
    return material


def measured(path: PathLike) -> BlendedMaterial:
    """A measured BRDF file as a material (the ``measured`` model over its table): a path,
    or the file name of a shipped measurement (``"carpaint_red.mbsdf"``).

    >>> import lookdev
    >>> lookdev.measured("carpaint_red.mbsdf").params.table.shape
    (45, 45, 90)
    """
    from lookdev.library.measured import read_measured, resolve_measured
    from lookdev.materials.measured import MeasuredParams
    from lookdev.pipeline.blend import BlendedMaterial

    table = read_measured(resolve_measured(path))
    return BlendedMaterial.of_params(MeasuredParams(table=table), name=Path(path).name)


def _materials(materials: Any, library: Any) -> list[Any]:
    """One material or several, each loaded if named; a name given twice counts once.

    Warnings about their maps are printed once all have loaded: a batch with a bad
    preset prints its error alone (:func:`lookdev.library.index.held_warnings`).
    """
    from lookdev.library.index import held_warnings

    if isinstance(materials, str | os.PathLike) or hasattr(materials, "model"):
        materials = [materials]
    out, seen = [], set()
    with held_warnings():
        for m in materials:
            key = os.fspath(m) if isinstance(m, str | os.PathLike) else id(m)
            if key not in seen:
                seen.add(key)
                out.append(_material(m, library))
    return out


# -- blending ----------------------------------------------------------------------------------
def blend(
    material: Any,
    resolution: int | tuple[int, int] = 1024,
    *,
    layering: str = "full",
    prune: bool = True,
    progress: Callable[[int, int], None] | None = None,
    library: Any = None,
    images: dict | None = None,
) -> BlendedMaterial:
    """Blend a material's layers into constants (where uniform) and maps (where not).

    Parameters
    ----------
    material
        A preset name or path, or a :class:`~lookdev.library.Material`.
    resolution
        Texels a side, or ``(width, height)``, of each UV square: a material whose textures
        are UDIM sets gets maps over every tile (a 2 × 2 set at 1024: 2048 × 2048), with
        ``uv_extent`` and ``tiles`` saying which.
    layering
        Pixar stacks: ``"full"`` (light through a layer meets the ones below, Smits'
        table) or ``"simple"`` (A over B).
    prune
        False turns off every saving (all layers, all parameters as maps).
    progress
        Called as ``progress(rows_done, rows_total)`` after each tile.
    library
        See :func:`load`.
    images
        A dict kept across calls: decoded textures and mask sources are reused from it,
        so re-blending after an edit decodes nothing again (the designer keeps one).

    Returns
    -------
    lookdev.pipeline.blend.BlendedMaterial
        ``maps[name][row, col]`` is the texel centred on ``((col + ½)/W, (row + ½)/H)``
        (over ``uv_extent``); ``params_at(row, col)`` the parameters there,
        ``params_at_uv(u, v)`` at a UV. Parameters read straight from one unchanged
        image are also in ``textures`` (the file, for exporters). A layered Pixar
        material blends to Smits' lobe weights (``representation == "lobe_weights"``).

    Examples
    --------
    >>> import lookdev
    >>> b = lookdev.blend("rusty_iron", 16)
    >>> b.resolution, sorted(b.maps)[:2]
    ((16, 16), ['base_color', 'metallic'])
    """
    from lookdev.pipeline.blend import blend as blend_material
    from lookdev.pipeline.blend.surface_maps import attach

    material = _material(material, library)
    result = blend_material(
        material, resolution, progress=progress, prune=prune, layering=layering, images=images
    )
    return attach(result, material)


def bake(
    blended: BlendedMaterial,
    folder: PathLike,
    *,
    progress: Callable[[int, int], None] | None = None,
) -> dict[str, Path]:
    """Write a blend's maps as EXR (``NAME_<param>.exr``) and the rest as ``NAME.json``.

    Returns the files by parameter name, and the JSON under ``"sidecar"``. Files are
    written top row = v 1, so UV (0, 0) is the bottom-left texel as a viewer shows it.
    """
    from lookdev.pipeline.blend import bake as bake_maps

    return bake_maps(blended, Path(folder), progress=progress)


# -- the BSDF ----------------------------------------------------------------------------------
EVALUATE_RESOLUTION = 512
"""Texels a side at which :func:`evaluate` and friends blend a layered material they are
given unblended; blend it once with :func:`blend` to choose, and to save the time."""


def hub(material: Any, resolution: int = EVALUATE_RESOLUTION, library: Any = None):
    """``material`` as the blended material every consumer takes: a blend or a model's
    parameters as they are, a preset (name, path or Material) blended at ``resolution``."""
    from lookdev.materials.params import Params
    from lookdev.pipeline.blend import BlendedMaterial

    material = _material(material, library)
    if isinstance(material, BlendedMaterial | Params):
        from lookdev.pipeline.blend.result import as_hub

        return as_hub(material)
    if not hasattr(material, "layers"):
        raise MaterialError(
            f"cannot use a {type(material).__name__}; give a preset name, a "
            "Material, a blended material or a model's parameters"
        )
    return blend(material, resolution)


def _bsdf(material: Any, uv: Any, lead: tuple[int, ...]) -> tuple[Model, Any, dict[str, Any]]:
    """(model, parameters, per-element maps) for evaluating ``material`` at ``uv``."""
    blended = hub(material)
    model = blended.bsdf_model
    if blended.maps and uv is None:
        raise MaterialError(
            f"parameters vary across the surface ({', '.join(sorted(blended.maps))}); "
            "pass uv= to say where to evaluate",
            where=blended.name,
        )
    if uv is None:
        return model, blended.params, {}
    rows, cols = _texels(blended, uv, lead)
    maps = {k: np.asarray(a)[rows, cols] for k, a in blended.maps.items()}
    return model, blended.params, maps


def _texels(blended: Any, uv: Any, lead: tuple[int, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Row and column of the texel under each ``uv`` (nearest texel, repeating)."""
    uv = np.broadcast_to(np.asarray(uv, dtype=np.float64), (*lead, 2))
    if not np.isfinite(uv).all():
        raise MaterialError("uv holds NaN or infinite values", where=blended.name, field="uv")
    rows, cols = blended.texel(uv)
    return rows, cols


def _lead(uv: Any, **vectors: Any) -> tuple[int, ...]:
    """The broadcast leading shape of direction arrays (…, 3) and ``uv`` (…, 2)."""
    shapes = []
    for name, v in vectors.items():
        shape = np.shape(v)
        if not shape or shape[-1] != 3:
            raise MaterialError(f"expected shape (..., 3), got {shape}", field=name)
        shapes.append(shape[:-1])
    if uv is not None:
        shape = np.shape(uv)
        if not shape or shape[-1] != 2:
            raise MaterialError(f"expected shape (..., 2), got {shape}", field="uv")
        shapes.append(shape[:-1])
    try:
        return np.broadcast_shapes(*shapes)
    except ValueError:
        raise MaterialError(
            "shapes do not broadcast: "
            + ", ".join(f"{k} {np.shape(v)}" for k, v in vectors.items())
            + ("" if uv is None else f", uv {np.shape(uv)}")
        ) from None


def _full(v: Any, lead: tuple[int, ...], dtype: Any) -> np.ndarray:
    return np.broadcast_to(np.asarray(v, dtype=dtype), (*lead, 3))


def evaluate(
    material: Any, wi: Any, wo: Any, uv: Any = None, *, dtype: Any = np.float64
) -> np.ndarray:
    """f(wi, wo) without the cosine, in the local shading frame (normal +z).

    Parameters
    ----------
    material
        A preset name or path, a :class:`~lookdev.library.Material`, a blended material
        (:func:`blend`), or a model's parameters (``DisneyParams``, …). A layered
        material given unblended is blended at :data:`EVALUATE_RESOLUTION`.
    wi, wo
        Unit directions ``(..., 3)`` towards the light and the viewer, both pointing away
        from the surface; they broadcast against each other and ``uv``.
    uv
        ``(..., 2)`` texture coordinates of a blend whose parameters vary: each element
        takes the parameters of the texel under it (nearest, repeating), the values
        ``params_at(row, col)`` gives. Normal maps are not applied: the directions are
        already in the shading frame.
    dtype
        ``np.float64`` (default) or ``np.float32``.

    Returns
    -------
    numpy.ndarray
        Shape ``(..., 3)``: RGB, per steradian.

    Examples
    --------
    >>> import numpy as np, lookdev
    >>> n = np.array([0.0, 0.0, 1.0])
    >>> lookdev.evaluate("plastic_glossy", [n, n], n).shape
    (2, 3)
    """
    from lookdev.materials.bsdf import evaluate as core

    lead = _lead(uv, wi=wi, wo=wo)
    model, params, maps = _bsdf(material, uv, lead)
    return core(model, params, _full(wi, lead, dtype), _full(wo, lead, dtype), dtype=dtype, **maps)


def pdf(material: Any, wi: Any, wo: Any, uv: Any = None, *, dtype: Any = np.float64) -> np.ndarray:
    """The solid-angle density with which :func:`sample` draws ``wi`` given ``wo``.

    Arguments as :func:`evaluate`; returns shape ``(...)``.

    >>> import lookdev
    >>> float(lookdev.pdf("gold", [0, 0, 1.0], [0, 0, 1.0])) > 0
    True
    """
    from lookdev.materials.bsdf import density

    lead = _lead(uv, wi=wi, wo=wo)
    model, params, maps = _bsdf(material, uv, lead)
    return density(
        model, params, _full(wi, lead, dtype), _full(wo, lead, dtype), dtype=dtype, **maps
    )


def sample(
    material: Any,
    wo: Any,
    u: Any,
    uv: Any = None,
    *,
    dtype: Any = np.float64,
    delta: bool = False,
) -> tuple[np.ndarray, ...]:
    """Draw a light direction for the view ``wo``: ``(wi, weight, pdf)``.

    ``u`` holds three uniforms in [0, 1) per element, ``(..., 3)``: the first picks the
    lobe, the other two the direction. ``weight`` is ``f · |cos θi| / pdf`` ``(..., 3)``;
    a failed sample has ``pdf`` 0 and ``weight`` 0. Other arguments as :func:`evaluate`.
    A smooth lobe (roughness below √10⁻³: glass, water, a mirror) is a delta: its
    samples have the probability of the lobe's choice as ``pdf``, and :func:`evaluate`
    and :func:`pdf` leave it out; ``delta=True`` adds a fourth array marking them.

    >>> import numpy as np, lookdev
    >>> wi, weight, p = lookdev.sample("gold", [0, 0, 1.0], np.full((5, 3), 0.5))
    >>> wi.shape, weight.shape, p.shape
    ((5, 3), (5, 3), (5,))
    """
    from lookdev.materials.bsdf import draw

    lead = _lead(uv, wo=wo, u=u)
    model, params, maps = _bsdf(material, uv, lead)
    wo, u = _full(wo, lead, dtype), _full(u, lead, dtype)
    return draw(model, params, wo, u, dtype=dtype, delta=delta, **maps)
