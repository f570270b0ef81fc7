"""Pixar layers in the blending engine: the stack of every tile composited into maps.

For each tile the stack (top first, pruned of hidden and empty layers) is composited by
:func:`.pixar_composite.composite` twice, for the view at normal incidence and at grazing
(:data:`VIEWS`), and the result is stored as the maps of a
:data:`lookdev.materials.pixar.LAYERED_MODEL` material: the twelve weights at both ends,
the highlight lobes' cones and falloffs, the IOR the view refracts by and the diffuse and
highlight normals. Uniform maps fold to constants.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from lookdev.materials.pixar import eta_of
from lookdev.materials.pixar_scatter import LOBES, PREFIX

from .masks import MaskSampler
from .pixar_composite import GROUP, Lobes, Part, composite, layer_lobes, unit
from .result import LOBE_WEIGHTS, TILE_TEXELS, BlendedMaterial
from .stack import Entry, prune_stack
from .textures import sample

VIEWS = {"": 1.0, "_grazing": 0.0}
"""Map-name suffix → cos θ of the view the weights are composited for."""
CONES = ("specular", "reflection", "specular_t", "reflection_t")
FALLOFFS = ("specular", "specular_t")


def opaque(entry: Entry) -> bool:
    """True when the layer transmits nothing at any view (it hides what is below); a
    textured layer is not taken to be (its transmission may vary from texel to texel)."""
    if entry.decoded:
        return False
    for cos_view in VIEWS.values():
        lobes = layer_lobes(entry.params, cos_view)
        if any(np.any(lobes[lobe].n > 0) or np.any(lobes[lobe].g > 0) for lobe in LOBES[3:]):
            return False
    return True


def blend_stack(
    name: str,
    entries: list[Entry],
    sampler: MaskSampler,
    progress,
    *,
    prune: bool = True,
    layered: bool = True,
    mode: str = "full",
):
    """The engine's Pixar path: prune, composite per tile, fold uniform outputs.

    A plain (not layered) Pixar material stays its parameters. A layered one becomes
    lobe weights (``representation = "lobe_weights"``): Smits' twelve weight names for
    the view at normal incidence and the same with ``_grazing`` for the view at grazing
    incidence (RGB), ``<lobe>_cone`` in degrees for the four highlight lobes,
    ``specular_falloff`` and ``specular_t_falloff`` (:attr:`Part.falloff`), the ``ior``
    the view refracts by (:func:`_ior`), and the diffuse and highlight normals as
    ``normal_map`` and ``specular_normal_map``: the inputs of
    :data:`lookdev.materials.pixar.LAYERED_MODEL`.
    """
    resolution = (sampler.width, sampler.height)
    if not layered:
        return _plain(name, entries[0], sampler, resolution)
    kept, decisions = prune_stack(
        entries,
        sampler,
        base_opaque=False,
        hides=lambda e: mode == "simple" or opaque(e),
        enabled=prune,
    )
    constant = all(
        e.uniform and e.normal_map is None and e.specular_normal_map is None and not e.decoded
        for e in kept
    )
    if constant and prune:  # nothing varies: one texel says it all
        sampler = MaskSampler((1, 1))
    outputs = _outputs(kept[::-1], sampler, progress, mode)
    out = BlendedMaterial(name, "pixar", resolution, {}, decisions=decisions)
    out.representation = LOBE_WEIGHTS
    for key, value in outputs.items():
        if key in ("normal_map", "specular_normal_map"):
            if not _is_flat(value):
                setattr(out, key, value.astype(np.float32))
        elif prune and _uniform(value):
            out.constants[key] = _constant(value)
        else:
            out.maps[key] = value.astype(np.float32)
    out.constants["layering"] = mode
    return out


def _plain(name: str, entry: Entry, sampler: MaskSampler, resolution) -> BlendedMaterial:
    """A plain Pixar material: its constants, and each textured parameter as a map read
    straight from its texture (so also in :attr:`BlendedMaterial.textures`)."""
    params = entry.params
    constants = {
        k: v for k, v in params.model_dump().items() if v is not None and k not in entry.decoded
    }
    out = BlendedMaterial(name, "pixar", resolution, constants, decisions=[])
    every_row = slice(0, sampler.height)
    for key, texture in entry.decoded.items():
        values = sample(sampler, entry, key, every_row)
        out.maps[key] = values[..., 0] if texture.count == 1 else values
        out.textures[key] = texture.tex.model_copy(update={"colorspace": texture.space})
    return out


def _outputs(top_first: list[Entry], sampler: MaskSampler, progress, mode: str):
    """Every output array, (H, W[, 3]), composited tile by tile."""
    height, width = sampler.height, sampler.width
    rows_per_tile = max(1, TILE_TEXELS // width)
    out: dict[str, np.ndarray] = {}
    constant_layers = {
        (i, cos_view): layer_lobes(e.params, cos_view)
        for i, e in enumerate(top_first)
        for cos_view in VIEWS.values()
        if not e.decoded
    }
    for r0 in range(0, height, rows_per_tile):
        rows = slice(r0, min(height, r0 + rows_per_tile))
        n = rows.stop - rows.start
        alphas = [e.coverage(sampler, rows) for e in top_first]  # scalars where uniform
        normals = [_entry_normals(e, sampler, rows) for e in top_first]
        # A textured layer's lobes are Smits' weights of its parameters at each texel.
        maps = [_texel_params(e, sampler, rows) for e in top_first]
        per_layer = dict(constant_layers)
        for i, e in enumerate(top_first):
            if e.decoded:
                for cos_view in VIEWS.values():
                    per_layer[i, cos_view] = layer_lobes(e.params, cos_view, maps=maps[i])
        for suffix, cos_view in VIEWS.items():
            stack = [
                (_with_normals(per_layer[i, cos_view], nm), a)
                for i, (nm, a) in enumerate(zip(normals, alphas, strict=True))
            ]
            lobes, group_normals = composite(stack, mode)
            for lobe, part in lobes.items():
                _store(out, f"{PREFIX[lobe]}N{suffix}", part.n, rows, n, width, height)
                _store(out, f"{PREFIX[lobe]}G{suffix}", part.g, rows, n, width, height)
                if suffix == "" and lobe in CONES:
                    _store(out, f"{lobe}_cone", part.cone, rows, n, width, height)
                if suffix == "" and lobe in FALLOFFS:
                    _store(out, f"{lobe}_falloff", part.falloff, rows, n, width, height)
            if suffix == "":
                _store(out, "ior", _ior(top_first, alphas, maps), rows, n, width, height)
                _store(out, "normal_map", group_normals["diffuse"], rows, n, width, height)
                _store(
                    out, "specular_normal_map", group_normals["highlight"], rows, n, width, height
                )
        if progress is not None:
            progress(rows.stop, height)
    return out


def _ior(top_first: list[Entry], alphas: list[Any], maps: list[dict[str, Any]]) -> Any:
    """The IOR the view refracts by: the uppermost layer present at the texel, i.e. the
    A-over-B mean Σ cₖ ηₖ (cₖ = αₖ Π(1 − αⱼ above)), the bottom layer's where none is."""
    eta: Any = 0.0
    remaining: Any = 1.0
    for entry, alpha, texel in zip(top_first, alphas, maps, strict=True):
        alpha = np.asarray(alpha, dtype=np.float64)  # η ≈ 1 refracts by η − 1: keep digits
        eta = eta + alpha * remaining * eta_of(entry.params, texel)
        remaining = remaining * (1.0 - alpha)
    return eta + remaining * eta_of(top_first[-1].params, maps[-1])


def _texel_params(entry: Entry, sampler: MaskSampler, rows: slice) -> dict[str, Any]:
    """A textured layer's parameters on ``rows``: (n, W) scalars, (n, W, 3) colours."""
    out = {}
    for key, texture in entry.decoded.items():
        values = sample(sampler, entry, key, rows).astype(np.float64)
        out[key] = values[..., 0] if texture.count == 1 else values
    return out


def _with_normals(lobes: Lobes, normals: dict[str, Any]) -> Lobes:
    """``lobes`` with the diffuse and highlight normals of this tile where a map gives one."""
    if not normals:
        return lobes
    return {
        lobe: Part(p.n, p.g, p.cone, normals.get(GROUP[lobe], p.normal), p.falloff)
        for lobe, p in lobes.items()
    }


def _entry_normals(entry: Entry, sampler: MaskSampler, rows: slice) -> dict[str, Any]:
    """The layer's diffuse and highlight normals on ``rows`` (unit), flat where absent."""
    out = {}
    if entry.normal_map is not None:
        out["diffuse"] = out["highlight"] = unit(entry.normals(sampler, entry.normal_map, rows))
    if entry.specular_normal_map is not None:
        out["highlight"] = unit(entry.normals(sampler, entry.specular_normal_map, rows))
    return out


def _store(out, key, value, rows, n, width, height) -> None:
    """Write one tile of output ``key`` (cones, falloffs and the IOR are scalars, the
    rest RGB or xyz)."""
    channels = () if key.endswith(("_cone", "_falloff", "ior")) else (3,)
    if key not in out:
        # One texel is a uniform result: its constants keep float64, as a plain preset's
        # do (near η = 1 refraction turns float32 rounding of η into 4e-4 of f); maps are
        # float32 like every map.
        dtype = np.float64 if height * width == 1 else np.float32
        out[key] = np.empty((height, width, *channels), dtype=dtype)
    out[key][rows] = np.broadcast_to(value, (n, width, *channels))


def _uniform(a: np.ndarray) -> bool:
    flat = a.reshape(-1, *a.shape[2:])
    return bool((flat == flat[0]).all())


def _constant(a: np.ndarray) -> Any:
    v = a[0, 0]
    return tuple(float(x) for x in v) if np.ndim(v) else float(v)


def _is_flat(normals: np.ndarray) -> bool:
    return bool(np.all(normals == np.array([0.0, 0.0, 1.0], dtype=normals.dtype)))


__all__ = ["VIEWS", "blend_stack", "opaque"]
