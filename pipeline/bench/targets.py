"""The main job's noise target against what it costs: ``lookdev bench targets``.

The main job (``lookdev proof`` on built-in defaults) is run once per setting — its
uniform default, then per-pixel sampling (:mod:`lookdev.pipeline.proof.adaptive`) at each
candidate target — as a fresh ``lookdev proof`` process over the same presets and IBLs,
one pose a turntable (the main job renders 4 + 4), so that the settings can be priced
side by side in a few minutes. Each run is charged the CPU seconds of its process tree
(``os.wait4``) and its wall seconds; its manifest says, per frame, whether the frame met
its target or where it stopped (``stop``), and at what mean samples per pixel. A frame
that stops at the cap has its residual and the share of its pixels that met the target
in the manifest: that is the record of why not.

What a setting *buys* (the error against converged references at equal time) is
measured by ``lookdev bench error --item adaptive`` (:mod:`.adaptive`).
"""

from __future__ import annotations

import json
import os
import sys
import tempfile
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from .cli import ENTRY, cpu_seconds

__all__ = ["FIGURE_CASES", "TargetSettings", "figure", "run", "run_setting"]


@dataclass(frozen=True)
class TargetSettings:
    presets: tuple[str, ...] = ()  # () = the main job's (lookdev.pipeline.api REPRESENTATIVE)
    ibls: tuple[str, ...] = ()  # () = every built-in, as the main job
    targets: tuple[float, ...] = (0.04, 0.03, 0.02)  # per-pixel targets (display RMS)
    resolution: tuple[int, int] | None = None  # None: the main job's
    max_spp: int | None = None  # None: the per-pixel default cap

    def __post_init__(self) -> None:
        from lookdev.materials.errors import argument, check_range
        from lookdev.pipeline.proof.settings import RANGES, ProofError

        for target in self.targets:  # refused here, in one line, not by a child's traceback
            check_range(target, *RANGES["noise"], field=argument("target"), error=ProofError)

    @classmethod
    def quick(cls) -> TargetSettings:
        return cls(("plastic_glossy",), ("studio",), (0.08,), (32, 16), 16)


def _proof_argv(s: TargetSettings, out: Path, target: float | None) -> list[str]:
    argv = [sys.executable, "-c", ENTRY, "proof", *s.presets, "-n", "1", "-m", "0"]
    argv += ["-o", str(out), "--rig", "full"]
    for ibl in s.ibls:
        argv += ["--ibl", ibl]
    if s.resolution is not None:
        argv += ["-r", str(s.resolution[0]), str(s.resolution[1])]
    if target is not None:
        argv += ["--adaptive", "--noise", str(target)]
        if s.max_spp is not None:
            argv += ["--max-spp", str(s.max_spp)]
    return argv


def _frames(out: Path) -> list[dict[str, Any]]:
    """Every frame's manifest entry, with its material and IBL."""
    batch = json.loads((out / "manifest.json").read_text(encoding="utf-8"))
    frames = []
    for proof in batch["proofs"]:
        entry = json.loads((out / proof["folder"] / "manifest.json").read_text(encoding="utf-8"))
        for f in entry["frames"]:
            frames.append({"material": proof["material"], "ibl": proof["ibl"], **f})
    return frames


def _folder(target: float | None) -> str:
    return "uniform" if target is None else f"target_{target:g}"


def run_setting(
    s: TargetSettings, target: float | None, keep: Path | None = None
) -> dict[str, Any]:
    """One setting's run: CPU and wall seconds, and what its frames did; its proofs are
    kept under ``keep`` when given."""
    with tempfile.TemporaryDirectory(prefix="lookdev-targets-") as tmp:
        out = (keep or Path(tmp)) / _folder(target)
        start = time.perf_counter()
        cpu = cpu_seconds(_proof_argv(s, out, target))
        wall = time.perf_counter() - start
        frames = _frames(out)
    stops = Counter(f["stop"] for f in frames)
    missed = [
        {k: f.get(k) for k in ("material", "ibl", "stop", "spp_mean", "noise", "converged")}
        for f in frames
        if f["stop"] != "target"
    ]
    return {
        "setting": "uniform default" if target is None else f"per pixel, target {target:g}",
        "target": target,
        "cpu_s": round(cpu, 2),
        "wall_s": round(wall, 2),
        "frames": len(frames),
        "met": stops.get("target", 0),
        "stops": dict(stops),
        "mean_spp": round(
            sum(f.get("spp_mean", f["spp"]) for f in frames) / max(len(frames), 1), 1
        ),
        "missed": missed,
    }


def run(s: TargetSettings, keep: Path | None = None) -> dict[str, Any]:
    """The uniform default, then every target of ``s``, one after the other; with
    ``keep``, the proofs stay there and :func:`figure` is written beside them."""
    from lookdev.pipeline.api.proofs import REPRESENTATIVE

    if not s.presets:
        s = TargetSettings(REPRESENTATIVE, s.ibls, s.targets, s.resolution, s.max_spp)
    rows = [run_setting(s, None, keep)] + [run_setting(s, t, keep) for t in s.targets]
    if keep is not None:
        figure(keep, (None, *s.targets), keep / "targets.png")
    load = os.getloadavg() if hasattr(os, "getloadavg") else ()
    return {"settings": s.__dict__, "load_average": [round(x, 2) for x in load], "rows": rows}


FIGURE_CASES = (("glass_clear", "sky"), ("gold", "studio"), ("skin", "sky"))
"""The frames :func:`figure` compares: the sun's glint and caustic, a metal's grain, skin."""


def figure(keep: Path, targets: tuple[float | None, ...], out: Path) -> Path:
    """The shown (denoised) first frame of each of :data:`FIGURE_CASES` that was run, a row
    each, a column per setting in ``targets`` order, cropped to the sphere and the cup."""
    import numpy as np

    from lookdev.pipeline.proof.contact import read_rgb, write_png

    rows = []
    for material, ibl in FIGURE_CASES:
        paths = [keep / _folder(t) / material / ibl / "frame_000_denoised.png" for t in targets]
        if all(p.exists() for p in paths):
            crops = [read_rgb(p) for p in paths]
            h, w = crops[0].shape[:2]
            rows.append(np.concatenate([c[h // 6 : h * 5 // 6, : w * 5 // 8] for c in crops], 1))
    if rows:
        write_png(np.concatenate(rows, axis=0), out)
    return out
