"""What path-traced subsurface scattering does and costs, measured by rendering.

* :func:`slab` — a thick slab of a solid subsurface material (a 100 × 100 × 2 box of
  scatter distance 0.02, so ≥ 50 σt⁻¹ deep and wide) under a uniform white sky, seen
  straight down by an orthographic camera: the radiance it sends up is its directional
  albedo at normal incidence, to be compared with its base colour (the claim of the
  slab albedo table, :data:`lookdev.materials.subsurface.SLAB_TABLE`). Specular
  and roughness 0, so the surface adds nothing but the entry into the medium.
* :func:`furnace` — a white solid subsurface sphere in a uniform white sky (≤ 1 at
  roughness 0; rougher, Burley's retro-reflection adds energy on the surface by design,
  less than it adds to the same sphere without a distance).
* :func:`rim_glow` — the proof cup lit from behind: the radiance of its thin rim with
  the material's scatter distance against the same preset without one.
* :func:`cost` — a proof's render time and noise with the medium against the same preset
  without a distance, at equal spp and (by noise² · time) at equal noise, in one run.
"""

from __future__ import annotations

import time
from typing import Any

import numpy as np

__all__ = [
    "COLOURS",
    "albedo_table",
    "cost",
    "furnace",
    "rim_glow",
    "run",
    "slab",
    "slab_of_albedo",
]

COLOURS = {"grey": (0.5, 0.5, 0.5), "skin": (0.8, 0.5, 0.35), "jade": (0.3, 0.6, 0.4)}
"""The three colours whose slabs are measured (a grey, a warm and a cool one)."""
SLAB_DISTANCE = 0.02
RIM_CLAMP = 10.0
"""Per-sample radiance limit of :func:`rim_glow` (the light is 500): the near rim does not
see the light past the far wall, so a polished cup (marble, roughness 0.12) is lit there
by rare glossy interreflection paths, fireflies whose unclamped mean did not converge
(marble without a distance: 0.026, 0.039, 0.058 at 8, 32, 128 spp; the ratio 8.1, 0.76,
1.85). Clamped, both renders lose the same caustic paths and keep the diffuse glow."""
SLAB_DEPTH = 4096  # paths end by Russian roulette long before; a slab is a deep walk


def _variant() -> Any:
    import mitsuba as mi

    from lookdev.pipeline.export.mitsuba.scene import _ensure_variant

    _ensure_variant()
    return mi


def _render(scene: dict[str, Any], spp: int, seed: int = 0) -> np.ndarray:
    mi = _variant()
    return np.asarray(mi.render(mi.load_dict(scene), spp=spp, seed=seed), dtype=np.float64)


def _sky() -> dict[str, Any]:
    return {"type": "constant", "radiance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}}


def _mean_and_error(pixels: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Mean of independent pixel estimates (N, 3) and its standard error."""
    return pixels.mean(axis=0), pixels.std(axis=0, ddof=1) / np.sqrt(len(pixels))


def slab(
    colour: tuple[float, float, float], *, spp: int = 256, size: int = 16
) -> tuple[np.ndarray, np.ndarray]:
    """The thick slab's rendered directional albedo (RGB) at normal incidence, and the
    standard error of that mean (from the spread of its independent pixels)."""
    _variant()

    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.export.mitsuba import bsdf_dict
    from lookdev.pipeline.export.mitsuba.medium import interior_dict

    p = DisneyParams(base_color=colour, specular=0.0, roughness=0.0, scatter_distance=SLAB_DISTANCE)
    medium = interior_dict(p)
    return _mean_and_error(
        _render(_slab_scene(bsdf_dict(p), medium, spp, size), spp).reshape(-1, 3)
    )


def _slab_scene(bsdf: dict, medium: dict, spp: int, size: int) -> dict[str, Any]:
    mi = _variant()
    from lookdev.pipeline.export.mitsuba.medium import integrator

    return {
        "type": "scene",
        "integrator": integrator(SLAB_DEPTH, medium),
        "sensor": {
            "type": "orthographic",
            "to_world": mi.ScalarTransform4f()
            .look_at(origin=[0, 0, 5], target=[0, 0, 0], up=[0, 1, 0])
            .scale([0.5, 0.5, 1]),
            "film": {"type": "hdrfilm", "width": size, "height": size, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "sky": _sky(),
        "slab": {
            "type": "cube",
            "to_world": mi.ScalarTransform4f().scale([50, 50, 1]),
            "bsdf": bsdf,
            "interior": medium,
        },
    }


def slab_of_albedo(
    albedo: tuple[float, float, float], *, spp: int = 256, size: int = 16
) -> tuple[np.ndarray, np.ndarray]:
    """The thick slab's rendered reflectance (RGB) and its standard error for a medium of
    single-scattering ``albedo`` per channel: the slab of :func:`slab` with its medium's
    albedo set directly and σt that of a grey 0.5 in every channel (the slab is hundreds
    of mean free paths deep whatever σt, so the reflectance depends on the albedo alone)."""
    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.export.mitsuba import bsdf_dict
    from lookdev.pipeline.export.mitsuba.medium import interior_dict

    grey = (0.5, 0.5, 0.5)  # one σt for all channels: no channel's free flight reweighted
    p = DisneyParams(base_color=grey, specular=0.0, roughness=0.0, scatter_distance=SLAB_DISTANCE)
    medium = interior_dict(p)
    medium["albedo"] = {"type": "rgb", "value": [float(a) for a in albedo]}
    scene = _slab_scene(bsdf_dict(p), medium, spp, size)
    return _mean_and_error(_render(scene, spp).reshape(-1, 3))


def albedo_table(
    roots: Any = None, *, spp: int = 256, size: int = 32
) -> tuple[tuple[float, float], ...]:
    """(rendered slab reflectance A, albedo α) rows of our own thick slab, for the table
    :data:`lookdev.materials.subsurface.SLAB_TABLE`: α = 1 − u² over ``roots`` u (three
    per render, one per channel), plus the exact ends (0, 0). Rows sorted by α; a noisy
    non-increasing A is kept as rendered (the test bounds it by the standard error).
    """
    if roots is None:
        roots = (*np.linspace(1.0, 0.1, 28)[1:], 0.08, 0.06, 0.045, 0.03, 0.02, 0.014, 0.01)
        roots = (*roots, 0.005, 0.0)
    u = np.asarray(roots, dtype=np.float64)
    u = np.concatenate([u, np.full((-len(u)) % 3, u[-1])])  # whole renders of three
    rows = {0.0: 0.0}
    for chunk in u.reshape(-1, 3):
        alpha = 1.0 - chunk * chunk
        got, _ = slab_of_albedo(tuple(alpha), spp=spp, size=size)
        rows.update({float(a): float(r) for a, r in zip(alpha, got, strict=True)})
    return tuple((rows[a], a) for a in sorted(rows))


def furnace(
    *, scatter_distance: float = 0.5, roughness: float = 0.5, spp: int = 256
) -> tuple[float, float]:
    """Mean radiance of a white solid subsurface sphere in a white sky (pixels inside
    90 % of its radius, all channels) and the standard error of that mean."""
    from lookdev.materials.params import DisneyParams
    from lookdev.pipeline.export.mitsuba import scene_dict

    p = DisneyParams(base_color=(1, 1, 1), roughness=roughness, scatter_distance=scatter_distance)
    size = 64
    img = _render(scene_dict(p, resolution=(size, size), spp=spp, max_depth=SLAB_DEPTH), spp)
    y, x = (np.mgrid[:size, :size] + 0.5 - size / 2) / (size / 2 / 1.15 * 0.999)
    inside = (x * x + y * y) < 0.9**2
    mean, error = _mean_and_error(img[inside].mean(axis=-1, keepdims=True))
    return float(mean[0]), float(error[0])


def _preset_pair(name: str, distance_scale: float = 1.0) -> tuple[Any, Any]:
    from lookdev import blend, load

    hub = blend(load(name), 64)
    if distance_scale != 1.0:
        d = hub.constants["scatter_distance"] * distance_scale
        hub.constants = {**hub.constants, "scatter_distance": d}
        hub.__dict__.pop("params", None)  # its cache, if built: from the constants again
    flat = blend(load(name), 64)
    flat.constants = {**flat.constants, "scatter_distance": 0.0}
    return hub, flat


def rim_glow(
    name: str = "skin",
    *,
    spp: int = 64,
    size: tuple[int, int] = (160, 80),
    distance_scale: float = 1.0,
    clamp: float | None = RIM_CLAMP,
) -> dict:
    """Mean radiance of the cup's rim under a back light, with and without the distance
    (the preset's, times ``distance_scale``).

    The environment is black but for a small bright light behind the cup (opposite the
    camera), so what the rim sends to the camera is light that went through it, or
    reached it at grazing.
    """
    from lookdev.pipeline.proof import shaderball
    from lookdev.pipeline.proof.turntable import material_bsdf, material_interior

    _variant()
    env = np.zeros((128, 256, 3), dtype=np.float32)
    # An 11° square light just above the horizon, behind the cup (−z: the lat-long's
    # edge columns; its centre column faces the camera, :data:`.ibl.ORIENTATION`).
    env[56:64, :4] = env[56:64, -4:] = 500.0
    out = {}
    for label, hub in zip(("with", "without"), _preset_pair(name, distance_scale), strict=True):
        bsdf, depth = material_bsdf(hub)
        interior = material_interior(hub)
        scene = shaderball.scene_dict(
            bsdf, env, size, depth, rig="none", interior=interior, clamp=clamp
        )
        out[label] = _render(scene, spp)
    rim = _rim_mask(size)
    w, wo = out["with"][rim].mean(), out["without"][rim].mean()
    return {"with": float(w), "without": float(wo), "ratio": float(w / max(wo, 1e-12))}


def _rim_mask(size: tuple[int, int]) -> np.ndarray:
    """Pixels of the cup's rim in the proof camera (a position pass, rendered once): the
    points above the cup's opening plane less half a wall, in the cup's own frame."""
    from lookdev.pipeline.proof import shaderball

    _variant()
    scene = shaderball.scene_dict(
        {"type": "diffuse"}, np.ones((8, 16, 3), np.float32), size, 2, rig="none"
    )
    scene["integrator"] = {"type": "aov", "aovs": "pos:position"}
    pos = _render(scene, 4)[..., :3]
    tilt = shaderball.rotation_x(shaderball.CUP_TILT_DEG)
    local = (pos - np.asarray(shaderball.CUP_CENTER)) @ tilt  # world → the cup's frame
    radial = np.hypot(local[..., 0], local[..., 2])
    dist = np.linalg.norm(local, axis=-1)
    on_cup = (dist > 1 - shaderball.CUP_WALL - 0.01) & (dist < 1.01) & (pos[..., 1] > 0.05)
    rim = (local[..., 1] > -shaderball.CUP_WALL / 2) & (radial > 1 - 1.5 * shaderball.CUP_WALL)
    return on_cup & rim


def cost(name: str = "skin", *, spp: int = 16, repeats: int = 2) -> dict[str, float]:
    """Render time and relative noise of a proof frame with and without the distance,
    interleaved in one process; the equal-noise ratio is (time · noise²) over (time ·
    noise²), since noise² falls as 1/spp."""
    from lookdev.pipeline.proof import ibl
    from lookdev.pipeline.proof.passes import render_frame
    from lookdev.pipeline.proof.turntable import (
        Frame,
        Turntable,
        material_bsdf,
        material_interior,
    )

    _variant()
    env = ibl.load("studio").pixels
    tables = {}
    for label, hub in zip(("with", "without"), _preset_pair(name), strict=True):
        bsdf, depth = material_bsdf(hub)
        tables[label] = Turntable(bsdf, env, (160, 80), depth, interior=material_interior(hub))
    times = {k: [] for k in tables}
    noise = {k: [] for k in tables}
    frame = Frame(0, "element", 0.0)
    for t in tables.values():  # warm-up: compile both kernels before timing
        render_frame(t, frame, spp=spp)
    for r in range(repeats):
        for k, t in tables.items():
            start = time.perf_counter()
            out = render_frame(t, Frame(r + 1, "element", 45.0 * (r + 1)), spp=spp)
            times[k].append(time.perf_counter() - start)
            noise[k].append(out.noise or 0.0)
    t_w, t_o = np.median(times["with"]), np.median(times["without"])
    n_w, n_o = np.mean(noise["with"]), np.mean(noise["without"])
    return {
        "time_ratio": float(t_w / t_o),
        "noise_with": float(n_w),
        "noise_without": float(n_o),
        "equal_noise_ratio": float((t_w * n_w**2) / (t_o * n_o**2)),
    }


def run(
    *,
    spp: int = 64,
    presets: tuple[str, ...] = ("skin", "jade"),
    rims: tuple[str, ...] = ("skin", "jade", "marble"),
) -> dict[str, Any]:
    """Every figure of this module in one run: slab error per colour and channel, the
    furnace's brightest block, the rim ratios, and the cost against no distance."""
    slabs = {}
    for name, colour in COLOURS.items():
        got, std = slab(colour, spp=4 * spp, size=32)
        slabs[name] = {"base": list(colour), "rendered": got.tolist(),
                       "error": (got - np.asarray(colour)).tolist(),
                       "standard_error": std.tolist()}  # fmt: skip
    return {
        "mapping": "albedo from our own slab table (SLAB_TABLE), s of Christensen-Burley 2015",
        "slab": slabs,
        # roughness 0: the medium and its boundary alone (≤ 1); 0.5: with Burley's
        # retro-reflection on the surface, which adds energy by design (see the opaque)
        "furnace": dict(
            zip(("mean", "standard_error"), furnace(roughness=0.0, spp=2 * spp), strict=True)
        ),
        "furnace_rough": {
            "with": furnace(roughness=0.5, spp=2 * spp)[0],
            "without": furnace(scatter_distance=0.0, roughness=0.5, spp=2 * spp)[0],
        },
        "rim": {name: rim_glow(name, spp=spp) for name in rims},
        "cost": {name: cost(name, spp=max(spp // 4, 4)) for name in presets},
    }
