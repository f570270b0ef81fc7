"""Equal-time curves of raw and denoised proof frames (``lookdev bench error --item denoise``).

For each case (a preset under an IBL) one proof frame (the shader ball and cup at the
turntable's first pose, the proofs' scene; 96×48 by default, small enough for a
4096-spp reference on a shared two-core machine) is rendered with a **box** pixel filter (the
filter denoised frames need: :mod:`lookdev.pipeline.proof.denoise`) at a ladder of
samples per pixel, several seeds each, and compared with a converged reference of the
same frame: relative MSE (:func:`.measure.relative_mse`, Rousselle et al. 2011), mean
over the seeds. A denoised point costs its raw render *plus* its guides (albedo and
normal, ``min(spp, GUIDE_SPP)`` samples) *plus* the denoiser, all wall time, the renders
frozen (``dr.freeze``) as the proofs run them, after warm-up launches.

From the curves (:func:`summarise`):

* **raw relMSE at equal wall time** for each denoised point: the raw curve fitted as
  relMSE = K/spp (unbiased Monte Carlo: variance ∝ 1/spp; K is the geometric mean of
  relMSE·spp over the raw ladder) and time = a + b·spp (least squares), read at the
  denoised point's time; ``ratio`` = denoised/raw there (the claim checked: ≤ 1/10);
* **the spp raw rendering needs to reach the denoised error**: K / relMSE_denoised,
  extrapolated along the 1/spp line beyond the ladder (stated as such in the output).

The reference is rendered as two independent halves: their difference estimates its own
noise, whose relMSE (``reference_floor``) is included in every measured relMSE (it
biases the denoised points, whose errors are small, most: their ratios are conservative).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from .measure import Row, relative_mse

__all__ = [
    "CASES",
    "CLAIM_RATIO",
    "Case",
    "DenoiseSettings",
    "bench_case",
    "summarise",
]

CASES: tuple[tuple[str, str], ...] = (("plastic_glossy", "sky"), ("glass_clear", "sky"))
"""(preset, IBL) pairs measured by default: a glossy plastic and clear glass under sky."""
CLAIM_RATIO = 0.1
"""The claim checked: at equal wall time denoised relMSE ≤ this fraction of raw's."""


@dataclass(frozen=True)
class DenoiseSettings:
    raw_ladder: tuple[int, ...] = (4, 8, 16, 32, 64)
    denoised_ladder: tuple[int, ...] = (4, 8, 16, 32)
    reference_spp: int = 4096
    seeds: int = 8
    resolution: tuple[int, int] = (96, 48)
    ibl_width: int = 256
    cases: tuple[tuple[str, str], ...] = CASES

    @classmethod
    def quick(cls) -> DenoiseSettings:
        return cls((2, 4, 8), (2, 4), 64, 1, (32, 16), 64, CASES)


@dataclass(frozen=True)
class Case:
    """One measured case: its curves and what follows from them (:func:`summarise`)."""

    preset: str
    ibl: str
    raw: list[dict[str, float]]  # {spp, rel_mse, seconds}
    denoised: list[dict[str, float]]  # {spp, rel_mse, seconds, render_s, aov_s, denoise_s}
    reference_spp: int
    reference_floor: float
    summary: dict[str, Any]

    def as_json(self) -> dict[str, Any]:
        return asdict(self)

    def rows(self) -> list[Row]:
        """The curves as :class:`.measure.Row` s for the error bench's table and plot."""
        label = f"{self.preset} × {self.ibl}"
        ref = f"{self.reference_spp} spp render"
        out = [
            Row("denoise", label, "raw", f"{p['spp']:g} spp", p["rel_mse"], p["seconds"], 1, ref)
            for p in self.raw
        ]
        out += [
            Row(
                "denoise",
                label,
                "denoised",
                f"{p['spp']:g} spp",
                p["rel_mse"],
                p["seconds"],
                1,
                ref,
            )
            for p in self.denoised
        ]
        return out


class _Frame:
    """The proof scene at its first pose, box-filtered, rendered by frozen launches."""

    def __init__(
        self, bsdf: dict, environment: np.ndarray, resolution: tuple[int, int], depth: int
    ):
        import drjit as dr
        import mitsuba as mi

        from lookdev.pipeline.proof import shaderball
        from lookdev.pipeline.proof.denoise import GuideRenderer

        scene = shaderball.scene_dict(bsdf, environment, resolution, depth)
        scene["sensor"]["film"]["rfilter"] = {"type": "box"}
        self.scene = mi.load_dict(scene)

        def launch(scene: Any, spp: int, seed: Any) -> Any:
            return mi.render(scene, spp=spp, seed=seed)

        self._launch = dr.freeze(launch) if dr.is_jit_v(mi.Float) else launch
        self.guides: dict[int, GuideRenderer] = {}

    def render(self, spp: int, seed: int) -> tuple[np.ndarray, float]:
        import mitsuba as mi

        t0 = time.perf_counter()
        image = np.array(self._launch(self.scene, spp, mi.UInt32(seed)), dtype=np.float32)
        return image[..., :3], time.perf_counter() - t0

    def guide_renderer(self, spp: int) -> Any:
        from lookdev.pipeline.proof.denoise import GUIDE_SPP, GuideRenderer

        n = min(spp, GUIDE_SPP)
        if n not in self.guides:
            self.guides[n] = GuideRenderer(self.scene, 0, n)
        return self.guides[n]


WARMUP = 3
"""Launches before timing: a frozen function records on its first calls (three here)."""


def bench_case(
    preset: str,
    ibl: str,
    bsdf: dict,
    environment: np.ndarray,
    depth: int,
    settings: DenoiseSettings,
    progress: Callable[[str], None] = lambda step: None,
) -> Case:
    """Measure one case (see the module docstring)."""
    frame = _Frame(bsdf, environment, settings.resolution, depth)
    progress(f"{preset}: reference ({settings.reference_spp} spp)")
    half = max(1, settings.reference_spp // 2)
    ref_a, _ = frame.render(half, seed=1_000_001)
    ref_b, _ = frame.render(half, seed=1_000_002)
    reference = 0.5 * (ref_a.astype(np.float64) + ref_b)
    # Var(mean of two) = E[(A − B)²]/4: the reference's own relMSE against the truth.
    floor = float(np.mean((ref_a - ref_b).astype(np.float64) ** 2 / 4.0 / (reference**2 + 1e-2)))
    ladder = sorted(set(settings.raw_ladder) | set(settings.denoised_ladder))
    for spp in ladder:  # warm-ups: recordings and kernel compiles are not proof time
        for k in range(WARMUP):
            frame.render(spp, seed=500_000 + k)
        if spp in settings.denoised_ladder:
            for k in range(WARMUP):
                frame.guide_renderer(spp).render(seed=500_000 + k)
    raw: dict[int, list[tuple[float, float]]] = {s: [] for s in ladder}
    den: dict[int, list[tuple[float, ...]]] = {s: [] for s in settings.denoised_ladder}
    for seed in range(settings.seeds):
        progress(f"{preset}: seed {seed + 1}/{settings.seeds}")
        for spp in ladder:  # interleaved: load on the machine hits every rung alike
            image, t = frame.render(spp, seed=seed * 1000 + spp)
            raw[spp].append((relative_mse(image.astype(np.float64), reference), t))
            if spp in den:
                d = frame.guide_renderer(spp).denoise(image, seed=seed * 1000 + spp)
                err = relative_mse(d.image.astype(np.float64), reference)
                den[spp].append((err, t, d.aov_seconds, d.denoise_seconds))
    raw_points = [
        {"spp": s, "rel_mse": _mean(v, 0), "seconds": _mean(v, 1)}
        for s, v in raw.items()
        if s in settings.raw_ladder
    ]
    den_points = []
    for s, v in den.items():
        render_s, aov_s, dn_s = _mean(v, 1), _mean(v, 2), _mean(v, 3)
        den_points.append(
            {
                "spp": s,
                "rel_mse": _mean(v, 0),
                "seconds": render_s + aov_s + dn_s,
                "render_s": render_s,
                "aov_s": aov_s,
                "denoise_s": dn_s,
            }
        )
    return Case(
        preset,
        ibl,
        raw_points,
        den_points,
        settings.reference_spp,
        floor,
        summarise(raw_points, den_points, settings.reference_spp),
    )


def _mean(values: Sequence[tuple[float, ...]], i: int) -> float:
    return float(np.mean([v[i] for v in values]))


def summarise(
    raw: list[dict[str, float]], denoised: list[dict[str, float]], reference_spp: int
) -> dict[str, Any]:
    """The 1/spp fit of the raw curve, and per denoised point the raw relMSE at the same
    wall time, their ratio, and the spp raw needs to match it (see the module docstring).

    >>> raw = [{"spp": 4, "rel_mse": 0.5, "seconds": 1.0}]
    >>> raw += [{"spp": 8, "rel_mse": 0.25, "seconds": 2.0}]
    >>> den = [{"spp": 4, "rel_mse": 0.01, "seconds": 2.0}]
    >>> s = summarise(raw, den, 4096)
    >>> s["K"], s["points"][0]["raw_rel_mse_same_time"], s["points"][0]["raw_spp_to_match"]
    (2.0, 0.25, 200.0)
    """
    spp = np.array([p["spp"] for p in raw], dtype=float)
    err = np.array([p["rel_mse"] for p in raw], dtype=float)
    sec = np.array([p["seconds"] for p in raw], dtype=float)
    k = float(np.exp(np.mean(np.log(err * spp))))
    b, a = np.polyfit(spp, sec, 1) if len(spp) > 1 else (sec[0] / spp[0], 0.0)
    a, b = float(a), max(float(b), 1e-12)
    slope = float(np.polyfit(np.log(spp), np.log(err), 1)[0]) if len(spp) > 1 else -1.0
    points = []
    for p in denoised:
        spp_same_time = max((p["seconds"] - a) / b, 1e-9)
        raw_same = k / spp_same_time
        match = k / p["rel_mse"] if p["rel_mse"] > 0 else math.inf
        points.append(
            {
                "spp": p["spp"],
                "denoised_rel_mse": p["rel_mse"],
                "seconds": p["seconds"],
                "raw_spp_same_time": round(spp_same_time, 2),
                "raw_rel_mse_same_time": raw_same,
                "ratio": p["rel_mse"] / raw_same,
                "claim_met": bool(p["rel_mse"] / raw_same <= CLAIM_RATIO),
                "raw_spp_to_match": round(match, 1),
                "extrapolated": bool(match > spp.max()),
            }
        )
    return {
        "K": round(k, 6),
        "raw_log_slope": round(slope, 3),
        "time_per_spp_s": b,
        "time_fixed_s": float(a),
        "points": points,
        "claim": f"denoised relMSE ≤ {CLAIM_RATIO:g} × raw at equal wall time",
        "claim_met": bool(all(q["claim_met"] for q in points)),
        "reference_spp": reference_spp,
    }


EQUAL_TIME_COLUMNS = [
    "case",
    "spp",
    "raw relMSE",
    "denoised relMSE",
    "s/frame raw",
    "s/frame denoised",
    "raw relMSE same time",
    "ratio",
    "raw spp to match",
]


def equal_time_rows(cases: Sequence[Case]) -> list[list[str]]:
    """The equal-time table, a row per denoised point (``†``: extrapolated beyond the
    raw ladder along the 1/spp line)."""
    rows = []
    for case in cases:
        raw = {p["spp"]: p for p in case.raw}
        for q, d in zip(case.summary["points"], case.denoised, strict=True):
            r = raw.get(q["spp"])
            rows.append(
                [
                    f"{case.preset} × {case.ibl}",
                    f"{q['spp']:g}",
                    f"{r['rel_mse']:.3g}" if r else "",
                    f"{q['denoised_rel_mse']:.3g}",
                    f"{r['seconds']:.3g}" if r else "",
                    f"{d['seconds']:.3g}",
                    f"{q['raw_rel_mse_same_time']:.3g}",
                    f"{q['ratio']:.3g}",
                    f"{q['raw_spp_to_match']:.0f}" + (" †" if q["extrapolated"] else ""),
                ]
            )
    return rows
