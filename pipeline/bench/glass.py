"""``lookdev bench glass``: what our glass costs against Mitsuba's own, at equal noise.

For each glass preset the proof shader ball (:mod:`lookdev.pipeline.proof.shaderball`: a
sphere and a cup of the material on a ground plane, under one IBL) is rendered twice
over: with our plugin and with the nearest Mitsuba built-in (:func:`builtin_dict`:
``dielectric`` for a smooth solid, ``roughdielectric`` with the same GGX α for a rough
one, ``thindielectric`` for a thin sheet). The two models need not be identical, only
near: what is compared is the work each needs for a given noise.

Per renderer, ``repeat`` frames of ``spp`` samples with independent seeds, taken in
interleaved rounds (ours, built-in, built-in, ours, …: ABBA, so a load that rises or
falls through the run slows both alike) after one warm-up render each, so compilation is
not counted:

* **noise** (:func:`noise`): the relMSE of one frame, estimated as the per-pixel variance
  over the frames over (ref² + ε), ref the two renderers' ``reference_spp`` references pooled, one
  denominator for both sides. An unbiased renderer's MSE is its variance, so no
  reference enters the numerator. (Measuring each frame against its own renderer's
  reference, as this bench first did, adds that one reference's error, fireflies
  included, to every frame of one side only, and the reference's seed was fixed, so
  every run repeated it: on the same 16 frames of ``ice`` three 1024-spp reference
  seeds gave ours/``roughdielectric`` 1.58, 1.53 and 1.27, the variance over the frames
  0.88.) A 90 % bootstrap interval over the seeds comes with the ratio: caustic
  fireflies make it wide.
* **time**: the median CPU time of a frame (every thread of this process, so time the
  scheduler gives other programs on a shared machine is not counted; wall time is
  reported beside it), and the quartiles of the per-round ratio.

Monte Carlo error falls as 1/spp while time grows as spp, so relMSE × seconds is the
cost at equal noise, and

    ratio = (relMSE × s)_ours / (relMSE × s)_built-in     (target ≤ 1.5).

``reference_difference`` is the relative difference of the two renderers' mean luminance
over every sample rendered (frames and reference pooled), with its standard error
(``reference_difference_se``, from the frames' spread): how near the models are.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from lookdev.materials.colour import luminance
from lookdev.materials.disney_prepare import ETA_MIN
from lookdev.materials.errors import LookdevError
from lookdev.materials.microfacet import ALPHA_MIN, is_delta

__all__ = [
    "DEFAULT_PRESETS",
    "TARGET",
    "BenchGlassError",
    "Settings",
    "builtin_dict",
    "noise",
    "run",
]

DEFAULT_PRESETS = (
    "glass_clear",
    "glass_green",
    "glass_thin",
    "water",
    "diamond",
    "acrylic",
    "ice",
    "glass_frosted",
)
"""Every built-in glass preset (``presets/glass``)."""
TARGET = 1.5
"""The cost ratio ours / built-in at equal noise (target ≤ 1.5), per preset."""


RELMSE_EPS = 1e-2
"""ε of relMSE's denominator (:func:`.measure.relative_mse`'s default)."""
BOOTSTRAP = 400
"""Resamplings of the seeds for the noise ratio's interval."""


class BenchGlassError(LookdevError):
    """The glass benchmark cannot run as asked."""


@dataclass(frozen=True)
class Settings:
    presets: tuple[str, ...] = DEFAULT_PRESETS
    ibl: str = "sky"
    spp: int = 16
    reference_spp: int = 256
    resolution: tuple[int, int] = (128, 64)
    repeat: int = 24
    ibl_width: int = 256

    @classmethod
    def quick(cls, **given: Any) -> Settings:
        """A few seconds per preset, for tests."""
        quick = {"spp": 4, "reference_spp": 64, "resolution": (32, 16), "repeat": 2}
        return cls(**{**quick, **given})


def builtin_dict(params: Any) -> dict[str, Any]:
    """The Mitsuba built-in nearest a Disney glass (``spec_trans`` 1, metallic 0).

    Same IOR (floored at :data:`ETA_MIN` as our model does) and transmittance (√base for a
    thin sheet, Schutte); ``dielectric`` where our lobes are deltas
    (:func:`~lookdev.materials.microfacet.is_delta`), else ``roughdielectric`` with our
    GGX α = roughness² (at least :data:`ALPHA_MIN`). Mitsuba has no rough thin sheet, so a
    thin preset always gets ``thindielectric``, which also adds the sheet's internal
    reflections; our thin sheet is one interface (Burley 2015).
    """
    if getattr(params, "spec_trans", 0.0) != 1.0 or getattr(params, "metallic", 1.0) != 0.0:
        raise BenchGlassError("only a Disney glass (spec_trans 1, metallic 0) has a built-in twin")
    ior = max(params.effective_ior, ETA_MIN)
    base = np.asarray(params.base_color, dtype=float)
    colour = np.sqrt(base) if params.thin else base
    out: dict[str, Any] = {
        "int_ior": float(ior),
        "ext_ior": 1.0,
        "specular_transmittance": {"type": "rgb", "value": [float(c) for c in colour]},
    }
    if params.thin:
        return {"type": "thindielectric", **out}
    if is_delta(params.roughness, params.anisotropic):
        return {"type": "dielectric", **out}
    alpha = max(params.roughness**2, ALPHA_MIN)
    return {"type": "roughdielectric", "distribution": "ggx", "alpha": alpha, **out}


def _render_timed(scene: Any, spp: int, seed: int) -> tuple[np.ndarray, float, float]:
    """(image, wall seconds, CPU seconds): the CPU time of every thread of this process,
    so time the scheduler gives to other programs on a shared machine is not counted."""
    import mitsuba as mi

    c0, t0 = time.process_time(), time.perf_counter()
    image = np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)
    return image, time.perf_counter() - t0, time.process_time() - c0


def noise(frames: np.ndarray, denominator: np.ndarray) -> float:
    """The relMSE of one frame, from independent frames (axis 0) of an unbiased renderer:
    the per-pixel sample variance over the frames (Bessel-corrected) over ``denominator``
    (ref² + ε, Rousselle et al. 2011 §6), averaged over pixels.

    MSE = variance for an unbiased renderer, so no converged reference enters the
    numerator: a reference's own fireflies (one realisation, shared by every frame
    compared with it) would otherwise add the same error to every frame of one side only.
    """
    return float(np.mean(np.var(frames, axis=0, ddof=1) / denominator))


def _interval(ours: np.ndarray, builtin: np.ndarray, den: np.ndarray, draws: int) -> list[float]:
    """A 90 % bootstrap interval of the noise ratio: the seeds (pairs of frames, one per
    renderer, taken in the same round) resampled with replacement."""
    rng = np.random.default_rng(0)
    n = len(ours)
    ratios = []
    for _ in range(draws):
        pick = rng.integers(0, n, n)
        if len(set(pick.tolist())) < 2:
            continue
        ratios.append(noise(ours[pick], den) / max(noise(builtin[pick], den), 1e-300))
    return [float(q) for q in np.quantile(ratios, (0.05, 0.95))]


def _brightness(frames: np.ndarray, reference: np.ndarray, spp: int, ref_spp: int):
    """(mean luminance of every sample rendered, its standard error): the frames and the
    reference pooled by their sample counts; the error from the frames' spread."""
    means = np.array([float(luminance(f).mean()) for f in frames])
    total = spp * len(frames) + ref_spp
    mean = (spp * means.sum() + ref_spp * float(luminance(reference).mean())) / total
    per_sample_var = float(np.var(means, ddof=1)) * spp
    return mean, math.sqrt(per_sample_var / total)


def measure(preset: str, s: Settings) -> dict[str, Any]:
    """Cost at equal noise of one preset, ours against the built-in (see the module doc)."""
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    import mitsuba as mi

    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.export.mitsuba import bsdf_dict, max_depth_for
    from lookdev.pipeline.proof import batch, ibl, shaderball

    hub = blend(load_material(preset), batch.MAP_RESOLUTION)
    if hub.bsdf_model.name != "disney" or hub.maps:
        raise BenchGlassError(f"{preset}: not an untextured Disney glass", field="presets")
    depth = max_depth_for(hub)
    env = ibl.load(s.ibl, s.ibl_width).pixels
    bsdfs = {"ours": bsdf_dict(hub), "builtin": builtin_dict(hub.params)}
    scenes = {
        k: mi.load_dict(shaderball.scene_dict(b, env, s.resolution, depth))
        for k, b in bsdfs.items()
    }
    keys = tuple(scenes)
    for key in keys:
        _render_timed(scenes[key], 1, 0)  # compiles the kernels
    refs = {k: _render_timed(scenes[k], s.reference_spp, 1_000_003)[0] for k in keys}
    frames: dict[str, list[np.ndarray]] = {k: [] for k in keys}
    wall: dict[str, list[float]] = {k: [] for k in keys}
    cpu: dict[str, list[float]] = {k: [] for k in keys}
    for r in range(s.repeat):
        # ABBA order: a load that rises or falls through the run slows both alike.
        for key in keys if r % 2 == 0 else keys[::-1]:
            image, w, c = _render_timed(scenes[key], s.spp, 1 + r)
            frames[key].append(image)
            wall[key].append(w)
            cpu[key].append(c)
    stacks = {k: np.stack(v) for k, v in frames.items()}
    # One denominator for both sides: the two references pooled.
    den = (0.5 * (refs["ours"] + refs["builtin"])) ** 2 + RELMSE_EPS
    out: dict[str, Any] = {"preset": preset, "builtin": bsdfs["builtin"]["type"], "depth": depth}
    for key in keys:
        out[f"{key}_relmse"] = noise(stacks[key], den)
        out[f"{key}_seconds"] = float(np.median(cpu[key]))
        out[f"{key}_wall_seconds"] = min(wall[key])
        out[f"{key}_cost"] = out[f"{key}_relmse"] * out[f"{key}_seconds"]
    out["ratio"] = out["ours_cost"] / max(out["builtin_cost"], 1e-300)
    out["time_ratio"] = out["ours_seconds"] / out["builtin_seconds"]
    out["wall_time_ratio"] = out["ours_wall_seconds"] / out["builtin_wall_seconds"]
    # Per round: the spread of the time ratio the machine allowed.
    rounds = np.array(cpu["ours"]) / np.array(cpu["builtin"])
    out["time_ratio_quartiles"] = [float(q) for q in np.quantile(rounds, (0.25, 0.75))]
    out["noise_ratio"] = out["ours_relmse"] / max(out["builtin_relmse"], 1e-300)
    out["noise_ratio_interval"] = (
        _interval(stacks["ours"], stacks["builtin"], den, BOOTSTRAP) if s.repeat > 2 else None
    )
    (y_o, se_o), (y_b, se_b) = (
        _brightness(stacks[k], refs[k], s.spp, s.reference_spp) for k in keys
    )
    out["reference_difference"] = y_o / max(y_b, 1e-12) - 1.0
    out["reference_difference_se"] = (y_o / max(y_b, 1e-12)) * math.hypot(
        se_o / max(y_o, 1e-12), se_b / max(y_b, 1e-12)
    )
    out["met"] = bool(out["ratio"] <= TARGET)
    return out


def run(s: Settings, progress: Any = None) -> dict[str, Any]:
    """Every preset of ``s``; the geometric mean and the worst ratio."""
    if s.reference_spp < 4 * s.spp:
        raise BenchGlassError(
            f"--reference-spp {s.reference_spp} must be at least 4 × --spp {s.spp}",
            field="--reference-spp",
        )
    rows = []
    for preset in s.presets:
        rows.append(measure(preset, s))
        if progress is not None:
            progress()
    ratios = [r["ratio"] for r in rows]
    return {
        "settings": asdict(s),
        "target": TARGET,
        "presets": rows,
        "geometric_mean_ratio": math.exp(float(np.mean(np.log(ratios)))) if rows else None,
        "worst_ratio": max(ratios) if rows else None,
        "all_met": all(r["met"] for r in rows),
    }
