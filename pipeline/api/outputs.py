"""The API's outputs: USD, Mitsuba scenes, proofs, plots, the stability sweep (see
:mod:`lookdev.pipeline.api`)."""

from __future__ import annotations

import dataclasses
import os
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import Executor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lookdev.materials.errors import LookdevError, argument, check_range

from .materials import PathLike, _materials, hub, library_for

__all__ = [
    "REPRESENTATIVE",
    "USD_CONTEXTS",
    "MitsubaExport",
    "Plot",
    "Stability",
    "UsdExport",
    "check",
    "export_mitsuba",
    "export_usd",
    "plot",
    "proof",
    "representative_presets",
]


# -- USD -----------------------------------------------------------------------------------------
USD_CONTEXTS = ("universal", "mtlx", "ri")
"""The render contexts :func:`export_usd` writes: UsdPreviewSurface, MaterialX, RenderMan."""


@dataclass
class UsdExport:
    """What :func:`export_usd` wrote.

    ``losses[material][context]`` is the sentence the surface of that render context
    carries in its ``customData`` (``lookdev:loss``): the live parameters it cannot
    express; ``""`` when it expresses everything.
    """

    output: Path
    files: list[Path]
    materials: list[str]
    contexts: tuple[str, ...]
    textures: list[Path]
    losses: dict[str, dict[str, str]] = field(default_factory=dict)
    fidelity: dict[str, Any] = field(default_factory=dict)
    """material → its universal context measured against it (``report=True``):
    :class:`lookdev.pipeline.export.usd.fidelity.Fidelity`."""
    contexts_fidelity: dict[str, Any] = field(default_factory=dict)
    """material → every context measured against it, one ``Fidelity`` each (``report``)."""

    def to_json(self) -> dict[str, Any]:
        """The summary ``lookdev export usd --json`` prints (with ``report``: ``fidelity``,
        the universal context per material, and ``context_fidelity``, a row per material
        × context)."""
        extra = {"fidelity": [f.to_json() for f in self.fidelity.values()]} if self.fidelity else {}
        if self.contexts_fidelity:
            extra["context_fidelity"] = [
                f.to_json() for rows in self.contexts_fidelity.values() for f in rows
            ]
        return extra | {
            "output": str(self.output),
            "files": [str(p) for p in self.files],
            "materials": self.materials,
            "contexts": list(self.contexts),
            "textures": [str(p) for p in self.textures],
            "losses": {m: {c: n for c, n in by.items() if n} for m, by in self.losses.items()},
        }

    def loss_rows(self) -> list[tuple[str, str, str]]:
        """(material, context, what it cannot express) for every context with a loss."""
        return [(m, c, n) for m, by in self.losses.items() for c, n in by.items() if n]


def export_usd(
    materials: Any,
    path: PathLike,
    contexts: Sequence[str] = USD_CONTEXTS,
    *,
    mtlx: PathLike | None = None,
    bake: bool = False,
    map_resolution: int = 1024,
    package: bool = False,
    split: PathLike | None = None,
    all_presets: bool = False,
    library: Any = None,
    progress: Callable[[int, int, str], None] | None = None,
    preview_opacity: str = "keep",
    meters_per_unit: float = 1.0,
    report: bool = False,
    collect: bool = False,
    preview_geometry: bool = False,
    mtlx_surface: str = "openpbr",
) -> UsdExport:
    """Write materials as UsdShade materials under ``/Materials`` of ``path``.

    Parameters
    ----------
    materials
        One or several preset names, paths or :class:`~lookdev.library.Material` s;
        several make a library whose ``/Materials/Look`` prim switches between them.
    path
        ``.usda``, ``.usdc``, ``.usd``, or ``.usdz`` (packaged with its textures).
    contexts
        Render contexts to write: ``universal`` (UsdPreviewSurface), ``mtlx``
        (MaterialX), ``ri`` (RenderMan).
    mtlx
        Also write the MaterialX networks to this standalone ``.mtlx``.
    bake
        Layered materials: bake blended parameter maps for every context (by default
        the MaterialX context mixes the layers live).
    map_resolution
        Texels a side of baked maps.
    package
        Write a ``.usdz`` holding the stage and its textures.
    split
        One file per material in this folder; ``path`` becomes a library referencing them.
    all_presets
        Also export every other preset of the library.
    library
        See :func:`load`.
    progress
        Called as ``progress(done, total, name)`` as each material is prepared.
    preview_opacity
        ``"keep"`` (default): the universal context keeps ``opacity`` at 1 for
        transmissive materials (DCCs read ``opacity`` as alpha) and names the loss;
        ``"transmission"``: the UsdPreviewSurface spec's reading, ``opacity = 1 −
        spec_trans`` (``1 − clear`` for Pixar).
    meters_per_unit
        The stage's ``metersPerUnit`` (0.01 for a centimetre scene). lookdev's lengths
        (``scatter_distance``) are metres; the subsurface radius is written in these units.
    report
        Measure each material's UsdPreviewSurface against the material (directional
        albedo over view angles and the highlight, see
        :mod:`lookdev.pipeline.export.usd.fidelity`): ``UsdExport.fidelity``.
    collect
        Copy every texture file a preset reads into ``<name>_textures`` beside ``path``
        (UDIM tiles included), referenced by relative paths; otherwise the files are
        referenced where they are, relative to ``path`` where possible.
    preview_geometry
        Add a sphere per material, bound to it, in a grid under ``/Materials/Geometry``.
    mtlx_surface
        The ``mtlx`` surface of Disney materials: ``"openpbr"`` (default, OpenPBR
        Surface through :mod:`lookdev.pipeline.export.usd.openpbr_map`) or ``"disney"``
        (``ND_disney_principled``).

    Returns
    -------
    UsdExport
        The files written, and per material and context what was lost.

    Raises
    ------
    LookdevError
        Nothing named, an unknown preset, an unwritable path …; nothing is left behind.
    """
    from lookdev.pipeline.export.usd import export_materials
    from lookdev.pipeline.export.usd.network import CONTEXTS, ExportError

    contexts = (contexts,) if isinstance(contexts, str) else tuple(contexts) or USD_CONTEXTS
    for context in contexts:
        if context not in CONTEXTS:
            raise ExportError(
                f"unknown render context {context!r}; allowed: {', '.join(CONTEXTS)}",
                field=argument("contexts"),
            )
    if isinstance(materials, str | os.PathLike) or hasattr(materials, "model"):
        materials = [materials]
    given = list(materials or [])
    lib = library_for(library)
    if all_presets:
        names = {m for m in given if isinstance(m, str)}
        given += [n for n in lib.names() if n not in names]
    if not given:
        raise ExportError("name at least one preset, or give --all", field="PRESETS")
    loaded = _materials(given, lib)
    result = export_materials(
        (hub(m, map_resolution) for m in loaded),
        path,
        count=len(loaded),
        contexts=contexts,
        mtlx=mtlx,
        bake=bake,
        package=package,
        split=split,
        progress=progress,
        preview_opacity=preview_opacity,
        meters_per_unit=meters_per_unit,
        report=report,
        collect=collect,
        preview_geometry=preview_geometry,
        mtlx_surface=mtlx_surface,
    )
    return UsdExport(
        result.files[0],
        result.files,
        result.materials,
        contexts,
        result.images,
        result.losses,
        result.fidelity,
        result.contexts_fidelity,
    )


# -- Mitsuba -------------------------------------------------------------------------------------
@dataclass
class MitsubaExport:
    """What :func:`export_mitsuba` wrote: the scene and what it holds."""

    scene: Path
    preset: str
    bsdf: str
    plugins: bool
    """True when the scene uses lookdev's BSDF plugins (register them before loading)."""
    max_depth: int
    textures: list[str]

    def to_json(self) -> dict[str, Any]:
        """The summary ``lookdev export mitsuba --json`` prints."""
        return {
            "preset": self.preset,
            "scene": str(self.scene),
            "bsdf": self.bsdf,
            "plugins": self.plugins,
            "max_depth": self.max_depth,
            "textures": self.textures,
        }


class IBLNotFoundError(LookdevError):
    """The environment light named for an export does not exist."""


def _environment_file(name_or_path: PathLike | None) -> Path | None:
    """An IBL name (built-in, via the proof package) or an image file; None = white sky."""
    if name_or_path is None:
        return None
    path = Path(name_or_path).expanduser()
    if path.suffix.lower() in (".exr", ".hdr") or path.exists():
        if not path.is_file():
            raise IBLNotFoundError("no such environment image", where=str(path))
        return path.resolve()
    from lookdev.pipeline.proof import ibl as ibls

    return Path(ibls.resolve(str(name_or_path)))


def _in_working_space(env: Path | None, scene: Path) -> Path | None:
    """The environment file as the scene renders it: itself when it is in the working
    space, else a converted copy beside the scene (``<stem>_env.exr``, written through
    OCIO like the proofs' IBLs, :func:`lookdev.pipeline.proof.ibl.load`), so an ACEScg
    scene is lit by ACEScg light."""
    if env is None:
        return None
    import numpy as np

    from lookdev.materials import colour
    from lookdev.pipeline.proof import contact
    from lookdev.pipeline.proof import ibl as ibls

    space = ibls.file_space(env)
    if space == colour.working_space():
        return env
    try:
        pixels = colour.to_working(ibls.read_image(env), space)
        out = scene.with_name(f"{scene.stem}_env.exr")
        return contact.write_exr(np.clip(pixels, 0.0, None), out).resolve()
    except LookdevError as exc:
        raise IBLNotFoundError(exc.message, where=str(env)) from None


FILM_MAX_SIDE = 16384
"""Largest film width or height of an exported Mitsuba scene, in pixels."""


def export_mitsuba(
    material: Any,
    path: PathLike,
    *,
    ibl: PathLike | None = None,
    ibl_rotation: float = 0.0,
    resolution: tuple[int, int] = (512, 512),
    spp: int = 128,
    map_resolution: int = 512,
    force_all_lobes: bool = False,
    library: Any = None,
) -> MitsubaExport:
    """Write a material as a Mitsuba 3 scene XML: the material on a sphere under a light.

    Parameters
    ----------
    material
        A preset name or path, a :class:`~lookdev.library.Material` or a blend.
    path
        The scene XML; maps of layered materials go to ``<stem>_textures/`` beside it.
    ibl
        A built-in IBL name (``studio``, ``sky``, ``overcast``, ``sunset``) or an
        ``.exr``/``.hdr`` file; None: a constant white sky (the white furnace).
    ibl_rotation
        Degrees the IBL turns about +y, with the proofs' orientation convention
        (:data:`lookdev.pipeline.proof.ibl.ORIENTATION`, stated in the XML): the scene
        lit as a proof's lighting frame at that angle.
    resolution, spp
        Film size in pixels and samples per pixel.
    map_resolution
        Texels a side at which a layered material is blended.
    force_all_lobes
        Trace every lobe, zero weights included (the baseline for measuring pruning).
    library
        See :func:`load`.

    Returns
    -------
    MitsubaExport
        If ``plugins`` is true, load the scene after
        ``lookdev.pipeline.export.mitsuba.register_plugins()``.
    """
    from lookdev.pipeline.export.mitsuba import MitsubaExportError, export_scene
    from lookdev.pipeline.export.mitsuba.scene import files_of, uses_our_plugins

    if len(tuple(resolution)) != 2:
        raise MitsubaExportError(f"{tuple(resolution)} is not W H", field=argument("resolution"))
    for side in resolution:
        check_range(side, 1, FILM_MAX_SIDE, field=argument("resolution"), error=MitsubaExportError)
    check_range(spp, 1, 2**20, field=argument("spp"), error=MitsubaExportError)
    check_range(
        ibl_rotation, -360.0, 360.0, field=argument("ibl_rotation"), error=MitsubaExportError
    )
    material = hub(material, map_resolution, library)
    env = _in_working_space(_environment_file(ibl), Path(path))
    scene = export_scene(
        material,
        path,
        resolution=tuple(resolution),
        spp=spp,
        environment=env,
        ibl_rotation=ibl_rotation,
        force_all_lobes=force_all_lobes,
    )
    bsdf = scene["ball"]["bsdf"]
    return MitsubaExport(
        Path(path),
        material.name,
        bsdf["bsdf"]["type"] if bsdf["type"] == "normalmap" else bsdf["type"],
        uses_our_plugins(scene),
        scene["integrator"]["max_depth"],
        [f for f in files_of(scene) if f != str(env)],
    )


# -- proofs --------------------------------------------------------------------------------------
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


# -- plots ---------------------------------------------------------------------------------------
PLOT_FORMATS = (".png", ".pdf", ".svg")
PLOT_VIEWS = ("slice", "albedo", "polar", "sphere")


@dataclass
class Plot:
    """What :func:`plot` wrote: the image, the view and the materials' labels."""

    output: Path
    view: str
    materials: list[str]

    def to_json(self) -> dict[str, Any]:
        return {"output": str(self.output), "view": self.view, "materials": self.materials}


def plot(
    materials: Any,
    path: PathLike,
    *,
    view: str = "slice",
    exposure: float = 0.0,
    ibl: str | None = None,
    resolution: int = 128,
    library: Any = None,
    vary: tuple[str, Sequence[float]] | None = None,
    uv: tuple[float, float] | None = None,
    overlay: bool = False,
) -> Plot:
    """Draw materials side by side as one BRDF-explorer view (Burley §3.2) to an image.

    ``uv``: draw a texture-driven material as it is at that UV (its parameters at the
    texel there, as :func:`lookdev.evaluate` takes them); by default the centre texel.

    ``view``: ``slice`` (f(θh, θd) at φd = 90°), ``albedo`` (directional albedo per
    channel), ``polar`` (f in the plane of incidence) or ``sphere`` (a lit sphere, also
    under ``ibl`` when given). ``path`` ends in ``.png``, ``.pdf`` or ``.svg``.
    ``vary`` = (parameter, values) draws each material once per value
    (``("specular_gamma", [1, 1.5, 2, 3])``). ``overlay``: the albedo and polar views draw
    every material on one axes (a measurement over its fit).
    """
    from lookdev.pipeline.analysis import plots

    output = Path(path)
    if output.suffix.lower() not in PLOT_FORMATS:
        raise plots.PlotError(
            f"cannot write {output.suffix or 'no extension'}; allowed {', '.join(PLOT_FORMATS)}",
            where=str(output),
        )
    if view not in PLOT_VIEWS:
        raise plots.PlotError(f"unknown view {view!r}; allowed {', '.join(PLOT_VIEWS)}")
    from lookdev.pipeline.proof.tonemap import EXPOSURE_MAX

    limit = EXPOSURE_MAX
    check_range(exposure, -limit, limit, field=argument("exposure"), error=plots.PlotError)
    check_range(resolution, 8, 1024, field=argument("resolution"), error=plots.PlotError)
    lib = library_for(library)
    if isinstance(materials, str | os.PathLike):
        materials = [materials]
    hubs = [hub(m, plots.MAP_RESOLUTION, lib) for m in _materials(materials, lib)]
    if uv is not None:
        hubs = [plots.at_uv(h, uv) for h in hubs]
    if vary is not None:  # after --uv, which makes a textured material uniform
        hubs = plots.varied(hubs, vary[0], [float(v) for v in vary[1]])
    environment = None
    if ibl is not None:
        if view != "sphere":
            raise plots.PlotError(
                f"{argument('ibl')} only applies to {argument('view')} sphere",
                field=argument("ibl"),
            )
        environment = plots.load_environment(ibl)
    fig = plots.figure(
        hubs,
        view,
        exposure=exposure,
        environment=environment,
        ibl_name=ibl or "",
        resolution=resolution,
        overlay=overlay,
    )
    plots.save_figure(fig, output)
    return Plot(output, view, [h.name for h in hubs])


# -- stability -------------------------------------------------------------------------------------
@dataclass
class Stability:
    """The stability sweep's findings: a report per model of the registry."""

    reports: dict[str, Any]
    """``{model: lookdev.pipeline.analysis.stability.ModelReport}``."""
    seconds: float

    @property
    def failed(self) -> bool:
        """True when any model produced a NaN, an infinity, a negative value, an
        exception or an energy gain beyond its allowance."""
        return any(r.failed for r in self.reports.values())

    def to_json(self) -> dict[str, Any]:
        """The object ``lookdev check --json`` prints."""
        return {
            "models": {name: r.to_json() for name, r in self.reports.items()},
            "seconds": round(self.seconds, 3),
        }


def check(
    models: Iterable[str] | None = None,
    *,
    progress: Callable[[int, int, str, str], None] | None = None,
) -> Stability:
    """Sweep every reflectance model (or those named) over its stiff and extreme cases.

    Parameters at both ends of their ranges and the named stiff combinations, directions at
    and beyond grazing, ``wi = −wo``, uniforms at 0, ½ and 1 − 2⁻²⁴, in float32 and
    float64; white-furnace albedos against each model's energy allowance.
    ``progress(done, total, model, case)`` is called after each parameter set.

    >>> import lookdev
    >>> try:
    ...     lookdev.check(["no_such_model"])
    ... except lookdev.LookdevError as exc:
    ...     print(type(exc).__name__)
    CheckError
    """
    import time

    from lookdev.library.measured import builtin_measured, read_measured
    from lookdev.pipeline.analysis import stability

    names = list(models) if models else None
    measured = [read_measured(p) for p in builtin_measured()]  # the shipped measurements
    total = stability.case_count(names, measured) if progress is not None else 0
    done = 0

    def advance(name: str, label: str) -> None:
        nonlocal done
        done += 1
        if progress is not None:
            progress(done, total, name, label)

    started = time.perf_counter()
    reports = stability.run(names, advance, measured)
    return Stability(reports, time.perf_counter() - started)
