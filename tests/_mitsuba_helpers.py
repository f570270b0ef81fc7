"""Shared pieces of the Mitsuba tests: the variant fixture and small geometry helpers."""

from __future__ import annotations

import math

import numpy as np


def mitsuba_module():
    """Mitsuba with lookdev's variant set (llvm_ad_rgb here); the tests' ``mi`` fixture."""
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba

    return mitsuba


def unit(v):
    v = np.asarray(v, dtype=np.float64)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def interaction(mi, wi, uv=(0.5, 0.5)):
    """A SurfaceInteraction3f per viewer direction ``wi`` (local frame), at ``uv``."""
    import drjit as dr

    wi = np.atleast_2d(np.asarray(wi, dtype=np.float32))
    si = dr.zeros(mi.SurfaceInteraction3f, len(wi))
    si.wi = mi.Vector3f(wi.T)
    si.uv = mi.Point2f(*uv)
    return si


def pixel_view_angles(scene, rows, cols):
    """View angle θ of the sphere's surface seen through each pixel centre (pinhole)."""
    film = scene["sensor"]["film"]
    width, height = film["width"], film["height"]
    matrix = np.array(scene["sensor"]["to_world"].matrix, dtype=np.float64)
    origin = matrix[:3, 3]
    half = math.tan(math.radians(scene["sensor"]["fov"]) / 2)  # fov along x
    x = (1 - 2 * (cols + 0.5) / width) * half  # Mitsuba's image x runs opposite world x
    y = (1 - 2 * (rows + 0.5) / height) * half * height / width
    d = unit(np.stack([x, y, -np.ones_like(x)], axis=-1))
    b = (d * origin).sum(-1)
    t = -b - np.sqrt(b * b - (origin @ origin - 1.0))
    normal = origin + t[..., None] * d
    return np.arccos(np.clip(-(d * normal).sum(-1), -1, 1))
