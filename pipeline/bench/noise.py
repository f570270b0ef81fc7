"""``lookdev bench noise``: what rendering to a noise target costs.

Three measurements, each a ratio within one run (the machine may be shared):

- **pixel filter**: one proof frame rendered with a box and with a Gaussian pixel filter,
  interleaved, best of ``repeat``; the Gaussian's cost over the box.
- **noise traces**: per preset × IBL, a frame of the proof at the new size rendered in
  passes (:func:`lookdev.pipeline.proof.passes.render_frame`), its estimated relative
  noise, firefly share, wall and CPU seconds after every pass; from these, for each
  candidate (target, cap), where a frame would stop, with how many samples and what noise.
- **pass cost**: one pass of ``trace_spp`` against passes of ``pass_spp`` adding up to
  it, interleaved: what a pass costs beyond its samples.
- **main job, new default vs old**: the same jobs also load and render the old default
  (192×96, 32 spp, Gaussian) interleaved with the new; a job's time is its scene load and
  first frame (kernels compile, the frozen render records) plus (frames − 1) × a steady
  frame, frame writes (EXR, PNG through the view) included; summed over the jobs, the
  ratio new/old of both wall and CPU seconds.
"""

from __future__ import annotations

import tempfile
import time
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["Settings", "candidates", "filter_cost", "pass_cost", "run", "traces"]


@dataclass(frozen=True)
class Settings:
    """What :func:`run` measures; the defaults are the main job's subjects and sizes."""

    presets: tuple[str, ...] = ("gold", "plastic_glossy", "glass_clear")
    ibls: tuple[str, ...] = ("sky", "sunset")
    resolution: tuple[int, int] = (480, 240)
    trace_spp: int = 16  # passes are traced up to this many samples per pixel
    pass_spp: int = 4
    targets: tuple[float, ...] = (0.05, 0.1, 0.2, 0.4)
    caps: tuple[int, ...] = (4, 8, 16)
    frames: int = 16  # frames of a turntable, for the main-job extrapolation
    old_resolution: tuple[int, int] = (192, 96)
    old_spp: int = 32
    old_filter: str = "gaussian"
    filter_spp: int = 16
    repeat: int = 3
    ibl_width: int = 512

    @classmethod
    def quick(cls, **kw: Any) -> Settings:
        """Tiny frames, one preset and IBL: for tests."""
        tiny = {
            "presets": ("plastic_glossy",),
            "ibls": ("sky",),
            "resolution": (32, 16),
            "trace_spp": 8,
            "caps": (4, 8),
            "targets": (0.5,),
            "old_resolution": (16, 8),
            "old_spp": 4,
            "filter_spp": 4,
            "repeat": 1,
            "ibl_width": 64,
        }
        return cls(**(tiny | kw))


class _Clock:
    def __enter__(self) -> _Clock:
        self.wall, self.cpu = time.perf_counter(), time.process_time()
        return self

    def __exit__(self, *exc: object) -> None:
        self.wall = time.perf_counter() - self.wall
        self.cpu = time.process_time() - self.cpu


def _table(preset: str, ibl_name: str, s: Settings, resolution: tuple[int, int], flt: str) -> Any:
    from lookdev.library import load_material
    from lookdev.pipeline.blend import blend
    from lookdev.pipeline.proof import batch, ibl, turntable

    bsdf, depth = turntable.material_bsdf(blend(load_material(preset), batch.MAP_RESOLUTION))
    env = ibl.load(ibl_name, s.ibl_width).pixels
    return turntable.Turntable(bsdf, env, resolution, depth, pixel_filter=flt)


def filter_cost(s: Settings) -> list[dict[str, Any]]:
    """Box vs Gaussian pixel filter, per preset under the first IBL, interleaved."""
    from lookdev.pipeline.proof import passes, turntable

    rows = []
    frame = turntable.Frame(0, "element", 0.0)
    for preset in s.presets:
        tables = {f: _table(preset, s.ibls[0], s, s.resolution, f) for f in ("box", "gaussian")}
        for table in tables.values():  # compiles and records: not timed
            passes.render_frame(table, frame, spp=s.filter_spp)
        best = {f: [np.inf, np.inf] for f in tables}
        for _ in range(s.repeat):
            for flt, table in tables.items():
                with _Clock() as c:
                    passes.render_frame(table, frame, spp=s.filter_spp)
                best[flt] = [min(best[flt][0], c.wall), min(best[flt][1], c.cpu)]
        rows.append(
            {
                "preset": preset,
                "ibl": s.ibls[0],
                "box_wall_s": best["box"][0],
                "gaussian_wall_s": best["gaussian"][0],
                "gaussian_over_box_wall": best["gaussian"][0] / best["box"][0],
                "gaussian_over_box_cpu": best["gaussian"][1] / best["box"][1],
            }
        )
    return rows


def pass_cost(s: Settings) -> dict[str, Any]:
    """One pass of ``trace_spp`` against passes of ``pass_spp`` adding up to it, on the
    first preset × IBL, interleaved, best of ``repeat``: the fixed cost of a pass."""
    from lookdev.pipeline.proof import passes, turntable

    table = _table(s.presets[0], s.ibls[0], s, s.resolution, "box")
    frame = turntable.Frame(s.frames - 1, "light", 180.0)
    ways = {
        "one": {"spp": s.trace_spp},
        "passes": {"noise": 1e-9, "max_spp": s.trace_spp, "pass_spp": s.pass_spp},
    }
    best = {k: [np.inf, np.inf] for k in ways}
    for rep in range(s.repeat + 1):
        for k, kw in ways.items():
            with _Clock() as c:
                passes.render_frame(table, frame, **kw)
            if rep:  # the first round compiles and records
                best[k] = [min(best[k][0], c.wall), min(best[k][1], c.cpu)]
    return {
        "preset": s.presets[0],
        "ibl": s.ibls[0],
        "spp": s.trace_spp,
        "pass_spp": s.pass_spp,
        "passes_over_one_wall": best["passes"][0] / best["one"][0],
        "passes_over_one_cpu": best["passes"][1] / best["one"][1],
    }


def _write_cost(image: np.ndarray, folder: Path) -> list[float]:
    """[wall, CPU] seconds to write a frame as a proof does: EXR, and PNG through the view."""
    from lookdev.pipeline.proof import contact, tonemap

    with _Clock() as c:
        contact.write_exr(image, folder / "f.exr")
        contact.write_png(tonemap.view(image), folder / "f.png")
    return [c.wall, c.cpu]


def traces(s: Settings) -> list[dict[str, Any]]:
    """Per preset × IBL: old and new default, interleaved, timed as the main job runs."""
    from lookdev.pipeline.proof import passes, turntable

    first = turntable.Frame(0, "element", 0.0)
    steady = turntable.Frame(s.frames - 1, "light", 180.0)
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        for preset in s.presets:
            for ibl_name in s.ibls:
                old = _setup(preset, ibl_name, s, s.old_resolution, s.old_filter, first, folder)
                with _Clock() as c:
                    r = passes.render_frame(old.pop("table"), steady, spp=s.old_spp)
                write = old["write_s"]
                old |= {"frame_s": [c.wall + write[0], c.cpu + write[1]], "noise": r.noise}
                new = _setup(preset, ibl_name, s, s.resolution, "box", first, folder)
                trace = _trace(new.pop("table"), steady, s)
                rows.append(
                    {"preset": preset, "ibl": ibl_name, "old": old, "new": new, "trace": trace}
                )
    return rows


def _setup(preset: str, ibl_name: str, s: Settings, res: Any, flt: str, first: Any, folder: Path):
    """A job's fixed cost: the scene load and its first frame (compiles and records)."""
    from lookdev.pipeline.proof import passes

    with _Clock() as setup:
        table = _table(preset, ibl_name, s, res, flt)
        r = passes.render_frame(table, first, spp=s.pass_spp)
    write = _write_cost(r.image, folder)
    return {"table": table, "setup_s": [setup.wall, setup.cpu], "write_s": write}


def _trace(table: Any, frame: Any, s: Settings) -> list[dict[str, Any]]:
    """Noise, firefly share, wall and CPU seconds after every pass, up to ``trace_spp``."""
    from lookdev.pipeline.proof import passes

    trace: list[dict[str, Any]] = []
    cpu0 = time.process_time()

    def record(spp: int, e: Any, wall: float) -> None:
        trace.append(
            {
                "spp": spp,
                "noise": e.relative,
                "firefly_share": e.firefly_share,
                "wall_s": wall,
                "cpu_s": time.process_time() - cpu0,
            }
        )

    passes.render_frame(
        table, frame, noise=1e-9, max_spp=s.trace_spp, pass_spp=s.pass_spp, on_pass=record
    )
    return trace


def _stop_at(trace: list[dict[str, Any]], target: float, cap: int) -> dict[str, Any]:
    for point in trace:
        if point["noise"] is None or point["noise"] <= target:
            return point | {"stop": "target"}
        if point["spp"] >= cap:
            return point | {"stop": "max_spp"}
    return trace[-1] | {"stop": "max_spp"}


def candidates(rows: list[dict[str, Any]], s: Settings) -> list[dict[str, Any]]:
    """For each (target, cap): per job where its frame stops, and the main job's time
    new/old extrapolated to ``s.frames`` frames per job (module docstring)."""
    out = []
    for target in s.targets:
        for cap in s.caps:
            new = np.zeros(2)
            old = np.zeros(2)
            stops = []
            for row in rows:
                p = _stop_at(row["trace"], target, cap)
                stops.append({"preset": row["preset"], "ibl": row["ibl"]} | p)
                frame = np.array([p["wall_s"], p["cpu_s"]]) + row["new"]["write_s"]
                new += np.array(row["new"]["setup_s"]) + (s.frames - 1) * frame
                old += np.array(row["old"]["setup_s"]) + (s.frames - 1) * np.array(
                    row["old"]["frame_s"]
                )
            out.append(
                {
                    "target": target,
                    "max_spp": cap,
                    "met": sum(p["stop"] == "target" for p in stops),
                    "jobs": len(stops),
                    "mean_spp": float(np.mean([p["spp"] for p in stops])),
                    "new_over_old_wall": float(new[0] / old[0]),
                    "new_over_old_cpu": float(new[1] / old[1]),
                    "frames": stops,
                }
            )
    return out


def run(s: Settings | None = None, *, filters: bool = True) -> dict[str, Any]:
    """Every measurement of this module as one JSON-ready dict."""
    from lookdev.pipeline.variant import use_mitsuba

    s = s or Settings()
    variant = use_mitsuba()
    rows = traces(s)
    return {
        "variant": variant,
        "settings": asdict(s),
        "load_average": list(_load()),
        "filter": filter_cost(s) if filters else [],
        "pass_cost": pass_cost(s),
        "traces": rows,
        "candidates": candidates(rows, s),
    }


def _load() -> tuple[float, ...]:
    import os

    try:
        return os.getloadavg()
    except OSError:
        return ()
