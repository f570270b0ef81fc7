"""A DCC's render beside lookdev's proof: Blender Cycles from the exported USD.

For each preset, three renders of one scene (the proof's ball, cup and ground under one
IBL, seen by the proof's camera, no rig):

- ``proof``: lookdev's proof of the preset (Mitsuba, the preset's own model);
- ``universal``: lookdev's ``--context universal`` proof (Mitsuba, the UsdPreviewSurface
  values by that surface's own BRDF: what the loss notes describe);
- ``cycles``: Blender Cycles (CPU) rendering the material Blender's USD importer made
  from the exported file, in a scene :func:`blender_scene` builds from the same numbers:
  camera origin, target and horizontal field of view, the IBL's pixels resampled to
  Blender's lat-long convention (:func:`blender_environment`), the same cup mesh and
  ground, Standard view, scene-linear EXR out. The ball's st is Mitsuba's sphere
  parametrisation (``blender_side``), so a textured preset's maps land where the proof
  shows them.

Compared on the ball (pixels whose camera ray meets it at under 70° from its normal,
:func:`ball_mask`): the mean colour's luminance and the per-pixel relative RMS
difference of luminance. Each side renders twice (Cycles with two seeds, the proofs at
``spp`` and ``spp + 2`` samples, an even count apart as the proofs round odd ones, so
Mitsuba's sampler draws other streams): half their difference is each side's noise
(:func:`compare`).

The loss note's stated size (the export's albedo change, :mod:`.fidelity`) is checked
against the render (:func:`agrees`): Cycles against the proof is within it plus three
standard errors of the two means, or the row is flagged.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "NOISE_SIGMAS",
    "PRESETS",
    "Y_UP_TO_Z_UP",
    "agrees",
    "ball_mask",
    "blender_environment",
    "blender_scene",
    "compare",
    "run",
]

PRESETS = (
    "gold",
    "plastic_glossy",
    "glass_clear",
    "velvet",
    "skin",
    "rusty_iron",
    "pixar_paint_red",
    "car_paint_red",
)
"""A metal, a glossy plastic, glass, velvet, skin, a layered textured preset, a Pixar
preset and a car paint."""

Y_UP_TO_Z_UP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])
"""lookdev's world (y up, camera on +z) → Blender's (z up, the same scene seen from −y)."""

GRAZING_COS = math.cos(math.radians(70.0))
NOISE_SIGMAS = 3.0
"""A difference within this many standard errors of the two means is noise."""


def _matrix4(linear: np.ndarray, translate=(0.0, 0.0, 0.0)) -> list[list[float]]:
    m = np.eye(4)
    m[:3, :3] = linear
    m[:3, 3] = translate
    return m.tolist()


def blender_environment(pixels: np.ndarray) -> np.ndarray:
    """A Mitsuba-convention lat-long (:mod:`lookdev.pipeline.proof.ibl`) resampled so that
    Blender's Environment Texture shows the same light from the same directions.

    Blender (observed in Cycles 4.5): column u at azimuth atan2(y, x) = π(1 − 2u) in its
    z-up world, row centres at θ = π(j + ½)/H from the zenith. In lookdev's y-up world
    that is u_Blender = u_Mitsuba + ¼, and Mitsuba's rows sit at θ = πj/(H − 1).
    Bilinear, wrapping in u.

    >>> env = np.random.default_rng(0).random((8, 16, 3)).astype(np.float32)
    >>> blender_environment(env).shape
    (8, 16, 3)
    """
    h, w = pixels.shape[:2]
    u_b = (np.arange(w) + 0.5) / w
    theta = math.pi * (np.arange(h) + 0.5) / h
    col = ((u_b - 0.25) % 1.0) * w - 0.5
    row = np.clip(theta / math.pi * (h - 1), 0.0, h - 1.0)
    c0 = np.floor(col).astype(int)
    fc = (col - c0)[None, :, None]
    r0 = np.minimum(np.floor(row).astype(int), h - 2)
    fr = (row - r0)[:, None, None]
    c0, c1 = c0 % w, (c0 + 1) % w
    top = pixels[r0][:, c0] * (1 - fc) + pixels[r0][:, c1] * fc
    bottom = pixels[r0 + 1][:, c0] * (1 - fc) + pixels[r0 + 1][:, c1] * fc
    return (top * (1 - fr) + bottom * fr).astype(np.float32)


def _camera() -> tuple[np.ndarray, np.ndarray, float]:
    """The proof camera without a rig: origin, target (y up) and horizontal fov (deg)."""
    from lookdev.pipeline.proof import shaderball

    origin, target = shaderball.eye("none")
    left, right = shaderball.framed("none")
    fov = 2.0 * math.degrees(
        math.atan(((right - left) / 2 + shaderball.MARGIN) / shaderball.DISTANCE)
    )
    return origin, target, fov


def blender_scene(environment: Path, resolution: tuple[int, int]) -> dict[str, Any]:
    """The proof scene (no rig) in Blender's coordinates, for ``blender_side.render``."""
    from lookdev.pipeline.proof import shaderball

    origin, target, fov = _camera()
    z = Y_UP_TO_Z_UP
    return {
        "environment": str(environment),
        "camera": {
            "origin": (z @ origin).tolist(),
            "target": (z @ target).tolist(),
            "fov_x_deg": fov,
        },
        "objects": [
            {
                "kind": "sphere",
                "matrix": _matrix4(np.eye(3), z @ shaderball.BALL_CENTER),
                # Blender's object axes → the ball's own (lookdev's world axes).
                "uv_frame": z.T.tolist(),
            },
            # The cup PLY is written in the proof's world already (cup_to_world(0) = 1).
            {"kind": "ply", "file": str(shaderball.cup_ply()), "matrix": _matrix4(z)},
            {
                "kind": "plane",
                "matrix": _matrix4(30.0 * np.eye(3)),
                "albedo": shaderball.GROUND_ALBEDO,
            },
        ],
        "resolution": list(resolution),
    }


def ball_mask(resolution: tuple[int, int]) -> np.ndarray:
    """(H, W) bool: pixels whose centre's camera ray meets the proof's ball at under 70°
    from its normal (the silhouette, where a tessellated and an exact sphere differ, is
    left out)."""
    from lookdev.pipeline.proof import shaderball

    w, h = resolution
    origin, target, fov = _camera()
    forward = (target - origin) / np.linalg.norm(target - origin)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    t = math.tan(math.radians(fov) / 2)
    x = (2 * (np.arange(w) + 0.5) / w - 1) * t
    y = (1 - 2 * (np.arange(h) + 0.5) / h) * t * h / w
    d = forward + x[None, :, None] * right + y[:, None, None] * up
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    oc = origin - np.asarray(shaderball.BALL_CENTER)
    b = d @ oc
    disc = b * b - (oc @ oc - 1.0)
    hit = disc > 0
    dist = -b - np.sqrt(np.where(hit, disc, 0.0))
    normal = oc + dist[..., None] * d
    cos = -np.sum(normal * d, axis=-1)
    return hit & (cos > GRAZING_COS)


@dataclass(frozen=True)
class Row:
    """One preset's figures (see the module docstring)."""

    preset: str
    mean: dict[str, list[float]]  # render → mean RGB on the ball
    mean_diff: dict[str, float]  # "cycles-universal", "cycles-proof": relative luminance
    pixel_rms: dict[str, float]  # the same pairs: per-pixel relative RMS of luminance
    noise: dict[str, float]  # per side (cycles, proof): the mean's standard error, per pixel
    loss: str  # the universal loss note, as Blender shows it
    stated: float  # the note's albedo change (0 where it says "fully")
    fully: bool  # the note says the universal context expresses the preset fully
    bound: float  # what |mean_diff["cycles-proof"]| may be: |stated| + noise
    agree: bool

    def to_json(self) -> dict[str, Any]:
        return self.__dict__.copy()


def agrees(diff: float, stated: float, fully: bool, noise: dict[str, float]) -> tuple[bool, float]:
    """Whether a render's relative mean difference agrees with a loss note: within the
    note's stated albedo change (none where the note says "fully") plus
    :data:`NOISE_SIGMAS` standard errors of the difference of the two means; and that
    bound.

    >>> ok, bound = agrees(0.008, -0.039, True, {"cycles_mean": 0.001, "proof_mean": 0.003})
    >>> ok, round(bound, 4)
    (True, 0.0095)
    >>> agrees(-0.70, -0.75, False, {"cycles_mean": 0.001, "proof_mean": 0.003})[0]
    True
    """
    sigma = math.hypot(noise["cycles_mean"], noise["proof_mean"])
    bound = (0.0 if fully else abs(stated)) + NOISE_SIGMAS * sigma
    return abs(diff) <= bound, bound


def _lum(rgb: np.ndarray) -> np.ndarray:
    from lookdev.materials.colour import luminance

    return np.asarray(luminance(rgb))


def _noise(a: np.ndarray, b: np.ndarray, ref: float) -> tuple[float, float]:
    """Two renders' average: its per-pixel noise (half their difference, RMS) and the
    standard error of its mean over the pixels, both relative to ``ref``."""
    half = 0.5 * (_lum(a) - _lum(b))
    pixel = float(np.sqrt(np.mean(half**2)))
    return pixel / math.sqrt(half.size) / ref, pixel / ref


def compare(
    renders: dict[str, np.ndarray], mask: np.ndarray
) -> tuple[dict[str, Any], dict[str, Any], dict[str, Any], dict[str, Any]]:
    """Means, relative mean differences, per-pixel relative RMS and each side's noise.

    ``renders``: ``universal``, two renders of the proof (``proof_a``, ``proof_b``) and
    of Cycles (``cycles_a``, ``cycles_b``), (H, W, 3) scene-linear. Each pair is used as
    its average.
    """
    ball = {"universal": renders["universal"][mask]}
    pairs = {}
    for side in ("cycles", "proof"):
        a, b = renders[f"{side}_a"][mask], renders[f"{side}_b"][mask]
        ball[side] = 0.5 * (a + b)
        pairs[side] = (a, b)
    mean = {k: v.mean(axis=0).tolist() for k, v in ball.items()}
    lum = {k: _lum(v) for k, v in ball.items()}
    ref = {k: float(lum[k].mean()) for k in lum}
    mean_diff, pixel = {}, {}
    for other in ("universal", "proof"):
        key = f"cycles-{other}"
        mean_diff[key] = (ref["cycles"] - ref[other]) / ref[other]
        pixel[key] = float(np.sqrt(np.mean((lum["cycles"] - lum[other]) ** 2)) / ref[other])
    noise = {}
    for side, (a, b) in pairs.items():
        noise[f"{side}_mean"], noise[f"{side}_pixel"] = _noise(a, b, ref[side])
    return mean, mean_diff, pixel, noise


def run(
    out: Path,
    presets: tuple[str, ...] = PRESETS,
    ibl: str = "studio",
    resolution: tuple[int, int] = (200, 100),
    spp: int = 128,
    progress: Any = None,
    python: Path | None = None,
) -> dict[str, Any]:
    """Render ``presets`` in Cycles and in lookdev's proofs; the figures (module doc).
    ``python``: the Blender to use (:func:`.blender.interpreter` by default)."""
    from lookdev.pipeline import api
    from lookdev.pipeline.proof import ibl as ibl_module
    from lookdev.pipeline.proof.contact import read_rgb, write_exr

    from . import blender

    out.mkdir(parents=True, exist_ok=True)
    usd = out / "usd" / "dcc.usda"
    usd.parent.mkdir(parents=True, exist_ok=True)
    step = progress or (lambda _text: None)
    step("export usd")
    sizes = api.export_usd(list(presets), usd, collect=True, report=True).fidelity
    for folder, samples in (("proofs", spp), ("proofs_b", spp + 2)):
        step(f"lookdev proofs (Mitsuba, {samples} spp)")
        api.proof(
            list(presets),
            [ibl],
            out / folder,
            frames=1,
            light_frames=0,
            spp=samples,
            resolution=resolution,
            rig="none",
            context="universal",
            denoise=False,
        )
    env = ibl_module.load(ibl, ibl_module.DEFAULT_WIDTH)
    env_path = write_exr(blender_environment(env.pixels), out / "blender_environment.exr")
    scene = blender_scene(env_path, resolution)
    depth = _depths(presets)
    frames: dict[str, dict[str, Path]] = {p: {} for p in presets}
    for seed, key in ((1, "cycles_a"), (2, "cycles_b")):
        for preset in presets:
            step(f"Cycles {preset} seed {seed}")
            folder = out / "cycles" / key
            folder.mkdir(parents=True, exist_ok=True)
            answer = blender.run(
                {
                    "op": "render",
                    "usd": str(usd),
                    "materials": [preset],
                    "out": str(folder),
                    "spp": spp // 2,
                    "max_bounces": max(depth[preset] - 2, 0),
                    "seed": seed,
                    "threads": 2,
                    **scene,
                },
                python=python,
            )
            frames[preset][key] = Path(answer["frames"][preset])
            version = answer["version"]
    mask = ball_mask(resolution)
    loss = _losses(usd)
    rows = []
    for preset in presets:
        renders = {k: read_rgb(p) for k, p in frames[preset].items()}
        renders["proof_a"] = read_rgb(out / "proofs" / preset / ibl / "frame_000.exr")
        renders["proof_b"] = read_rgb(out / "proofs_b" / preset / ibl / "frame_000.exr")
        renders["universal"] = read_rgb(
            out / "proofs" / f"{preset}-universal" / ibl / "frame_000.exr"
        )
        mean, mean_diff, pixel, noise = compare(renders, mask)
        size = sizes[preset]
        stated = 0.0 if size.fully else size.albedo_change
        agree, bound = agrees(mean_diff["cycles-proof"], stated, size.fully, noise)
        note = loss.get(preset, "")
        rows.append(
            Row(preset, mean, mean_diff, pixel, noise, note, stated, size.fully, bound, agree)
        )
    return {
        "blender": version,
        "ibl": ibl,
        "resolution": list(resolution),
        "spp": spp,
        "ball_pixels": int(mask.sum()),
        "rows": [r.to_json() for r in rows],
    }


def _depths(presets: tuple[str, ...]) -> dict[str, int]:
    """The path depth each proof renders with (Cycles gets as many bounces)."""
    from lookdev.pipeline.export.mitsuba import max_depth_for

    from .quality import blended

    return {p: int(max_depth_for(blended(p))) for p in presets}


def _losses(usd: Path) -> dict[str, str]:
    from pxr import Usd

    from lookdev.pipeline.export.usd.authoring import DCC_LOSS

    stage = Usd.Stage.Open(str(usd))
    out = {}
    for prim in stage.Traverse():
        attr = prim.GetAttribute(DCC_LOSS)
        if attr:
            out[prim.GetName()] = str(attr.Get())
    return out
