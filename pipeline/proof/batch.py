"""Batch proofs: materials × IBLs, one turntable each, on any ``concurrent.futures.Executor``.

Layout of an output folder::

    OUT/manifest.json                    the batch: one entry per material × IBL
    OUT/overview.png                     the first frame of each, materials × IBLs
    OUT/<material>/<ibl>/frame_NNN.exr   scene-linear frames
    OUT/<material>/<ibl>/frame_NNN.png   the same through the proof view transform
    OUT/<material>/<ibl>/contact.png     all frames of the turntable, labelled
    OUT/<material>/<ibl>/frame_NNN_denoised.exr/.png, contact_denoised.png
                                         with ``--denoise``: the frames denoised by
                                         OIDN (:mod:`.denoise`), the raw ones kept
    OUT/<material>/<ibl>/manifest.json   every frame: images and files (size, SHA-256),
                                         spp, noise reached and target, why sampling
                                         stopped, render time, firefly share; the
                                         settings' key and the pixel filter

A job (one material under one IBL) loads its scene once and renders only the frames its
manifest does not vouch for: a frame counts as done when its manifest entry exists, the
settings key matches, and both files have the recorded size and hash. Files are written
under temporary names and renamed, and a frame enters the manifest only after both of its
files are complete, so an interruption never leaves a frame that looks finished.

A local process pool runs jobs by default; ``Client(address).get_executor()`` runs them on
a Dask cluster (the output folder must then be shared by the workers).
"""

from __future__ import annotations

import hashlib
import itertools
import json
import os
import time
import traceback
from collections import Counter
from collections.abc import Callable, Iterator
from concurrent.futures import (
    FIRST_COMPLETED,
    Executor,
    Future,
    ProcessPoolExecutor,
    ThreadPoolExecutor,
    wait,
)
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from lookdev.library import files
from lookdev.materials import colour
from lookdev.materials.errors import LookdevError

from . import contact, denoise, ibl, rig
from .contact import file_entry
from .settings import MAX_SAMPLES, MAX_SIDE, MIN_SIDE, ProofError, Settings
from .turntable import Frame

__all__ = [
    "FORMAT_VERSION",
    "MANIFEST",
    "MAP_RESOLUTION",
    "MAX_SAMPLES",
    "MAX_SIDE",
    "MIN_SIDE",
    "Job",
    "Progress",
    "ProofError",
    "Settings",
    "check_writable",
    "executor_for",
    "file_entry",
    "frames_done",
    "make_jobs",
    "proof",
    "read_manifest",
    "run_batch",
    "run_job",
    "summary",
]

MANIFEST = "manifest.json"
TICK_S = 0.5
FORMAT_VERSION = 2  # 2: per-frame sampling fields, ``images`` and ``files``
MAP_RESOLUTION = 512
"""Texels a side of a layered material's maps in a proof (the blend the proof renders)."""


@dataclass
class Job:
    """One material under one IBL; everything a worker needs, picklable."""

    material: Any  # the blended material (lookdev.pipeline.blend.BlendedMaterial)
    ibl: str
    environment: np.ndarray
    folder: Path
    settings: Settings
    key: str = field(init=False)

    def __post_init__(self) -> None:
        h = hashlib.sha256()
        h.update(json.dumps([FORMAT_VERSION, self.settings.as_json()], sort_keys=True).encode())
        h.update(self.material.digest().encode())
        h.update(np.ascontiguousarray(self.environment).tobytes())
        self.key = h.hexdigest()[:16]


# -- manifests -----------------------------------------------------------------------------
def _still_valid(folder: Path, entry: dict[str, Any]) -> bool:
    path = folder / entry["file"]
    try:
        return path.stat().st_size == entry["size"] and file_entry(path) == entry
    except (OSError, KeyError, TypeError):
        return False


def read_manifest(folder: Path, key: str) -> dict[int, dict[str, Any]]:
    """Frames of ``folder``'s manifest still valid under settings ``key``, by index."""
    try:
        doc = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    if not isinstance(doc, dict) or doc.get("key") != key:
        return {}
    done = {}
    for entry in doc.get("frames", []):
        listed = entry.get("files") if isinstance(entry, dict) else None
        if (
            isinstance(listed, dict)
            and listed
            and all(isinstance(f, dict) and _still_valid(folder, f) for f in listed.values())
        ):
            done[int(entry["index"])] = entry
    return done


def frames_done(job: Job) -> int:
    """Frames a running job has finished so far, from its manifest on disk.

    Workers write the manifest after every frame, so this works for local processes and
    for a cluster sharing the output folder alike, without any channel between them.
    """
    try:
        doc = json.loads((job.folder / MANIFEST).read_text(encoding="utf-8"))
        return len(doc["frames"]) if doc.get("key") == job.key else 0
    except (OSError, ValueError, KeyError, TypeError, AttributeError):
        return 0


def write_json(doc: dict[str, Any], path: Path) -> None:
    """Write ``doc`` as JSON atomically (:mod:`lookdev.library.files`, the one write path)."""
    files.atomic_write(path, json.dumps(doc, indent=2) + "\n")


# -- one job (runs in a worker) ------------------------------------------------------------
def run_job(job: Job) -> dict[str, Any]:
    """Render the frames of ``job`` that are not done yet; its manifest, as written."""
    from lookdev.pipeline.variant import use_mitsuba

    variant = use_mitsuba()
    with colour.use(**asdict(job.settings.colour)):
        return _run_job(job, variant)


def _run_job(job: Job, variant: str) -> dict[str, Any]:
    folder = files.make_folder(job.folder)
    done = read_manifest(folder, job.key)
    todo = [f for f in job.settings.frames() if f.index not in done]
    doc = {
        "material": job.material.name,
        "model": job.material.preset_model,
        "ibl": job.ibl,
        "key": job.key,
        "variant": variant,
        "settings": job.settings.as_json(),
        "rig": rig.manifest_entry(job.settings.rig),
        "ibl_orientation": ibl.ORIENTATION,
        "filter": job.settings.pixel_filter,
        "clamp": job.settings.clamp,
        "frames": [done[i] for i in sorted(done)],
    }
    rendered = 0
    if todo:
        for entry in _render(job, todo):
            doc["frames"] = sorted([*doc["frames"], entry], key=lambda e: e["index"])
            write_json(doc, folder / MANIFEST)
            rendered += 1
    _remove_strays(folder, doc)
    sheets = {"contact_sheet": ("png", "contact.png")}
    if job.settings.denoise:
        sheets["contact_sheet_denoised"] = ("denoised_png", "contact_denoised.png")
    # side by side: OpenImageIO's text and PNG writer release the GIL
    with ThreadPoolExecutor(len(sheets), thread_name_prefix="proof-sheet") as pool:
        made = {k: pool.submit(_sheet, job, doc, *args) for k, args in sheets.items()}
        doc |= {k: file_entry(sheet.result()) for k, sheet in made.items()}
    write_json(doc, folder / MANIFEST)
    return doc | {"rendered": rendered, "skipped": len(done)}


def _render(job: Job, todo: list[Frame]) -> Iterator[dict[str, Any]]:
    """Load the scene once (or relight the worker's last one, :func:`.uniform.turntable_for`),
    then render and write each frame; yields manifest entries."""
    from .uniform import keep, render_uniform_frames, turntable_for

    s = job.settings
    table = turntable_for(job.material, job.environment, s)
    guides = denoise.guide_renderer(table) if s.denoise else None
    if s.per_pixel():
        from .pixelframe import render_pixel_frames

        yield from render_pixel_frames(job.folder, table, guides, todo, s)
    else:
        yield from render_uniform_frames(job.folder, table, guides, todo, s)
    keep(table)


def _remove_strays(folder: Path, doc: dict[str, Any]) -> None:
    """Delete frame files the manifest does not list (left by a run with more frames)."""
    keep = {f["file"] for frame in doc["frames"] for f in frame["files"].values()}
    for path in folder.glob("frame_*"):
        if path.name not in keep:
            path.unlink(missing_ok=True)


def _sheet(job: Job, doc: dict[str, Any], role: str = "png", name: str = "contact.png") -> Path:

    images, labels = [], []
    for entry in doc["frames"]:
        images.append(contact.read_rgb(job.folder / entry["images"][role]))
        labels.append(f"{entry['kind']} {entry['angle']:.0f}°  {entry['spp']} spp")
    title = f"{job.material.name} × {job.ibl}  ({_sampling_label(job.settings)})"
    columns = max(job.settings.element_frames, job.settings.light_frames)
    if role != "png":
        title += "  denoised"
    sheet = contact.contact_sheet(images, labels, title, columns)
    return contact.write_png(sheet, job.folder / name)


def _sampling_label(s: Settings) -> str:
    if s.spp is not None:
        return f"{s.spp} spp"
    # words, not "≤": the sheets' font (DroidSans) has no glyph for it and drew a gap
    budget = f", up to {s.time_budget:g} s" if s.time_budget is not None else ""
    clamp = f", clamped at {s.clamp:g}" if s.clamp is not None else ""
    return f"target noise {s.noise:g}, up to {s.max_spp} spp{budget}{clamp}"


# -- a batch (runs in the parent) ----------------------------------------------------------
def check_writable(out: Path) -> None:
    """Fail early, in one line, when ``out`` cannot hold the proofs."""
    files.make_folder(out)
    try:
        probe = out / f".lookdev-write-test-{os.getpid()}"
        probe.write_bytes(b"")
        probe.unlink()
    except OSError as exc:
        raise ProofError(
            f"output folder is not writable ({exc.strerror or exc})", where=str(out)
        ) from None


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name) or "unnamed"


def make_jobs(
    materials: list[Any], environments: list[Any], out: Path, settings: Settings
) -> list[Job]:
    """Every material under every environment (``ibl.Environment``), in that order."""
    for kind, names in (
        ("material", [m.name for m in materials]),
        ("IBL", [e.name for e in environments]),
    ):
        slugs = [_slug(n) for n in names]
        clash = next((n for n, sl in zip(names, slugs, strict=True) if slugs.count(sl) > 1), None)
        if clash is not None:
            raise ProofError(
                f"two {kind}s would share the folder {_slug(clash)!r}; rename one", where=clash
            )
    return [
        Job(m, env.name, env.pixels, out / _slug(m.name) / _slug(env.name), settings)
        for m in materials
        for env in environments
    ]


@contextmanager
def executor_for(scheduler: str | None, workers: int | None) -> Iterator[Executor]:
    """A Dask cluster's executor for ``scheduler``, else a local process pool.

    Local workers are spawned, not forked: a forked Dr.Jit/LLVM runtime is not safe.
    """
    if scheduler:
        try:
            from distributed import Client

            client = Client(scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError) as exc:
            raise ProofError(f"cannot reach the scheduler ({exc})", where=scheduler) from None
        try:
            yield client.get_executor()
        finally:
            client.close()
        return
    from .spawn import CONTEXT  # spawned, and without re-running the caller's script

    with ProcessPoolExecutor(max_workers=workers or default_workers(), mp_context=CONTEXT) as pool:
        yield pool


def default_workers() -> int:
    """One: Dr.Jit already renders every frame on all cores, and a second process only
    competes for them (measured on 2 cores, 4 proofs of 16 frames: one worker 17.2 s,
    two workers 28.0 s). The pool still isolates renders from the command's process.
    """
    return 1


def run_batch(
    jobs: list[Job],
    executor: Executor,
    on_done: Callable[[Job, dict[str, Any]], None] | None = None,
    in_flight: int | None = None,
    on_tick: Callable[[list[Job]], None] | None = None,
) -> list[dict[str, Any]]:
    """Run ``jobs`` on ``executor``; their manifests in job order.

    At most ``in_flight`` jobs are submitted at a time (all of them when None, as a
    cluster's scheduler wants), so an interrupted local batch has nothing queued behind
    the jobs that were running. ``on_tick(running_jobs)`` is called about twice a second
    (for frame-level progress: see :func:`frames_done`). The first failing job cancels
    those not started and its error is raised (a :class:`LookdevError` keeps its one line).
    """
    queue = iter(enumerate(jobs))
    futures: dict[Future, int] = {}
    results: list[dict[str, Any] | None] = [None] * len(jobs)

    def submit_next() -> None:
        for i, job in itertools.islice(queue, 1):
            futures[executor.submit(run_job, job)] = i

    for _ in range(in_flight or len(jobs)):
        submit_next()
    try:
        while futures:
            finished, _ = wait(futures, timeout=TICK_S, return_when=FIRST_COMPLETED)
            if on_tick is not None:
                on_tick([jobs[i] for i in futures.values()])
            for fut in finished:
                i = futures.pop(fut)
                results[i] = _result(fut, jobs[i])
                if on_done is not None:
                    on_done(jobs[i], results[i])
                submit_next()
    except BaseException:
        for fut in futures:
            fut.cancel()
        raise
    return [r for r in results if r is not None]


def _result(fut: Future, job: Job) -> dict[str, Any]:
    """A job's manifest; a crash becomes one line, its traceback goes to ``error.log``."""
    try:
        return fut.result()
    except LookdevError:
        raise
    except Exception as exc:  # noqa: BLE001 - any worker crash is reported the same way
        log = job.folder / "error.log"
        first = str(exc).splitlines()[0] if str(exc) else ""
        try:
            job.folder.mkdir(parents=True, exist_ok=True)
            files.atomic_write(log, "".join(traceback.format_exception(exc)))
            where_log = f"traceback in {log}"
        except (OSError, files.WriteError) as log_exc:  # a full disk: no half-written log
            where_log = f"its traceback could not be saved ({getattr(log_exc, 'message', log_exc)})"
        raise ProofError(
            f"rendering failed ({type(exc).__name__}: {first}); {where_log}",
            where=f"{job.material.name} × {job.ibl}",
        ) from None


@dataclass(frozen=True)
class Progress:
    """Where a batch is, for a progress bar: reported about twice a second and as each
    proof finishes (``finished``: that proof's manifest, with ``rendered`` and
    ``skipped`` frame counts)."""

    frames_done: int
    frames_total: int
    finished: dict[str, Any] | None = None


def proof(
    materials: list[Any],
    environments: list[Any],
    out: Path,
    settings: Settings,
    *,
    scheduler: str | None = None,
    workers: int | None = None,
    executor: Executor | None = None,
    progress: Callable[[Progress], None] | None = None,
) -> dict[str, Any]:
    """Proof every material under every environment into ``out``; the batch manifest.

    Runs on ``executor`` when given, else on the Dask cluster at ``scheduler``, else on a
    local pool of ``workers`` processes (:func:`executor_for`). Frames the manifests in
    ``out`` vouch for are kept, so a second call resumes an interrupted batch.
    """
    check_writable(out)
    jobs = make_jobs(materials, environments, out, settings)
    start = time.perf_counter()
    per_job = settings.element_frames + settings.light_frames
    total = len(jobs) * per_job
    finished = 0
    shown = -1

    def report(frames: int, doc: dict[str, Any] | None = None) -> None:
        nonlocal shown
        frames = max(shown, frames)  # a finished job's count replaces its partial one
        if progress is not None and (doc is not None or frames != shown):
            progress(Progress(frames, total, doc))
        shown = frames

    def done(job: Job, doc: dict[str, Any]) -> None:
        nonlocal finished
        finished += 1
        report(finished * per_job, doc)

    def tick(running: list[Job]) -> None:
        report(finished * per_job + sum(frames_done(job) for job in running))

    own = executor is None
    with executor_for(scheduler, workers) if own else _given(executor) as pool:
        in_flight = (workers or default_workers()) if own and not scheduler else None
        results = run_batch(jobs, pool, done, in_flight, tick)
        report(total)
    return summary(out, jobs, results, time.perf_counter() - start)


@contextmanager
def _given(executor: Executor) -> Iterator[Executor]:
    yield executor  # the caller's: not shut down here


def summary(out: Path, jobs: list[Job], results: list[dict[str, Any]], seconds: float) -> dict:
    """The batch manifest: one entry per job, with totals; written to ``OUT/manifest.json``.

    A folder that already holds a batch keeps it: the entries of its ``manifest.json``
    whose proofs are still on disk (their own manifest lists frames) and that this run
    did not redo stay listed, in their place, and stay in ``overview.png``; this run's
    proofs replace their namesakes and follow. So a re-proof of a subset adds to the
    batch instead of forgetting the rest.
    """
    entries = []
    for job, doc in zip(jobs, results, strict=True):
        frames = doc["frames"]
        noise = [f["noise"] for f in frames if f["noise"] is not None]
        entries.append(
            {
                "material": doc["material"],
                "ibl": doc["ibl"],
                "folder": str(job.folder.relative_to(out)),
                "frames": len(frames),
                "rendered": doc["rendered"],
                "skipped": doc["skipped"],
                "filter": doc["filter"],
                "render_seconds": round(sum(f["time_s"] for f in frames), 3),
                "mean_spp": float(np.mean([f["spp"] for f in frames])) if frames else None,
                "mean_noise_relative": float(np.mean(noise)) if noise else None,
                "max_noise_relative": max(noise) if noise else None,
                "stops": dict(Counter(f["stop"] for f in frames)),
                "max_firefly_share": max(
                    (f["firefly_share"] for f in frames if f["firefly_share"] is not None),
                    default=None,
                ),
                "contact_sheet": str(job.folder.relative_to(out) / "contact.png"),
            }
        )
        if "contact_sheet_denoised" in doc:
            sheet = job.folder.relative_to(out) / doc["contact_sheet_denoised"]["file"]
            entries[-1]["contact_sheet_denoised"] = str(sheet)
    entries = merge_entries(out, entries)
    doc = {
        "version": FORMAT_VERSION,
        "wall_seconds": round(seconds, 3),
        "settings": jobs[0].settings.as_json() if jobs else {},
        "ibl_orientation": ibl.ORIENTATION,
        "proofs": entries,
        "overview": overview(out, entries).name if entries else None,
    }
    write_json(doc, out / MANIFEST)
    return doc


def merge_entries(out: Path, entries: list[dict[str, Any]]) -> list[dict[str, Any]]:
    """``entries`` merged into the batch manifest ``out`` already holds (see :func:`summary`)."""
    try:
        old = json.loads((out / MANIFEST).read_text(encoding="utf-8")).get("proofs", [])
    except (OSError, ValueError, AttributeError):
        return entries
    new = {(e["material"], e["ibl"]): e for e in entries}
    merged = []
    for entry in old if isinstance(old, list) else []:
        try:
            key = (entry["material"], entry["ibl"])
            kept = key not in new and bool(_first_png(out, entry))
        except (KeyError, TypeError):
            continue
        if key in new:
            merged.append(new.pop(key))
        elif kept:
            merged.append(entry | {"rendered": 0, "skipped": entry.get("frames", 0)})
    return merged + list(new.values())


def _first_png(out: Path, entry: dict[str, Any]) -> Path | None:
    """The first frame's PNG of a batch entry (denoised where it was), from its own
    manifest; None when gone."""
    folder = out / entry["folder"]
    try:
        doc = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        images = doc["frames"][0]["images"]
        first = folder / images.get("denoised_png", images["png"])
    except (OSError, ValueError, KeyError, IndexError, TypeError, AttributeError):
        return None
    return first if first.is_file() else None


def overview(out: Path, entries: list[dict[str, Any]]) -> Path:
    """``OUT/overview.png``: the first frame of every proof the batch lists, a row per
    material."""

    images, labels = [], []
    for entry in entries:
        first = _first_png(out, entry)
        if first is None:
            continue
        images.append(contact.read_rgb(first))
        labels.append(f"{entry['material']} × {entry['ibl']}")
    columns = len({e["ibl"] for e in entries})
    sheet = contact.contact_sheet(images, labels, f"{len(images)} proofs", columns)
    return contact.write_png(sheet, out / "overview.png")
