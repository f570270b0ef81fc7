"""Per-pixel adaptive sampling against uniform passes: ``lookdev bench error --item adaptive``.

For each case (a preset under an IBL, the turntable's first pose, the proof scene at
``resolution``) a converged reference is rendered as two independent halves, then:

* **adaptive** — :func:`lookdev.pipeline.proof.adaptive.render_adaptive` to ``target``
  (the proofs' default), its CPU time measured;
* **uniform** — every pixel the same count, chosen so that its CPU time equals the
  adaptive frame's (from a calibration pass's CPU time per sample);
* **adaptive + checked denoising** — the same loop with the checked denoiser's residual
  (:mod:`lookdev.pipeline.proof.checked`) as the stop test, and the frame it shows.

Each gets its relative MSE against the reference (:func:`.measure.relative_mse`, RGB,
scene-linear) and its display RMS error (the view the target is set on). *CPU time to the
target*: measured for both adaptive loops; for uniform passes it is predicted from the
calibration frame (variance ∝ 1/n: n·(q/target)² samples, q the
:data:`~lookdev.pipeline.proof.adaptive.CONVERGED_SHARE` quantile of its pixels'
estimates), marked ``predicted``.

**The estimate check**: per pixel class — ``edges`` (the reference's display gradient in
its top 10 %), ``hot`` (the reference's per-pixel variance in its top 1 %: caustics,
fireflies, glints) and ``smooth`` (the rest) — the RMS of the estimated error against the
RMS of the measured one (the reference's own noise taken out); a ratio within 2 passes.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .measure import relative_mse

__all__ = [
    "AdaptiveSettings", "CASES", "IBLS", "PRESETS", "bench_case", "classes", "environment", "run",
    "tasks", "uniform_halves",
]  # fmt: skip

PRESETS = ("plastic_glossy", "gold", "glass_clear", "skin", "rusty_car_paint")
IBLS = ("sky", "studio", "real")
"""``real``: the real HDR in ``tests/data`` (:data:`lookdev.pipeline.proof.ibl.REAL_HDR`)."""
CASES = tuple((p, i) for p in PRESETS for i in IBLS)
ESTIMATE_FACTOR = 2.0
FIREFLY_CASE = 0.1
"""A case has fireflies when its hottest 0.1 % of pixels hold more than this share of a
16-spp frame's squared A − B (:func:`lookdev.pipeline.proof.passes.firefly_share`;
plain grain gives ≈ 0.01)."""


@dataclass(frozen=True)
class AdaptiveSettings:
    cases: tuple[tuple[str, str], ...] = CASES
    resolution: tuple[int, int] = (120, 60)
    reference_spp: int = 1024
    target: float | None = None  # None: the proofs' default (settings.DEFAULT_NOISE)
    max_spp: int = 256
    ibl_width: int = 512

    @classmethod
    def quick(cls) -> AdaptiveSettings:
        return cls(cases=(("plastic_glossy", "sky"),), resolution=(32, 16), reference_spp=64)


def environment(name: str, width: int) -> np.ndarray:
    """The pixels of a built-in IBL, or of the real HDR for ``real``."""
    from lookdev.pipeline.proof import ibl

    return ibl.load(ibl.REAL_HDR if name == "real" else name, width).pixels


def uniform_halves(renderer: Any, spp: int, seed: int) -> tuple[np.ndarray, np.ndarray, float]:
    """Halves (H, W, 3) of ``spp`` samples a pixel (in launches of ≤ 64), and CPU seconds."""
    h, w = renderer.height, renderer.width
    sa, sb = np.zeros((h * w, 3)), np.zeros((h * w, 3))
    c0 = time.process_time()
    done, k = 0, 0
    while done < spp:
        step = min(64, spp - done)
        a, b = renderer.render(np.arange(h * w), np.full(h * w, step), seed + k)
        sa, sb, done, k = sa + a, sb + b, done + step, k + 1
    cpu = time.process_time() - c0
    return (sa / (spp / 2)).reshape(h, w, 3), (sb / (spp / 2)).reshape(h, w, 3), cpu


def classes(reference: np.ndarray, ref_variance: np.ndarray) -> dict[str, np.ndarray]:
    """Masks (H, W) of the pixel classes (module docstring) of a reference's display
    image (H, W, 3) and its per-pixel variance (H, W)."""
    lum = reference.mean(axis=-1)
    gy, gx = np.gradient(lum)
    grad = np.hypot(gx, gy)
    hot = ref_variance >= np.quantile(ref_variance, 0.99)
    edges = (grad >= np.quantile(grad, 0.90)) & ~hot
    return {"smooth": ~(hot | edges), "edges": edges, "hot": hot}


def _display_error(image, ref_view, ref_var, exposure=0.0):  # noqa: ANN001, ANN202
    from lookdev.pipeline.proof.tonemap import view

    d = view(image, exposure, exact=True) - ref_view
    return np.mean(d * d, axis=-1) - ref_var  # the reference's own noise taken out


def _check(estimate: np.ndarray, measured: np.ndarray, masks: dict) -> dict[str, Any]:
    out = {}
    for name, m in masks.items():
        est = math.sqrt(float(np.mean(np.square(estimate[m])))) if m.any() else 0.0
        meas = math.sqrt(max(float(np.mean(measured[m])), 0.0)) if m.any() else 0.0
        ratio = est / meas if meas > 0 else None
        ok = ratio is not None and 1 / ESTIMATE_FACTOR <= ratio <= ESTIMATE_FACTOR
        out[name] = {"pixels": int(m.sum()), "estimated": est, "measured": meas,
                     "ratio": ratio, "within_2x": ok}  # fmt: skip
    return out


@dataclass
class CaseResult:
    preset: str
    ibl: str
    data: dict[str, Any] = field(default_factory=dict)


def bench_case(preset: str, ibl_name: str, s: AdaptiveSettings) -> CaseResult:
    """One case: reference, uniform at equal CPU time, adaptive, adaptive + checked."""
    from lookdev.pipeline.proof import adaptive, checked, denoise, passes, settings
    from lookdev.pipeline.proof.tonemap import view
    from lookdev.pipeline.proof.turntable import Frame

    from .quality import blended, proof_table

    target = s.target if s.target is not None else settings.DEFAULT_NOISE
    table = proof_table(blended(preset), environment(ibl_name, s.ibl_width), s.resolution, "box")
    table.set_frame(Frame(0, "element", 0.0))
    r = adaptive.PixelRenderer(table.scene, table.camera_index, freeze=False)
    ra, rb, ref_cpu = uniform_halves(r, s.reference_spp, 7_000_000)
    ref = 0.5 * (ra + rb)
    dv = view(ra, exact=True) - view(rb, exact=True)
    ref_var = np.mean(dv * dv, axis=-1) / 4.0
    ref_view = view(ref, exact=True)
    masks = classes(ref_view, ref_var)
    uniform_halves(r, adaptive.MIN_SPP, 2)  # warm-up: the kernels compile outside the timing
    ca, cb, cal_cpu = uniform_halves(r, adaptive.MIN_SPP, 1)  # calibration: CPU per sample
    per_spp = cal_cpu / adaptive.MIN_SPP
    cal_err = adaptive.pixel_error(ca, cb)
    q = float(np.quantile(cal_err, adaptive.CONVERGED_SHARE))
    uniform_to_target = adaptive.MIN_SPP * (q / target) ** 2 * per_spp

    def seeds(base: int):  # noqa: ANN202
        return lambda i: base + i

    c0 = time.process_time()
    f = adaptive.render_adaptive(r, target=target, max_spp=s.max_spp, seed=seeds(100))
    ad_cpu = time.process_time() - c0
    n_u = max(2, int(round(ad_cpu / per_spp / 2)) * 2)
    ua, ub, u_cpu = uniform_halves(r, n_u, 200)
    uniform = 0.5 * (ua + ub)

    guides = denoise.guide_renderer(table).render(seed=0)

    def check(a, b, e):  # noqa: ANN001, ANN202
        return checked.check(a, b, e, lambda im: denoise.denoise(im, guides))

    c0 = time.process_time()
    g = adaptive.render_adaptive(r, target=target, max_spp=s.max_spp, seed=seeds(300), check=check)
    dn_cpu = time.process_time() - c0 + guides.cpu_seconds
    shown = g.checked.image
    measured_raw = _display_error(f.image, ref_view, ref_var)
    measured_dn = _display_error(shown, ref_view, ref_var)
    floor = relative_mse(ra, rb) / 4.0  # the reference's own relMSE: Var of the mean

    def disp(x: np.ndarray) -> float:
        return math.sqrt(max(float(np.mean(x)), 0.0))

    share = passes.firefly_share(np.mean(np.square(ca - cb), axis=-1))
    fireflies = share is not None and share > FIREFLY_CASE
    data = {
        "resolution": list(s.resolution),
        "target": target,
        "reference": {"spp": s.reference_spp, "cpu_s": round(ref_cpu, 2), "relmse_floor": floor},
        "fireflies": fireflies,
        "firefly_share": share,
        "uniform": {
            "spp": n_u,
            "cpu_s": round(u_cpu, 3),
            "relmse": relative_mse(uniform, ref),
            "display_rms": disp(_display_error(uniform, ref_view, ref_var)),
            "cpu_to_target_s": round(uniform_to_target, 2),
            "cpu_to_target": "predicted",
        },
        "adaptive": {
            "spp_mean": round(f.mean_spp, 2),
            "spp_max": int(f.spp.max()),
            "passes": f.passes,
            "stop": f.stop,
            "converged": f.converged,
            "cpu_s": round(ad_cpu, 3),
            "relmse": relative_mse(f.image, ref),
            "display_rms": disp(measured_raw),
            "estimate": f.noise,
            "cpu_to_target_s": round(ad_cpu, 2) if f.stop == "target" else None,
            "estimate_check": _check(f.raw_error, measured_raw, masks),
        },
        "adaptive_checked": {
            "spp_mean": round(g.mean_spp, 2),
            "passes": g.passes,
            "stop": g.stop,
            "converged": g.converged,
            "cpu_s": round(dn_cpu, 3),
            "relmse": relative_mse(shown, ref),
            "relmse_denoiser_alone": relative_mse(g.checked.denoised, ref),
            "display_rms": disp(measured_dn),
            "residual": g.noise,
            "raw_weight": g.checked.raw_weight,
            "cpu_to_target_s": round(dn_cpu, 2) if g.stop == "target" else None,
            "estimate_check": _check(g.error, measured_dn, masks),
        },
    }
    return CaseResult(preset, ibl_name, data)


def run(s: AdaptiveSettings, progress: Any = None) -> list[dict[str, Any]]:
    """Every case of ``s``; a case that fails is listed with its reason."""
    from lookdev.pipeline.export.mitsuba import register_plugins
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    register_plugins()
    out = []
    for i, (preset, name) in enumerate(s.cases):
        if progress is not None:
            progress(f"adaptive {preset} × {name}", i, len(s.cases))
        try:
            c = bench_case(preset, name, s)
            out.append({"preset": preset, "ibl": name, **c.data})
        except Exception as exc:  # noqa: BLE001 - one broken case must not hide the rest
            first = (str(exc).splitlines() or [""])[0]
            out.append({"preset": preset, "ibl": name, "skipped": f"{type(exc).__name__}: {first}"})
    return out


def tasks(s: AdaptiveSettings, report: Any) -> list[tuple[str, Any]]:
    """One task per case for :func:`.error.run`: each appends its result to
    ``report.adaptive`` and returns its rows (relMSE against CPU seconds)."""
    from .measure import Row

    def task(preset: str, name: str) -> list[Row]:
        from lookdev.pipeline.export.mitsuba import register_plugins

        register_plugins()
        data = {"preset": preset, "ibl": name, **bench_case(preset, name, s).data}
        report.adaptive.append(data)
        ref = f"{data['reference']['spp']} spp"
        rows = []
        for method in ("uniform", "adaptive", "adaptive_checked"):
            m = data[method]
            spp = m.get("spp", m.get("spp_mean"))
            rows.append(
                Row(
                    "adaptive",
                    f"{preset} × {name}",
                    method.replace("_", " + "),
                    f"{spp} spp",
                    m["relmse"],
                    m["cpu_s"],
                    reference=ref,
                )  # fmt: skip
            )
        return rows

    return [(f"adaptive {p} × {n}", lambda p=p, n=n: task(p, n)) for p, n in s.cases]
