"""``blend()``: a layered material in, a :class:`BlendedMaterial` out.

The result holds each parameter as a constant where it is uniform and as a map where it
varies, and nothing is computed that the result does not need (:doc:`/design`):

- a layer whose mask is zero everywhere is dropped;
- a layer under a full-coverage layer (mask 1 everywhere, presence 1) is dropped;
- a layer that sets every parameter to what is already below it, and carries no normal
  map, is dropped;
- a uniform mask folds into the constants: parameters stay constants until a varying
  mask meets a value that differs from the one below;
- a material that needs no map produces none.

Coverage is bounded from the mask sources before any texel is evaluated
(:meth:`.MaskSampler.bounds`). Maps are computed in tiles of rows so the peak memory is
the output plus the mask sources plus one tile of temporaries.

Maps are float32 ``(H, W)`` scalars and ``(H, W, 3)`` colours and normals, in UV order:
``map[r, c]`` is the texel centred on ``(u, v) = ((c + ½)/W, (r + ½)/H)``, so texel (0, 0)
is UV (0, 0), the bottom-left corner of the image as a viewer shows it. Normal maps are
unit tangent-space vectors (decoded, not 0..1 encoded).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Any

import numpy as np
from threadpoolctl import threadpool_limits

from . import disney, pixar
from .errors import BlendError
from .masks import MaskSampler
from .result import TILE_TEXELS, BlendedMaterial
from .stack import Decision, Entry, prune_stack, stack_of
from .textures import extent_of, open_textures, sample

__all__ = ["Progress", "Textured", "blend"]

Progress = Callable[[int, int], None]
"""Called as ``progress(rows_done, rows_total)`` after each tile."""


def blend(
    material: Any,
    resolution: int | tuple[int, int] = 1024,
    *,
    progress: Progress | None = None,
    prune: bool = True,
    images: dict | None = None,
    layering: str = "full",
) -> BlendedMaterial:
    """Blend a library :class:`~lookdev.library.Material` at ``resolution``.

    ``resolution`` is ``N`` (N × N) or ``(width, height)`` per UV square: UDIM textures
    widen the maps to every square their tiles cover (:attr:`BlendedMaterial.uv_extent`).
    A non-layered material blends to constants, and maps only for textured parameters.
    Disney stacks blend parameters (:mod:`.disney`); Pixar stacks composite lobe weights
    (:mod:`.pixar`). ``prune=False`` turns off every
    saving (all layers, all parameters as maps) and exists to measure them. ``images``
    caches decoded textures across calls (see :class:`.MaskSampler`). ``layering`` is
    Smits' ``"full"`` (transmitted light meets the layers below) or ``"simple"`` layering
    of Pixar stacks.
    """
    if layering not in ("full", "simple"):
        raise BlendError(f"unknown Pixar layering {layering!r}; allowed: full, simple")
    width, height = (resolution, resolution) if isinstance(resolution, int) else resolution
    if width < 1 or height < 1:
        raise BlendError(f"resolution {width}x{height} must be at least 1x1", where=material.name)
    entries = stack_of(material)
    folded = open_textures(entries)
    extent = extent_of(entries, _surface_sets(material))
    du, dv = extent[2] - extent[0], extent[3] - extent[1]
    sampler = MaskSampler(
        (height * dv, width * du), images, output_channels=_channels_bound(entries), extent=extent
    )
    if entries[0].model == "openpbr":
        return _openpbr(material, entries)
    if entries[0].model == "pixar":
        result = pixar.blend_stack(
            material.name,
            entries,
            sampler,
            progress,
            prune=prune,
            layered=material.model == "layered",
            mode=layering,
        )
    else:
        kept, decisions = prune_stack(entries, sampler, enabled=prune)
        result = _blend_disney(material.name, kept, sampler, progress, naive=not prune)
        result.decisions = decisions + result.decisions
    result.decisions = folded + result.decisions
    result.uv_extent = extent
    result.tiles = tuple(
        sorted({t for e in entries for x in e.decoded.values() for t in x.tiles} - {None})
    )
    result.description = getattr(material, "description", "")
    result.origin = material
    result.layered = getattr(material, "model", None) == "layered"
    return result


def _surface_sets(material: Any) -> list[str]:
    """The texture-set height and normal maps of ``material`` (:mod:`.surface_maps` puts
    them on the hub): their UDIM tiles widen the extent every map spans."""
    height, normal = getattr(material, "height", None), getattr(material, "normal_map", None)
    return [str(p) for p in (height and height.texture, normal and normal.path) if p]


def _channels_bound(entries: list[Entry]) -> float:
    """At most how many float channels a blend of ``entries`` writes per texel: the
    Disney parameters that differ between layers (each kind of normal map adds three);
    unbounded for Pixar stacks, whose composited weights are many. Sizes the sampler's
    texture budget."""
    if entries[0].model != "disney":
        return math.inf
    values = [_values(e) for e in entries]
    differing = [k for k in values[0] if any(v[k] != values[0][k] for v in values)]
    differing += [k for k in values[0] if k not in differing and isinstance(values[0][k], Textured)]
    normals = sum(
        any(getattr(e, which) is not None for e in entries)
        for which in ("normal_map", "specular_normal_map")
    )
    return sum(3 if k == disney.COLOR else 1 for k in differing) + 3 * normals


class Textured:
    """A layer's value of a parameter that a texture drives (``field``: the parameter the
    texture was written for; ``ior`` for a ``specular`` spelled as a textured IOR)."""

    def __init__(self, field: str, texture: Any):
        self.field, self.texture = field, texture

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Textured) and (self.field, self.texture) == (
            other.field,
            other.texture,
        )

    def __hash__(self) -> int:
        return hash((self.field, self.texture))


def _openpbr(material: Any, entries: list[Entry]) -> BlendedMaterial:
    """An ``openpbr`` preset (an OpenPBR material imported as itself): its constants;
    it has no layering or texture rules of its own."""
    if len(entries) > 1 or entries[0].decoded:
        raise BlendError(
            f"{material.name}: openpbr presets take constants only (no layers, no textures)",
            field="model",
        )
    out = BlendedMaterial.of_params(entries[0].params, name=material.name)
    out.description = material.description
    return out


def _values(entry: Entry) -> dict[str, Any]:
    """A layer's values in blending space, :class:`Textured` where a texture drives them."""
    values = disney.layer_values(entry.params)
    for key, texture in entry.decoded.items():
        values["specular" if key == "ior" else key] = Textured(key, texture.tex)
    return values


def _blend_disney(
    name: str, kept: list[Entry], sampler: MaskSampler, progress, *, naive: bool = False
) -> BlendedMaterial:
    """Parameter blending of the kept layers (bottom first) into constants and maps."""
    values = [_values(e) for e in kept]
    if naive:
        constants, varying, inert = {}, set(values[0]), set()
    else:
        constants, varying, inert = _plan(values, kept)
    decisions = [Decision(kept[i].label, False, "sets what is already below it") for i in inert]
    kept = [e for i, e in enumerate(kept) if i not in inert]
    values = [v for i, v in enumerate(values) if i not in inert]
    discrete = disney.check_discrete([(e.label, e.params) for e in kept])
    stack = [e.params for e in kept]
    resolution = (sampler.width, sampler.height)
    out = BlendedMaterial(name, "disney", resolution, {}, decisions=decisions)
    out.layers = kept
    out.maps = _disney_maps(kept, values, varying, sampler, progress, out)
    out.constants = disney.assemble(constants, discrete, stack)
    for key in _passed_through(values):
        if values[0][key].field == key:  # the file as it is (a textured IOR becomes specular)
            out.textures[key] = (
                kept[0]
                .decoded[key]
                .tex.model_copy(update={"colorspace": kept[0].decoded[key].space})
            )
    if "specular" in out.maps:
        out.maps.update(disney.spell_specular(stack, out.maps.pop("specular")))
    return out


def _plan(values: list[dict[str, Any]], kept: list[Entry]):
    """Which parameters vary, the constants of the rest, and layers that change nothing.

    Walks the stack bottom to top with each parameter either a constant or "varying".
    A uniform mask lerps constants into constants; a varying mask makes a parameter vary
    unless the layer's value equals the constant below.
    """
    varying = {k for v in values for k, x in v.items() if isinstance(x, Textured)}
    constants: dict[str, Any] = {k: x for k, x in values[0].items() if k not in varying}
    inert = []
    bumpy = False  # a normal map so far: any layer over it flattens it where it shows
    for i, (entry, layer) in enumerate(zip(kept[1:], values[1:], strict=True), start=1):
        bumpy = bumpy or _has_normals(kept[i - 1])
        changes = bumpy or _has_normals(entry)
        for key, p in layer.items():
            if key in varying:
                changes = True
            elif entry.uniform:
                changes |= p != constants[key]
                constants[key] = _lerp(constants[key], p, entry.low)
            elif p != constants[key]:
                varying.add(key)
                del constants[key]
                changes = True
        if not changes:
            inert.append(i)
    return constants, varying, set(inert)


def _passed_through(values: list[dict[str, Any]]) -> list[str]:
    """Parameters every kept layer takes from one and the same texture: their blend is the
    texture itself (the weights sum to 1), read straight, and exporters may reference it."""
    return [
        k
        for k, x in values[0].items()
        if isinstance(x, Textured) and all(v[k] == x for v in values[1:])
    ]


def _has_normals(entry: Entry) -> bool:
    return entry.normal_map is not None or entry.specular_normal_map is not None


def _lerp(a: Any, b: Any, m: float) -> Any:
    """``a + m (b − a)`` per channel, exact at m = 0 and m = 1."""
    if m == 0.0 or a == b:
        return a
    if m == 1.0:
        return b
    if isinstance(a, tuple):
        return tuple((1.0 - m) * x + m * y for x, y in zip(a, b, strict=True))
    return (1.0 - m) * a + m * b


def _disney_maps(kept, values, varying, sampler, progress, out: BlendedMaterial):
    """Fill the varying parameter maps (and normal maps) tile by tile.

    Per tile: the layer weights (L, T), then every varying scalar as one matrix product
    (S, L) @ (L, T) written straight into the maps (their rows are whole, so a tile is a
    strided BLAS output), and the colour as (T, L) @ (L, 3) into the interleaved colour
    map. BLAS runs on one thread: tiles are small and a threaded BLAS on a busy machine
    spends its time spinning (measured 30× slower with 2 shared cores); ``np.einsum``
    avoids threads too but is 2-10× slower than one BLAS thread here.
    """
    height, width = sampler.height, sampler.width
    scalars = [k for k in disney.SCALARS if k in varying]
    normals = any(e.normal_map is not None for e in kept)
    spec_normals = any(e.specular_normal_map is not None for e in kept)
    if not (varying or normals or spec_normals):
        return {}
    block = np.empty((len(scalars), height, width), dtype=np.float32)
    maps = {k: block[i] for i, k in enumerate(scalars)}
    p_scalar = np.array([[_const(v[k]) for v in values] for k in scalars], dtype=np.float32)
    p_color = np.array([_const(v[disney.COLOR], 3) for v in values], dtype=np.float32)
    passed = set(_passed_through(values))
    textured = [
        (k, i, entry)
        for k in [*scalars, disney.COLOR]
        if k in varying
        for i, (entry, v) in enumerate(zip(kept, values, strict=True))
        if isinstance(v[k], Textured) and (k not in passed or i == 0)
    ]
    if disney.COLOR in varying:
        maps[disney.COLOR] = np.empty((height, width, 3), dtype=np.float32)
    if normals:
        out.normal_map = np.empty((height, width, 3), dtype=np.float32)
    if spec_normals:
        out.specular_normal_map = np.empty((height, width, 3), dtype=np.float32)
    rows_per_tile = max(1, TILE_TEXELS // width)
    weights_buf = np.empty((len(kept), rows_per_tile * width), dtype=np.float32)
    color = maps.get(disney.COLOR)
    with threadpool_limits(limits=1, user_api="blas"):
        for r0 in range(0, height, rows_per_tile):
            rows = slice(r0, min(height, r0 + rows_per_tile))
            n = rows.stop - rows.start
            weights = _tile_weights(kept, sampler, rows, weights_buf[:, : n * width])
            if scalars:
                np.matmul(p_scalar, weights, out=block[:, rows].reshape(len(scalars), -1))
            if color is not None:
                np.matmul(weights.T, p_color, out=color[rows].reshape(-1, 3))
            for key, i, entry in textured:
                values_here = sample(sampler, entry, key, rows)
                target = maps[key][rows]
                if key in passed:
                    target[...] = values_here.reshape(target.shape)
                else:
                    w = weights[i].reshape(n, width, *([1] if target.ndim == 3 else []))
                    target += w * values_here.reshape(target.shape)
            for which in ("normal_map", "specular_normal_map"):
                if getattr(out, which) is not None:
                    getattr(out, which)[rows] = _tile_normals(kept, sampler, rows, weights, which)
            if progress is not None:
                progress(rows.stop, height)
    return maps


def _const(value: Any, count: int = 1) -> Any:
    """A layer's constant for the matrix product; 0 where a texture adds its own share."""
    if isinstance(value, Textured):
        return 0.0 if count == 1 else (0.0, 0.0, 0.0)
    return value


def _tile_weights(kept: list[Entry], sampler: MaskSampler, rows: slice, out: np.ndarray):
    """Layer weights into ``out`` (L, texels of the tile), base first (stack_weights)."""
    masks = [np.reshape(e.coverage(sampler, rows), -1) for e in kept[1:]]
    return disney.stack_weights(masks, out=out)


def _tile_normals(kept, sampler, rows, weights, which: str) -> np.ndarray:
    """Σ wᵢ nᵢ renormalised; layers without a map (or a specular map) count as flat."""
    n = rows.stop - rows.start
    total = np.zeros((n * sampler.width, 3), dtype=np.float32)
    for entry, w in zip(kept, weights, strict=True):
        tex = getattr(entry, which) or (entry.normal_map if which != "normal_map" else None)
        if tex is None:
            total[:, 2] += w
        else:
            total += w[:, None] * entry.normals(sampler, tex, rows).reshape(-1, 3)
    length = np.linalg.norm(total, axis=1, keepdims=True)
    flat = length[:, 0] < 1e-6  # opposite normals cancelled: the geometric normal remains
    total[flat] = (0.0, 0.0, 1.0)
    length[flat] = 1.0
    return (total / length).reshape(n, sampler.width, 3)
