"""What the main job's defaults buy: ``lookdev bench error --item mainjob``.
(What each knob costs: :mod:`.knobs`, ``lookdev bench mainjob``.)

**Error of the defaults** (:func:`error`). For a sampled subset of the main job (a glossy
plastic, a metal, glass and skin, one IBL each, the turntable's first pose), a converged
reference is rendered as two independent halves (their difference is its own noise,
stated), and the frame as each default renders it is compared with it:

* *old* — the job's old defaults: 192×96, a fixed 32 spp, Gaussian pixel filter, raw;
  its reference is rendered at 192×96 with the same filter, so the error is noise alone;
* *new* — :mod:`lookdev.pipeline.proof.settings`' defaults: 480×240, box filter, the noise
  target and its cap, and the denoised frame when denoising is on; reference at 480×240.

Error is relative MSE (:func:`.measure.relative_mse`, Rousselle et al. 2011) over the
frame's RGB, the mean over ``seeds`` renders; the reference's own relMSE (``floor``, from
its halves: Var of their mean = E[(A − B)²]/4) is part of every measured value and is
listed beside it. The *estimate check* compares each raw frame's own noise
estimate (:func:`lookdev.pipeline.proof.passes.estimate`, relative RMS on luminance) with
the error measured the same way against the reference, the reference's noise taken out in
quadrature: within a factor of 2 passes. The estimate describes the raw frame, never the
denoised one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from .measure import Row, relative_mse
from .proof import Clock

__all__ = [
    "CASES",
    "blended",
    "proof_table",
    "ErrorSettings",
    "error",
    "error_case",
    "error_rows",
    "table_rows",
    "tasks",
    "summarise",
]

CASES: tuple[tuple[str, str], ...] = (
    ("plastic_glossy", "sky"),
    ("gold", "sunset"),
    ("glass_clear", "sky"),
    ("skin", "studio"),
)
"""The sampled subset of the main job whose error is measured: (preset, IBL)."""
ESTIMATE_FACTOR = 2.0
"""The target: a frame's noise estimate within this factor of its measured error."""


def blended(preset: str) -> Any:
    """A built-in preset blended as the proofs blend it."""
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.proof import batch

    return blend(load_material(preset), batch.MAP_RESOLUTION)


def proof_table(hub: Any, env: np.ndarray, resolution: tuple[int, int], pixel_filter: str) -> Any:
    """The proof's Turntable of ``hub`` exactly as a proof job builds it (default rig)."""
    from lookdev.pipeline.proof import turntable

    bsdf, depth = turntable.material_bsdf(hub)
    return turntable.Turntable(
        bsdf,
        env,
        resolution,
        depth,
        pixel_filter=pixel_filter,
        interior=turntable.material_interior(hub),
    )


# -- error ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class ErrorSettings:
    cases: tuple[tuple[str, str], ...] = CASES
    reference_spp: int = 512  # per pixel of the new reference (both halves); its own
    # relMSE is reported: a third to a half of the denoised frames' on a shared machine's
    # budget (README); raise it where time allows
    old_reference_spp: int = 1024  # of the old one (192×96, 32 spp: 3 % of its error)
    reference_pass: int = 64  # samples per pass of a reference (bounded wavefront memory)
    seeds: int = 2
    old_resolution: tuple[int, int] = (192, 96)
    old_spp: int = 32
    old_filter: str = "gaussian"
    ibl_width: int = 512
    new: dict[str, Any] | None = None  # None: the proof defaults (settings.Settings())
    other_caps: tuple[int, ...] = (8, 16)  # also measured against the new reference: new_caps

    @classmethod
    def quick(cls) -> ErrorSettings:
        return cls(
            cases=(("plastic_glossy", "sky"),),
            reference_spp=64,
            old_reference_spp=128,
            reference_pass=32,
            seeds=1,
            old_resolution=(16, 8),
            old_spp=8,
            ibl_width=64,
            new={"resolution": (32, 16)},
            other_caps=(8,),
        )


def _reference(table: Any, frame: Any, spp: int, per_pass: int) -> tuple[np.ndarray, Any, float]:
    """A converged frame from ``spp`` samples in independent halves: the image, the
    noise estimate of its halves (:func:`.passes.estimate`), and its own relMSE."""
    from lookdev.pipeline.proof.passes import estimate

    table.set_frame(frame)
    half = max(1, min(per_pass, spp) // 2)
    sum_a = sum_b = 0.0
    n = max(1, spp // (2 * half))
    for k in range(n):
        a, b = table.render_halves(half, seed=0x7000_0000 + k)
        sum_a, sum_b = sum_a + a.astype(np.float64), sum_b + b.astype(np.float64)
    a, b = sum_a / n, sum_b / n
    ref = 0.5 * (a + b)
    floor = float(np.mean((a - b) ** 2 / 4.0 / (ref**2 + 1e-2)))  # as relative_mse's ε
    return ref, estimate(a, b), floor


def _measured_relative_rms(image: np.ndarray, ref: np.ndarray, ref_rmse: float) -> float:
    """Relative RMS error on luminance, the reference's own noise taken out in quadrature
    (the measure the frame's noise estimate predicts)."""
    from lookdev.materials.colour import luminance

    lum_ref = luminance(ref)
    d2 = float(np.mean((luminance(image.astype(np.float64)) - lum_ref) ** 2))
    return math.sqrt(max(d2 - ref_rmse**2, 0.0)) / float(np.mean(lum_ref))


def _measure(
    table: Any, sampling: dict[str, Any], seeds: int, ref: Any, guides: Any
) -> dict[str, Any]:
    """The frame as ``sampling`` renders it, ``seeds`` times (the pose repeated under new
    frame indices, so new seeds): error, estimate check, time; denoised with ``guides``."""
    from lookdev.pipeline.proof.passes import render_frame
    from lookdev.pipeline.proof.turntable import Frame

    image_ref, ref_est, floor = ref
    runs = []
    for k in range(seeds):
        frame = Frame(1000 + k, "element", 0.0)
        with Clock() as c:
            r = render_frame(table, frame, **sampling)
        run: dict[str, Any] = {
            "spp": r.spp,
            "stop": r.stop,
            "render": c.timing.to_json(),
            "rel_mse": relative_mse(r.image.astype(np.float64), image_ref),
            "estimate": r.noise,
            "measured": _measured_relative_rms(r.image, image_ref, ref_est.rmse),
            "firefly_share": r.firefly_share,
        }
        if guides is not None:
            with Clock() as c:
                d = guides.denoise(r.image, seed=frame.index, spp=r.spp)
            run["denoise_time"] = c.timing.to_json()
            run["denoised_rel_mse"] = relative_mse(d.image.astype(np.float64), image_ref)
        runs.append(run)
    return summarise(runs) | {"reference_floor": floor, "reference_noise": ref_est.relative}


def summarise(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """The seeds of one measured frame in one: relMSE and times their means; the noise
    estimate and the measured relative RMS error their RMS over the seeds (each squared
    is an unbiased estimate of the frame's mean squared error; with sun caustics a
    single frame's is dominated by a few pixels, so one seed alone may be off by 3×).

    >>> s = summarise([{"spp": 4, "stop": "max_spp", "rel_mse": 1.0, "estimate": 3.0,
    ...                 "measured": 1.0}, {"spp": 4, "stop": "max_spp", "rel_mse": 3.0,
    ...                 "estimate": 1.0, "measured": 3.0}])
    >>> s["rel_mse"], s["estimate_over_measured"], s["estimate_within_2x"]
    (2.0, 1.0, True)
    """
    out: dict[str, Any] = {k: runs[0][k] for k in ("spp", "stop")}
    for key, rms in (("rel_mse", 0), ("denoised_rel_mse", 0), ("estimate", 1), ("measured", 1)):
        if key in runs[0] and all(r.get(key) is not None for r in runs):
            values = np.array([r[key] for r in runs], dtype=np.float64)
            out[key] = float(np.sqrt(np.mean(values**2)) if rms else np.mean(values))
    for key in ("render", "denoise_time"):
        if key in runs[0]:
            out[key] = {t: float(np.mean([r[key][t] for r in runs])) for t in ("wall_s", "cpu_s")}
    if out.get("estimate") and out.get("measured"):
        ratio = out["estimate"] / out["measured"]
        out["estimate_over_measured"] = ratio
        out["estimate_within_2x"] = bool(1 / ESTIMATE_FACTOR <= ratio <= ESTIMATE_FACTOR)
    out["runs"] = runs
    return out


def error(s: ErrorSettings, progress: Any = lambda step: None) -> list[dict[str, Any]]:
    """Per case of ``s.cases``: :func:`error_case`."""
    return [error_case(preset, name, s, progress) for preset, name in s.cases]


def error_case(
    preset: str, ibl_name: str, s: ErrorSettings, progress: Any = lambda step: None
) -> dict[str, Any]:
    """The old default's and the new default's error against references, one case."""
    from lookdev.pipeline.proof import denoise, ibl, settings
    from lookdev.pipeline.proof.turntable import Frame
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    # whole-frame passes (the 480×240, 4-spp-cap default); per pixel: .adaptive
    new = settings.Settings(**({"adaptive": False} | (s.new or {})))
    pose = Frame(0, "element", 0.0)
    hub, env = blended(preset), ibl.load(ibl_name, s.ibl_width).pixels
    progress(f"{preset} × {ibl_name}: old default and its reference")
    table = proof_table(hub, env, s.old_resolution, s.old_filter)
    ref = _reference(table, pose, s.old_reference_spp, s.reference_pass)
    old = _measure(table, {"spp": s.old_spp}, s.seeds, ref, None)
    progress(f"{preset} × {ibl_name}: new default and its reference")
    table = proof_table(hub, env, tuple(new.resolution), new.pixel_filter)
    guides = denoise.guide_renderer(table) if new.denoise else None
    ref = _reference(table, pose, s.reference_spp, s.reference_pass)
    fresh = _measure(table, new.sampling(), s.seeds, ref, guides)
    others = {
        str(cap): _measure(table, new.sampling() | {"max_spp": cap}, s.seeds, ref, guides)
        for cap in s.other_caps
        if new.spp is None and cap != new.max_spp
    }
    return {
        "preset": preset,
        "ibl": ibl_name,
        "old": old | {"resolution": list(s.old_resolution), "filter": s.old_filter,
                      "denoise": False, "reference_spp": s.old_reference_spp},
        "new": fresh | {"resolution": list(new.resolution), "filter": new.pixel_filter,
                        "denoise": new.denoise, "reference_spp": s.reference_spp},
        "new_caps": others,  # the new default but for its cap: {cap: as "new"}
    }  # fmt: skip


def tasks(s: ErrorSettings, report: Any) -> list[tuple[str, Any]]:
    """The error bench's tasks (``lookdev bench error --item mainjob``): one per case,
    each appending its result to ``report.mainjob`` and returning its rows."""

    def task(preset: str, name: str) -> list[Row]:
        case = error_case(preset, name, s)
        report.mainjob.append(case)
        return error_rows([case])

    return [(f"mainjob {p} × {n}", lambda p=p, n=n: task(p, n)) for p, n in s.cases]


TABLE_COLUMNS = [
    "case",
    "default",
    "frame",
    "s/frame",
    "relMSE raw",
    "relMSE denoised",
    "reference relMSE",
    "noise estimate",
    "measured",
    "est/measured",
]


def table_rows(cases: list[dict[str, Any]]) -> list[list[str]]:
    """The README's table: per case, the old and the new default side by side."""
    out = []
    for c in cases:
        for which in ("old", "new"):
            m = c[which]
            w, h = m["resolution"]
            den = m.get("denoised_rel_mse")
            seconds = _shown_seconds(m)
            ratio = m.get("estimate_over_measured")
            out.append(
                [
                    f"{c['preset']} × {c['ibl']}",
                    which,
                    f"{w}×{h}, {m['spp']} spp, {m['filter']}",
                    f"{seconds:.3g}",
                    f"{m['rel_mse']:.3g}",
                    f"{den:.3g}" if den is not None else "",
                    f"{m['reference_floor']:.2g} ({m['reference_spp']} spp)",
                    f"{m['estimate']:.3g}" if m.get("estimate") is not None else "",
                    f"{m['measured']:.3g}" if m.get("measured") is not None else "",
                    f"{ratio:.2f}" if ratio is not None else "",
                ]
            )
    return out


def _shown_seconds(m: dict[str, Any]) -> float:
    """Wall seconds of a frame as its default shows it: render, and denoise when on."""
    dn = m["denoise_time"]["wall_s"] if m.get("denoised_rel_mse") is not None else 0.0
    return m["render"]["wall_s"] + dn


def error_rows(cases: list[dict[str, Any]]) -> list[Row]:
    """The cases as :class:`.measure.Row` s of the error bench (its table and plot): the
    error each default's frame is seen with (denoised when the default denoises)."""
    rows = []
    for c in cases:
        for which in ("old", "new"):
            m = c[which]
            den = m.get("denoised_rel_mse")
            seconds = _shown_seconds(m)
            w, h = m["resolution"]
            setting = f"{w}×{h} {m['spp']} spp {m['filter']}" + (" denoised" if den else "")
            rows.append(
                Row(
                    "mainjob",
                    f"{c['preset']} × {c['ibl']}",
                    f"{which} default",
                    setting,
                    den if den is not None else m["rel_mse"],
                    seconds,
                    1,
                    f"{m['reference_spp']} spp render (its relMSE {m['reference_floor']:.2g})",
                )
            )
    return rows
