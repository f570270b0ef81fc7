"""``lookdev bench designer``: the Material Designer's viewport against its targets.

At 480×270 unless stated, on the proof scene under ``studio``:

``designer_edit``
    designer mode, a parameter edit → the first updated frame as the page receives it
    (its display through the OCIO view and its JPEG included): median and 90th
    percentile over random edits of one to three continuous parameters (lobe switches
    among them), wall and CPU seconds. Target ≤ 0.15 s.
``client_edit``
    the same through the running server, as the page sees it: an HTTP edit (the
    session's validation and blend included) → the first frame after it on the page's
    websocket that shows it (frames carry the session's version of their material).
    Target ≤ 0.15 s.
``ibl_rotation``
    designer mode at 240×135: IBL rotations (each followed by the frame it makes, as a
    JPEG) per second. Target ≥ 10.
``designer_converge``
    designer mode, after an edit: seconds of refinement until the material's pixels
    reach relative MSE ≤ 0.01 against the same material refined to 1024 samples per pixel
    (its own reference), the samples that took, and the relMSE after each pass
    (``trajectory``: wall s, CPU s, spp, relMSE). Target ≤ 2 s.
``truth_edit``
    truth mode, an edit → the first frame (JPEG included): median over random edits. Target ≤ 0.4 s.
``truth_compiles``
    truth mode: kernels compiled (Dr.Jit's kernel history: launches that missed its
    cache) and scenes rebuilt over 100 random edits after the first frame. Target 0.
``designer_vs_truth``
    per preset of the main job's set (:data:`lookdev.pipeline.api.REPRESENTATIVE`), at
    ``compare_size``: relative MSE (:cite:`Rousselle2011`, as ``lookdev bench error``) of
    the converged designer image against truth (the path tracer), over the material's
    pixels and the whole frame, with the shares that explain it: truth with direct light
    only (path depth 2: what inter-reflection adds) and designer without shadow rays.

Timings carry wall and CPU (process) seconds, and the machine's load average is recorded
before and after each item: the machine is shared.
"""

from __future__ import annotations

import os
import statistics
import time
from collections.abc import Callable
from typing import Any

import numpy as np

__all__ = ["EDITABLE", "random_edit", "run"]

EDITABLE = (
    "base_color",
    "roughness",
    "metallic",
    "specular",
    "specular_tint",
    "anisotropic",
    "sheen",
    "sheen_tint",
    "clearcoat",
    "clearcoat_gloss",
    "spec_trans",
    "subsurface",
)
"""The Disney parameters the random edits move (each a 0..1 slider in the designer)."""


def random_edit(rng: np.random.Generator, params: Any) -> Any:
    """``params`` with one to three of :data:`EDITABLE` set to random values; a lobe
    weight is set to exactly 0 a quarter of the time (a lobe switched off, then on)."""
    keys = rng.choice(len(EDITABLE), size=int(rng.integers(1, 4)), replace=False)
    update: dict[str, Any] = {}
    for k in keys:
        name = EDITABLE[int(k)]
        if name == "base_color":
            update[name] = tuple(float(c) for c in rng.random(3))
        else:
            update[name] = 0.0 if rng.random() < 0.25 else float(rng.random())
    return params.model_copy(update=update)


def _load() -> float:
    return round(os.getloadavg()[0], 2)


def _timed(fn: Callable[[], Any]) -> tuple[Any, float, float]:
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - t0, time.process_time() - c0


def _summary(wall: list[float], cpu: list[float]) -> dict[str, float]:
    return {
        "median_s": statistics.median(wall),
        "p90_s": float(np.percentile(wall, 90)),
        "median_cpu_s": statistics.median(cpu),
        "count": len(wall),
    }


def relative_mse(image: np.ndarray, reference: np.ndarray, mask: np.ndarray | None = None):
    """relMSE (:func:`lookdev.pipeline.bench.measure.relative_mse`) over ``mask``'s pixels."""
    from .measure import relative_mse as rel

    if mask is None:
        return rel(image, reference)
    return rel(image[mask], reference[mask])


def _hub(params: Any) -> Any:
    from lookdev.pipeline.blend.result import BlendedMaterial

    return BlendedMaterial.of_params(params)


def _edits(view: Any, start: Any, count: int, seed: int) -> tuple[list[float], list[float]]:
    from lookdev.pipeline.designer.render import encode

    rng = np.random.default_rng(seed)
    wall, cpu, params = [], [], start
    for _ in range(count):
        params = random_edit(rng, params)
        hub = _hub(params)

        def edit(hub: Any = hub) -> Any:
            view.update_material(hub)
            return encode(view.step().display)

        _, w, c = _timed(edit)
        wall.append(w)
        cpu.append(c)
    return wall, cpu


def designer_edit(start: Any, size: tuple[int, int], edits: int) -> dict[str, Any]:
    from lookdev.pipeline.designer.viewport import Viewport

    load = _load()
    view = Viewport(_hub(start), width=size[0], height=size[1])
    for _ in range(4):
        view.step()
    _edits(view, start, 3, seed=99)  # warm-up: the recordings of a first edit
    wall, cpu = _edits(view, start, edits, seed=1)
    view.close()
    return {**_summary(wall, cpu), "target_s": 0.15, "load": [load, _load()]}


def client_edit(size: tuple[int, int], edits: int, seed: int = 1) -> dict[str, Any]:
    import json
    import tempfile
    from pathlib import Path

    import httpx
    from websockets.sync.client import connect

    from lookdev.library import Library
    from lookdev.pipeline.designer.server import Designer

    load = _load()
    rng = np.random.default_rng(seed)
    with tempfile.TemporaryDirectory(prefix="lookdev-bench-designer-") as folder:
        d = Designer(
            ["plastic_glossy"],
            library=Library([], use_env=False),
            folder=Path(folder),
            size=size,
        )
        stop = d.serve_in_background()
        base = f"127.0.0.1:{d.port}"
        try:
            with (
                connect(f"ws://{base}/{d.token}/ws", origin=f"http://{base}") as ws,
                httpx.Client(base_url=f"http://{base}/{d.token}") as http,
            ):

                def frame_of(version: int) -> None:
                    while True:
                        message = json.loads(ws.recv())
                        if message.get("type") == "frame":
                            ws.recv()  # its JPEG
                            if message["version"] >= version:
                                return

                wall, cpu = [], []
                for i in range(edits + 2):  # two untimed: the first edit's recordings
                    field = EDITABLE[1 + int(rng.integers(len(EDITABLE) - 1))]
                    op = {
                        "op": "set",
                        "target": None,
                        "field": field,
                        "value": round(float(rng.uniform(0.05, 0.95)), 3),
                    }
                    t0, c0 = time.perf_counter(), time.process_time()
                    response = http.post("/api/edit", json=op)
                    response.raise_for_status()
                    frame_of(response.json()["version"])
                    if i >= 2:
                        wall.append(time.perf_counter() - t0)
                        cpu.append(time.process_time() - c0)
        finally:
            stop()
    return {**_summary(wall, cpu), "target_s": 0.15, "load": [load, _load()]}


def ibl_rotation(start: Any, size: tuple[int, int], seconds: float) -> dict[str, Any]:
    from lookdev.pipeline.designer.render import encode
    from lookdev.pipeline.designer.viewport import Viewport

    load = _load()
    view = Viewport(_hub(start), width=size[0], height=size[1])
    for angle in (0.0, 5.0, 10.0):
        view.rotate_ibl(angle)
        view.step()
    count, angle = 0, 10.0
    t0, c0 = time.perf_counter(), time.process_time()
    while time.perf_counter() - t0 < seconds:
        angle += 5.0
        view.rotate_ibl(angle)
        encode(view.step().display)
        count += 1
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    view.close()
    return {
        "updates_per_s": count / wall,
        "cpu_s_per_update": cpu / count,
        "updates": count,
        "size": list(size),
        "target_per_s": 10.0,
        "load": [load, _load()],
    }


def designer_converge(start: Any, size: tuple[int, int], target: float) -> dict[str, Any]:
    from lookdev.pipeline.designer.viewport import Viewport

    load = _load()
    view = Viewport(_hub(start), width=size[0], height=size[1], noise_target=0.0, max_spp=1024)
    engine_frame = view.step()
    engine = view._engines["designer"]
    mask = engine.gbuffer.material_mask()
    while not engine.parts["material"].converged:
        reference = view.step().rgb
    reference = view.step().rgb
    view.update_material(_hub(start.model_copy(update={"roughness": 0.9})))
    view.step()
    view.update_material(_hub(start))
    elapsed = cpu = 0.0
    error, frame, trajectory = np.inf, engine_frame, []
    while error > target and not frame.converged:
        frame, w, c = _timed(view.step)
        elapsed += w
        cpu += c
        error = relative_mse(frame.rgb, reference, mask)
        trajectory.append([round(elapsed, 4), round(cpu, 4), frame.spp, float(error)])
    view.close()
    return {
        "seconds": elapsed,
        "cpu_s": cpu,
        "spp": frame.spp,
        "rel_mse": error,
        "trajectory": trajectory,
        "target_rel_mse": target,
        "reference_spp": 1024,
        "target_s": 2.0,
        "load": [load, _load()],
    }


def truth(start: Any, size: tuple[int, int], edits: int, compile_edits: int) -> dict[str, Any]:
    import drjit as dr

    from lookdev.pipeline.designer.viewport import Viewport

    load = _load()
    view = Viewport(_hub(start), mode="truth", width=size[0], height=size[1])
    view.step()
    view.step()
    engine = view._engines["truth"]
    _edits(view, start, 2, seed=99)
    wall, cpu = _edits(view, start, edits, seed=2)
    rebuilds = engine.rebuilds
    recordings = engine.table.recordings
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    dr.kernel_history()
    _edits(view, start, compile_edits, seed=3)
    history = dr.kernel_history()
    dr.set_flag(dr.JitFlag.KernelHistory, False)
    compiled = sum(1 for k in history if k.get("cache_hit") is not None and not k["cache_hit"])
    launched = sum(1 for k in history if k.get("cache_hit") is not None)
    out = {
        "edit": {**_summary(wall, cpu), "target_s": 0.4},
        "compiles": {
            "edits": compile_edits,
            "kernels_compiled": compiled,
            "kernel_launches": launched,
            "scene_rebuilds": engine.rebuilds - rebuilds,
            "new_recordings": engine.table.recordings - recordings,
            "target": 0,
        },
        "load": [load, _load()],
    }
    view.close()
    return out


def _refined(engine: Any) -> np.ndarray:
    while not engine.converged:
        engine.step()
    return engine.step()


def compare(hub: Any, environment: np.ndarray, size: tuple[int, int], spp: int) -> dict:
    """Designer against truth for one material, each refined to ``spp`` (see module doc)."""
    from lookdev.pipeline.designer.designer_mode import DesignerMode
    from lookdev.pipeline.designer.truth import TruthMode
    from lookdev.pipeline.proof.turntable import Turntable, material_bsdf, material_interior

    t0, c0 = time.perf_counter(), time.process_time()
    images, masks = {}, None
    for shadows in (True, False):
        engine = DesignerMode(
            hub, environment, size, noise_target=0.0, max_spp=spp, shadows=shadows
        )
        images["designer" if shadows else "designer_no_shadows"] = _refined(engine)
        masks = engine.gbuffer.material_mask()
    designer_s = time.perf_counter() - t0
    truth = TruthMode(hub, environment, size, noise_target=0.0, max_spp=spp, pass_spp=16)
    images["truth"] = _refined(truth)
    a, b = truth.part.halves()
    reference = images["truth"].reshape(-1, 3)
    noise = float(np.mean(((a - b) / 2.0) ** 2 / (reference**2 + 1e-2)))
    bsdf, _ = material_bsdf(hub)
    direct = Turntable(bsdf, environment, size, 2, interior=material_interior(hub))
    images["truth_direct"] = direct.render(spp, 1)
    flat = {k: v.reshape(-1, 3) for k, v in images.items()}
    mask = masks.reshape(-1)

    def pair(x: str, y: str) -> dict[str, float]:
        return {
            "material": relative_mse(flat[x], flat[y], mask),
            "frame": relative_mse(flat[x], flat[y]),
        }

    return {
        "designer_vs_truth": pair("designer", "truth"),
        "designer_vs_truth_direct": pair("designer", "truth_direct"),
        "truth_direct_vs_truth": pair("truth_direct", "truth"),
        "designer_no_shadows_vs_truth": pair("designer_no_shadows", "truth"),
        "truth_noise_rel_mse": noise,
        "live_lobes": list(hub.live_lobes),
        "designer_s": designer_s,
        "seconds": time.perf_counter() - t0,
        "cpu_s": time.process_time() - c0,
    }


def run(
    *,
    size: tuple[int, int] = (480, 270),
    rotation_size: tuple[int, int] = (240, 135),
    compare_size: tuple[int, int] = (160, 90),
    compare_spp: int = 256,
    presets: tuple[str, ...] | None = None,
    edits: int = 20,
    compile_edits: int = 100,
    rotation_seconds: float = 3.0,
    items: tuple[str, ...] = ("designer", "client", "rotation", "converge", "truth", "compare"),
    progress: Callable[[str], None] | None = None,
) -> dict[str, Any]:
    """Every figure of the benchmark (module docstring), as one JSON-ready dict."""
    import lookdev
    from lookdev.pipeline.api import REPRESENTATIVE
    from lookdev.pipeline.proof import ibl
    from lookdev.pipeline.variant import use_mitsuba

    variant = use_mitsuba()
    start = lookdev.blend("plastic_glossy", 64).params
    out: dict[str, Any] = {
        "variant": variant,
        "size": list(size),
        "start_material": "plastic_glossy",
        "cpus": os.cpu_count(),
        "load_start": _load(),
    }

    def say(what: str) -> None:
        if progress is not None:
            progress(what)

    if "designer" in items:
        say("designer mode: edits")
        out["designer_edit"] = designer_edit(start, size, edits)
    if "client" in items:
        say("designer mode: edits through the server")
        out["client_edit"] = client_edit(size, edits)
    if "rotation" in items:
        say("designer mode: IBL rotation")
        out["ibl_rotation"] = ibl_rotation(start, rotation_size, rotation_seconds)
    if "converge" in items:
        say("designer mode: convergence")
        out["designer_converge"] = designer_converge(start, size, 0.01)
    if "truth" in items:
        say("truth mode: edits and compiles")
        result = truth(start, size, edits, compile_edits)
        out["truth_edit"] = result["edit"] | {"load": result["load"]}
        out["truth_compiles"] = result["compiles"]
    if "compare" in items:
        environment = ibl.load("studio", 512).pixels
        out["designer_vs_truth"] = {
            "size": list(compare_size),
            "spp": compare_spp,
            "ibl": "studio",
            "presets": {},
        }
        for name in presets or REPRESENTATIVE:
            say(f"designer vs truth: {name}")
            load = _load()
            hub = lookdev.blend(name, 256)
            result = compare(hub, environment, compare_size, compare_spp)
            out["designer_vs_truth"]["presets"][name] = result | {"load": [load, _load()]}
    out["load_end"] = _load()
    return out
