"""The API's turntable proofs under environment lights (see :mod:`lookdev.pipeline.api`)."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Sequence
from concurrent.futures import Executor
from pathlib import Path
from typing import Any

from lookdev.materials.errors import argument

from .materials import PathLike, _materials, hub, library_for

__all__ = [
    "REPRESENTATIVE",
    "proof",
    "representative_presets",
]


REPRESENTATIVE = (
    "gold",
    "plastic_glossy",
    "velvet",
    "glass_clear",
    "rusty_car_paint",
    "pixar_paint_red",
    "skin",
)
"""The default subjects of :func:`proof`: a metal, a glossy plastic, cloth, glass, a
layered material, a Pixar lobe-weight material and a path-traced subsurface one."""


def representative_presets(library: Any) -> list[str]:
    """:data:`REPRESENTATIVE` as far as the library has them; else its first four."""
    names = library.names()
    chosen = [n for n in REPRESENTATIVE if n in names]
    return chosen or names[:4]


def proof(
    materials: Any = None,
    ibls: Sequence[PathLike] | PathLike | None = None,
    out: PathLike = "proofs",
    *,
    frames: int | None = None,
    light_frames: int | None = None,
    spp: int | None = None,
    noise: float | None = None,
    max_spp: int | None = None,
    time_budget: float | None = None,
    clamp: float | None = None,
    pixel_filter: str = "box",
    resolution: tuple[int, int] | None = None,
    exposure: float = 0.0,
    ibl_width: int = 512,
    rig: str = "full",
    jobs: int | None = None,
    scheduler: str | None = None,
    executor: Executor | None = None,
    report: bool = False,
    library: Any = None,
    progress: Callable[[Any], None] | None = None,
    context: str | None = None,
    geometry: PathLike | None = None,
    denoise: bool | None = None,
    adaptive: bool | None = None,
) -> dict[str, Any]:
    """Render turntable proofs (Burley §6.1): every material under every IBL.

    Each proof turns the element through ``frames`` frames, then the lighting through
    ``light_frames``, and writes under ``out/MATERIAL/IBL/``: EXR frames, view-transformed
    PNGs, a labelled ``contact.png`` and a ``manifest.json``; and
    ``out/MATERIAL/material.json`` (resolved parameters, source, USD loss notes) for the
    review page. Calling again with the same arguments renders only the frames the
    manifests do not vouch for (size and SHA-256), so an interrupted batch resumes.

    Parameters
    ----------
    materials
        Preset names, paths or Materials; None: :data:`REPRESENTATIVE`.
    ibls
        Built-in IBL names or ``.exr``/``.hdr`` files; None: every built-in.
    out
        The batch folder (shared with the workers when on a cluster).
    frames, light_frames, resolution, exposure
        Element-rotation frames, lighting-rotation frames (default
        ``DEFAULT_FRAMES`` and ``DEFAULT_LIGHT_FRAMES``), frame size ``(width, height)``
        (default :data:`~lookdev.pipeline.proof.settings.DEFAULT_RESOLUTION`), and stops
        applied by the PNG view transform.
    spp
        A fixed count of samples per pixel for every frame. Without it, each frame is
        rendered in passes to a noise target (:mod:`lookdev.pipeline.proof.passes`).
    noise, max_spp, time_budget
        The target (estimated relative RMS noise of the frame, default
        :data:`~lookdev.pipeline.proof.settings.DEFAULT_NOISE`), the most samples per
        pixel a frame may take to reach it (default ``DEFAULT_MAX_SPP``), and the most
        seconds of rendering a frame may take (default: no limit). Each frame's manifest
        entry says which ended it (``stop``).
    clamp
        Limit each camera sample's radiance to this value: hides fireflies, biases the
        image; for quick previews only. Default None (unclamped); recorded in the manifests.
    pixel_filter
        ``"box"`` (default: keeps pixel noise independent, as a denoiser needs) or
        ``"gaussian"``.
    ibl_width
        Every IBL is resampled to this width (× ½ high) so render kernels are reused.
    rig
        The calibrated rig beside the material (:mod:`lookdev.pipeline.proof.rig`):
        ``full`` (chrome ball, 18 % grey ball, ColorChecker chart), ``balls``, ``none``.
    jobs
        Local worker processes (default 1: each renders on every core). They are spawned
        without re-running the caller's script (:mod:`lookdev.pipeline.proof.spawn`), so a
        plain script needs no ``if __name__ == "__main__":`` guard.
    scheduler
        A Dask scheduler address (``tcp://host:8786``): run the proofs on that cluster.
    executor
        Any ``concurrent.futures.Executor`` to run the proofs on (it is not shut down).
    report
        Also write ``out/index.html``, a static review page: turntable players, a
        synchronised comparison, raw/denoised, each material's parameters and losses.
    library
        See :func:`load`.
    denoise
        Also write every frame denoised by Intel Open Image Denoise (``pyoidn``), guided
        by albedo and normal images rendered with it, beside the raw frame
        (:mod:`lookdev.pipeline.proof.denoise`); a :class:`DenoiseError` when ``pyoidn``
        is not installed. None: ``DEFAULT_DENOISE`` (on); False for raw frames only.
        With per-pixel sampling the denoised frame is checked (its residual estimated,
        :mod:`lookdev.pipeline.proof.checked`) and the target applies to it.
    adaptive
        Sample each frame per pixel to ``noise`` (display RMS; the default with a target
        and the box filter, :mod:`lookdev.pipeline.proof.adaptive`); False for whole-frame
        passes to a relative noise on luminance.
    progress
        Called with a :class:`lookdev.pipeline.proof.batch.Progress` about twice a second
        and as each proof finishes (``frames_done``, ``frames_total``, ``finished``).
    context
        ``"universal"``: also proof, beside each material, its USD universal context as
        ``NAME-universal``: the UsdPreviewSurface values rendered by that surface's own
        BRDF (:func:`lookdev.pipeline.export.usd.fidelity.preview_hub`), what a DCC
        preview shows. ``"mtlx"``: its ``mtlx`` context as ``NAME-mtlx``, the OpenPBR
        Surface values rendered by the OpenPBR model
        (:func:`lookdev.pipeline.export.usd.context_views.mtlx_hub`), what an OpenPBR
        renderer shows.
    geometry
        A mesh (PLY, OBJ, or USD geometry) rendered in the cup's place beside the ball,
        with its own UVs (:mod:`lookdev.pipeline.proof.geometry`).

    Returns
    -------
    dict
        The batch manifest, as written to ``out/manifest.json`` (``proofs``: per material
        × IBL the frames, how many were rendered and skipped, render time, noise), plus
        ``report`` when one was written.
    """
    from lookdev.pipeline.proof import batch
    from lookdev.pipeline.proof import ibl as ibl_module
    from lookdev.pipeline.proof import settings as proof_settings

    if denoise is None:
        denoise = proof_settings.DEFAULT_DENOISE
    if frames is None:
        frames = proof_settings.DEFAULT_FRAMES
    if light_frames is None:
        light_frames = proof_settings.DEFAULT_LIGHT_FRAMES
    settings = proof_settings.check(
        proof_settings.Settings(
            element_frames=frames,
            light_frames=light_frames,
            spp=spp,
            resolution=tuple(resolution or proof_settings.DEFAULT_RESOLUTION),
            exposure=exposure,
            noise=noise,
            max_spp=max_spp,
            time_budget=time_budget,
            clamp=clamp,
            pixel_filter=pixel_filter,
            rig=rig,
            denoise=denoise,
            adaptive=proof_settings.DEFAULT_ADAPTIVE if adaptive is None else adaptive,
        ),
        jobs,
    )
    if denoise:
        from lookdev.pipeline.proof.denoise import oidn

        oidn()  # missing: one line before anything is loaded or rendered
    lib = library_for(library)
    if materials is None or (not isinstance(materials, str | os.PathLike) and not materials):
        materials = representative_presets(lib)
    # The whole batch is checked before the first frame: the output folder, every preset
    # and every texture it names (layers a blend would prune included), every IBL.
    output = Path(out)
    batch.check_writable(output)
    if geometry is not None:
        from lookdev.pipeline.proof.geometry import proof_mesh

        settings = dataclasses.replace(settings, geometry=str(proof_mesh(geometry)))
    chosen = _materials(materials, lib)
    for material in chosen:
        check_textures(material)
    if isinstance(ibls, str | os.PathLike):
        ibls = [ibls]
    ibl_names = list(dict.fromkeys(ibls or ibl_module.builtin_names()))
    environments = [ibl_module.load(name, ibl_width) for name in ibl_names]
    loaded = [hub(m, batch.MAP_RESOLUTION, lib) for m in chosen]
    if context not in (None, "source", "universal", "mtlx"):
        raise batch.ProofError(
            f"unknown context {context!r}; allowed: universal, mtlx", field=argument("context")
        )
    if context == "universal":
        from lookdev.pipeline.export.usd.fidelity import preview_hub

        loaded = [h for m in loaded for h in (m, preview_hub(m))]
    if context == "mtlx":
        from lookdev.pipeline.export.usd.context_views import mtlx_hub

        loaded = [h for m in loaded for h in (m, mtlx_hub(m))]
    doc = batch.proof(
        loaded,
        environments,
        output,
        settings,
        scheduler=scheduler,
        workers=jobs,
        executor=executor,
        progress=progress,
    )
    from lookdev.pipeline.proof.material_info import write_material_info

    write_material_info(output, loaded)
    if report:
        from lookdev.pipeline.analysis.report import write_report

        doc["report"] = str(write_report(output, materials={m.name: m for m in loaded}))
    return doc


def check_textures(material: Any) -> None:
    """Every texture a material names (masks and normal maps of every layer, nested
    layered presets included, pruned or not) exists, decodes and has its channels; else
    the one line of :class:`~lookdev.pipeline.blend.resample.TextureError`."""
    from lookdev.library.images import TextureFile
    from lookdev.materials.layers import textures

    for i, layer in enumerate(getattr(material, "layers", None) or []):
        if not hasattr(layer, "mask"):  # a blend's or a model's own: nothing to read
            return
        where = f"{material.name}: layer {layer.name or layer.material.name or i!r}"
        for tex in textures(layer.mask):
            TextureFile(tex, 1, where=where)
        for tex in (layer.normal_map, layer.specular_normal_map):
            if tex is not None:
                TextureFile(tex, 3, where=where)
        check_textures(layer.material)
