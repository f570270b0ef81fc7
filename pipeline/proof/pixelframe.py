"""A proof job's frames rendered per pixel to their target, and what their manifests say.

Each frame: posed, its guides rendered once (when denoising), then :func:`.adaptive.
render_adaptive` adds samples where the estimate — the raw one, or the checked denoised
residual (:mod:`.checked`) when denoising is on — misses the target. The files of a frame
are written on a second thread while the next frame renders (Dr.Jit's kernels release the
GIL), and its manifest entry is yielded only once they are complete.

Files beside the raw EXR/PNG when denoising: ``_denoised.exr/.png`` (the checked frame that
is shown: raw and denoised blended by their estimated errors) and ``_difference.png``, the
view of what the denoiser changed: 0.5 + :data:`DIFFERENCE_GAIN` × (view(shown) −
view(raw)), grey where nothing changed.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from . import adaptive, checked, contact, denoise, tonemap
from .passes import estimate, seed_for
from .settings import Settings
from .turntable import Frame
from .uniform import one_behind

__all__ = ["DIFFERENCE_GAIN", "difference_view", "render_pixel_frames"]

DIFFERENCE_GAIN = 4.0
"""Display difference × this in the difference view: a change of 1/8 of the display range
reaches black or white."""


def difference_view(shown: np.ndarray, raw: np.ndarray, exposure: float = 0.0) -> np.ndarray:
    """Display values (H, W, 3): 0.5 + gain × (view(shown) − view(raw)), clipped to [0, 1]."""
    d = tonemap.view(shown, exposure, exact=True) - tonemap.view(raw, exposure, exact=True)
    return np.clip(0.5 + DIFFERENCE_GAIN * d, 0.0, 1.0)


def render_pixel_frames(
    folder: Path,
    table: Any,
    guides: denoise.GuideRenderer | None,
    todo: list[Frame],
    s: Settings,
) -> Iterator[dict[str, Any]]:
    """Render ``todo`` per pixel to ``s.noise``; their manifest entries, files complete."""
    renderer = adaptive.PixelRenderer(table.scene, table.camera_index, freeze=False)

    def frames() -> Iterator[Callable[[], dict[str, Any]]]:
        for frame in todo:
            r0, c0 = time.perf_counter(), time.process_time()
            table.set_frame(frame)
            check, aov = None, None
            if guides is not None:
                aov = guides.render(seed=frame.index)

                def check(a, b, raw_error, g=aov):  # noqa: ANN001, ANN202
                    return checked.check(
                        a, b, raw_error, lambda im: denoise.denoise(im, g), s.exposure
                    )

            f = adaptive.render_adaptive(
                renderer,
                target=s.noise,
                max_spp=s.max_spp,
                seed=lambda i, fr=frame: seed_for(fr, i),
                exposure=s.exposure,
                time_budget=s.time_budget,
                check=check,
            )
            wall, cpu = time.perf_counter() - r0, time.process_time() - c0
            yield partial(_write, folder, frame, f, aov, s, wall, cpu)

    yield from one_behind(frames())


def _write(
    folder: Path,
    frame: Frame,
    f: adaptive.AdaptiveFrame,
    aov: denoise.Guides | None,
    s: Settings,
    wall: float,
    cpu: float,
) -> dict[str, Any]:
    w0 = time.perf_counter()
    stem = folder / f"frame_{frame.index:03d}"
    images = {
        "raw": contact.write_exr(f.image, stem.with_suffix(".exr")),
        "png": contact.write_png(tonemap.view(f.image, s.exposure), stem.with_suffix(".png")),
    }
    if f.checked is not None:
        shown = f.checked.image
        name = stem.name
        images["denoised"] = contact.write_exr(shown, stem.with_name(name + "_denoised.exr"))
        images["denoised_png"] = contact.write_png(
            tonemap.view(shown, s.exposure), stem.with_name(name + "_denoised.png")
        )
        images["difference_png"] = contact.write_png(
            difference_view(shown, f.image, s.exposure), stem.with_name(name + "_difference.png")
        )
    est = estimate(f.a, f.b)
    raw_noise = float(np.sqrt(np.mean(np.square(f.raw_error))))
    entry = {
        "index": frame.index,
        "kind": frame.kind,
        "angle": frame.angle,
        "images": {role: path.name for role, path in images.items()},
        "files": {role: contact.file_entry(path) for role, path in images.items()},
        "sampling": "per_pixel",
        "spp": int(round(f.mean_spp)),
        "spp_mean": round(f.mean_spp, 2),
        "spp_max": int(f.spp.max()),
        "passes": f.passes,
        "noise": round(f.noise, 5),
        "noise_raw": round(raw_noise, 5),
        "noise_measure": "display RMS (view-transformed, code values 0-1), per pixel",
        "noise_target": s.noise,
        "converged": round(f.converged, 5),
        "noise_relative": est.relative,
        "noise_rmse": est.rmse,
        "stop": f.stop,
        "time_s": round(f.seconds - f.check_seconds, 4),
        "firefly_share": est.firefly_share,
        "clamp": s.clamp,
        "cpu_s": round(cpu, 3),
        "wall_s": round(wall, 3),
    }
    if f.checked is not None:
        entry["denoise"] = {
            "residual": round(f.checked.noise, 5),
            "raw_weight": round(f.checked.raw_weight, 4),
            "check_s": round(f.check_seconds, 4),
            "aov_s": round(aov.seconds, 4) if aov is not None else None,
            "guide_spp": aov.spp if aov is not None else None,
        }
    entry["write_s"] = round(time.perf_counter() - w0, 4)
    return entry
