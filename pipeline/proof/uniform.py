"""A proof job's frames rendered in whole-frame passes (:mod:`.passes`), and their files.

Each frame is posed and rendered, its guides rendered at that pose (when denoising), and
then its files — the raw EXR, its PNG through the view, and with denoising OIDN's frame
(:func:`.denoise.write_guided`) — are made on a second thread while the next frame
renders: Dr.Jit's kernels, OIDN, OpenImageIO's writers, OCIO and hashing release the GIL,
so that work fills whatever the renderer leaves of the cores (on 2 cores it cannot make
CPU time: both compete for the same cores). A frame's manifest entry is yielded only once
its files are complete, so the batch's rule holds: a frame in the manifest is finished.

A worker keeps the scene of its last job (:func:`turntable_for`): the next job of the
same material and settings, under another IBL of the same size, swaps the envmap's pixels
(:meth:`.turntable.Turntable.set_environment`, frames equal to a fresh load's) instead of
loading the scene again — the batch orders its jobs material by material.
"""

from __future__ import annotations

import hashlib
import json
import threading
from collections.abc import Callable, Iterator
from concurrent.futures import Future, ThreadPoolExecutor
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from . import contact, denoise, tonemap
from .settings import Settings
from .turntable import Frame, Turntable

__all__ = ["frame_entry", "keep", "one_behind", "render_uniform_frames", "turntable_for"]

_kept = threading.local()  # per thread: a thread pool running jobs must not share a scene


def _scene_key(material: Any, settings: Settings, environment: np.ndarray) -> str:
    """What a loaded scene depends on but the IBL's pixels."""
    h = hashlib.sha256(json.dumps(settings.as_json(), sort_keys=True).encode())
    h.update(material.digest().encode())
    h.update(repr(np.shape(environment)).encode())
    return h.hexdigest()


def turntable_for(material: Any, environment: np.ndarray, settings: Settings) -> Turntable:
    """The turntable of ``material`` under ``environment``: this thread's last one, relit,
    when only the IBL differs, else a newly loaded scene. Give it back with
    :func:`keep` once its frames are done (a job that fails keeps nothing)."""
    from .turntable import material_bsdf, material_interior

    key = _scene_key(material, settings, environment)
    last = getattr(_kept, "table", None)
    _kept.table = None
    if last is not None and last[0] == key:
        last[1].set_environment(environment)
        return last[1]
    last = None  # the old scene is released before the new one loads
    s = settings
    bsdf, depth = material_bsdf(material)
    table = Turntable(
        bsdf,
        environment,
        s.resolution,
        depth,
        s.geometry,
        rig=s.rig,
        pixel_filter=s.pixel_filter,
        clamp=s.clamp,
        interior=material_interior(material),
    )
    table.scene_key = key
    return table


def keep(table: Turntable) -> None:
    """Keep ``table`` for this thread's next job (:func:`turntable_for`)."""
    _kept.table = (table.scene_key, table)


def render_uniform_frames(
    folder: Path,
    table: Turntable,
    guides: denoise.GuideRenderer | None,
    todo: list[Frame],
    s: Settings,
) -> Iterator[dict[str, Any]]:
    """Render ``todo`` in whole-frame passes; their manifest entries, files complete."""
    from .passes import render_frame

    def frames() -> Iterator[Callable[[], dict[str, Any]]]:
        for frame in todo:
            r = render_frame(table, frame, **s.sampling())
            # at the pose just rendered, before the next frame turns the scene
            aov = guides.render(seed=frame.index, spp=r.spp) if guides is not None else None
            yield partial(_write, folder, r, aov, s)

    yield from one_behind(frames())


def one_behind(tasks: Iterator[Callable[[], Any]]) -> Iterator[Any]:
    """Each of ``tasks`` run on a second thread while the next one is made (the next
    frame rendered); their results in order, each once its task is complete."""
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="proof-write") as writer:
        pending: Future | None = None
        for task in tasks:
            job = writer.submit(task)
            if pending is not None:
                yield pending.result()
            pending = job
        if pending is not None:
            yield pending.result()


def _write(folder: Path, r: Any, aov: denoise.Guides | None, s: Settings) -> dict[str, Any]:
    stem = folder / f"frame_{r.frame.index:03d}"
    exr = contact.write_exr(r.image, stem.with_suffix(".exr"))
    png = contact.write_png(tonemap.view(r.image, s.exposure), stem.with_suffix(".png"))
    images = {"raw": exr, "png": png}
    timings = None
    if aov is not None:  # the raw frame stays beside
        written, timings = denoise.write_guided(aov, r.image, stem, s.exposure)
        images |= written
    entry = frame_entry(r, images, s)
    if timings is not None:
        entry["denoise"] = timings
    return entry


def frame_entry(r: Any, images: dict[str, Path], settings: Settings) -> dict[str, Any]:
    """A frame's manifest entry (its fields, per frame).

    ``images``: the role of each written file (``raw`` EXR, view-transformed ``png``) →
    its name in the proof's folder; ``files``: the same roles with size and SHA-256,
    which a resumed run checks. ``noise`` is the estimated relative RMS noise reached
    (:mod:`.passes`), ``noise_target`` the target (None for a fixed ``spp``), ``stop``
    why sampling ended, ``time_s`` the frame's rendering seconds.
    """
    return {
        "index": r.frame.index,
        "kind": r.frame.kind,
        "angle": r.frame.angle,
        "images": {role: path.name for role, path in images.items()},
        "files": {role: contact.file_entry(path) for role, path in images.items()},
        "spp": r.spp,
        "passes": r.passes,
        "noise": r.noise,
        "noise_rmse": r.noise_rmse,
        "noise_target": settings.noise,
        "stop": r.stop,
        "time_s": round(r.seconds, 4),
        "firefly_share": r.firefly_share,
        "clamp": settings.clamp,
    }
