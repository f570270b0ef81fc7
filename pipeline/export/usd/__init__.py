"""USD export (usd-core, UsdShade) and import.

:func:`export_materials` is the whole export of blended materials (what ``lookdev
export usd`` and :func:`lookdev.export_usd` run); the modules beside this one build the
networks (:mod:`.network`, one module per render context) and author them (:mod:`.writer`).
Importing this package does not import ``pxr``: :func:`export_materials` does.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any

from lookdev.library import files

__all__ = ["export_materials", "loss_notes"]


def export_materials(
    materials: Iterable[Any],
    out: str | Path,
    *,
    count: int | None = None,
    contexts: Sequence[str] | None = None,
    mtlx: str | Path | None = None,
    bake: bool = False,
    package: bool = False,
    split: str | Path | None = None,
    progress: Callable[[int, int, str], None] | None = None,
    preview_opacity: str = "keep",
    meters_per_unit: float = 1.0,
    report: bool = False,
    collect: bool = False,
    preview_geometry: bool = False,
    mtlx_surface: str = "openpbr",
):
    """Write blended materials (:class:`~lookdev.pipeline.blend.BlendedMaterial`) as
    UsdShade materials to ``out``.

    ``materials`` may be a generator that blends each on demand (``count`` says how many,
    for ``progress``), so only one material's maps are held at a time. Returns the
    writer's :class:`.writer.ExportResult`: the files written, the material names, the
    textures referenced and the loss notes per material and context.
    ``progress(done, total, name)`` is called after each material's network source is
    made (varying parameters are baked then). Maps are baked into a scratch folder beside
    ``out`` and only copied into place when every file could be written.
    ``preview_opacity``: see :data:`.names.PREVIEW_OPACITY`. ``meters_per_unit``: the
    stage's ``metersPerUnit`` (lengths are written in its units). ``report``: measure each
    material's contexts against the material (:mod:`.fidelity`): the universal one in the
    result's ``fidelity``, every one (both ``mtlx`` surfaces) in ``contexts_fidelity``.
    The universal context is measured either way: its figures are in the loss note a
    DCC shows (:func:`.authoring.dcc_loss_note`).
    ``preview_opacity``: see :data:`.names.PREVIEW_OPACITY`. ``collect`` copies the
    presets' own texture files beside ``out``; ``preview_geometry`` adds a sphere per
    material (:func:`.writer.export_usd`).
    """
    from .network import CONTEXTS
    from .record import preset_record
    from .sources import source_for
    from .writer import export_usd as write

    contexts = tuple(contexts) if contexts else CONTEXTS
    out = Path(out).expanduser()
    package = package or out.suffix == ".usdz"
    # Scratch beside the output (same filesystem); removed on errors, Ctrl-C and SIGTERM,
    # and swept by the next export when a SIGKILL left it (lookdev.library.files).
    with files.scratch_folder(out.parent) as scratch:
        textures = f"{out.stem}_textures"
        texture_dir = Path(scratch, textures) if package else out.parent / textures
        sources = []
        measured: dict = {}
        contexts_measured: dict = {}
        for material in materials:
            source = source_for(material, texture_dir, scratch=Path(scratch), bake=bake)
            source.record = preset_record(material)
            sources.append(source)
            if report:
                from .fidelity import context_fidelity

                rows = context_fidelity(material, source, preview_opacity, meters_per_unit)
                measured[material.name] = rows[0]  # the universal context
                contexts_measured[material.name] = rows
                source.size = rows[0]
            elif "universal" in contexts:
                # The loss note a DCC shows says by how much (a few hundredths of a
                # CPU-second a constant material: two models' albedo by 4096 samples).
                from .fidelity import fidelity

                source.size = fidelity(material, source, preview_opacity)
            if progress is not None:
                progress(len(sources), count or len(sources), material.name)
        result = write(
            sources,
            out,
            contexts=contexts,
            mtlx_path=None if mtlx is None else Path(mtlx),
            package=package,
            split_dir=None if split is None else Path(split),
            workdir=Path(scratch),
            preview_opacity=preview_opacity,
            meters_per_unit=meters_per_unit,
            collect=collect,
            preview_geometry=preview_geometry,
            mtlx_surface=mtlx_surface,
        )
        result.fidelity = measured
        result.contexts_fidelity = contexts_measured
        return result


def loss_notes(
    material: Any, contexts: Sequence[str] | None = None, preview_opacity: str = "keep"
) -> dict[str, str]:
    """``{context: note}``: what each render context of an export of ``material`` (a
    blended material) could not express (``""``: nothing), as :func:`export_materials`
    would record it, without writing a stage. Layered materials bake their maps into a
    temporary folder that is removed afterwards.
    """
    import tempfile

    from .network import CONTEXTS
    from .sources import source_for
    from .writer import losses_of, material_spec

    contexts = tuple(contexts) if contexts else CONTEXTS
    from lookdev.materials.preview_surface import MODEL as PREVIEW

    if getattr(material, "model", None) == PREVIEW.name:  # proof --context universal's:
        return dict.fromkeys(contexts, "")  # it is an export's universal context already
    with tempfile.TemporaryDirectory(prefix="lookdev-losses-") as scratch:
        source = source_for(material, Path(scratch, "textures"), scratch=Path(scratch))
        spec = material_spec(source, contexts, preview_opacity)
        return losses_of([spec])[spec.name]
