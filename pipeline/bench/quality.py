"""What the main job's defaults cost and buy (issue 16): ``lookdev bench mainjob`` and
``lookdev bench error --item mainjob``.

**Cost of each knob** (:func:`cost`): for every preset of the main job under one IBL, a
proof job is replayed as :func:`lookdev.pipeline.proof.batch.run_job` runs it — the
Turntable built (the scene loaded, kernels compiled on the first frame), then the frames
of a 4 + 4 turntable rendered to the default noise target under each candidate sample cap,
each written (EXR, and PNG through the view) and denoised (guides rendered, OIDN, the
denoised EXR and PNG written). The caps are measured preset by preset, one after the
other, so load on a shared machine falls on both alike. From these timings,
:func:`project` prices each candidate default (frames per turntable, cap, denoise on or
off) over the whole main job, as a ratio to the previous default (16 frames, cap 8, raw):
a job costs its set-up and first frame, plus its other frames at the steady cost.

**Error of the defaults** (:func:`error`): for a sampled subset of the main job (a glossy
plastic, a metal, glass and skin, one IBL each, the turntable's first pose), a converged
reference is rendered as two independent halves (their difference is its own noise,
stated), and the frame as each default renders it is compared with it:

* *old* — the job before issue 16: 192×96, a fixed 32 spp, Gaussian pixel filter, raw;
  its reference is rendered at 192×96 with the same filter, so the error is noise alone;
* *new* — :mod:`lookdev.pipeline.proof.settings`' defaults: 480×240, box filter, the noise
  target and its cap, and the denoised frame when denoising is on; reference at 480×240.

Error is relative MSE (:func:`.measure.relative_mse`, Rousselle et al. 2011) over the
frame's RGB, the mean over ``seeds`` renders; the reference's own relMSE (``floor``, from
its halves: Var of their mean = E[(A − B)²]/4) is part of every measured value and is
listed beside it. The *estimate check* of issue 16 compares each raw frame's own noise
estimate (:func:`lookdev.pipeline.proof.passes.estimate`, relative RMS on luminance) with
the error measured the same way against the reference, the reference's noise taken out in
quadrature: within a factor of 2 passes. The estimate describes the raw frame, never the
denoised one.
"""

from __future__ import annotations

import math
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .measure import Row, relative_mse
from .proof import Clock, Timing

__all__ = [
    "CASES",
    "CostSettings",
    "ErrorSettings",
    "cost",
    "error",
    "error_case",
    "error_rows",
    "job_rows",
    "table_rows",
    "tasks",
    "project",
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
"""Issue 16: a frame's noise estimate within this factor of its measured error."""


def _hub(preset: str) -> Any:
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.proof import batch

    return blend(load_material(preset), batch.MAP_RESOLUTION)


def _table(hub: Any, env: np.ndarray, resolution: tuple[int, int], pixel_filter: str) -> Any:
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


# -- cost ----------------------------------------------------------------------------------
@dataclass(frozen=True)
class CostSettings:
    presets: tuple[str, ...] = ()  # () = the main job's (lookdev.pipeline.api REPRESENTATIVE)
    ibl: str = "sky"
    ibls_in_job: int = 4  # the main job's IBLs (every built-in): the projection's multiplier
    resolution: tuple[int, int] = (480, 240)
    caps: tuple[int, ...] = (4, 8)
    element_frames: int = 4  # the poses timed per job; longer turntables are projected
    light_frames: int = 4
    ibl_width: int = 512
    denoise: bool = True  # also time guides + OIDN + the denoised files per frame

    @classmethod
    def quick(cls) -> CostSettings:
        return cls(("plastic_glossy",), "sky", 1, (32, 16), (2, 4), 2, 1, 64)


def cost(s: CostSettings) -> list[dict[str, Any]]:
    """Per preset and cap: the job's set-up and every frame's render, write and denoise
    timings (wall and CPU seconds), in the order a proof job spends them."""
    from lookdev.pipeline.api.outputs import REPRESENTATIVE
    from lookdev.pipeline.proof import contact, denoise, ibl, tonemap, turntable
    from lookdev.pipeline.proof.passes import render_frame
    from lookdev.pipeline.proof.settings import DEFAULT_NOISE
    from lookdev.pipeline.variant import use_mitsuba

    use_mitsuba()
    env = ibl.load(s.ibl, s.ibl_width).pixels
    poses = turntable.frames(s.element_frames, s.light_frames)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for preset in s.presets or REPRESENTATIVE:
            hub = _hub(preset)
            for cap in s.caps:
                with Clock() as c:
                    table = _table(hub, env, s.resolution, "box")
                    guides = denoise.guide_renderer(table, None) if s.denoise else None
                setup, frames = c.timing, []
                for frame in poses:
                    stem = Path(tmp) / f"frame_{frame.index:03d}"
                    with Clock() as c:
                        r = render_frame(table, frame, noise=DEFAULT_NOISE, max_spp=cap)
                    render = c.timing
                    with Clock() as c:
                        contact.write_exr(r.image, stem.with_suffix(".exr"))
                        contact.write_png(tonemap.view(r.image), stem.with_suffix(".png"))
                    write, dn = c.timing, Timing()
                    if guides is not None:
                        with Clock() as c:
                            denoise.write_denoised(guides, r.image, stem, 0.0, frame.index)
                        dn = c.timing
                    frames.append(
                        {
                            "spp": r.spp,
                            "noise": r.noise,
                            "render": render.to_json(),
                            "write": write.to_json(),
                            "denoise": dn.to_json(),
                        }
                    )
                rows.append({"preset": preset, "max_spp": cap, "setup": setup.to_json(),
                             "frames": frames})  # fmt: skip
    return rows


def _job_seconds(row: dict[str, Any], frames: int, denoised: bool, clock: str) -> float:
    """One job's seconds at ``frames`` frames: set-up, the timed frames in order, and
    beyond them the mean of the timed frames after the first two (steady state)."""
    per = [
        f["render"][clock] + f["write"][clock] + (f["denoise"][clock] if denoised else 0.0)
        for f in row["frames"]
    ]
    steady = float(np.mean(per[2:] if len(per) > 2 else per))
    return row["setup"][clock] + sum(per[:frames]) + max(0, frames - len(per)) * steady


def project(
    rows: list[dict[str, Any]],
    s: CostSettings,
    frames: tuple[int, ...] = (8, 16),
    baseline: tuple[int, int, bool] | None = None,
) -> list[dict[str, Any]]:
    """Each candidate (frames per turntable, cap, denoise): the main job's proofs
    (presets × ``s.ibls_in_job``) in wall and CPU seconds as measured here, and as a
    ratio to ``baseline`` measured in the same run: by default the previous default (16 frames, cap
    8, raw; the largest cap measured when 8 was not)."""
    baseline = baseline or (16, 8 if 8 in s.caps else max(s.caps), False)

    def total(n: int, cap: int, dn: bool, clock: str) -> float:
        jobs = [r for r in rows if r["max_spp"] == cap]
        return s.ibls_in_job * sum(_job_seconds(r, n, dn, clock) for r in jobs)

    base = {k: total(*baseline, k) for k in ("wall_s", "cpu_s")}
    out = []
    for n in frames:
        for cap in s.caps:
            for dn in (False, True) if s.denoise else (False,):
                t = {k: total(n, cap, dn, k) for k in ("wall_s", "cpu_s")}
                out.append(
                    {
                        "frames": n,
                        "max_spp": cap,
                        "denoise": dn,
                        **t,
                        "over_today_wall": t["wall_s"] / base["wall_s"],
                        "over_today_cpu": t["cpu_s"] / base["cpu_s"],
                    }
                )
    return out


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
                d = guides.denoise(r.image, seed=frame.index)
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
    new = settings.Settings(**(s.new or {}))
    pose = Frame(0, "element", 0.0)
    hub, env = _hub(preset), ibl.load(ibl_name, s.ibl_width).pixels
    progress(f"{preset} × {ibl_name}: old default and its reference")
    table = _table(hub, env, s.old_resolution, s.old_filter)
    ref = _reference(table, pose, s.old_reference_spp, s.reference_pass)
    old = _measure(table, {"spp": s.old_spp}, s.seeds, ref, None)
    progress(f"{preset} × {ibl_name}: new default and its reference")
    table = _table(hub, env, tuple(new.resolution), new.pixel_filter)
    guides = denoise.guide_renderer(table, new.spp) if new.denoise else None
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


def job_rows(rows: list[dict[str, Any]]) -> list[list[Any]]:
    """Per job of :func:`cost`: set-up, first frame, steady frame and denoise, CPU seconds."""
    out = []
    for r in rows:
        per = [f["render"]["cpu_s"] + f["write"]["cpu_s"] for f in r["frames"]]
        den = [f["denoise"]["cpu_s"] for f in r["frames"]]
        steady = per[2:] if len(per) > 2 else per
        out.append(
            [r["preset"], r["max_spp"], r["setup"]["cpu_s"], per[0], float(np.mean(steady)),
             float(np.mean(den[2:] if len(den) > 2 else den))]
        )  # fmt: skip
    return out
