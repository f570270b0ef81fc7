"""``lookdev bench proof``: what the proof pipeline costs, measured against baselines.

In one process, on the variant :func:`~lookdev.pipeline.variant.use_mitsuba` picks
(``llvm_ad_rgb`` on a CPU machine), for one material under one IBL:

* **pipeline**: a turntable as :mod:`lookdev.pipeline.proof` renders it: the scene
  loaded once, each frame posed through ``mi.traverse`` and rendered as two half-sample
  images (the noise estimate).
* **bare render**: the ``mi.render`` calls alone for the same frames at the same total
  samples, poses set outside the clock: the floor no pipeline can beat. Target: the
  pipeline's overhead over it below 10 %.
* **naive**: what a script does without kernel reuse: rebuild the scene from its files
  (the IBL's EXR, the cup's PLY) for every frame, pose baked in, then render. Target: the
  pipeline at least 3× faster.
* **kernels**: the run time of the render kernels alone in the pipeline's frames, from
  Dr.Jit's kernel history: what no pipeline, frozen or not, can go below. ``naive /
  kernels`` bounds the speed-up any pipeline can have over the naive script.
* **by frame size**: the three runs again at smaller frames (previews), where a frame's
  fixed costs (a rebuild, tracing) weigh more against its samples; it shows up to which
  frame size the 3× target holds.
* **rig**: the same turntable with the calibrated rig (``full``, the default; ``balls``)
  against none: what the chrome ball, the grey ball and the chart cost.
* **pruning**: time and noise of frames of the material as exported (lobes with zero
  weight dropped) against the same material with every lobe forced on, at equal spp.

Times are the best of ``--repeat`` interleaved rounds after one warm-up round, so
compilation is not counted and a busy machine slows every case alike; ratios come from
the same run (no absolute timings are asserted).
"""

from __future__ import annotations

import os
import time
from dataclasses import asdict, dataclass, replace
from typing import Any

import numpy as np

__all__ = [
    "Clock",
    "Settings",
    "Timing",
    "by_frame_size",
    "compare",
    "interleaved",
    "naive_scene",
    "run",
    "target_met_up_to",
    "time_bare",
    "time_kernels",
    "time_naive",
    "time_pipeline",
    "turntable_cases",
]


@dataclass(frozen=True)
class Settings:
    preset: str = "plastic_glossy"
    ibl: str = "studio"
    frames: int = 16
    spp: int = 32
    resolution: tuple[int, int] = (192, 96)
    ibl_width: int = 512
    repeat: int = 3
    # (width, height, spp) of the preview sizes timed besides the main one
    sweep: tuple[tuple[int, int, int], ...] = ((32, 16, 4), (64, 32, 8), (96, 48, 16))

    @classmethod
    def quick(cls, **given: Any) -> Settings:
        tiny = {"frames": 4, "spp": 4, "resolution": (32, 16), "ibl_width": 64}
        return cls(**tiny | {"sweep": ((16, 8, 2),)} | given)

    @property
    def samples_per_frame(self) -> int:
        return self.resolution[0] * self.resolution[1] * self.spp

    def at_size(self, width: int, height: int, spp: int) -> Settings:
        return replace(self, resolution=(width, height), spp=spp)


def _frames(n: int) -> list[Any]:
    from lookdev.pipeline.proof.turntable import frames

    return frames(n - n // 2, n // 2)


@dataclass(frozen=True)
class Timing:
    """Wall-clock and CPU seconds (all threads) of a run; its mean relative noise."""

    wall: float = 0.0
    cpu: float = 0.0
    noise: float | None = None

    def __add__(self, other: Timing) -> Timing:
        return Timing(self.wall + other.wall, self.cpu + other.cpu, self.noise)

    def to_json(self) -> dict[str, Any]:
        return {"wall_s": self.wall, "cpu_s": self.cpu}


class Clock:
    """``with Clock() as c: …`` then ``c.timing``: wall and process CPU time between."""

    def __enter__(self) -> Clock:
        self._start = (time.perf_counter(), time.process_time())
        return self

    def __exit__(self, *exc: object) -> None:
        wall, cpu = self._start
        self.timing = Timing(time.perf_counter() - wall, time.process_time() - cpu)


def time_pipeline(bsdf: dict, depth: int, env: Any, s: Settings, rig: str = "full") -> Timing:
    """A whole turntable (scene load included), with the frames' mean noise; ``rig``
    beside the material (:mod:`lookdev.pipeline.proof.rig`)."""
    from lookdev.pipeline.proof.passes import render_frame
    from lookdev.pipeline.proof.turntable import Turntable

    with Clock() as clock:
        table = Turntable(bsdf, env.pixels, s.resolution, depth, rig=rig)
        noise = [render_frame(table, f, spp=s.spp) for f in _frames(s.frames)]
    mean_noise = float(np.mean([r.noise or 0.0 for r in noise]))
    return Timing(clock.timing.wall, clock.timing.cpu, mean_noise)


def time_bare(bsdf: dict, depth: int, env: Any, s: Settings) -> Timing:
    """Time inside ``mi.render`` alone for the same frames and samples."""
    import mitsuba as mi

    from lookdev.pipeline.proof.turntable import Turntable

    table = Turntable(bsdf, env.pixels, s.resolution, depth)
    total = Timing()
    for f in _frames(s.frames):
        table.set_frame(f)
        with Clock() as clock:
            np.array(mi.render(table.scene, sensor=table.camera_index, spp=s.spp, seed=f.index))
        total += clock.timing
    return total


def naive_scene(bsdf: dict, depth: int, env: Any, s: Settings, frame: Any) -> dict:
    """The proof scene with ``frame``'s pose baked in, every input read from its file."""
    import mitsuba as mi

    from lookdev.pipeline.proof import shaderball

    element = frame.angle if frame.kind == "element" else 0.0
    light = frame.angle if frame.kind == "light" else 0.0
    scene = shaderball.scene_dict(bsdf, env.pixels, s.resolution, depth)
    scene["environment"] = {
        "type": "envmap",
        "filename": str(env.source),
        "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], light),
    }
    scene["ball"]["to_world"] = shaderball.ball_to_world(element)
    scene["cup"]["to_world"] = shaderball.cup_to_world(element)
    return scene


def time_naive(bsdf: dict, depth: int, env: Any, s: Settings) -> Timing:
    """Rebuilding and rendering the scene for every frame."""
    import mitsuba as mi

    with Clock() as clock:
        for f in _frames(s.frames):
            scene = mi.load_dict(naive_scene(bsdf, depth, env, s, f))
            np.array(mi.render(scene, spp=s.spp, seed=f.index))
    return clock.timing


def time_kernels(bsdf: dict, depth: int, env: Any, s: Settings) -> Timing:
    """Run time of the kernels Dr.Jit launches for one pipeline turntable (as wall time).

    Measured in a run of its own (timing each launch may itself cost a little): the
    kernel history records every launch's execution time, the floor beneath the
    Python, tracing and scene updates around it.
    """
    import drjit as dr

    dr.kernel_history()  # drop what earlier launches left
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    try:
        time_pipeline(bsdf, depth, env, s)
        history = dr.kernel_history()
    finally:
        dr.set_flag(dr.JitFlag.KernelHistory, False)
    return Timing(wall=sum(k.get("execution_time", 0.0) for k in history) / 1000.0)


def turntable_cases(bsdf: dict, depth: int, env: Any, s: Settings) -> dict[str, Any]:
    """The three ways of rendering the same turntable and the floor beneath them, each a
    call returning its Timing."""
    return {
        "pipeline": lambda: time_pipeline(bsdf, depth, env, s),
        "bare": lambda: time_bare(bsdf, depth, env, s),
        "naive": lambda: time_naive(bsdf, depth, env, s),
        "kernels": lambda: time_kernels(bsdf, depth, env, s),
    }


def compare(got: dict[str, Timing]) -> dict[str, Any]:
    """Ratios of the pipeline against the bare calls, the naive script and the floor."""
    pipeline, bare, naive = (got[k] for k in ("pipeline", "bare", "naive"))
    kernels = got["kernels"].wall
    return {
        "pipeline": pipeline.to_json(),
        "bare_render": bare.to_json(),
        "naive_rebuild": naive.to_json(),
        "kernels_s": kernels,
        "speedup_vs_naive": naive.wall / pipeline.wall,
        "overhead_vs_bare": pipeline.wall / bare.wall - 1.0,
        "cpu_speedup_vs_naive": naive.cpu / pipeline.cpu,
        "cpu_overhead_vs_bare": pipeline.cpu / bare.cpu - 1.0,
        "bound_vs_naive": naive.wall / kernels if kernels > 0 else None,
    }


def by_frame_size(bsdf: dict, depth: int, env: Any, s: Settings) -> list[dict[str, Any]]:
    """:func:`compare` at each of ``s.sweep``'s sizes, smallest first."""
    rows = []
    for width, height, spp in s.sweep:
        at = s.at_size(width, height, spp)
        got = interleaved(turntable_cases(bsdf, depth, env, at), s.repeat)
        row = {"resolution": [width, height], "spp": spp, "samples_per_frame": at.samples_per_frame}
        rows.append(row | compare(got))
    return rows


def target_met_up_to(rows: list[dict[str, Any]], target: float = 3.0) -> int | None:
    """The largest samples per frame of a run meeting the speed-up ``target``, or None.

    >>> target_met_up_to([{"samples_per_frame": 8, "speedup_vs_naive": 3.5},
    ...                   {"samples_per_frame": 64, "speedup_vs_naive": 2.0}])
    8
    """
    met = [r["samples_per_frame"] for r in rows if r["speedup_vs_naive"] >= target]
    return max(met, default=None)


def interleaved(cases: dict[str, Any], repeat: int) -> dict[str, Timing]:
    """Each case's fastest (wall-clock) run over ``repeat`` rounds, after a warm-up round.

    Rounds run the cases in turn (A B C A B C …), so a machine busy with other work
    slows every case alike instead of whichever happened to run then.
    """
    best: dict[str, Timing] = {}
    for round_ in range(repeat + 1):
        for name, fn in cases.items():
            result = fn()
            if round_ and (name not in best or result.wall < best[name].wall):
                best[name] = result
    return best


def run(s: Settings) -> dict[str, Any]:
    """Every measurement of the benchmark, as one JSON-able dict.

    Ratios are on wall-clock time (what a user waits for), with the same ratios on CPU
    time (all threads) beside them: on a machine busy with other work, CPU time is the
    steadier of the two, and the recorded load average says which to trust.
    """
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.proof import batch, ibl
    from lookdev.pipeline.proof.turntable import material_bsdf
    from lookdev.pipeline.variant import use_mitsuba

    variant = use_mitsuba()
    load_before = os.getloadavg()[0]
    material = blend(load_material(s.preset), batch.MAP_RESOLUTION)
    env = ibl.load(s.ibl, s.ibl_width)
    bsdf, depth = material_bsdf(material)
    forced, _ = material_bsdf(material, force_all_lobes=True)
    cases = turntable_cases(bsdf, depth, env, s)
    cases["all_lobes"] = lambda: time_pipeline(forced, depth, env, s)
    for rig in ("balls", "none"):  # the pipeline's own run has the default, full rig
        cases[f"rig_{rig}"] = lambda rig=rig: time_pipeline(bsdf, depth, env, s, rig)
    got = interleaved(cases, s.repeat)
    turntable = compare(got)
    sizes = by_frame_size(bsdf, depth, env, s)
    main = {"resolution": list(s.resolution), "spp": s.spp}
    main |= {"samples_per_frame": s.samples_per_frame} | turntable
    pipeline, all_on = got["pipeline"], got["all_lobes"]
    return {
        "variant": variant,
        "settings": asdict(s),
        "bsdf": bsdf.get("type"),
        # Other work on the machine inflates wall times (not CPU times): judge with this.
        "load_average": [load_before, os.getloadavg()[0]],
        "cpu_count": os.cpu_count(),
        "turntable": turntable
        | {"targets": {"speedup_vs_naive": ">= 3", "overhead_vs_bare": "< 0.10"}},
        "by_frame_size": [*sizes, main],
        "speedup_target_met_up_to_samples_per_frame": target_met_up_to([*sizes, main]),
        "rig": {
            "full": pipeline.to_json(),
            "balls": got["rig_balls"].to_json(),
            "none": got["rig_none"].to_json(),
            "cost_full_vs_none": pipeline.wall / got["rig_none"].wall,
            "cpu_cost_full_vs_none": pipeline.cpu / got["rig_none"].cpu,
            "cost_balls_vs_none": got["rig_balls"].wall / got["rig_none"].wall,
        },
        "pruning": {
            "pruned": pipeline.to_json() | {"noise_relative": pipeline.noise},
            "all_lobes": all_on.to_json() | {"noise_relative": all_on.noise},
            "speedup": all_on.wall / pipeline.wall,
            "cpu_speedup": all_on.cpu / pipeline.cpu,
        },
    }
