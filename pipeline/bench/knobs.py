"""What each knob of the main job costs: ``lookdev bench mainjob``.

For every preset of the main job under one IBL, a proof job is replayed as
:func:`lookdev.pipeline.proof.batch.run_job` runs it — the Turntable built (the scene
loaded, kernels compiled on the first frame), then the frames of a 4 + 4 turntable
rendered to the default noise target under each candidate sample cap, each written (EXR,
and PNG through the view) and denoised (guides rendered, OIDN, the denoised EXR and PNG
written). The caps are measured preset by preset, one after the other, so load on a
shared machine falls on both alike. From these timings, :func:`project` prices each
candidate default (frames per turntable, cap, denoise on or off) over the whole main
job, as a ratio to the previous default (16 frames, cap 8, raw): a job costs its set-up
and first frame, plus its other frames at the steady cost. What the defaults *buy* is
measured by :mod:`.quality`.
"""

from __future__ import annotations

import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from .proof import Clock, Timing
from .quality import blended, proof_table  # the proofs' own material and scene

__all__ = ["CostSettings", "cost", "job_rows", "project"]


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
    from lookdev.pipeline.api.proofs import REPRESENTATIVE
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
            hub = blended(preset)
            for cap in s.caps:
                with Clock() as c:
                    table = proof_table(hub, env, s.resolution, "box")
                    guides = denoise.guide_renderer(table) if s.denoise else None
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
                            denoise.write_denoised(guides, r.image, stem, 0.0, frame.index, r.spp)
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
