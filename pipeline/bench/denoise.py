"""Equal-time curves of raw and denoised proof frames (``lookdev bench error --item denoise``).

For each case (a preset under an IBL) one proof frame (the shader ball, cup and rig at the
turntable's first pose, the proofs' scene; 192×96 by default, ``--resolution`` for the
proofs' 480×240, whose 4096-spp reference costs 6.25× as much) is rendered with a
**box** pixel filter (the filter denoised frames need:
:mod:`lookdev.pipeline.proof.denoise`) at a ladder of samples per pixel, several seeds
each, and compared with a converged reference of the same frame: relative MSE
(:func:`.measure.relative_mse`, Rousselle et al. 2011), mean over the seeds. A denoised
point costs its raw render *plus* its guides (albedo and normal, ``min(spp, guide_spp)``
samples, as the proofs render them) *plus* the denoiser, the renders frozen
(``dr.freeze``) as the proofs run them, after warm-up launches. Every cost is taken twice:
wall time, and process time (CPU seconds of all this process's threads), which a
machine shared with other jobs disturbs less; raw and denoised renders are interleaved
seed by seed, so load hits both alike.

From the curves (:func:`summarise`):

* **raw relMSE at equal wall time** for each denoised point: the raw curve fitted as
  relMSE = K/spp (unbiased Monte Carlo: variance ∝ 1/spp; K is the geometric mean of
  relMSE·spp over the raw ladder) and time = a + b·spp (least squares), read at the
  denoised point's time; ``ratio`` = denoised/raw there (the claim checked: ≤ 1/10);
  ``ratio_cpu`` the same read on process time; ``ratio_same_spp`` denoised/raw at the
  same spp (the denoiser's gain before its cost);
* **the spp raw rendering needs to reach the denoised error**: K / relMSE_denoised,
  extrapolated along the 1/spp line beyond the ladder (stated as such in the output).

The reference is rendered as two independent halves: their difference estimates its own
noise, whose relMSE (``reference_floor``) is included in every measured relMSE (it
biases the denoised points, whose errors are small, most: their ratios are conservative).
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Sequence
from dataclasses import asdict, dataclass
from typing import Any

import numpy as np

from lookdev.pipeline.proof.denoise import GUIDE_SPP
from lookdev.pipeline.proof.rig import DEFAULT_RIG

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
    resolution: tuple[int, int] = (192, 96)
    ibl_width: int = 256
    cases: tuple[tuple[str, str], ...] = CASES
    guide_spp: int = GUIDE_SPP
    rig: str = DEFAULT_RIG  # the proofs' rig beside the material (``--rig none``: without)

    @classmethod
    def quick(cls) -> DenoiseSettings:
        return cls((2, 4, 8), (2, 4), 64, 1, (32, 16), 64, CASES)


@dataclass(frozen=True)
class Case:
    """One measured case: its curves and what follows from them (:func:`summarise`).

    Every point carries wall time (``seconds``; a denoised point's split into
    ``render_s``, ``aov_s``, ``denoise_s``) and process time (``cpu_s``, all threads of
    this process; split likewise into ``*_cpu_s``): on a machine shared with other jobs
    the wall clock also counts waiting for a core, process time mostly does not.
    ``load_average``: the machine's 1-minute load average before and after the case.
    """

    preset: str
    ibl: str
    raw: list[dict[str, float]]  # {spp, rel_mse, seconds, cpu_s}
    denoised: list[dict[str, float]]  # {spp, rel_mse, seconds, cpu_s, render_s, aov_s, …}
    reference_spp: int
    reference_floor: float
    summary: dict[str, Any]
    resolution: tuple[int, int] = (0, 0)
    guide_spp: int = GUIDE_SPP
    load_average: tuple[float, float] = (0.0, 0.0)
    rig: str = DEFAULT_RIG

    def as_json(self) -> dict[str, Any]:
        return asdict(self)

    def rows(self) -> list[Row]:
        """The curves as :class:`.measure.Row` s for the error bench's table and plot."""
        label = f"{self.preset} × {self.ibl}"
        ref = f"{self.reference_spp} spp render"
        return [
            Row("denoise", label, method, f"{p['spp']:g} spp", p["rel_mse"], p["seconds"], 1, ref)
            for method, points in (("raw", self.raw), ("denoised", self.denoised))
            for p in points
        ]


class _Frame:
    """The proof scene at its first pose, box-filtered, rendered by frozen launches."""

    def __init__(
        self,
        bsdf: dict,
        environment: np.ndarray,
        resolution: tuple[int, int],
        depth: int,
        guide_spp: int,
        rig: str = DEFAULT_RIG,
    ):
        import drjit as dr
        import mitsuba as mi

        from lookdev.pipeline.proof import shaderball

        scene = shaderball.scene_dict(
            bsdf, environment, resolution, depth, rig=rig, pixel_filter="box"
        )
        self.scene = mi.load_dict(scene)
        self.guide_spp = guide_spp

        def launch(scene: Any, spp: int, seed: Any) -> Any:
            return mi.render(scene, spp=spp, seed=seed)

        self._launch = dr.freeze(launch) if dr.is_jit_v(mi.Float) else launch
        self.guides: dict[int, Any] = {}

    def render(self, spp: int, seed: int) -> tuple[np.ndarray, float, float]:
        """The image, its wall seconds and its process (CPU) seconds."""
        import mitsuba as mi

        t0, c0 = time.perf_counter(), time.process_time()
        image = np.array(self._launch(self.scene, spp, mi.UInt32(seed)), dtype=np.float32)
        return image[..., :3], time.perf_counter() - t0, time.process_time() - c0

    def guide_renderer(self, spp: int) -> Any:
        """Guides as the proofs render them: ``min(spp, guide_spp)`` samples."""
        from lookdev.pipeline.proof.denoise import GuideRenderer

        n = min(spp, self.guide_spp)
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
    load_before = _load()
    frame = _Frame(bsdf, environment, settings.resolution, depth, settings.guide_spp, settings.rig)
    progress(f"{preset}: reference ({settings.reference_spp} spp)")
    half = max(1, settings.reference_spp // 2)
    ref_a = frame.render(half, seed=1_000_001)[0]
    ref_b = frame.render(half, seed=1_000_002)[0]
    reference = 0.5 * (ref_a.astype(np.float64) + ref_b)
    # Var(mean of two) = E[(A − B)²]/4: the reference's own relMSE against the truth.
    floor = float(np.mean((ref_a - ref_b).astype(np.float64) ** 2 / 4.0 / (reference**2 + 1e-2)))
    ladder = sorted(set(settings.raw_ladder) | set(settings.denoised_ladder))
    for spp in ladder:  # warm-ups: recordings and kernel compiles are not proof time
        for k in range(WARMUP):
            frame.render(spp, seed=500_000 + k)
        if spp in settings.denoised_ladder:
            for k in range(WARMUP):
                frame.guide_renderer(spp).denoise(ref_a, seed=500_000 + k)
    raw: dict[int, list[tuple[float, ...]]] = {s: [] for s in ladder}
    den: dict[int, list[tuple[float, ...]]] = {s: [] for s in settings.denoised_ladder}
    for seed in range(settings.seeds):
        progress(f"{preset}: seed {seed + 1}/{settings.seeds}")
        for spp in ladder:  # interleaved: load on the machine hits every rung alike
            image, t, c = frame.render(spp, seed=seed * 1000 + spp)
            raw[spp].append((relative_mse(image.astype(np.float64), reference), t, c))
            if spp in den:
                d = frame.guide_renderer(spp).denoise(image, seed=seed * 1000 + spp)
                err = relative_mse(d.image.astype(np.float64), reference)
                den[spp].append(
                    (err, t, d.aov_seconds, d.denoise_seconds, c)
                    + (d.aov_cpu_seconds, d.denoise_cpu_seconds)
                )
    raw_points = [
        {"spp": s, "rel_mse": _mean(v, 0), "seconds": _mean(v, 1), "cpu_s": _mean(v, 2)}
        for s, v in raw.items()
        if s in settings.raw_ladder
    ]
    den_points = []
    for s, v in den.items():
        render_s, aov_s, dn_s = _mean(v, 1), _mean(v, 2), _mean(v, 3)
        render_c, aov_c, dn_c = _mean(v, 4), _mean(v, 5), _mean(v, 6)
        den_points.append(
            {
                "spp": s,
                "rel_mse": _mean(v, 0),
                "seconds": render_s + aov_s + dn_s,
                "render_s": render_s,
                "aov_s": aov_s,
                "denoise_s": dn_s,
                "cpu_s": render_c + aov_c + dn_c,
                "render_cpu_s": render_c,
                "aov_cpu_s": aov_c,
                "denoise_cpu_s": dn_c,
                "guide_spp": min(s, settings.guide_spp),
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
        tuple(settings.resolution),
        settings.guide_spp,
        (load_before, _load()),
        settings.rig,
    )


def _load() -> float:
    """The machine's 1-minute load average (0 where the platform has none)."""
    try:
        return round(os.getloadavg()[0], 2)
    except (AttributeError, OSError):
        return 0.0


def _mean(values: Sequence[tuple[float, ...]], i: int) -> float:
    return float(np.mean([v[i] for v in values]))


def summarise(
    raw: list[dict[str, float]], denoised: list[dict[str, float]], reference_spp: int
) -> dict[str, Any]:
    """The 1/spp fit of the raw curve, and per denoised point the raw relMSE at the same
    wall time, their ratio, and the spp raw needs to match it (see the module docstring).
    With ``cpu_s`` in every point, the same at equal process time (``ratio_cpu``); with a
    raw point at the same spp, the ratio at equal spp (``ratio_same_spp``: the denoiser's
    own gain, before its cost).

    >>> raw = [{"spp": 4, "rel_mse": 0.5, "seconds": 1.0}]
    >>> raw += [{"spp": 8, "rel_mse": 0.25, "seconds": 2.0}]
    >>> den = [{"spp": 4, "rel_mse": 0.01, "seconds": 2.0}]
    >>> s = summarise(raw, den, 4096)
    >>> point = s["points"][0]
    >>> round(s["K"], 12), round(point["raw_rel_mse_same_time"], 12), point["raw_spp_to_match"]
    (2.0, 0.25, 200.0)
    """
    spp = np.array([p["spp"] for p in raw], dtype=float)
    err = np.array([p["rel_mse"] for p in raw], dtype=float)
    k = float(np.exp(np.mean(np.log(err * spp))))
    slope = float(np.polyfit(np.log(spp), np.log(err), 1)[0]) if len(spp) > 1 else -1.0
    a, b = _time_fit(raw, "seconds")
    cpu = all("cpu_s" in p for p in raw + denoised)
    ac, bc = _time_fit(raw, "cpu_s") if cpu else (0.0, 1.0)
    same_spp = {p["spp"]: p["rel_mse"] for p in raw}
    points = []
    for p in denoised:
        spp_same_time = max((p["seconds"] - a) / b, 1e-9)
        raw_same = k / spp_same_time
        match = k / p["rel_mse"] if p["rel_mse"] > 0 else math.inf
        point = {
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
        if p["spp"] in same_spp:
            point["ratio_same_spp"] = p["rel_mse"] / same_spp[p["spp"]]
        if cpu:
            spp_same_cpu = max((p["cpu_s"] - ac) / bc, 1e-9)
            point["raw_spp_same_cpu"] = round(spp_same_cpu, 2)
            point["ratio_cpu"] = p["rel_mse"] * spp_same_cpu / k
        points.append(point)
    out = {
        "K": round(k, 6),
        "raw_log_slope": round(slope, 3),
        "time_per_spp_s": b,
        "time_fixed_s": a,
        "points": points,
        "claim": f"denoised relMSE ≤ {CLAIM_RATIO:g} × raw at equal wall time",
        "claim_met": bool(all(q["claim_met"] for q in points)),
        "reference_spp": reference_spp,
    }
    if cpu:
        out |= {"cpu_per_spp_s": bc, "cpu_fixed_s": ac}
        out["claim_met_cpu"] = bool(all(q["ratio_cpu"] <= CLAIM_RATIO for q in points))
    return out


def _time_fit(raw: list[dict[str, float]], key: str) -> tuple[float, float]:
    """(a, b) of time = a + b·spp, least squares over the raw ladder (b > 0)."""
    spp = np.array([p["spp"] for p in raw], dtype=float)
    sec = np.array([p[key] for p in raw], dtype=float)
    b, a = np.polyfit(spp, sec, 1) if len(spp) > 1 else (sec[0] / spp[0], 0.0)
    return float(a), max(float(b), 1e-12)


EQUAL_TIME_COLUMNS = [
    "case",
    "spp",
    "raw relMSE",
    "denoised relMSE",
    "ratio same spp",
    "s/frame raw",
    "s/frame denoised",
    "raw relMSE same time",
    "ratio",
    "ratio same CPU",
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
                    f"{q['ratio_same_spp']:.3g}" if "ratio_same_spp" in q else "",
                    f"{r['seconds']:.3g}" if r else "",
                    f"{d['seconds']:.3g}",
                    f"{q['raw_rel_mse_same_time']:.3g}",
                    f"{q['ratio']:.3g}",
                    f"{q['ratio_cpu']:.3g}" if "ratio_cpu" in q else "",
                    f"{q['raw_spp_to_match']:.0f}" + (" †" if q["extrapolated"] else ""),
                ]
            )
    return rows
