"""A lit sphere, evaluated directly with the numpy backend (Burley 2012 §3.2, "lit sphere").

An orthographic camera looks down −z at a unit sphere, world y up (Mitsuba's
convention, so an IBL lights the sphere as it lights the proof renders). Each pixel's
normal gives a shading frame; light and view are moved into it and the model's own
``eval``/``sample``/``pdf`` do the rest — no renderer in between, so what the sphere
shows is exactly the model the other plots describe.

* :func:`point_light_sphere`: one distant light of irradiance ``irradiance`` (at normal
  incidence): L = f(l, v) · max(N·L, 0) · E. A white Lambertian sphere lit head-on with
  the default E = π shows 1.0 at its centre.
* :func:`ibl_sphere`: a lat-long environment, L = ∫ f · cos · L_env dω by Monte Carlo
  with multiple importance sampling (balance heuristic, Veach 1997 §9.2) of the BSDF's
  sampler and the environment's luminance, so both a mirror and a diffuse sphere
  converge with a few dozen samples per pixel.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lookdev.materials.bsdf import Model, density, draw, evaluate
from lookdev.materials.colour import luminance

__all__ = [
    "LatLong",
    "MARGIN",
    "ibl_sphere",
    "maps_at",
    "point_light_sphere",
    "shading_frames",
    "sphere_normals",
    "sphere_uv",
    "to_local",
]

MARGIN = 1.08


def sphere_normals(resolution: int) -> tuple[np.ndarray, np.ndarray]:
    """World normals (H, W, 3) of the visible hemisphere and the disk mask (H, W).

    Row 0 is the top of the image (+y); pixel centres sample the square
    [−MARGIN, MARGIN]², so the sphere's silhouette sits inside the frame.
    """
    c = ((np.arange(resolution) + 0.5) / resolution * 2.0 - 1.0) * MARGIN
    x, y = np.meshgrid(c, -c)
    r2 = x * x + y * y
    inside = r2 < 1.0
    z = np.sqrt(np.clip(1.0 - r2, 0.0, None))
    return np.stack([x, y, z], axis=-1), inside


def shading_frames(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Tangent and bitangent for unit normals (..., 3), branch-free.

    :cite:t:`Duff2017`, Listing 3.
    """
    sign = np.where(n[..., 2] >= 0, 1.0, -1.0)
    a = -1.0 / (sign + n[..., 2])
    b = n[..., 0] * n[..., 1] * a
    t = np.stack([1.0 + sign * n[..., 0] ** 2 * a, sign * b, -sign * n[..., 0]], axis=-1)
    s = np.stack([b, sign + n[..., 1] ** 2 * a, -n[..., 1]], axis=-1)
    return t, s


def to_local(d: np.ndarray, t: np.ndarray, s: np.ndarray, n: np.ndarray) -> np.ndarray:
    """World direction(s) into the (t, s, n) frame."""
    return np.stack([(d * t).sum(-1), (d * s).sum(-1), (d * n).sum(-1)], axis=-1)


def sphere_uv(n: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Texture coordinates of world normals (..., 3): a lat-long wrap, seam at the back.

    u = ½ + atan2(x, z)/2π runs left to right across the visible half (0.25..0.75), and
    v = ½ + asin(y)/π runs bottom to top, so the front shows the texture's middle half.

    >>> [round(float(c), 3) for c in sphere_uv(np.array([0.0, 0.0, 1.0]))]
    [0.5, 0.5]
    """
    u = 0.5 + np.arctan2(n[..., 0], n[..., 2]) / (2.0 * math.pi)
    v = 0.5 + np.arcsin(np.clip(n[..., 1], -1.0, 1.0)) / math.pi
    return u, v


def maps_at(maps: dict[str, np.ndarray], n: np.ndarray) -> dict[str, np.ndarray]:
    """Each parameter map's nearest texel under normals (..., 3): (...) or (..., 3).

    Maps are in the blend's UV order: ``map[r, c]`` is centred on ((c + ½)/W, (r + ½)/H).
    """
    u, v = sphere_uv(n)
    out = {}
    for name, a in maps.items():
        h, w = a.shape[:2]
        col = np.clip((u * w).astype(int), 0, w - 1)
        row = np.clip((v * h).astype(int), 0, h - 1)
        out[name] = np.asarray(a[row, col], dtype=np.float64)
    return out


def _per_sample(pixel_maps: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Per-pixel maps (m,) / (m, 3) shaped to broadcast over (m, spp) samples."""
    return {k: a[:, None] if a.ndim == 1 else a[:, None, :] for k, a in pixel_maps.items()}


def point_light_sphere(
    model: Model,
    params: Any,
    *,
    resolution: int = 128,
    light: tuple[float, float, float] = (-1.0, 1.0, 1.0),
    irradiance: float = math.pi,
    maps: dict[str, np.ndarray] | None = None,
) -> np.ndarray:
    """Radiance image (H, W, 3) of the sphere under one distant light; black outside.

    ``maps`` (a blend's parameter maps) are wrapped onto the sphere (:func:`sphere_uv`).
    """
    n, inside = sphere_normals(resolution)
    l_world = np.asarray(light, dtype=np.float64)
    l_world = l_world / np.linalg.norm(l_world)
    t, s = shading_frames(n[inside])
    nn = n[inside]
    wi = to_local(l_world[None, :], t, s, nn)
    wo = to_local(np.array([[0.0, 0.0, 1.0]]), t, s, nn)
    f = evaluate(model, params, wi, wo, **maps_at(maps or {}, nn))
    image = np.zeros((resolution, resolution, 3))
    image[inside] = np.nan_to_num(f) * np.clip(wi[:, 2:3], 0.0, None) * irradiance
    return image


class LatLong:
    """A lat-long environment where Mitsuba's ``envmap`` shows it, importance-sampled.

    Mitsuba 3.9 puts column i at u = (i + ½)/W and row j at v = j/(H − 1) (measured by
    the proof module, :func:`lookdev.pipeline.proof.ibl.directions`); a direction is
    (sin φ sin θ, cos θ, −cos φ sin θ) with φ = 2πu, θ = πv (y up, row 0 the zenith).
    Row j therefore owns the band θ ∈ [π(j − ½)/(H − 1), π(j + ½)/(H − 1)] (half bands
    at the poles); texels are chosen by luminance × solid angle, then a direction
    uniformly in (φ, θ) within the texel.
    """

    def __init__(self, pixels: np.ndarray):
        self.pixels = np.asarray(pixels, dtype=np.float64)[..., :3]
        h, w = self.pixels.shape[:2]
        inner = (np.arange(1, h) - 0.5) / (h - 1) * math.pi
        self.edges = np.concatenate([[0.0], inner, [math.pi]])
        self.dphi = 2.0 * math.pi / w
        omega = self.dphi * (np.cos(self.edges[:-1]) - np.cos(self.edges[1:]))
        weight = np.maximum(luminance(self.pixels), 0.0) * omega[:, None]
        # A floor keeps every direction reachable, so MIS stays unbiased.
        weight = weight + 1e-3 * max(float(weight.sum() / omega.sum() / w), 1e-12) * omega[:, None]
        self.pmf = (weight / weight.sum()).reshape(-1)
        self.cdf = np.cumsum(self.pmf)
        self.shape = (h, w)

    def _texel(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(row, col, θ) of world directions (..., 3)."""
        h, w = self.shape
        u = (np.arctan2(d[..., 0], -d[..., 2]) / (2.0 * math.pi)) % 1.0
        theta = np.arccos(np.clip(d[..., 1], -1.0, 1.0))
        col = np.minimum((u * w).astype(int), w - 1)
        row = np.clip(np.searchsorted(self.edges, theta, side="right") - 1, 0, h - 1)
        return row, col, theta

    def lookup(self, d: np.ndarray) -> np.ndarray:
        """Radiance along world directions (..., 3), nearest texel."""
        row, col, _ = self._texel(d)
        return self.pixels[row, col]

    def pdf(self, d: np.ndarray) -> np.ndarray:
        """Solid-angle density of :meth:`sample` at world directions (..., 3)."""
        row, col, theta = self._texel(d)
        dtheta = self.edges[row + 1] - self.edges[row]
        sin_theta = np.maximum(np.sin(theta), 1e-8)
        return self.pmf[row * self.shape[1] + col] / (self.dphi * dtheta * sin_theta)

    def sample(self, u: np.ndarray) -> np.ndarray:
        """World directions for uniforms u (..., 3): u[0] picks a texel, u[1:] place in it."""
        h, w = self.shape
        idx = np.minimum(np.searchsorted(self.cdf, u[..., 0] * self.cdf[-1]), h * w - 1)
        row, col = np.divmod(idx, w)
        phi = self.dphi * (col + u[..., 1])
        theta = self.edges[row] + u[..., 2] * (self.edges[row + 1] - self.edges[row])
        return np.stack(
            [np.sin(phi) * np.sin(theta), np.cos(theta), -np.cos(phi) * np.sin(theta)], axis=-1
        )


def ibl_sphere(
    model: Model,
    params: Any,
    environment: np.ndarray,
    *,
    resolution: int = 96,
    spp: int = 64,
    seed: int = 0,
    maps: dict[str, np.ndarray] | None = None,
) -> np.ndarray:
    """Radiance image (H, W, 3) of the sphere lit by a lat-long environment (H', W', 3).

    Each pixel takes ``spp`` BSDF samples and ``spp`` environment samples, combined with
    the balance heuristic; the estimate is unbiased for any roughness. ``maps`` as in
    :func:`point_light_sphere`.
    """
    env = LatLong(environment)
    n, inside = sphere_normals(resolution)
    nn = n[inside]
    t, s = shading_frames(nn)
    wo = to_local(np.array([[0.0, 0.0, 1.0]]), t, s, nn)[:, None, :]
    rng = np.random.default_rng(seed)
    m = len(nn)
    frame = [a[:, None, :] for a in (t, s, nn)]
    per = _per_sample(maps_at(maps or {}, nn))

    # Strategy 1: the BSDF's own sampler.
    wi, weight, p_bsdf, delta = draw(
        model, params, np.broadcast_to(wo, (m, spp, 3)), rng.random((m, spp, 3)), delta=True, **per
    )
    world = sum(wi[..., k : k + 1] * frame[k] for k in range(3))
    p_env = env.pdf(world)
    # A delta lobe's direction cannot be drawn by the environment: weight 1.
    mis = np.where(delta, 1.0, np.where(p_bsdf > 0, p_bsdf / (p_bsdf + p_env), 0.0))
    est = np.nan_to_num(weight * env.lookup(world) * mis[..., None]).sum(axis=1)

    # Strategy 2: the environment's luminance.
    world = env.sample(rng.random((m, spp, 3)))
    wi = to_local(world, *frame)
    f = evaluate(model, params, wi, np.broadcast_to(wo, (m, spp, 3)), **per)
    p_bsdf = density(model, params, wi, np.broadcast_to(wo, (m, spp, 3)), **per)
    p_env = env.pdf(world)
    contrib = f * np.abs(wi[..., 2:3]) * env.lookup(world) / (p_env + p_bsdf)[..., None]
    est += np.nan_to_num(contrib).sum(axis=1)

    image = np.zeros((resolution, resolution, 3))
    image[inside] = est / spp
    return image
