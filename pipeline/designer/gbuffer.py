"""The designer mode's geometry buffer: what the camera sees, rendered once per pose.

:cite:`Burley2012` §6.1: the Material Designer "renders out a geometry buffer (or g-buffer)
containing normals, object IDs, and material layer masks" and relights it while the
material is edited. Here the buffer is made by Mitsuba's own ray intersection on the proof
scene (:func:`lookdev.pipeline.proof.shaderball.scene_dict`: the ball and the cup, or a
user's mesh in the cup's place, the rig and the ground) with a stand-in BSDF on the
material's shapes, so no material is traced to make it and it stays valid while the
material changes. It is rendered again only when the camera, the film or the element's
rotation changes.

Per pixel it holds, at :data:`SUBPIXELS` positions inside the pixel (a stratified grid,
so the progressive image converges to the box-filtered pixel the proofs render):

* the object id (:attr:`GBuffer.objects`), position, shading normal and tangent, UV;
* for the material's pixels the view direction and the pixel they land in
  (:class:`Hits`), from which :mod:`.relight` shades the model;
* for the other objects what their own Mitsuba BSDFs say at that view, read once: the
  diffuse reflectance (``eval_diffuse_reflectance``: the ground, the grey ball, the
  chart) and the delta reflection's direction and weight (the chrome ball's mirror), so
  relighting them needs no BSDF call at all;
* for the background, the camera ray's direction (the environment is seen there).

The layer masks of a layered material are read at the pixels' UVs (:func:`layer_masks`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["SUBPIXELS", "GBuffer", "Hits", "layer_masks", "render"]

SUBPIXELS = 4
"""Positions per pixel (a 2 × 2 grid, centred in each quarter); pass i shades position
i mod SUBPIXELS, so every 4 passes are one anti-aliased sample of the whole image."""


CHUNK = 4096
"""Hit arrays are padded to a multiple of this many entries (see :class:`Hits`)."""


@dataclass
class Hits:
    """One sub-pixel position's hits of one kind, as Dr.Jit arrays (SoA) and numpy.

    The Dr.Jit arrays hold :attr:`width` entries, the hits padded with copies of the
    last one to a multiple of :data:`CHUNK` shared by every sub-pixel position of the
    buffer, so the frozen passes (:mod:`.relight`) see one width per buffer, and mostly
    the same one when the element turns; only the first :attr:`count` results are kept.
    """

    pixel: np.ndarray  # (N,) flat pixel index y·W + x
    arrays: dict[str, Any]  # Dr.Jit values over the padded hits
    uv: np.ndarray | None = None  # (N, 2), material hits only
    width: int = 0

    @property
    def count(self) -> int:
        return int(self.pixel.size)


@dataclass
class GBuffer:
    """The g-buffer of one pose (see the module docstring)."""

    width: int
    height: int
    objects: tuple[str, ...]
    """Object names by id; id 0 is the background."""
    object_id: np.ndarray  # (H, W) uint8 at the first sub-pixel position
    position: np.ndarray  # (H, W, 3) float32 world space
    normal: np.ndarray  # (H, W, 3) shading normal
    tangent: np.ndarray  # (H, W, 3)
    uv: np.ndarray  # (H, W, 2)
    material: list[Hits]  # per sub-pixel position: the material's pixels
    other: list[Hits]  # per sub-pixel position: every other pixel (objects and background)

    def material_mask(self) -> np.ndarray:
        """(H, W) bool: pixels whose first sub-pixel position sees the material."""
        out = np.zeros(self.width * self.height, bool)
        out[self.material[0].pixel] = True
        return out.reshape(self.height, self.width)


MATERIAL_OBJECTS = ("ball", "cup")
"""The proof scene's shapes that carry the material (the cup slot holds a user's mesh)."""


def _ids(mi: Any, dr: Any, ptr: Any) -> np.ndarray:
    return np.array(dr.reinterpret_array(mi.UInt32, ptr), dtype=np.uint32)


def _np(v: Any) -> np.ndarray:
    """A Dr.Jit 3-vector as (N, 3) float32."""
    return np.asarray(v, dtype=np.float32).reshape(3, -1).T


def _padded(a: np.ndarray, width: int) -> np.ndarray:
    if len(a) == width:
        return a
    if len(a) == 0:
        return np.zeros((width, *a.shape[1:]), a.dtype)
    return np.concatenate([a, np.repeat(a[-1:], width - len(a), axis=0)])


def _width(counts: list[int]) -> int:
    return max(CHUNK, -(-max(counts) // CHUNK) * CHUNK)


def _arrays(mi: Any, columns: dict[str, tuple[np.ndarray, Any]], width: int) -> dict[str, Any]:
    """Padded numpy columns as Dr.Jit values of the given types."""
    out = {}
    for key, (a, kind) in columns.items():
        a = _padded(a, width)
        if kind is mi.Bool:
            out[key] = mi.Bool(np.ascontiguousarray(a))
            continue
        a = np.ascontiguousarray(a, dtype=np.float32)
        out[key] = kind(*(mi.Float(np.ascontiguousarray(a[:, k])) for k in range(a.shape[1])))
    return out


def render(scene: Any, width: int, height: int, subpixels: int = SUBPIXELS) -> GBuffer:
    """The g-buffer of ``scene`` (a loaded proof scene) through its first sensor."""
    import drjit as dr
    import mitsuba as mi

    sensor = scene.sensors()[0]
    shapes = list(scene.shapes())
    objects = ("background", *(s.id() for s in shapes))
    registry = {int(_ids(mi, dr, mi.ShapePtr(s))[0]): i + 1 for i, s in enumerate(shapes)}
    lookup = np.zeros(max(registry) + 1, np.uint8)
    for rid, oid in registry.items():
        lookup[rid] = oid
    material_ids = [objects.index(n) for n in MATERIAL_OBJECTS if n in objects]
    side = max(1, math.isqrt(subpixels))
    offsets = [((i % side + 0.5) / side, (i // side + 0.5) / side) for i in range(side * side)]
    n = width * height
    index = np.arange(n)
    px, py = (index % width).astype(np.float32), (index // width).astype(np.float32)
    material, other, first = [], [], None
    for ox, oy in offsets:
        ray, _ = sensor.sample_ray(
            0.0,
            0.0,
            mi.Point2f(mi.Float((px + ox) / width), mi.Float((py + oy) / height)),
            mi.Point2f(0.5, 0.5),
        )
        si = scene.ray_intersect(ray)
        bsdf = si.bsdf()
        albedo = bsdf.eval_diffuse_reflectance(si)
        ctx = mi.BSDFContext()
        ctx.type_mask = mi.BSDFFlags.Delta
        bs, mirror = bsdf.sample(ctx, si, 0.5, mi.Point2f(0.5, 0.5))
        mirror_d = si.to_world(bs.wo)
        dr.eval(si, albedo, mirror, mirror_d, ray)
        inst, shape = _ids(mi, dr, si.instance), _ids(mi, dr, si.shape)
        hit_ids = np.where(inst != 0, inst, shape)
        oid = np.where(hit_ids < lookup.size, lookup[np.minimum(hit_ids, lookup.size - 1)], 0)
        oid = np.where(np.asarray(si.is_valid(), bool), oid, 0).astype(np.uint8)
        p, nrm, tan = _np(si.p), _np(si.sh_frame.n), _np(si.sh_frame.s)
        uv = np.asarray(si.uv, np.float32).reshape(2, -1).T
        view = -_np(ray.d)
        is_mat = np.isin(oid, material_ids)
        m, o = np.flatnonzero(is_mat), np.flatnonzero(~is_mat)
        # Objects first, background last: SIMD packets then mostly share one branch.
        o = np.concatenate([o[oid[o] != 0], o[oid[o] == 0]])
        hit = oid[o] != 0
        material.append(
            (
                m,
                {
                    "p": (p[m], mi.Point3f),
                    "n": (nrm[m], mi.Vector3f),
                    "s": (tan[m], mi.Vector3f),
                    "wo": (view[m], mi.Vector3f),
                },
                uv[m],
            )
        )
        other.append(
            (
                o,
                {
                    "p": (p[o], mi.Point3f),
                    "n": (nrm[o], mi.Vector3f),
                    "view": (view[o], mi.Vector3f),
                    "hit": (hit, mi.Bool),
                    "albedo": (np.clip(_np(albedo)[o], 0.0, None), mi.Color3f),
                    "mirror_d": (_np(mirror_d)[o], mi.Vector3f),
                    "mirror_w": (np.where(hit[:, None], _np(mirror)[o], 0.0), mi.Color3f),
                },
                None,
            )
        )
        if first is None:
            first = (oid, p, nrm, tan, uv)
    oid, p, nrm, tan, uv = first
    kinds = []
    for entries in (material, other):
        width_ = _width([len(e[0]) for e in entries])
        kinds.append([Hits(i, _arrays(mi, cols, width_), uv_, width_) for i, cols, uv_ in entries])
    material, other = kinds
    return GBuffer(
        width,
        height,
        objects,
        oid.reshape(height, width),
        p.reshape(height, width, 3),
        nrm.reshape(height, width, 3),
        tan.reshape(height, width, 3),
        uv.reshape(height, width, 2),
        material,
        other,
    )


def layer_masks(hub: Any, uv: np.ndarray) -> dict[str, np.ndarray]:
    """Each layer's mask of a layered material read at ``uv`` (…, 2), by layer label.

    The masks are evaluated by the blend's own sampler
    (:class:`lookdev.pipeline.blend.masks.MaskSampler`) at the material's map resolution
    over its UV extent and read at the nearest texel (:meth:`BlendedMaterial.texel`).
    """
    from lookdev.pipeline.blend.masks import MaskSampler

    width, height = hub.resolution
    sampler = MaskSampler((height, width), extent=tuple(hub.uv_extent))
    rows, cols = hub.texel(uv)
    return {
        str(entry.label): sampler.evaluate(entry.mask)[rows, cols]
        for entry in getattr(hub, "layers", None) or []
    }
