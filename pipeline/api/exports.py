"""The API's exports: USD shading networks and Mitsuba scenes (see :mod:`lookdev.pipeline.api`)."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from lookdev.materials.errors import LookdevError, argument, check_range

from .materials import PathLike, _materials, hub, library_for

__all__ = [
    "USD_CONTEXTS",
    "export_mitsuba",
    "export_usd",
    "MitsubaExport",
    "UsdExport",
]


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
